#pragma once
// Who answers a session's trials: the model observer (on the frames the
// renderer makes), a script, or a person at the screen.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/runner/session/run_options.h"
#include "atonlab/runner/session/stimulus_renderer.h"

namespace atonlab::runner {

/// What the observer is shown in trial t: each view's window of its rendered
/// frame (rendered or from the cache). `frames` keeps the frames alive while
/// the returned Shown points into them.
protocols::Shown shown_for(const protocols::ScheduledTrial& t, StimulusRenderer& renderer,
                           std::vector<std::shared_ptr<const FrameViews>>& frames);

/// A model observer's answers are a pure function of (observer seed, the
/// trial's first step, what it was shown): each trial (each adjustment match)
/// gets a fresh ModelObserver seeded derive_seed(observer_seed, step), so a
/// resumed session answers exactly as an uninterrupted one would have.
class SessionObserver {
public:
    /// params: the model observer's (the protocol's [observer] table; ignored
    /// unless o.model_observer).
    SessionObserver(const RunOptions& o, std::uint64_t observer_seed, std::optional<protocols::ScriptedObserver> script,
                    protocols::ModelObserverParams params = {});

    bool model() const noexcept { return model_; }
    bool custom() const noexcept { return static_cast<bool>(custom_); }       ///< RunOptions::custom_observer answers
    bool person() const noexcept { return !model_ && !script_ && !custom_; }  ///< a person answers at the screen
    /// What the trials store as the observer's kind: "model", "custom", "script" or "person".
    std::string_view kind() const noexcept;
    const std::string& custom_name() const noexcept { return custom_name_; }
    std::uint64_t seed() const noexcept { return seed_; }
    const protocols::ModelObserverParams& params() const noexcept { return params_; }

    /// The answer to trial `t`. Renders what the model observer looks at.
    protocols::Answer answer(const protocols::ScheduledTrial& t, StimulusRenderer* renderer);

    /// A scripted observer skips the lines the logged trials used.
    void skip(protocols::Task task, std::optional<std::size_t> adjusted_view) {
        if (script_) script_->answer(protocols::Shown{task, {}, adjusted_view});
    }

private:
    bool model_;
    std::uint64_t seed_;
    protocols::ModelObserverParams params_{};
    std::optional<protocols::ScriptedObserver> script_;
    std::function<protocols::Answer(const protocols::ScheduledTrial&, const protocols::Shown&)> custom_;
    std::string custom_name_;
    std::unique_ptr<protocols::ModelObserver> current_;
    std::string match_;
};

}  // namespace atonlab::runner
