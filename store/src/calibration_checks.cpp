// A calibration's photometer readings and its checks (schema version 2;
// docs/store.md, docs/calibration.md).
#include <fmt/format.h>

#include <cmath>

#include "atonlab/common/iso_date.h"
#include "store_impl.h"

namespace atonlab::store {
namespace {

std::optional<int> optional_int(const sql::Statement& s, int col) {
    if (s.is_null(col)) return std::nullopt;
    return s.int32(col);
}

std::optional<double> optional_real(const sql::Statement& s, int col) {
    if (s.is_null(col)) return std::nullopt;
    return s.real(col);
}

CalibrationCheck check_from_row(const sql::Statement& s) {
    CalibrationCheck c;
    c.id = CalibrationCheckId{s.int64(0)};
    c.calibration = CalibrationId{s.int64(1)};
    c.checked_at = s.text(2);
    c.passed = s.int64(3) != 0;
    c.results_json = s.text(4);
    c.source = s.text(5);
    c.recorded_at = s.text(6);
    return c;
}

/// not_found unless the calibration exists.
void require_calibration(Store::Impl& impl, CalibrationId id, std::string_view doing) {
    sql::Use s(impl.db->cached("SELECT 1 FROM calibrations WHERE id = ?1"));
    s->bind(1, id.value);
    if (!s->step(doing)) impl.not_found(doing, fmt::format("calibration {}", id.value));
}

}  // namespace

std::vector<CalibrationReading> Store::calibration_readings(CalibrationId id) const {
    static constexpr const char* sql_readings =
        "SELECT patch, channel, level, code, bits, drive_r, drive_g, drive_b, luminance_cd_m2, xyz_x_cd_m2, "
        "xyz_z_cd_m2, source_line, transcript FROM calibration_readings WHERE calibration_id = ?1 ORDER BY seq";
    const std::string doing = fmt::format("read the readings of calibration {}", id.value);
    sql::Transaction tx(*impl_->db, sql::Transaction::Kind::read, doing);
    require_calibration(*impl_, id, doing);
    sql::Use s(impl_->db->cached(sql_readings));
    s->bind(1, id.value);
    std::vector<CalibrationReading> out;
    while (s->step(doing)) {
        CalibrationReading r;
        r.patch = s->text(0);
        r.channel = s->text(1);
        r.level = s->real(2);
        r.code = optional_int(*s, 3);
        r.bits = optional_int(*s, 4);
        r.drive_r = s->real(5);
        r.drive_g = s->real(6);
        r.drive_b = s->real(7);
        r.luminance_cd_m2 = s->real(8);
        r.xyz_x_cd_m2 = optional_real(*s, 9);
        r.xyz_z_cd_m2 = optional_real(*s, 10);
        r.source_line = optional_int(*s, 11);
        r.transcript = s->optional_text(12);
        out.push_back(std::move(r));
    }
    return out;
}

CalibrationCheckId Store::put_calibration_check(const CalibrationCheck& c) {
    const std::string doing = fmt::format("store a check of calibration {}", c.calibration.value);
    impl_->require_writable(doing);
    if (!iso_date(c.checked_at)) impl_->invalid(doing, "checked_at is not an ISO 8601 date (YYYY-MM-DD...)");
    sql::Connection& db = *impl_->db;
    sql::Transaction tx(db, sql::Transaction::Kind::write, doing);
    if (!json_valid(db, c.results_json, doing)) impl_->invalid(doing, "results_json is not valid JSON");
    require_calibration(*impl_, c.calibration, doing);
    sql::Use s(
        db.cached("INSERT INTO calibration_checks (calibration_id, checked_at, passed, results_json, source, "
                  "recorded_at) VALUES (?1, ?2, ?3, ?4, ?5, " ATONLAB_STORE_NOW ")"));
    s->bind(1, c.calibration.value);
    s->bind(2, c.checked_at);
    s->bind(3, c.passed ? 1 : 0);
    s->bind(4, c.results_json);
    s->bind(5, c.source);
    s->run(doing);
    const CalibrationCheckId id{sqlite3_last_insert_rowid(db.get())};
    s->reset();
    tx.commit();
    return id;
}

std::vector<CalibrationCheck> Store::calibration_checks(CalibrationId id) const {
    static constexpr const char* sql_checks =
        "SELECT id, calibration_id, checked_at, passed, results_json, source, recorded_at FROM calibration_checks "
        "WHERE calibration_id = ?1 ORDER BY checked_at DESC, id DESC";
    const std::string doing = fmt::format("read the checks of calibration {}", id.value);
    sql::Use s(impl_->db->cached(sql_checks));
    s->bind(1, id.value);
    std::vector<CalibrationCheck> out;
    while (s->step(doing)) out.push_back(check_from_row(*s));
    return out;
}

std::optional<CalibrationCheck> Store::latest_calibration_check(CalibrationId id) const {
    static constexpr const char* sql_latest =
        "SELECT id, calibration_id, checked_at, passed, results_json, source, recorded_at FROM calibration_checks "
        "WHERE calibration_id = ?1 ORDER BY checked_at DESC, id DESC LIMIT 1";
    sql::Use s(impl_->db->cached(sql_latest));
    s->bind(1, id.value);
    if (!s->step(fmt::format("read the latest check of calibration {}", id.value))) return std::nullopt;
    return check_from_row(*s);
}

}  // namespace atonlab::store
