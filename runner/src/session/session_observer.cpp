// The session's observer and what it is shown (session_observer.h).
#include "atonlab/runner/session/session_observer.h"

#include <fmt/format.h>

#include "atonlab/protocols/rng.h"
#include "atonlab/runner/session/scene_queries.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;

p::Shown shown_for(const p::ScheduledTrial& t, StimulusRenderer& renderer,
                   std::vector<std::shared_ptr<const FrameViews>>& frames) {
    frames.assign(t.stimulus.frames.size(), nullptr);
    p::Shown shown;
    shown.task = t.task;
    shown.adjusted_view = t.stimulus.adjusted_view;
    for (std::size_t f = 0; f < frames.size(); ++f)
        frames[f] = renderer.views(t.stimulus.frames[f], judged_lights(t.stimulus, f));
    std::vector<std::size_t> seen(frames.size(), 0);
    for (const p::StimulusView& v : t.stimulus.views) {
        const LightWindow& w = frames[v.frame]->windows[seen[v.frame]++];
        shown.views.push_back(p::View{&w.image, w.light_px});
    }
    return shown;
}

SessionObserver::SessionObserver(const RunOptions& o, std::uint64_t observer_seed,
                                 std::optional<p::ScriptedObserver> script, p::ModelObserverParams params)
    : model_(o.model_observer && !o.custom_observer),
      seed_(observer_seed),
      params_(params),
      script_(std::move(script)),
      custom_(o.custom_observer),
      custom_name_(o.custom_observer_name) {}

std::string_view SessionObserver::kind() const noexcept {
    if (model_) return "model";
    if (custom_) return "custom";
    return script_ ? "script" : "person";
}

p::Answer SessionObserver::answer(const p::ScheduledTrial& t, StimulusRenderer* renderer) {
    if (custom_) {
        std::vector<std::shared_ptr<const FrameViews>> frames;
        return custom_(t, shown_for(t, *renderer, frames));
    }
    if (!model_) return script_->answer(p::Shown{t.task, {}, t.stimulus.adjusted_view});
    const std::string match = fmt::format("{}#{}", t.procedure_id, t.proposal.trial);
    if (!current_ || t.task != p::Task::Adjust || match != match_) {
        current_ = std::make_unique<p::ModelObserver>(params_, p::derive_seed(seed_, t.step));
        match_ = match;
    }
    std::vector<std::shared_ptr<const FrameViews>> frames;
    return current_->answer(shown_for(t, *renderer, frames));
}

}  // namespace atonlab::runner
