// Store::salvage(): what SQLite can still read of a damaged study file, row by
// row (docs/store.md, "Damaged files").
#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "atonlab/store/schema.h"
#include "constraints.h"
#include "schema_check.h"
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

// Why a row that is not read was left out.
std::string unreadable(const StoreError& e) {
    return fmt::format("cannot be read (SQLite: {})",
                       e.sqlite_code() != 0 ? sqlite3_errstr(e.sqlite_code()) : e.what());
}
constexpr const char* kAbsent = "cannot be found (its page is lost, or the row was never written)";

// The constraints of `table` as a column of a query over it, by row id (a
// correlated subquery, so the query may join other tables).
std::string broken_column(const detail::TableConstraints& c, const char* table, const char* id) {
    return fmt::format("(SELECT {} FROM {} WHERE rowid = {})", c.which, table, id);
}

// The constraints a row of `table` is judged by: the CHECKs atonlab's own
// migrations wrote for the file's version, so that a file whose schema was
// altered (a CHECK weakened, removed) does not let through rows the analysis
// assumes cannot exist; the file's own where atonlab's cannot be evaluated
// on it (a column they name was removed).
detail::TableConstraints constraints_for(sql::Connection& db, const char* table, int version) {
    if (version >= 1 && version <= schema_version()) {
        if (const auto own = detail::reference_table_sql(schema_migrations(), version, table)) {
            try {
                detail::TableConstraints c = detail::table_constraints(db, table, *own);
                sql::Statement probe(db, fmt::format("SELECT {} FROM {} LIMIT 0", c.which, table));
                return c;
            } catch (const StoreError&) {
                // fall back to the file's own constraints
            }
        }
    }
    return detail::table_constraints(db, table);
}

}  // namespace

Salvage Store::salvage() const {
    sql::Connection& db = *impl_->db;
    Salvage out;

    // A row that breaks its table's CHECK or NOT NULL constraints (a value
    // overwritten inside its record) is left out and named, as is one that
    // cannot be read or found.
    const auto skip = [&out](const char* table, std::int64_t id, std::string why, std::int64_t& count) {
        ++count;
        out.skipped.push_back({table, id, std::move(why)});
    };

    // Sessions, one row id at a time; the trial count is of the trials read below.
    if (const auto last = largest_id(db, "SELECT max(id) FROM sessions", out.problems, "sessions")) {
        const detail::TableConstraints c = constraints_for(db, "sessions", file_schema_version());
        // displayability_json NULL: a damaged file may be of a schema before it (v4); the
        // scene's hash and name where the file has them (v6); last, the first constraint the
        // row breaks (NULL when none).
        const bool scenes = file_schema_version() >= 6;
        sql::Statement s(
            db, fmt::format("SELECT s.id, o.code, s.protocol_id, p.name, p.sha256, s.software_version, s.seed, "
                            "s.calibration_id, s.started_at, s.ended_at, s.status, s.resume_count, 0, NULL, {}, {} "
                            "FROM sessions s JOIN observers o ON o.id = s.observer_id "
                            "JOIN protocols p ON p.id = s.protocol_id {}WHERE s.id = ?1",
                            scenes ? "sc.sha256, sc.name" : "NULL, NULL", broken_column(c, "sessions", "s.id"),
                            scenes ? "LEFT JOIN scenes sc ON sc.id = s.scene_id " : ""));
        for (std::int64_t id = 1; id <= *last; ++id) {
            try {
                s.bind(1, id);
                if (!s.step("read a session")) {
                    skip("sessions", id, kAbsent, out.unreadable_sessions);
                } else if (!s.is_null(16)) {
                    skip("sessions", id, "breaks " + c.names.at(static_cast<std::size_t>(s.int64(16))),
                         out.unreadable_sessions);
                } else {
                    out.sessions.push_back(session_from_row(s, db.path()));
                }
            } catch (const StoreError& e) {
                skip("sessions", id, unreadable(e), out.unreadable_sessions);
            }
            s.reset();
        }
    }

    // Trials, by row id: the table's b-tree only, not the (session, index) index.
    if (const auto last = largest_id(db, "SELECT max(id) FROM trials", out.problems, "trials")) {
        const detail::TableConstraints c = constraints_for(db, "trials", file_schema_version());
        sql::Statement s(db, fmt::format("SELECT session_id, trial_index, block, condition_id, procedure_id, level, "
                                         "test_on_left, stimulus_json, response, response_value, response_time_s, "
                                         "onset_time_s, dropped_frames, missed_deadline, procedure_state_json, "
                                         "recorded_at, {} FROM trials WHERE id = ?1",
                                         c.which));
        for (std::int64_t id = 1; id <= *last; ++id) {
            try {
                s.bind(1, id);
                if (!s.step("read a trial")) {
                    skip("trials", id, kAbsent, out.unreadable_trials);
                } else if (!s.is_null(16)) {
                    skip("trials", id, "breaks " + c.names.at(static_cast<std::size_t>(s.int64(16))),
                         out.unreadable_trials);
                } else {
                    out.trials.push_back({SessionId{s.int64(0)}, trial_from_row(s, 1)});
                }
            } catch (const StoreError& e) {
                skip("trials", id, unreadable(e), out.unreadable_trials);
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
