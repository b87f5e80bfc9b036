// The session's closing summary (summary.h).
#include "atonlab/runner/session/summary.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "atonlab/runner/session/true_value.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;

std::vector<ConditionSummary> summarise(const p::Protocol& protocol, const p::Schedule& schedule,
                                        StimulusRenderer* renderer, const SessionObserver& observer,
                                        bool compute_true) {
    std::map<std::string, ConditionSummary> by_name;
    for (const p::TrackResult& r : schedule.results()) {
        ConditionSummary& row = by_name[r.condition_id];
        ++row.n_tracks;
        row.finished += r.finished ? 1 : 0;
        row.responses += r.responses;
        if (std::isfinite(r.estimate.value)) row.tracks.push_back(r.estimate.value);
        if (row.method.empty()) row.method = r.estimate.method;
    }
    std::vector<ConditionSummary> out;
    for (const p::Block& b : protocol.blocks) {
        for (const p::Condition& c : b.conditions) {
            const auto it = by_name.find(c.name);
            if (it == by_name.end()) continue;
            ConditionSummary row = it->second;
            row.condition = c.name;
            if (!row.tracks.empty())
                row.estimate =
                    std::accumulate(row.tracks.begin(), row.tracks.end(), 0.0) / static_cast<double>(row.tracks.size());
            if (compute_true && renderer) {
                double v = 0.0;
                row.true_value_why = true_value(*renderer, protocol, c, observer.params(), v);
                if (row.true_value_why.empty()) {
                    const std::optional<double> pt = c.procedure.target_p_yes();
                    const bool pse = c.task != p::Task::YesNo && pt && *pt == 0.5;
                    row.true_value = v;
                    row.true_kind = pse ? "PSE" : fmt::format("level at P = {:.3f}", *pt);
                }
            }
            out.push_back(std::move(row));
        }
    }
    return out;
}

void print_summary(const std::vector<ConditionSummary>& rows) {
    std::printf("\nper condition (levels in the procedure's units):\n");
    for (const ConditionSummary& row : rows) {
        std::string est = "no estimate";
        if (row.estimate) {
            std::string each;
            for (const double v : row.tracks) each += fmt::format("{}{:.3f}", each.empty() ? "" : ", ", v);
            est = fmt::format("{:.3f}", *row.estimate);
            if (row.tracks.size() > 1) est += fmt::format(" (tracks {})", each);
        }
        std::string truth;
        if (row.true_value) {
            truth = fmt::format("; model's true {} {:.3f}", row.true_kind, *row.true_value);
            if (row.estimate) truth += fmt::format(" (estimate − true = {:+.3f})", *row.estimate - *row.true_value);
        } else if (!row.true_value_why.empty()) {
            truth = "; true value: " + row.true_value_why;
        }
        std::printf("  %-24s %s [%s; %zu of %zu tracks finished, %zu responses]%s\n", row.condition.c_str(),
                    est.c_str(), row.method.c_str(), row.finished, row.n_tracks, row.responses, truth.c_str());
    }
}

}  // namespace atonlab::runner
