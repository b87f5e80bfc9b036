// Displays and their calibrations.
#include <fmt/format.h>

#include <cmath>

#include "atonlab/common/iso_date.h"
#include "store_impl.h"

namespace atonlab::store {
namespace {

bool positive(double v) {
    return std::isfinite(v) && v > 0.0;
}

bool unit_interval(double v) {
    return std::isfinite(v) && v >= 0.0 && v <= 1.0;
}

// Why a reading cannot be stored ("" when it can): the schema's CHECKs, said
// in words before anything is written.
std::string reading_problem(const CalibrationReading& r) {
    if (r.patch.empty()) return "has no patch name";
    if (r.channel != "red" && r.channel != "green" && r.channel != "blue" && r.channel != "grey" &&
        r.channel != "other")
        return fmt::format("has channel \"{}\"; it must be red, green, blue, grey or other", r.channel);
    if (!unit_interval(r.level)) return fmt::format("has level {}, outside [0, 1]", r.level);
    if (!unit_interval(r.drive_r) || !unit_interval(r.drive_g) || !unit_interval(r.drive_b))
        return "has a drive level outside [0, 1]";
    if (!std::isfinite(r.luminance_cd_m2) || r.luminance_cd_m2 < 0.0)
        return fmt::format("has luminance {} cd/m2; it must be a finite number >= 0", r.luminance_cd_m2);
    if (r.code.has_value() != r.bits.has_value()) return "has a code value without its bits, or bits without a code";
    if (r.bits && (*r.bits < 1 || *r.bits > 16)) return fmt::format("has {} bits; 1 to 16 are possible", *r.bits);
    if (r.code && (*r.code < 0 || *r.code > (1 << *r.bits) - 1))
        return fmt::format("has code {}, outside 0..{} for {} bits", *r.code, (1 << *r.bits) - 1, *r.bits);
    if (r.xyz_x_cd_m2.has_value() != r.xyz_z_cd_m2.has_value()) return "has X without Z or Z without X";
    if (r.xyz_x_cd_m2 && !(std::isfinite(*r.xyz_x_cd_m2) && std::isfinite(*r.xyz_z_cd_m2)))
        return "has an X or Z that is not a finite number";
    if (r.source_line && *r.source_line < 1)
        return fmt::format("has source line {}; lines count from 1", *r.source_line);
    return {};
}

void insert_readings(sql::Connection& db, CalibrationId id, std::span<const CalibrationReading> readings,
                     std::string_view doing) {
    static constexpr const char* sql_insert =
        "INSERT INTO calibration_readings (calibration_id, seq, patch, channel, level, code, bits, drive_r, "
        "drive_g, drive_b, luminance_cd_m2, xyz_x_cd_m2, xyz_z_cd_m2, source_line, transcript) "
        "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15)";
    for (std::size_t i = 0; i < readings.size(); ++i) {
        const CalibrationReading& r = readings[i];
        sql::Use s(db.cached(sql_insert));
        s->bind(1, id.value);
        s->bind(2, static_cast<std::int64_t>(i));
        s->bind(3, r.patch);
        s->bind(4, r.channel);
        s->bind(5, r.level);
        s->bind(6, r.code);
        s->bind(7, r.bits);
        s->bind(8, r.drive_r);
        s->bind(9, r.drive_g);
        s->bind(10, r.drive_b);
        s->bind(11, r.luminance_cd_m2);
        s->bind(12, r.xyz_x_cd_m2);
        s->bind(13, r.xyz_z_cd_m2);
        s->bind(14, r.source_line);
        s->bind(15, r.transcript);
        s->run(doing);
    }
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

CalibrationId Store::put_calibration(const Calibration& c, std::span<const CalibrationReading> readings) {
    const std::string doing = fmt::format("store a calibration of display \"{}\"", c.display_name);
    impl_->require_writable(doing);
    if (c.display_name.empty()) impl_->invalid(doing, "the display name is empty");
    if (c.width_px <= 0 || c.height_px <= 0) impl_->invalid(doing, "the resolution is not positive");
    if (!positive(c.width_m) || !positive(c.height_m) || !positive(c.viewing_distance_m)) {
        impl_->invalid(doing, "the width, height and viewing distance must be positive metres");
    }
    if (!iso_date(c.measured_at)) impl_->invalid(doing, "measured_at is not an ISO 8601 date (YYYY-MM-DD...)");
    for (std::size_t i = 0; i < readings.size(); ++i)
        if (const std::string why = reading_problem(readings[i]); !why.empty())
            impl_->invalid(doing, fmt::format("reading {} (patch \"{}\") {}", i, readings[i].patch, why));
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
    insert_readings(db, id, readings, doing);
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

std::vector<Calibration> Store::calibrations(std::string_view display_name) const {
    static constexpr const char* sql_all =
        "SELECT c.id, d.name, c.width_px, c.height_px, c.width_m, c.height_m, c.viewing_distance_m, c.fit_json, "
        "c.source, c.measured_at, c.recorded_at FROM calibrations c JOIN displays d ON d.id = c.display_id "
        "WHERE d.name = ?1 ORDER BY c.measured_at DESC, c.id DESC";
    const std::string doing = fmt::format("read the calibrations of display \"{}\"", display_name);
    sql::Use s(impl_->db->cached(sql_all));
    s->bind(1, display_name);
    std::vector<Calibration> out;
    while (s->step(doing)) out.push_back(calibration_from_row(*s));
    return out;
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

namespace atonlab::store {

std::vector<std::string> Store::display_names() const {
    sql::Use s(impl_->db->cached(
        "SELECT d.name FROM displays d WHERE EXISTS (SELECT 1 FROM calibrations c WHERE c.display_id = d.id) "
        "ORDER BY d.name"));
    std::vector<std::string> out;
    while (s->step("list the displays")) out.push_back(s->text(0));
    return out;
}

}  // namespace atonlab::store
