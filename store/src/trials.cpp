// Trials: one committed transaction per response, and reading them back.
#include <fmt/format.h>

#include <cmath>

#include "store_impl.h"

namespace atonlab::store {
namespace {

// Checks that need no database, so a bad value never starts a transaction.
// SQLite would store a NaN as NULL, so finiteness is checked here.
std::string why_invalid(const TrialRecord& t) {
    if (t.trial_index < 0) return "trial_index is negative";
    if (t.block < 0) return "block is negative";
    if (t.condition_id.empty()) return "condition_id is empty";
    if (t.procedure_id.empty()) return "procedure_id is empty";
    if (!std::isfinite(t.level)) return "level is not finite";
    if (t.response.empty()) return "response is empty";
    if (t.response_value && !std::isfinite(*t.response_value)) return "response_value is not finite";
    if (!std::isfinite(t.response_time_s) || t.response_time_s < 0.0) {
        return "response_time_s is not a finite, non-negative number of seconds";
    }
    if (!std::isfinite(t.onset_time_s)) return "onset_time_s is not finite";
    if (t.dropped_frames < 0) return "dropped_frames is negative";
    return {};
}

}  // namespace

// The body of record_trial's and record_trials' transactions.
void Store::Impl::insert_trial(SessionId session, const TrialRecord& t, const std::string& doing) {
    Impl& impl = *this;
    {
        // The session must be running, the index must be the next one (no gap,
        // no overwrite), and the JSON must parse: all checked under the write
        // lock, so two writers cannot both take the same index.
        sql::Use s(db->cached("SELECT s.status, "
                             "coalesce((SELECT max(trial_index) FROM trials WHERE session_id = s.id), -1) + 1, "
                             "json_valid(?2), json_valid(?3) FROM sessions s WHERE s.id = ?1"));
        s->bind(1, session.value);
        s->bind(2, t.stimulus_json);
        s->bind(3, t.procedure_state_json);
        if (!s->step(doing)) impl.not_found(doing, fmt::format("session {}", session.value));
        const std::string status = s->text(0);
        if (status != "running") {
            impl.invalid(doing, fmt::format("session {} is {}, not running", session.value, status));
        }
        if (const std::int64_t next = s->int64(1); next != t.trial_index) {
            impl.invalid(doing, fmt::format("the session's next trial index is {}", next));
        }
        if (s->int64(2) != 1) impl.invalid(doing, "stimulus_json is not valid JSON");
        if (s->int64(3) != 1) impl.invalid(doing, "procedure_state_json is not valid JSON");
    }
    sql::Use s(db->cached(
        "INSERT INTO trials (session_id, trial_index, block, condition_id, procedure_id, level, test_on_left, "
        "stimulus_json, response, response_value, response_time_s, onset_time_s, dropped_frames, "
        "missed_deadline, procedure_state_json, recorded_at) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, " ATONLAB_STORE_NOW ")"));
    s->bind(1, session.value);
    s->bind(2, t.trial_index);
    s->bind(3, t.block);
    s->bind(4, t.condition_id);
    s->bind(5, t.procedure_id);
    s->bind(6, t.level);
    if (t.test_on_left) {
        s->bind(7, *t.test_on_left ? 1 : 0);
    } else {
        s->bind_null(7);
    }
    s->bind(8, t.stimulus_json);
    s->bind(9, t.response);
    s->bind(10, t.response_value);
    s->bind(11, t.response_time_s);
    s->bind(12, t.onset_time_s);
    s->bind(13, t.dropped_frames);
    s->bind(14, t.missed_deadline ? 1 : 0);
    s->bind(15, t.procedure_state_json);
    s->run(doing);
}

namespace {

/// A disk-full error says what was kept.
[[noreturn]] void rethrow_disk_full(const StoreError& e, std::string_view what_was_not_stored) {
    // The transaction was rolled back before any commit record reached the WAL.
    throw StoreError(e.kind(), e.file(),
                     fmt::format("{}; {} not stored, and the trials stored before {} intact", e.what(),
                                 what_was_not_stored, what_was_not_stored == "this trial was" ? "it are" : "them are"),
                     e.sqlite_code());
}

}  // namespace

void Store::record_trial(SessionId session, const TrialRecord& t) {
    const std::string doing = fmt::format("record trial {} of session {}", t.trial_index, session.value);
    impl_->require_writable(doing);
    if (const std::string why = why_invalid(t); !why.empty()) impl_->invalid(doing, why);
    try {
        sql::Transaction tx(*impl_->db, sql::Transaction::Kind::write, doing);
        impl_->insert_trial(session, t, doing);
        tx.commit();  // synchronous=FULL: the WAL is on disk when this returns
    } catch (const StoreError& e) {
        if (e.kind() != StoreErrc::disk_full) throw;
        rethrow_disk_full(e, "this trial was");
    }
}

void Store::record_trials(SessionId session, std::span<const TrialRecord> trials) {
    if (trials.empty()) return;
    const std::string doing = fmt::format("record trials {} to {} of session {}", trials.front().trial_index,
                                          trials.back().trial_index, session.value);
    impl_->require_writable(doing);
    for (const TrialRecord& t : trials)
        if (const std::string why = why_invalid(t); !why.empty())
            impl_->invalid(doing, fmt::format("trial {}: {}", t.trial_index, why));
    try {
        sql::Transaction tx(*impl_->db, sql::Transaction::Kind::write, doing);
        for (const TrialRecord& t : trials) impl_->insert_trial(session, t, doing);
        tx.commit();
    } catch (const StoreError& e) {
        if (e.kind() != StoreErrc::disk_full) throw;
        rethrow_disk_full(e, "these trials were");
    }
}

std::vector<TrialRecord> Store::Impl::read_trials(SessionId session, std::string_view doing) {
    std::vector<TrialRecord> out;
    sql::Use s(db->cached(
        "SELECT trial_index, block, condition_id, procedure_id, level, test_on_left, stimulus_json, response, "
        "response_value, response_time_s, onset_time_s, dropped_frames, missed_deadline, procedure_state_json, "
        "recorded_at FROM trials WHERE session_id = ?1 ORDER BY trial_index"));
    s->bind(1, session.value);
    while (s->step(doing)) out.push_back(trial_from_row(*s, 0));
    return out;
}

TrialRecord trial_from_row(const sql::Statement& s, int c) {
    TrialRecord t;
    t.trial_index = s.int64(c);
    t.block = s.int32(c + 1);
    t.condition_id = s.text(c + 2);
    t.procedure_id = s.text(c + 3);
    t.level = s.real(c + 4);
    if (!s.is_null(c + 5)) t.test_on_left = s.int64(c + 5) != 0;
    t.stimulus_json = s.text(c + 6);
    t.response = s.text(c + 7);
    if (!s.is_null(c + 8)) t.response_value = s.real(c + 8);
    t.response_time_s = s.real(c + 9);
    t.onset_time_s = s.real(c + 10);
    t.dropped_frames = s.int32(c + 11);
    t.missed_deadline = s.int64(c + 12) != 0;
    t.procedure_state_json = s.text(c + 13);
    t.recorded_at = s.text(c + 14);
    return t;
}

std::vector<TrialRecord> Store::trials(SessionId session) const {
    const std::string doing = fmt::format("read the trials of session {}", session.value);
    sql::Transaction tx(*impl_->db, sql::Transaction::Kind::read, doing);
    impl_->status_of(session, doing);  // not_found for an unknown session, rather than an empty list
    auto out = impl_->read_trials(session, doing);
    tx.commit();
    return out;
}

std::int64_t Store::trial_count(SessionId session) const {
    const std::string doing = fmt::format("count the trials of session {}", session.value);
    sql::Transaction tx(*impl_->db, sql::Transaction::Kind::read, doing);
    impl_->status_of(session, doing);
    sql::Use s(impl_->db->cached("SELECT count(*) FROM trials WHERE session_id = ?1"));
    s->bind(1, session.value);
    s->step(doing);
    const std::int64_t n = s->int64(0);
    s->reset();
    tx.commit();
    return n;
}

ResumePoint Store::resume_point(SessionId session) const {
    const std::string doing = fmt::format("read the resume point of session {}", session.value);
    // One read transaction: the session row and its trials come from one snapshot
    // even while a writer appends.
    sql::Transaction tx(*impl_->db, sql::Transaction::Kind::read, doing);
    ResumePoint r = impl_->read_resume_point(session, doing);
    tx.commit();
    return r;
}

}  // namespace atonlab::store
