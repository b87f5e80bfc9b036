// The session's closing summary (summary.h).
#include "session/summary.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "session/true_value.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;

void print_summary(const p::Protocol& protocol, const p::Schedule& schedule, StimulusRenderer* renderer,
                   const SessionObserver& observer, bool compute_true) {
    struct Row {
        std::vector<double> values;
        std::string method;
        std::size_t tracks = 0, finished = 0, responses = 0;
    };
    std::map<std::string, Row> rows;
    for (const p::TrackResult& r : schedule.results()) {
        Row& row = rows[r.condition_id];
        ++row.tracks;
        row.finished += r.finished ? 1 : 0;
        row.responses += r.responses;
        if (std::isfinite(r.estimate.value)) row.values.push_back(r.estimate.value);
        if (row.method.empty()) row.method = r.estimate.method;
    }
    std::printf("\nper condition (levels in the procedure's units):\n");
    for (const p::Block& b : protocol.blocks) {
        for (const p::Condition& c : b.conditions) {
            const auto it = rows.find(c.name);
            if (it == rows.end()) continue;
            const Row& row = it->second;
            std::string est = "no estimate";
            if (!row.values.empty()) {
                const double mean =
                    std::accumulate(row.values.begin(), row.values.end(), 0.0) / static_cast<double>(row.values.size());
                std::string each;
                for (const double v : row.values) each += fmt::format("{}{:.3f}", each.empty() ? "" : ", ", v);
                est = fmt::format("{:.3f}", mean);
                if (row.values.size() > 1) est += fmt::format(" (tracks {})", each);
            }
            std::string truth;
            if (compute_true && renderer) {
                double v = 0.0;
                const std::string why = true_value(*renderer, protocol, c, observer.params(), v);
                if (why.empty()) {
                    const std::optional<double> pt = c.procedure.target_p_yes();
                    const bool pse = c.task != p::Task::YesNo && pt && *pt == 0.5;
                    truth = fmt::format("; model's true {} {:.3f}",
                                        pse ? "PSE" : fmt::format("level at P = {:.3f}", *pt), v);
                    if (!row.values.empty())
                        truth += fmt::format(" (estimate − true = {:+.3f})",
                                             std::accumulate(row.values.begin(), row.values.end(), 0.0) /
                                                     static_cast<double>(row.values.size()) -
                                                 v);
                } else {
                    truth = "; true value: " + why;
                }
            }
            std::printf("  %-24s %s [%s; %zu of %zu tracks finished, %zu responses]%s\n", c.name.c_str(), est.c_str(),
                        row.method.c_str(), row.finished, row.tracks, row.responses, truth.c_str());
        }
    }
}

}  // namespace atonlab::runner
