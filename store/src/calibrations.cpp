// Displays and their calibrations.
#include <fmt/format.h>

#include <cmath>

#include "store_impl.h"

namespace atonlab::store {
namespace {

bool positive(double v) {
    return std::isfinite(v) && v > 0.0;
}

// ISO 8601 starts YYYY-MM-DD; with that prefix, text order is date order.
bool iso_date_prefix(std::string_view s) {
    if (s.size() < 10) return false;
    for (std::size_t i = 0; i < 10; ++i) {
        const bool dash = i == 4 || i == 7;
        if (dash ? s[i] != '-' : (s[i] < '0' || s[i] > '9')) return false;
    }
    return true;
}

Calibration calibration_from_row(const sql::Statement& s) {
    Calibration c;
    c.id = CalibrationId{s.int64(0)};
    c.display_name = s.text(1);
    c.width_px = s.int32(2);
    c.height_px = s.int32(3);
    c.width_m = s.real(4);
    c.height_m = s.real(5);
    c.viewing_distance_m = s.real(6);
    c.fit_json = s.text(7);
    c.source = s.text(8);
    c.measured_at = s.text(9);
    c.recorded_at = s.text(10);
    return c;
}

}  // namespace

CalibrationId Store::put_calibration(const Calibration& c) {
    const std::string doing = fmt::format("store a calibration of display \"{}\"", c.display_name);
    impl_->require_writable(doing);
    if (c.display_name.empty()) impl_->invalid(doing, "the display name is empty");
    if (c.width_px <= 0 || c.height_px <= 0) impl_->invalid(doing, "the resolution is not positive");
    if (!positive(c.width_m) || !positive(c.height_m) || !positive(c.viewing_distance_m)) {
        impl_->invalid(doing, "the width, height and viewing distance must be positive metres");
    }
    if (!iso_date_prefix(c.measured_at)) impl_->invalid(doing, "measured_at is not an ISO 8601 date (YYYY-MM-DD...)");
    sql::Connection& db = *impl_->db;
    sql::Transaction tx(db, sql::Transaction::Kind::write, doing);
    if (!json_valid(db, c.fit_json, doing)) impl_->invalid(doing, "fit_json is not valid JSON");
    std::int64_t display_id = 0;
    {
        sql::Use ins(db.cached("INSERT INTO displays (name) VALUES (?1) ON CONFLICT (name) DO NOTHING"));
        ins->bind(1, c.display_name);
        ins->run(doing);
        sql::Use sel(db.cached("SELECT id FROM displays WHERE name = ?1"));
        sel->bind(1, c.display_name);
        sel->step(doing);
        display_id = sel->int64(0);
    }
    sql::Use s(
        db.cached("INSERT INTO calibrations (display_id, width_px, height_px, width_m, height_m, "
                  "viewing_distance_m, fit_json, source, measured_at, recorded_at) "
                  "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, " ATONLAB_STORE_NOW ")"));
    s->bind(1, display_id);
    s->bind(2, c.width_px);
    s->bind(3, c.height_px);
    s->bind(4, c.width_m);
    s->bind(5, c.height_m);
    s->bind(6, c.viewing_distance_m);
    s->bind(7, c.fit_json);
    s->bind(8, c.source);
    s->bind(9, c.measured_at);
    s->run(doing);
    const CalibrationId id{sqlite3_last_insert_rowid(db.get())};
    s->reset();
    tx.commit();
    return id;
}

std::optional<Calibration> Store::latest_calibration(std::string_view display_name) const {
    static constexpr const char* sql_latest =
        "SELECT c.id, d.name, c.width_px, c.height_px, c.width_m, c.height_m, c.viewing_distance_m, c.fit_json, "
        "c.source, c.measured_at, c.recorded_at FROM calibrations c JOIN displays d ON d.id = c.display_id "
        "WHERE d.name = ?1 ORDER BY c.measured_at DESC, c.id DESC LIMIT 1";
    sql::Use s(impl_->db->cached(sql_latest));
    s->bind(1, display_name);
    if (!s->step(fmt::format("read the latest calibration of display \"{}\"", display_name))) return std::nullopt;
    return calibration_from_row(*s);
}

Calibration Store::calibration(CalibrationId id) const {
    static constexpr const char* sql_one =
        "SELECT c.id, d.name, c.width_px, c.height_px, c.width_m, c.height_m, c.viewing_distance_m, c.fit_json, "
        "c.source, c.measured_at, c.recorded_at FROM calibrations c JOIN displays d ON d.id = c.display_id "
        "WHERE c.id = ?1";
    const std::string doing = fmt::format("read calibration {}", id.value);
    sql::Use s(impl_->db->cached(sql_one));
    s->bind(1, id.value);
    if (!s->step(doing)) impl_->not_found(doing, fmt::format("calibration {}", id.value));
    return calibration_from_row(*s);
}

}  // namespace atonlab::store
