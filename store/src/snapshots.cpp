// Stimulus snapshots: the rendered stimulus of a condition, kept in the study file.
#include <fmt/format.h>

#include "atonlab/store/sha256.h"
#include "store_impl.h"

namespace atonlab::store {

void Store::put_snapshot(SessionId session, std::string_view condition_id, std::span<const std::byte> data,
                         std::string_view format) {
    const std::string doing =
        fmt::format("store the snapshot of condition \"{}\" of session {}", condition_id, session.value);
    impl_->require_writable(doing);
    if (condition_id.empty()) impl_->invalid(doing, "condition_id is empty");
    if (format.empty()) impl_->invalid(doing, "the format is empty");
    const std::string hash = sha256_hex(data);
    sql::Connection& db = *impl_->db;
    sql::Transaction tx(db, sql::Transaction::Kind::write, doing);
    impl_->status_of(session, doing);
    {
        sql::Use s(
            db.cached("INSERT INTO snapshots (session_id, condition_id, format, data, sha256, recorded_at) "
                      "VALUES (?1, ?2, ?3, ?4, ?5, " ATONLAB_STORE_NOW ") "
                      "ON CONFLICT (session_id, condition_id) DO UPDATE SET format = excluded.format, "
                      "data = excluded.data, sha256 = excluded.sha256, recorded_at = excluded.recorded_at"));
        s->bind(1, session.value);
        s->bind(2, condition_id);
        s->bind(3, format);
        s->bind_blob(4, data);
        s->bind(5, hash);
        s->run(doing);
    }
    tx.commit();
}

std::optional<Snapshot> Store::get_snapshot(SessionId session, std::string_view condition_id) const {
    const std::string doing =
        fmt::format("read the snapshot of condition \"{}\" of session {}", condition_id, session.value);
    sql::Use s(
        impl_->db->cached("SELECT format, data, sha256, recorded_at FROM snapshots "
                          "WHERE session_id = ?1 AND condition_id = ?2"));
    s->bind(1, session.value);
    s->bind(2, condition_id);
    if (!s->step(doing)) return std::nullopt;
    Snapshot out;
    out.session = session;
    out.condition_id = std::string(condition_id);
    out.format = s->text(0);
    out.data = s->blob(1);
    out.sha256 = s->text(2);
    out.recorded_at = s->text(3);
    if (sha256_hex(out.data) != out.sha256) {
        throw StoreError(StoreErrc::corrupt, impl_->path(),
                         fmt::format("{}: cannot {}: its bytes do not match the SHA-256 stored with them",
                                     impl_->path().string(), doing));
    }
    return out;
}

}  // namespace atonlab::store
