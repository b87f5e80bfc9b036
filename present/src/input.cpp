// Key and gamepad names (input.h). The names are the protocol file's
// (protocols/src/protocol_file.cpp, docs/protocol-file.md "Key names"); the
// codes are GLFW's, which name keys by their place on a US layout.
#include "atonlab/present/input.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <utility>

namespace atonlab::present {
namespace {

const std::vector<std::pair<std::string, int>>& key_table() {
    static const std::vector<std::pair<std::string, int>> table = [] {
        std::vector<std::pair<std::string, int>> t;
        for (int c = 0; c < 26; ++c) t.emplace_back(std::string(1, static_cast<char>('a' + c)), GLFW_KEY_A + c);
        for (int c = 0; c < 10; ++c) t.emplace_back(std::string(1, static_cast<char>('0' + c)), GLFW_KEY_0 + c);
        for (int i = 1; i <= 12; ++i) t.emplace_back("f" + std::to_string(i), GLFW_KEY_F1 + i - 1);
        for (int i = 0; i <= 9; ++i) t.emplace_back("kp_" + std::to_string(i), GLFW_KEY_KP_0 + i);
        const std::pair<const char*, int> named[] = {
            {"left", GLFW_KEY_LEFT},
            {"right", GLFW_KEY_RIGHT},
            {"up", GLFW_KEY_UP},
            {"down", GLFW_KEY_DOWN},
            {"space", GLFW_KEY_SPACE},
            {"enter", GLFW_KEY_ENTER},
            {"escape", GLFW_KEY_ESCAPE},
            {"backspace", GLFW_KEY_BACKSPACE},
            {"tab", GLFW_KEY_TAB},
            {"insert", GLFW_KEY_INSERT},
            {"delete", GLFW_KEY_DELETE},
            {"home", GLFW_KEY_HOME},
            {"end", GLFW_KEY_END},
            {"page_up", GLFW_KEY_PAGE_UP},
            {"page_down", GLFW_KEY_PAGE_DOWN},
            {"kp_enter", GLFW_KEY_KP_ENTER},
            {"kp_add", GLFW_KEY_KP_ADD},
            {"kp_subtract", GLFW_KEY_KP_SUBTRACT},
            {"kp_multiply", GLFW_KEY_KP_MULTIPLY},
            {"kp_divide", GLFW_KEY_KP_DIVIDE},
            {"kp_decimal", GLFW_KEY_KP_DECIMAL},
            {"comma", GLFW_KEY_COMMA},
            {"period", GLFW_KEY_PERIOD},
            {"slash", GLFW_KEY_SLASH},
            {"semicolon", GLFW_KEY_SEMICOLON},
            {"apostrophe", GLFW_KEY_APOSTROPHE},
            {"minus", GLFW_KEY_MINUS},
            {"equal", GLFW_KEY_EQUAL},
            {"left_bracket", GLFW_KEY_LEFT_BRACKET},
            {"right_bracket", GLFW_KEY_RIGHT_BRACKET},
            {"backslash", GLFW_KEY_BACKSLASH},
            {"grave_accent", GLFW_KEY_GRAVE_ACCENT},
        };
        for (const auto& [name, code] : named) t.emplace_back(name, code);
        return t;
    }();
    return table;
}

// GLFW_GAMEPAD_BUTTON_A ... GLFW_GAMEPAD_BUTTON_DPAD_LEFT, in GLFW's order.
constexpr std::string_view kButtonNames[kGamepadButtons] = {
    "a",     "b",          "x",           "y",       "left_bumper", "right_bumper", "back",     "start",
    "guide", "left_thumb", "right_thumb", "dpad_up", "dpad_right",  "dpad_down",    "dpad_left"};
static_assert(kGamepadButtons == GLFW_GAMEPAD_BUTTON_LAST + 1);

bool bound(const std::vector<std::string>& names, std::string_view name) {
    return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

std::optional<std::string_view> key_name(int code) {
    for (const auto& [name, c] : key_table())
        if (c == code) return std::string_view(name);
    return std::nullopt;
}

std::optional<int> glfw_key(std::string_view name) {
    for (const auto& [n, c] : key_table())
        if (n == name) return c;
    return std::nullopt;
}

std::string_view gamepad_button_name(std::size_t index) {
    return index < kGamepadButtons ? kButtonNames[index] : std::string_view();
}

std::vector<std::string_view> newly_pressed(const GamepadButtons& before, const GamepadButtons& now) {
    std::vector<std::string_view> out;
    for (std::size_t i = 0; i < kGamepadButtons; ++i)
        if (now[i] == GLFW_PRESS && before[i] != GLFW_PRESS) out.push_back(kButtonNames[i]);
    return out;
}

std::optional<protocols::Action> action_of(const protocols::ResponseMap& map, InputContext context,
                                           protocols::Task task, const InputEvent& e) {
    using protocols::Action;
    const bool key = e.source == InputEvent::Source::keyboard;
    if (context == InputContext::trial) return key ? map.key_action(task, e.name) : map.button_action(task, e.name);
    // Screens (and the pause screen): continue or quit.
    auto names = [&](Action a) -> const std::vector<std::string>& { return key ? map.keys_of(a) : map.buttons_of(a); };
    if (bound(names(Action::Continue), e.name)) return Action::Continue;
    if (bound(names(Action::Quit), e.name)) return Action::Quit;
    return std::nullopt;
}

void InputQueue::drop_before(double t_s) {
    while (!events_.empty() && events_.front().time_s < t_s) events_.pop_front();
}

}  // namespace atonlab::present
