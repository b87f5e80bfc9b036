// The stored trial record (trial_record.h).
#include "session/trial_record.h"

#include <fmt/format.h>

#include <algorithm>

#include "atonlab/stimuli/glare_stage.h"
#include "json_text.h"
#include "session/scene_queries.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;
namespace st = atonlab::store;

std::string view_glare(const s::Scene& sc, const std::string& light) {
    for (const s::Light& l : sc.lights)
        if (!light.empty() && (l.name == light || l.name.starts_with(light + "/")))
            return std::string(s::glare_model_name(s::light_glare_model(sc, l)));
    return std::string(s::glare_model_name(sc.glare.model));
}

std::string stimulus_json(const p::Protocol& protocol, const p::Condition& c, const p::ScheduledTrial& t,
                          const std::vector<double>& frame_times, const std::string& frames_shown_json,
                          const std::vector<std::string>& view_glares) {
    const p::Stimulus& stim = t.stimulus;
    std::string j = "{";
    j += fmt::format("\"task\":{},\"presentation\":{},", json_string(p::to_string(c.task)),
                     json_string(p::to_string(c.presentation)));
    j += fmt::format("\"level_key\":{},\"level_scale\":{},\"level_on\":{},\"level\":{},\"scene_value\":{},",
                     json_string(c.level_key), json_string(p::to_string(c.level_scale)),
                     json_string(p::to_string(c.level_on)), json_number(stim.level), json_number(stim.scene_value));
    j += fmt::format("\"scene\":{},", json_string(protocol.scene.string()));
    j += "\"frames\":[";
    for (std::size_t f = 0; f < stim.frames.size(); ++f) {
        const p::Frame& fr = stim.frames[f];
        if (f) j += ',';
        j += fmt::format("{{\"role\":{},\"time_s\":{},\"overrides\":[",
                         fr.role ? json_string(p::to_string(*fr.role)) : std::string("\"both\""),
                         json_number(f < frame_times.size() ? frame_times[f] : 0.0));
        for (std::size_t i = 0; i < fr.overrides.size(); ++i) j += (i ? "," : "") + json_string(fr.overrides[i]);
        j += "]}";
    }
    j += "],\"views\":[";
    for (std::size_t i = 0; i < stim.views.size(); ++i) {
        const p::StimulusView& v = stim.views[i];
        j += fmt::format("{}{{\"frame\":{},\"light\":{},\"role\":{}", i ? "," : "", v.frame, json_string(v.light),
                         json_string(p::to_string(v.role)));
        if (i < view_glares.size()) j += fmt::format(",\"glare\":{}", json_string(view_glares[i]));
        j += '}';
    }
    j += "]";
    if (stim.adjusted_view) j += fmt::format(",\"adjusted_view\":{}", *stim.adjusted_view);
    const p::Timing& tm = protocol.timing;
    // The durations asked for (s) and, in "frames", what the flips gave:
    // whole refreshes at the measured (on screen) or nominal (headless) rate.
    j += fmt::format(",\"timing\":{{\"stimulus_s\":{},\"inter_stimulus_s\":{},\"inter_trial_s\":{},\"frames\":{}}}",
                     json_number(tm.stimulus_s), json_number(tm.inter_stimulus_s), json_number(tm.inter_trial_s),
                     frames_shown_json.empty() ? std::string("null") : frames_shown_json);
    return j + "}";
}

std::string state_json(const p::Schedule& schedule, const SessionObserver& observer, double answer_rt_s,
                       const std::optional<p::Response>& answer, const std::string& input, std::size_t step) {
    std::string j =
        fmt::format("{{\"schedule\":{},\"observer\":{},\"observer_seed\":{},\"answer_after_offset_s\":{},\"step\":{}",
                    json_string(schedule.state()),
                    json_string(observer.person()  ? "person"
                                : observer.model() ? "model"
                                                   : "script"),
                    observer.seed(), json_number(answer_rt_s), step);
    if (answer) j += fmt::format(",\"answer\":{}", json_string(p::response_word(*answer)));
    if (!input.empty()) j += fmt::format(",\"input\":{}", json_string(input));
    return j + "}";
}

std::optional<std::uint64_t> logged_observer_seed(const std::vector<st::TrialRecord>& trials) {
    if (trials.empty()) return std::nullopt;
    const std::string& j = trials.front().procedure_state_json;
    const std::string tag = "\"observer_seed\":";
    const auto at = j.find(tag);
    if (at == std::string::npos) return std::nullopt;
    std::size_t end = at + tag.size();
    std::uint64_t v = 0;
    bool any = false;
    for (; end < j.size() && j[end] >= '0' && j[end] <= '9'; ++end) {
        v = v * 10 + static_cast<std::uint64_t>(j[end] - '0');
        any = true;
    }
    return any ? std::optional<std::uint64_t>(v) : std::nullopt;
}

st::TrialRecord trial_record(const p::Protocol& protocol, const p::ScheduledTrial& t, std::size_t row,
                             const TrialShown& shown, bool counted, const p::Schedule& schedule,
                             const SessionObserver& observer, StimulusRenderer& renderer) {
    const p::Condition& c = protocol.blocks[t.block].conditions[t.condition];
    std::vector<double> frame_times;
    std::vector<std::string> view_glares(t.stimulus.views.size());
    for (std::size_t f = 0; f < t.stimulus.frames.size(); ++f) {
        const s::Scene sc = renderer.scene(t.stimulus.frames[f].overrides);
        frame_times.push_back(brightest_moment_s(sc, judged_lights(t.stimulus, f), protocol.timing.stimulus_s));
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
    tr.stimulus_json = stimulus_json(protocol, c, t, frame_times, shown.timing_json, view_glares);
    tr.response = counted ? std::string(p::response_word(*shown.response))
                          : std::string(shown.end == TrialEnd::timeout ? "timeout" : "missed");
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
