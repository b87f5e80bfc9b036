#include "calibration_policy.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

#include "atonlab/common/iso_date.h"
#include "atonlab/store/json.h"
#include "calibration_record.h"

namespace atonlab::runner {
namespace {

/// "peak_percent 10.3 > 5, luminance_percent 10.1 > 5" from a check's results_json.
std::string failed_tolerances(const store::CalibrationCheck& check) {
    try {
        const nlohmann::json j = store::parse_json(check.results_json);
        std::string out;
        for (const nlohmann::json& failed : store::array_at(j, "/failed")) {
            if (!failed.is_string()) continue;
            const std::string name = failed.get<std::string>();
            using Pointer = nlohmann::json::json_pointer;  // escapes a name's '/' and '~'
            const auto value = store::number_at(j, (Pointer("/values") / name).to_string());
            const auto limit = store::number_at(j, (Pointer("/tolerances") / name).to_string());
            out += fmt::format("{}{} {} > {}", out.empty() ? "" : ", ", name,
                               value ? fmt::format("{:.3g}", *value) : std::string("(not computable)"),
                               limit ? fmt::format("{}", *limit) : std::string("?"));
        }
        return out.empty() ? std::string("see the check's results") : out;
    } catch (const store::StoreError&) {
        return "its results are unreadable";
    }
}

}  // namespace

std::string utc_today() {
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char date[16];
    std::strftime(date, sizeof date, "%Y-%m-%d", &utc);
    return date;
}

std::optional<long> days_between(const std::string& iso, const std::string& today) {
    const auto a = iso_date(iso), b = iso_date(today);
    if (!a || !b) return std::nullopt;
    return static_cast<long>((*b - *a).count());
}

void apply_display_model(stimuli::Scene& scene, const display::DisplayModel& model) {
    scene.output.display = model;
    scene.output.tonemap.display_peak_cd_m2 = model.peak_cd_m2;
}

SessionCalibration session_calibration(const store::Store* store, const protocols::Display& display,
                                       std::optional<store::CalibrationId> resumed_with, const std::string& today,
                                       const std::string& db, const RunProfiles& profiles) {
    SessionCalibration out;
    std::optional<store::Calibration> cal;
    const store::Store* source = store;  // the file `cal` is in
    if (resumed_with && store) {
        // A session continues with what it began with.
        store::Calibration c = store->calibration(*resumed_with);
        if (!is_measured(c)) return out;
        cal = std::move(c);
    } else if (display.name.empty()) {
        out.notes.push_back(
            "the protocol's [display] table names no display (name = \"...\"), so no measured calibration can be "
            "used: the session encodes for the scene's nominal display model (docs/calibration.md)");
        return out;
    } else {
        if (store) cal = latest_measured_calibration(*store, display.name);
        // The display-profile file's, when it is measured later than the
        // study file's own (or on the same date: it may hold a newer check).
        if (profiles.file)
            if (auto p = latest_measured_calibration(*profiles.file, display.name);
                p && (!cal || p->measured_at >= cal->measured_at)) {
                cal = std::move(p);
                source = profiles.file;
            }
        if (!cal) {
            out.warnings.push_back(
                profiles.file
                    ? fmt::format("display \"{}\" has no calibration in the display-profile file {} or in {}: the "
                                  "session encodes for the scene's nominal display model; measure it first with "
                                  "`atonlab calibrate measure --display {}` (or import a .ti3)",
                                  display.name, profiles.path, db, display.name)
                    : fmt::format("display \"{}\" has no calibration in {}: the session encodes for the scene's "
                                  "nominal display model; measure it first with `atonlab calibrate measure --display "
                                  "{}` into the lab's display-profile file (or --db {}; or import a .ti3)",
                                  display.name, db, display.name, db));
            return out;
        }
    }
    out.display = display_model_of(*cal);
    const std::optional<store::CalibrationCheck> latest_check = source->latest_calibration_check(cal->id);
    const std::string which =
        source == store ? fmt::format("calibration {} of display \"{}\" (measured {})", cal->id.value,
                                      cal->display_name, cal->measured_at)
                        : fmt::format("calibration {} of display \"{}\" in the display-profile file {} (measured {})",
                                      cal->id.value, cal->display_name, profiles.path, cal->measured_at);
    if (source == store)
        out.calibration = cal->id;
    else
        out.from_profiles = ProfileCopy{profiles.path, *cal, source->calibration_readings(cal->id), latest_check};
    if (const auto& check = latest_check; check && !check->passed)
        out.warnings.push_back(
            fmt::format("the latest check of {} failed on {} ({}): recalibrate the display "
                        "with `atonlab calibrate measure`",
                        which, check->checked_at, failed_tolerances(*check)));
    const double max_days = display.max_calibration_age_days.value_or(kDefaultMaxCalibrationAgeDays);
    if (const auto age = days_between(cal->measured_at, today); age && static_cast<double>(*age) > max_days)
        out.warnings.push_back(
            fmt::format("{} is {} days old, older than max_calibration_age_days = {}{}: "
                        "recalibrate the display (or check it with `atonlab calibrate check`)",
                        which, *age, max_days, display.max_calibration_age_days ? "" : " (the default)"));
    if (!resumed_with && (cal->width_px != display.width_px || cal->height_px != display.height_px ||
                          std::abs(cal->width_m - display.width_m) > 1e-9 ||
                          std::abs(cal->viewing_distance_m - display.viewing_distance_m) > 1e-9))
        out.warnings.push_back(fmt::format(
            "{} was measured for {} x {} px, {} m wide, viewed from {} m, but the protocol's [display] says {} x {} "
            "px, {} m, {} m: frames are rendered for the protocol's geometry and encoded with the calibration's "
            "transfer functions",
            which, cal->width_px, cal->height_px, cal->width_m, cal->viewing_distance_m, display.width_px,
            display.height_px, display.width_m, display.viewing_distance_m));
    return out;
}

store::CalibrationId copy_into_study(store::Store& study, const ProfileCopy& copy) {
    const store::Calibration& c = copy.calibration;
    std::optional<store::CalibrationId> id;
    for (const store::Calibration& s : study.calibrations(c.display_name))
        if (s.measured_at == c.measured_at && s.fit_json == c.fit_json && s.width_px == c.width_px &&
            s.height_px == c.height_px && s.width_m == c.width_m && s.height_m == c.height_m &&
            s.viewing_distance_m == c.viewing_distance_m) {
            id = s.id;
            break;
        }
    if (!id) {
        store::Calibration copied = c;
        copied.source = fmt::format("copied from the display-profile file {} (calibration {}): {}",
                                    copy.profiles_file, c.id.value, c.source);
        id = study.put_calibration(copied, copy.readings);
    }
    if (copy.latest_check) {
        bool present = false;
        for (const store::CalibrationCheck& k : study.calibration_checks(*id))
            present = present || (k.checked_at == copy.latest_check->checked_at &&
                                  k.results_json == copy.latest_check->results_json);
        if (!present) {
            store::CalibrationCheck k = *copy.latest_check;
            k.calibration = *id;
            k.source = fmt::format("copied from the display-profile file {} (check {}): {}", copy.profiles_file,
                                   copy.latest_check->id.value, copy.latest_check->source);
            study.put_calibration_check(k);
        }
    }
    return *id;
}

void print_calibration_warnings(const SessionCalibration& calibration, bool quiet) {
    for (const std::string& w : calibration.warnings) std::fprintf(stderr, "atonlab: warning: %s\n", w.c_str());
    if (!quiet)
        for (const std::string& n : calibration.notes) std::fprintf(stderr, "atonlab: note: %s\n", n.c_str());
}

}  // namespace atonlab::runner
