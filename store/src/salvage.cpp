// Store::salvage(): what SQLite can still read of a damaged study file, row by
// row (docs/store.md, "Damaged files").
#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "store_impl.h"

namespace atonlab::store {
namespace {

// The largest row id of `table`, or std::nullopt when even that cannot be read.
std::optional<std::int64_t> largest_id(sql::Connection& db, const char* sql, std::vector<std::string>& problems,
                                       const char* what) {
    try {
        sql::Statement s(db, sql);
        if (!s.step(fmt::format("find the largest {} row id", what))) return 0;
        return s.is_null(0) ? 0 : s.int64(0);
    } catch (const StoreError& e) {
        problems.push_back(fmt::format("the {} table cannot be read at all: {}", what, e.what()));
        return std::nullopt;
    }
}

}  // namespace

Salvage Store::salvage() const {
    sql::Connection& db = *impl_->db;
    Salvage out;

    // Sessions, one row id at a time; the trial count is of the trials read below.
    if (const auto last = largest_id(db, "SELECT max(id) FROM sessions", out.problems, "sessions")) {
        // displayability_json NULL: a damaged file may be of a schema before it
        // (v4); the scene's hash and name where the file has them (v6).
        const bool scenes = file_schema_version() >= 6;
        sql::Statement s(db, scenes ? "SELECT s.id, o.code, s.protocol_id, p.name, p.sha256, s.software_version, "
                                      "s.seed, s.calibration_id, s.started_at, s.ended_at, s.status, s.resume_count, "
                                      "0, NULL, sc.sha256, sc.name "
                                      "FROM sessions s JOIN observers o ON o.id = s.observer_id "
                                      "JOIN protocols p ON p.id = s.protocol_id "
                                      "LEFT JOIN scenes sc ON sc.id = s.scene_id WHERE s.id = ?1"
                                    : "SELECT s.id, o.code, s.protocol_id, p.name, p.sha256, s.software_version, "
                                      "s.seed, s.calibration_id, s.started_at, s.ended_at, s.status, s.resume_count, "
                                      "0, NULL, NULL, NULL "
                                      "FROM sessions s JOIN observers o ON o.id = s.observer_id "
                                      "JOIN protocols p ON p.id = s.protocol_id WHERE s.id = ?1");
        for (std::int64_t id = 1; id <= *last; ++id) {
            try {
                s.bind(1, id);
                if (s.step("read a session")) {
                    out.sessions.push_back(session_from_row(s, db.path()));
                } else {
                    ++out.unreadable_sessions;
                }
            } catch (const StoreError&) {
                ++out.unreadable_sessions;
            }
            s.reset();
        }
    }

    // Trials, by row id: the table's b-tree only, not the (session, index) index.
    if (const auto last = largest_id(db, "SELECT max(id) FROM trials", out.problems, "trials")) {
        sql::Statement s(db,
                         "SELECT session_id, trial_index, block, condition_id, procedure_id, level, test_on_left, "
                         "stimulus_json, response, response_value, response_time_s, onset_time_s, dropped_frames, "
                         "missed_deadline, procedure_state_json, recorded_at FROM trials WHERE id = ?1");
        for (std::int64_t id = 1; id <= *last; ++id) {
            try {
                s.bind(1, id);
                if (s.step("read a trial")) {
                    out.trials.push_back({SessionId{s.int64(0)}, trial_from_row(s, 1)});
                } else {
                    ++out.unreadable_trials;
                }
            } catch (const StoreError&) {
                ++out.unreadable_trials;
            }
            s.reset();
        }
    }
    std::stable_sort(out.trials.begin(), out.trials.end(), [](const SalvagedTrial& a, const SalvagedTrial& b) {
        return a.session != b.session ? a.session < b.session : a.trial.trial_index < b.trial.trial_index;
    });
    std::map<SessionId, std::int64_t> counts;
    for (const SalvagedTrial& t : out.trials) ++counts[t.session];
    for (SessionRecord& r : out.sessions) r.trial_count = counts[r.id];
    return out;
}

}  // namespace atonlab::store
