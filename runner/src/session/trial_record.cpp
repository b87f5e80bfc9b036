// The stored trial record (trial_record.h).
#include "session/trial_record.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "atonlab/runner/session/scene_queries.h"
#include "atonlab/stimuli/glare_stage.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;
namespace st = atonlab::store;
/// Keys in the order written (nlohmann::json would sort them).
using Json = nlohmann::ordered_json;

namespace {

/// A time or rate as the stimulus column has always stored it: a whole value as
/// an integer ("60", not "60.0"; the record was once written with fmt's
/// shortest form and read back), so records of this and earlier versions, and
/// a resumed session's and an uninterrupted one's, hold the same text.
Json stored_number(double v) {
    if (std::isfinite(v) && v == std::trunc(v) && std::abs(v) < 1e15) return static_cast<std::int64_t>(v);
    return v;
}

Json frames_shown_json(const FramesShown& f) {
    Json j;
    j["refresh_hz"] = stored_number(f.refresh_hz);
    j["stimulus_frames"] = f.stimulus_frames;
    j["inter_stimulus_frames"] = f.inter_stimulus_frames;
    j["inter_trial_frames"] = f.inter_trial_frames;
    j["presented_s"] = stored_number(f.presented_s);
    Json shown = Json::array();
    for (const ShownStep& step : f.shown) {
        Json one;
        one["step"] = step.frame >= 0 ? "frame" + std::to_string(step.frame) : std::string("blank");
        one["onset_s"] = stored_number(step.onset_s);
        one["duration_s"] = stored_number(step.duration_s);
        one["flips"] = step.flips;
        one["dropped"] = step.dropped;
        shown.push_back(std::move(one));
    }
    j["shown"] = std::move(shown);
    return j;
}

}  // namespace

std::string view_glare(const s::Scene& sc, const std::string& light) {
    for (const s::Light& l : sc.lights)
        if (!light.empty() && (l.name == light || l.name.starts_with(light + "/")))
            return std::string(s::glare_model_name(s::light_glare_model(sc, l)));
    return std::string(s::glare_model_name(sc.glare.model));
}

