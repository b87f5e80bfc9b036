// Keys and gamepad buttons of the full-screen runner (present/include/atonlab/present/input.h):
// every key name a protocol may use has a GLFW key (and back), the protocol's
// bindings give the actions a task takes, gamepad presses are the up-to-down
// edges of the polled state, and the event queue hands out what a screen
// accepts in arrival order.
#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <set>

#include "atonlab/present/input.h"
#include "atonlab/protocols/protocol_file.h"

namespace atonlab::present {
namespace {

using protocols::Action;
using protocols::Task;

TEST(RunnerKeys, EveryProtocolKeyNameHasAGlfwKey) {
    // The names docs/protocol-file.md lists ("Key names").
    std::vector<std::string> names;
    for (char c = 'a'; c <= 'z'; ++c) names.emplace_back(1, c);
    for (char c = '0'; c <= '9'; ++c) names.emplace_back(1, c);
    for (int i = 1; i <= 12; ++i) names.push_back("f" + std::to_string(i));
    for (int i = 0; i <= 9; ++i) names.push_back("kp_" + std::to_string(i));
    for (const char* s :
         {"left",         "right",         "up",        "down",        "space",       "enter",     "escape",
          "backspace",    "tab",           "insert",    "delete",      "home",        "end",       "page_up",
          "page_down",    "kp_enter",      "kp_add",    "kp_subtract", "kp_multiply", "kp_divide", "kp_decimal",
          "comma",        "period",        "slash",     "semicolon",   "apostrophe",  "minus",     "equal",
          "left_bracket", "right_bracket", "backslash", "grave_accent"})
        names.emplace_back(s);
    std::set<int> codes;
    for (const std::string& n : names) {
        const auto code = glfw_key(n);
        ASSERT_TRUE(code.has_value()) << n;
        EXPECT_TRUE(codes.insert(*code).second) << n << " shares a key code";
        EXPECT_EQ(key_name(*code), n);
    }
    EXPECT_EQ(glfw_key("left"), GLFW_KEY_LEFT);
    EXPECT_EQ(glfw_key("a"), GLFW_KEY_A);
    EXPECT_EQ(glfw_key("7"), GLFW_KEY_7);
    EXPECT_EQ(glfw_key("f12"), GLFW_KEY_F12);
    EXPECT_EQ(glfw_key("kp_enter"), GLFW_KEY_KP_ENTER);
    EXPECT_EQ(glfw_key("enter"), GLFW_KEY_ENTER);
    EXPECT_FALSE(glfw_key("Left").has_value()) << "names are lower case";
    EXPECT_FALSE(key_name(GLFW_KEY_LEFT_SHIFT).has_value()) << "modifiers answer nothing";
}

TEST(RunnerKeys, GamepadPressesAreUpToDownEdges) {
    GamepadButtons before{}, now{};
    now[GLFW_GAMEPAD_BUTTON_A] = GLFW_PRESS;
    now[GLFW_GAMEPAD_BUTTON_DPAD_LEFT] = GLFW_PRESS;
    EXPECT_EQ(newly_pressed(before, now), (std::vector<std::string_view>{"a", "dpad_left"}));
    EXPECT_TRUE(newly_pressed(now, now).empty()) << "a held button is one press";
    before = now;
    now[GLFW_GAMEPAD_BUTTON_A] = GLFW_RELEASE;
    now[GLFW_GAMEPAD_BUTTON_RIGHT_BUMPER] = GLFW_PRESS;
    EXPECT_EQ(newly_pressed(before, now), (std::vector<std::string_view>{"right_bumper"}));
    EXPECT_EQ(gamepad_button_name(GLFW_GAMEPAD_BUTTON_START), "start");
    EXPECT_EQ(gamepad_button_name(GLFW_GAMEPAD_BUTTON_DPAD_UP), "dpad_up");
}

InputEvent key(std::string name, double t = 0.0) {
    return InputEvent{InputEvent::Source::keyboard, std::move(name), t};
}
InputEvent button(std::string name, double t = 0.0) {
    return InputEvent{InputEvent::Source::gamepad, std::move(name), t};
}

TEST(RunnerKeys, TheProtocolsBindingsGiveEachTasksActions) {
    const protocols::Protocol p = protocols::parse_protocol(R"(
[protocol]
scene = "s.toml"
seed = 1
[display]
width_px = 64
height_px = 64
width_m = 0.1
viewing_distance_m = 1.0
[responses.keys]
left = ["left", "1"]
[responses.gamepad]
left = "dpad_left"
right = "dpad_right"
continue = ["a", "start"]
quit = "back"
[[block]]
task = "2afc"
level_key = "light.a.intensity_cd"
procedure = { kind = "staircase", start = 1.0, n_trials = 2 }
[[block.condition]]
name = "c"
)",
                                                            "/tmp/input-test.toml");
    const auto& m = p.responses;
    EXPECT_EQ(action_of(m, InputContext::trial, Task::TwoAfc, key("1")), Action::Left);
    EXPECT_EQ(action_of(m, InputContext::trial, Task::TwoAfc, key("left")), Action::Left);
    EXPECT_EQ(action_of(m, InputContext::trial, Task::TwoAfc, key("right")), Action::Right);
    EXPECT_EQ(action_of(m, InputContext::trial, Task::TwoAfc, key("escape")), Action::Quit);
    EXPECT_EQ(action_of(m, InputContext::trial, Task::TwoAfc, key("y")), std::nullopt) << "yes is not a 2AFC answer";
    EXPECT_EQ(action_of(m, InputContext::trial, Task::YesNo, key("y")), Action::Yes);
    // The default adjustment keys: arrows up/down coarse, right/left fine, enter/space confirm.
    EXPECT_EQ(action_of(m, InputContext::trial, Task::Adjust, key("up")), Action::CoarseUp);
    EXPECT_EQ(action_of(m, InputContext::trial, Task::Adjust, key("left")), Action::FineDown);
    EXPECT_EQ(action_of(m, InputContext::trial, Task::Adjust, key("space")), Action::Confirm);
    EXPECT_EQ(action_of(m, InputContext::trial, Task::TwoAfc, button("dpad_right")), Action::Right);
    EXPECT_EQ(action_of(m, InputContext::trial, Task::TwoAfc, button("back")), Action::Quit);
    EXPECT_EQ(action_of(m, InputContext::trial, Task::TwoAfc, key("dpad_right")), std::nullopt)
        << "a key is not a button of the same name";
    EXPECT_EQ(action_of(m, InputContext::screen, Task::TwoAfc, key("space")), Action::Continue);
    EXPECT_EQ(action_of(m, InputContext::screen, Task::TwoAfc, key("enter")), Action::Continue);
    EXPECT_EQ(action_of(m, InputContext::screen, Task::TwoAfc, button("start")), Action::Continue);
    EXPECT_EQ(action_of(m, InputContext::pause, Task::TwoAfc, key("escape")), Action::Quit);
    EXPECT_EQ(action_of(m, InputContext::screen, Task::TwoAfc, key("left")), std::nullopt);
}

TEST(RunnerKeys, TheQueueHandsOutAcceptedEventsInOrder) {
    InputQueue q;
    q.push(key("a", 1.0));
    q.push(key("left", 2.0));
    q.push(key("b", 3.0));
    q.push(key("right", 4.0));
    auto arrow = [](const InputEvent& e) { return e.name == "left" || e.name == "right"; };
    ASSERT_NE(q.find(0.0, arrow), nullptr);
    EXPECT_EQ(q.find(2.5, arrow)->name, "right") << "events before `since` do not count";
    const auto first = q.take_first(0.0, arrow);
    ASSERT_TRUE(first.has_value());
    EXPECT_EQ(first->name, "left");
    EXPECT_EQ(first->time_s, 2.0);
    EXPECT_EQ(q.size(), 2u) << "the event and everything before it are gone";
    q.drop_before(3.5);
    EXPECT_EQ(q.size(), 1u);
    EXPECT_EQ(q.take_first(0.0, arrow)->name, "right");
    EXPECT_TRUE(q.empty());
}

}  // namespace
}  // namespace atonlab::present
