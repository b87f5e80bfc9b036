// Sessions: begin, finish, resume, and reading them back.
#include <fmt/format.h>

#include <algorithm>

#include "atonlab/store/sha256.h"
#include "atonlab/store/version.h"
#include "store_impl.h"

namespace atonlab::store {
namespace {

constexpr const char* select_sessions =
    "SELECT s.id, o.code, s.protocol_id, p.name, p.sha256, s.software_version, s.seed, s.calibration_id, "
    "s.started_at, s.ended_at, s.status, s.resume_count, "
    "(SELECT count(*) FROM trials t WHERE t.session_id = s.id), s.displayability_json, sc.sha256, sc.name, "
    "s.simulation_json, s.stop_json "
    "FROM sessions s JOIN observers o ON o.id = s.observer_id JOIN protocols p ON p.id = s.protocol_id "
    "LEFT JOIN scenes sc ON sc.id = s.scene_id "
    "ORDER BY s.id";

constexpr const char* select_one_session =
    "SELECT s.id, o.code, s.protocol_id, p.name, p.sha256, s.software_version, s.seed, s.calibration_id, "
    "s.started_at, s.ended_at, s.status, s.resume_count, "
    "(SELECT count(*) FROM trials t WHERE t.session_id = s.id), s.displayability_json, sc.sha256, sc.name, "
    "s.simulation_json, s.stop_json "
    "FROM sessions s JOIN observers o ON o.id = s.observer_id JOIN protocols p ON p.id = s.protocol_id "
    "LEFT JOIN scenes sc ON sc.id = s.scene_id "
    "WHERE s.id = ?1";

// An observer code, not a name: short, and no spaces, so "Jane Doe" is refused.
bool valid_observer_code(std::string_view code) {
    return !code.empty() && code.size() <= 32 && std::all_of(code.begin(), code.end(), [](char c) {
        return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    });
}

}  // namespace

SessionRecord session_from_row(const sql::Statement& s, const std::filesystem::path& path) {
    SessionRecord r;
    r.id = SessionId{s.int64(0)};
    r.observer_code = s.text(1);
    r.protocol_id = s.int64(2);
    r.protocol_name = s.text(3);
    r.protocol_sha256 = s.text(4);
    r.software_version = s.text(5);
    r.seed = static_cast<std::uint64_t>(s.int64(6));  // the bits stored by begin_session
    if (!s.is_null(7)) r.calibration = CalibrationId{s.int64(7)};
    r.started_at = s.text(8);
    r.ended_at = s.optional_text(9);
    const std::string status = s.text(10);
    const auto parsed = session_status_from_string(status);
    if (!parsed) {  // the schema's CHECK makes this unreachable unless the file was edited by hand
        throw StoreError(StoreErrc::corrupt, path,
                         fmt::format("{}: session {} has an unknown status \"{}\"", path.string(), r.id.value, status));
    }
    r.status = *parsed;
    r.resume_count = s.int32(11);
    r.trial_count = s.int64(12);
    r.displayability_json = s.optional_text(13);
    r.scene_sha256 = s.optional_text(14);
    r.scene_name = s.optional_text(15).value_or("");
    r.simulation_json = s.optional_text(16);
    r.stop_json = s.optional_text(17);
    return r;
}

std::int64_t Store::Impl::put_text(StoredText kind, std::string_view name, std::string_view text,
                                   std::string_view doing) {
    // Two tables of one shape; the SQL stays literal (no SQL is built from a value).
    const bool scene = kind == StoredText::scene;
    const std::string hash = sha256_hex(text);
    sql::Use ins(
        db->cached(scene ? "INSERT INTO scenes (sha256, name, text, added_at) VALUES (?1, ?2, ?3, " ATONLAB_STORE_NOW
                           ") ON CONFLICT (sha256) DO NOTHING"
                         : "INSERT INTO protocols (sha256, name, text, added_at) VALUES (?1, ?2, ?3, " ATONLAB_STORE_NOW
                           ") ON CONFLICT (sha256) DO NOTHING"));
    ins->bind(1, hash);
    ins->bind(2, name);
    ins->bind(3, text);
    ins->run(doing);
    sql::Use sel(db->cached(scene ? "SELECT id, text FROM scenes WHERE sha256 = ?1"
                                  : "SELECT id, text FROM protocols WHERE sha256 = ?1"));
    sel->bind(1, hash);
    sel->step(doing);
    const std::int64_t id = sel->int64(0);
    if (sel->text(1) != text) {  // only if someone edited the stored text by hand
        throw StoreError(StoreErrc::corrupt, path(),
                         fmt::format("{}: cannot {}: the stored {} with SHA-256 {} has different text", path().string(),
                                     doing, scene ? "scene" : "protocol", hash));
    }
    return id;
}

SessionStatus Store::Impl::status_of(SessionId session, std::string_view doing) {
    sql::Use s(db->cached("SELECT status FROM sessions WHERE id = ?1"));
    s->bind(1, session.value);
    if (!s->step(doing)) not_found(doing, fmt::format("session {}", session.value));
    const auto status = session_status_from_string(s->text(0));
    if (!status) not_found(doing, fmt::format("a valid status for session {}", session.value));
    return *status;
}

SessionRecord Store::Impl::read_session(SessionId session, std::string_view doing) {
    sql::Use s(db->cached(select_one_session));
    s->bind(1, session.value);
    if (!s->step(doing)) not_found(doing, fmt::format("session {}", session.value));
    return session_from_row(*s, path());
}

std::string Store::Impl::read_protocol_text(SessionId session, std::string_view doing) {
    sql::Use s(db->cached("SELECT p.text FROM sessions s JOIN protocols p ON p.id = s.protocol_id WHERE s.id = ?1"));
    s->bind(1, session.value);
    if (!s->step(doing)) not_found(doing, fmt::format("session {}", session.value));
    return s->text(0);
}

std::optional<std::string> Store::Impl::read_scene_text(SessionId session, std::string_view doing) {
    sql::Use s(db->cached("SELECT sc.text FROM sessions s LEFT JOIN scenes sc ON sc.id = s.scene_id WHERE s.id = ?1"));
    s->bind(1, session.value);
    if (!s->step(doing)) not_found(doing, fmt::format("session {}", session.value));
    return s->optional_text(0);
}

ResumePoint Store::Impl::read_resume_point(SessionId session, std::string_view doing) {
    ResumePoint r;
    r.session = read_session(session, doing);
    r.protocol_text = read_protocol_text(session, doing);
    r.trials = read_trials(session, doing);
    r.next_trial_index = static_cast<std::int64_t>(r.trials.size());
    return r;
}

SessionId Store::begin_session(const SessionStart& start) {
    const std::string doing = fmt::format("begin a session for observer \"{}\"", start.observer_code);
    impl_->require_writable(doing);
    if (!valid_observer_code(start.observer_code)) {
        impl_->invalid(doing, "an observer code is 1 to 32 letters, digits, '-' or '_' (a code, never a name)");
    }
    if (start.protocol_text.empty()) impl_->invalid(doing, "the protocol text is empty");
    const std::string_view version = start.software_version.empty() ? std::string_view(software_version())
                                                                    : std::string_view(start.software_version);

    sql::Connection& db = *impl_->db;
    sql::Transaction tx(db, sql::Transaction::Kind::write, doing);

    if (start.calibration) {
        sql::Use c(db.cached("SELECT 1 FROM calibrations WHERE id = ?1"));
        c->bind(1, start.calibration->value);
        if (!c->step(doing)) impl_->not_found(doing, fmt::format("calibration {}", start.calibration->value));
    }

    std::int64_t observer_id = 0;
    {
        sql::Use ins(db.cached("INSERT INTO observers (code, added_at) VALUES (?1, " ATONLAB_STORE_NOW
                               ") ON CONFLICT (code) DO NOTHING"));
        ins->bind(1, start.observer_code);
        ins->run(doing);
        sql::Use sel(db.cached("SELECT id FROM observers WHERE code = ?1"));
        sel->bind(1, start.observer_code);
        sel->step(doing);
        observer_id = sel->int64(0);
    }

    const std::int64_t protocol_id =
        impl_->put_text(StoredText::protocol, start.protocol_name, start.protocol_text, doing);
    std::optional<std::int64_t> scene_id;
    if (!start.scene_text.empty())
        scene_id = impl_->put_text(StoredText::scene, start.scene_name, start.scene_text, doing);

    sql::Use ins(db.cached(
        "INSERT INTO sessions (observer_id, protocol_id, calibration_id, software_version, seed, "
        "started_at, displayability_json, scene_id, simulation_json) "
        "VALUES (?1, ?2, ?3, ?4, ?5, " ATONLAB_STORE_NOW ", ?6, ?7, ?8)"));
    ins->bind(1, observer_id);
    ins->bind(2, protocol_id);
    if (start.calibration) {
        ins->bind(3, start.calibration->value);
    } else {
        ins->bind_null(3);
    }
    ins->bind(4, version);
    ins->bind(5, static_cast<std::int64_t>(start.seed));  // uint64 bits kept exactly (modular conversion)
    if (start.displayability_json.empty()) {
        ins->bind_null(6);
    } else {
        ins->bind(6, start.displayability_json);
    }
    if (scene_id) {
        ins->bind(7, *scene_id);
    } else {
        ins->bind_null(7);
    }
    if (start.simulation_json.empty()) {
        ins->bind_null(8);
    } else {
        ins->bind(8, start.simulation_json);
    }
    ins->run(doing);
    const SessionId id{sqlite3_last_insert_rowid(db.get())};
    ins->reset();
    tx.commit();
    return id;
}

void Store::finish_session(SessionId session, SessionStatus status) {
    const std::string doing = fmt::format("finish session {} as {}", session.value, to_string(status));
    impl_->require_writable(doing);
    if (status == SessionStatus::running) impl_->invalid(doing, "a finished session cannot be 'running'");
    sql::Transaction tx(*impl_->db, sql::Transaction::Kind::write, doing);
    const SessionStatus now = impl_->status_of(session, doing);
    if (now != SessionStatus::running) {
        impl_->invalid(doing, fmt::format("session {} is already {}", session.value, to_string(now)));
    }
    sql::Use s(impl_->db->cached("UPDATE sessions SET status = ?2, ended_at = " ATONLAB_STORE_NOW " WHERE id = ?1"));
    s->bind(1, session.value);
    s->bind(2, std::string_view(to_string(status)));
    s->run(doing);
    tx.commit();
}

void Store::stop_session(SessionId session, std::string_view stop) {
    const std::string doing = fmt::format("record why session {} stopped", session.value);
    impl_->require_writable(doing);
    sql::Transaction tx(*impl_->db, sql::Transaction::Kind::write, doing);
    const SessionStatus now = impl_->status_of(session, doing);
    if (now != SessionStatus::running) {
        impl_->invalid(doing, fmt::format("session {} is {}, not running", session.value, to_string(now)));
    }
    {
        sql::Use check(impl_->db->cached("SELECT CASE WHEN json_valid(?1) THEN json_type(?1) = 'object' ELSE 0 END"));
        check->bind(1, stop);
        check->step(doing);
        if (check->int64(0) != 1) impl_->invalid(doing, "the stop record is not a JSON object");
    }
    // Appended ('$[#]': after the last element) to what earlier stops left.
    sql::Use s(impl_->db->cached(
        "UPDATE sessions SET status = 'quit', ended_at = " ATONLAB_STORE_NOW ", stop_json = "
        "json_insert(COALESCE(stop_json, '[]'), '$[#]', json_set(json(?2), '$.stopped_at', " ATONLAB_STORE_NOW "))"
        " WHERE id = ?1"));
    s->bind(1, session.value);
    s->bind(2, stop);
    s->run(doing);
    tx.commit();
}

ResumePoint Store::resume_session(SessionId session) {
    const std::string doing = fmt::format("resume session {}", session.value);
    impl_->require_writable(doing);
    sql::Transaction tx(*impl_->db, sql::Transaction::Kind::write, doing);
    const SessionStatus now = impl_->status_of(session, doing);
    if (now == SessionStatus::completed) impl_->invalid(doing, "the session is completed");
    {
        sql::Use s(impl_->db->cached(
            "UPDATE sessions SET status = 'running', ended_at = NULL, resume_count = resume_count + 1 WHERE id = ?1"));
        s->bind(1, session.value);
        s->run(doing);
    }
    ResumePoint r = impl_->read_resume_point(session, doing);
    tx.commit();
    return r;
}

std::vector<SessionRecord> Store::sessions() const {
    std::vector<SessionRecord> out;
    sql::Use s(impl_->db->cached(select_sessions));
    while (s->step("list the sessions")) out.push_back(session_from_row(*s, impl_->path()));
    return out;
}

SessionRecord Store::session(SessionId session) const {
    return impl_->read_session(session, fmt::format("read session {}", session.value));
}

std::optional<std::string> Store::scene_text(SessionId session) const {
    return impl_->read_scene_text(session, fmt::format("read the scene of session {}", session.value));
}

std::string Store::protocol_text(SessionId session) const {
    return impl_->read_protocol_text(session, fmt::format("read the protocol of session {}", session.value));
}

void Store::switch_to_rollback_journal() {
    const std::string doing = "switch to a rollback journal";
    impl_->require_writable(doing);
    const std::string mode = impl_->db->query_text("PRAGMA journal_mode = DELETE", doing);
    if (mode != "delete")
        throw StoreError(StoreErrc::other, impl_->path(),
                         fmt::format("{}: cannot {} (SQLite kept \"{}\")", impl_->path().string(), doing, mode));
}

}  // namespace atonlab::store