std::string stimulus_json(const p::Protocol& protocol, const p::Condition& c, const p::ScheduledTrial& t,
                          const std::vector<double>& frame_times, const std::optional<FramesShown>& frames_shown,
                          const std::vector<std::string>& view_glares,
                          const std::vector<s::FramePlacements>& placements) {
    const p::Stimulus& stim = t.stimulus;
    Json j;
    j["task"] = std::string(p::to_string(c.task));
    j["presentation"] = std::string(p::to_string(c.presentation));
    j["level_key"] = c.level_key;
    j["level_scale"] = std::string(p::to_string(c.level_scale));
    j["level_on"] = std::string(p::to_string(c.level_on));
    j["level"] = stim.level;
    j["scene_value"] = stim.scene_value;
    j["scene"] = protocol.scene.string();
    Json frames = Json::array();
    for (std::size_t f = 0; f < stim.frames.size(); ++f) {
        const p::Frame& fr = stim.frames[f];
        Json frame;
        frame["role"] = fr.role ? std::string(p::to_string(*fr.role)) : std::string("both");
        frame["time_s"] = f < frame_times.size() ? frame_times[f] : 0.0;
        frame["overrides"] = fr.override_texts();
        if (f < placements.size()) {
            // Where its glare arithmetic ran (placement.h): "gpu", "cpu" or "none".
            Json where;
            where["veil"] = std::string(s::placement_name(placements[f].veil));
            where["psf_fft"] = std::string(s::placement_name(placements[f].psf_fft));
            frame["placement"] = std::move(where);
        }
        frames.push_back(std::move(frame));
    }
    j["frames"] = std::move(frames);
    Json views = Json::array();
    for (std::size_t i = 0; i < stim.views.size(); ++i) {
        const p::StimulusView& v = stim.views[i];
        Json view;
        view["frame"] = v.frame;
        view["light"] = v.light;
        view["role"] = std::string(p::to_string(v.role));
        if (i < view_glares.size()) view["glare"] = view_glares[i];
        views.push_back(std::move(view));
    }
    j["views"] = std::move(views);
    if (stim.adjusted_view) j["adjusted_view"] = *stim.adjusted_view;
    const p::Timing& tm = protocol.timing;
    // The durations asked for (s) and, in "frames", what the flips gave:
    // whole refreshes at the measured (on screen) or nominal (headless) rate.
    Json timing;
    timing["stimulus_s"] = tm.stimulus_s;
    timing["inter_stimulus_s"] = tm.inter_stimulus_s;
    timing["inter_trial_s"] = tm.inter_trial_s;
    timing["frames"] = frames_shown ? frames_shown_json(*frames_shown) : Json(nullptr);
    j["timing"] = std::move(timing);
    return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

std::string state_json(const p::Schedule& schedule, const SessionObserver& observer, double answer_rt_s,
                       const std::optional<p::Response>& answer, const std::string& input, std::size_t step) {
    std::string json = state_json(schedule, observer.kind(), observer.seed(), answer_rt_s, answer, input, step);
    if (!observer.custom()) return json;
    Json j = Json::parse(json);
    j["observer_name"] = observer.custom_name();
    return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

std::string state_json(const p::Schedule& schedule, std::string_view observer_kind, std::uint64_t observer_seed,
                       double answer_rt_s, const std::optional<p::Response>& answer, const std::string& input,
                       std::size_t step) {
    Json j;
    j["schedule"] = schedule.state();
    j["observer"] = std::string(observer_kind);
    j["observer_seed"] = observer_seed;
    j["answer_after_offset_s"] = answer_rt_s;
    j["step"] = step;
    if (answer) j["answer"] = std::string(p::response_word(*answer));
    if (!input.empty()) j["input"] = input;
    return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

std::optional<std::uint64_t> logged_observer_seed(const std::vector<st::TrialRecord>& trials) {
    if (trials.empty()) return std::nullopt;
    // A state that does not parse, or has no unsigned observer_seed: none recorded.
    const Json j = Json::parse(trials.front().procedure_state_json, nullptr, false);
    if (!j.is_object()) return std::nullopt;
    const auto it = j.find("observer_seed");
    if (it == j.end() || !it->is_number_unsigned()) return std::nullopt;
    return it->get<std::uint64_t>();
}

st::TrialRecord trial_record(const p::Protocol& protocol, const p::ScheduledTrial& t, std::size_t row,
                             const TrialShown& shown, bool counted, const p::Schedule& schedule,
                             const SessionObserver& observer, StimulusRenderer& renderer) {
    const p::Condition& c = protocol.blocks[t.block].conditions[t.condition];
    std::vector<double> frame_times;
    std::vector<s::FramePlacements> placements;
    std::vector<std::string> view_glares(t.stimulus.views.size());
    for (std::size_t f = 0; f < t.stimulus.frames.size(); ++f) {
        const auto scene = renderer.scene(t.stimulus.frames[f].overrides);
        const s::Scene& sc = *scene;
        frame_times.push_back(brightest_moment_s(sc, judged_lights(t.stimulus, f), protocol.timing.stimulus_s));
        placements.push_back(s::frame_placements(sc, sc.display.width_px, sc.display.height_px));
        for (std::size_t v = 0; v < t.stimulus.views.size(); ++v)
            if (t.stimulus.views[v].frame == f) view_glares[v] = view_glare(sc, t.stimulus.views[v].light);
    }
    st::TrialRecord tr;
    tr.trial_index = static_cast<std::int64_t>(row);
    tr.block = static_cast<int>(t.block);
    tr.condition_id = t.condition_id;
    tr.procedure_id = t.procedure_id;
    tr.level = t.proposal.level;
    tr.test_on_left = t.proposal.test_on_left;
    tr.stimulus_json = stimulus_json(protocol, c, t, frame_times, shown.frames, view_glares, placements);
    tr.response = counted ? std::string(p::response_word(*shown.response))
                          : std::string(shown.end == TrialEnd::timeout ? p::kTimeoutWord : p::kMissedWord);
    if (t.task == p::Task::Adjust) tr.response_value = t.stimulus.scene_value;
    tr.response_time_s = std::max(0.0, shown.response_time_s);  // onset to answer
    tr.onset_time_s = shown.onset_s;
    tr.dropped_frames = shown.dropped_frames;
    tr.missed_deadline = shown.missed_deadline;
    tr.procedure_state_json =
        state_json(schedule, observer, shown.answer_after_offset_s, shown.response, shown.input, t.step);
    return tr;
}

}  // namespace atonlab::runner
