#pragma once
// Keyboard and gamepad input of the full-screen runner (docs/running.md,
// "Keys"): GLFW's key codes and standard-gamepad buttons under the names a
// protocol's [responses.keys] / [responses.gamepad] use
// (docs/protocol-file.md), timestamped events, and the press detection for
// gamepads (GLFW reports their state, not events). Pure: no window needed.
#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/protocols/protocol.h"

namespace atonlab::present {

/// One press of a key or a gamepad button.
struct InputEvent {
    enum class Source : std::uint8_t { keyboard, gamepad };
    Source source = Source::keyboard;
    std::string name;     ///< the protocol's name ("left", "space", "dpad_up", ...)
    double time_s = 0.0;  ///< when it was seen, on the presenter's clock (s)
};

/// The protocol's name of a GLFW key code (GLFW_KEY_*), nullopt for a key it has no name for.
std::optional<std::string_view> key_name(int glfw_key);
/// The GLFW key code of a protocol key name, nullopt for an unknown name.
std::optional<int> glfw_key(std::string_view name);

/// GLFW's standard gamepad has 15 buttons (GLFW_GAMEPAD_BUTTON_LAST + 1).
inline constexpr std::size_t kGamepadButtons = 15;
using GamepadButtons = std::array<unsigned char, kGamepadButtons>;  ///< GLFW_PRESS (1) or GLFW_RELEASE (0) each
/// The protocol's name of GLFW_GAMEPAD_BUTTON_i.
std::string_view gamepad_button_name(std::size_t index);
/// The buttons pressed between two polled states (up before, down now), in button order.
std::vector<std::string_view> newly_pressed(const GamepadButtons& before, const GamepadButtons& now);

/// What an event means on the screen the runner shows.
enum class InputContext : std::uint8_t {
    trial,   ///< a trial of a task: its answers, or quit
    screen,  ///< a text screen: continue or quit
    pause,   ///< the pause screen: continue (go on) or quit (end the session)
};

/// The action of an event in a context (keys and gamepad buttons as the
/// protocol binds them); nullopt when it means nothing there.
std::optional<protocols::Action> action_of(const protocols::ResponseMap& map, InputContext context,
                                           protocols::Task task, const InputEvent& event);

/// Events in arrival order; the presenter's callbacks push, the session takes.
class InputQueue {
public:
    void push(InputEvent e) { events_.push_back(std::move(e)); }
    bool empty() const noexcept { return events_.empty(); }
    std::size_t size() const noexcept { return events_.size(); }
    /// Drops every event seen before t_s (a key pressed before the screen that takes it).
    void drop_before(double t_s);
    void clear() { events_.clear(); }
    /// The first event (at or after since_s) for which accept() holds; it and
    /// every event before it are removed.
    template <class Accept>
    std::optional<InputEvent> take_first(double since_s, Accept accept) {
        for (std::size_t i = 0; i < events_.size(); ++i) {
            if (events_[i].time_s < since_s || !accept(events_[i])) continue;
            InputEvent e = events_[i];
            events_.erase(events_.begin(), events_.begin() + static_cast<std::ptrdiff_t>(i) + 1);
            return e;
        }
        return std::nullopt;
    }
    /// The first event (at or after since_s) for which accept() holds, left in place.
    template <class Accept>
    const InputEvent* find(double since_s, Accept accept) const {
        for (const InputEvent& e : events_)
            if (e.time_s >= since_s && accept(e)) return &e;
        return nullptr;
    }

private:
    std::deque<InputEvent> events_;
};

}  // namespace atonlab::present
