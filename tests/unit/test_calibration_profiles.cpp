// A lab's display-profile file as `atonlab run` and `atonlab calibrate show`
// use it (docs/calibration.md, "The display-profile file", "Drift"), without
// GL: a display measured once is used by two studies, each of which holds a
// copy of the fit (with its readings and latest check) and nothing twice; a
// study's own, later calibration wins; the drift table and figure hold the
// stored checks' values. Checks are made by the runner's own evaluate_check
// from readings of a known power-law display, so every value is analytic.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "analysis_test_data.h"
#include "atonlab/analysis/calibration_drift.h"
#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/plots.h"
#include "atonlab/analysis/report.h"
#include "atonlab/analysis/study_analysis.h"
#include "atonlab/display/calibration.h"
#include "atonlab/store/json.h"
#include "atonlab/store/profiles.h"
#include "calibrate/calibration_check.h"
#include "calibrate/calibration_patches.h"
#include "calibrate/calibration_policy.h"
#include "calibrate/calibration_record.h"
#include "calibrate/profile_location.h"
#include "../support/skip.h"

namespace atonlab::runner {
namespace {

namespace fs = std::filesystem;
using store::test_support::file_bytes;
using store::test_support::TempDir;

/// L = black + (peak - black) V^gamma on grey, split over R, G, B by Rec.709 weight.
display::DisplayModel power_display(double gamma, double peak = 100.0, double black = 0.2) {
    std::array<display::GogParams, 3> p{};
    const double w[3] = {0.2126, 0.7152, 0.0722};
    for (int c = 0; c < 3; ++c)
        p[static_cast<std::size_t>(c)] = {w[c] * black, 0.0, std::pow(w[c] * (peak - black), 1.0 / gamma), gamma};
    return display::DisplayModel::gog(p, "power");
}

/// A measured calibration of `truth` (every measurement patch read exactly).
store::Calibration measured(const std::string& display, const display::DisplayModel& truth, const std::string& date) {
    std::vector<display::Measurement> ms;
    for (const Patch& p : measurement_patches())
        ms.push_back(display::Measurement{p.level(), p.channel, display::displayed_luminance_cd_m2(truth, p.rgb, 8), 0,
                                          glm::dvec3(p.rgb) / 255.0, "synthetic"});
    const auto report = display::fit_calibration(ms);
    store::Calibration c;
    c.display_name = display;
    c.width_px = 1920;
    c.height_px = 1080;
    c.width_m = 0.598;
    c.height_m = 0.3364;
    c.viewing_distance_m = 0.9;
    c.fit_json = display::measured_fit_json(report, display::display_from_calibration(report, display),
                                            {1920, 1080, 0.598, 0.9, 0.3364}, "measured");
    c.source = "measured";
    c.measured_at = date;
    return c;
}

std::vector<store::CalibrationReading> two_readings() {
    std::vector<store::CalibrationReading> out(2);
    out[0].patch = "black";
    out[0].channel = "grey";
    out[0].luminance_cd_m2 = 0.2;
    out[1].patch = "white";
    out[1].channel = "grey";
    out[1].level = out[1].drive_r = out[1].drive_g = out[1].drive_b = 1.0;
    out[1].luminance_cd_m2 = 100.0;
    return out;
}

/// A check of `cal` (stored in `file`) with every check patch read as `scale` times the truth.
CheckOutcome check(store::Store& file, const store::Calibration& cal, const display::DisplayModel& truth, double scale,
                   const std::string& date, const CheckTolerances& tol = {}) {
    std::vector<PhotometerReading> readings;
    for (const Patch& p : check_patches())
        {
        PhotometerReading r;
        r.luminance_cd_m2 = scale * display::displayed_luminance_cd_m2(truth, p.rgb, 8);
        readings.push_back(r);
    }
    const CheckOutcome o = evaluate_check(display_model_of(cal), check_patches(), readings, tol);
    store::CalibrationCheck k;
    k.calibration = cal.id;
    k.checked_at = date;
    k.passed = o.passed();
    k.results_json = check_results_json(o, tol, cal);
    k.source = "measured";
    file.put_calibration_check(k);
    return o;
}

protocols::Display booth(const std::string& name) {
    protocols::Display d;
    d.width_px = 1920;
    d.height_px = 1080;
    d.width_m = 0.598;
    d.viewing_distance_m = 0.9;
    d.name = name;
    d.max_calibration_age_days = 365.0;
    return d;
}

TEST(CalibrationProfiles, OneMeasurementServesTwoStudiesEachKeepingACopy) {
    TempDir dir;
    const display::DisplayModel truth = power_display(2.2);
    store::CalibrationId in_profiles;
    {
        store::Profiles p = store::Profiles::create_or_open(dir / "profiles.sqlite");
        in_profiles = p.displays().put_calibration(measured("booth-2", truth, "2024-05-01"), two_readings());
        const store::Calibration cal = p.displays().calibration(in_profiles);
        check(p.displays(), cal, truth, 1.0, "2024-05-10");
    }
    const store::Profiles profiles = store::Profiles::open_read_only(dir / "profiles.sqlite");
    const RunProfiles run{&profiles.displays(), (dir / "profiles.sqlite").string()};
    const store::Calibration original = profiles.displays().calibration(in_profiles);

    for (const char* name : {"a.db", "b.db"}) {
        SCOPED_TRACE(name);
        store::Store study = store::Store::create_or_open(dir / name);
        // The study file has nothing of its own: the profile file's calibration is used.
        SessionCalibration s = session_calibration(&study, booth("booth-2"), std::nullopt, "2024-06-01", name, run);
        EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
        EXPECT_FALSE(s.calibration.has_value());
        ASSERT_TRUE(s.from_profiles.has_value());
        ASSERT_TRUE(s.display.has_value());
        EXPECT_EQ(s.display->peak_cd_m2, display_model_of(original).peak_cd_m2);
        const store::CalibrationId copied = copy_into_study(study, *s.from_profiles);
        // A second session adds nothing: the same id, one calibration, one check.
        s = session_calibration(&study, booth("booth-2"), std::nullopt, "2024-06-01", name, run);
        ASSERT_TRUE(s.from_profiles.has_value());
        EXPECT_EQ(copy_into_study(study, *s.from_profiles), copied);
        const auto cals = study.calibrations("booth-2");
        ASSERT_EQ(cals.size(), 1u);
        EXPECT_EQ(cals[0].fit_json, original.fit_json);
        EXPECT_EQ(cals[0].measured_at, "2024-05-01");
        EXPECT_EQ(cals[0].width_m, 0.598);
        EXPECT_NE(cals[0].source.find("copied from the display-profile file"), std::string::npos);
        EXPECT_EQ(study.calibration_readings(copied), two_readings());
        const auto checks = study.calibration_checks(copied);
        ASSERT_EQ(checks.size(), 1u);
        EXPECT_EQ(checks[0].checked_at, "2024-05-10");
        EXPECT_TRUE(checks[0].passed);
        EXPECT_EQ(checks[0].results_json, profiles.displays().calibration_checks(in_profiles)[0].results_json);
    }
}

TEST(CalibrationProfiles, AStudysOwnLaterCalibrationWinsAndOldStudiesKeepWorking) {
    TempDir dir;
    store::Profiles p = store::Profiles::create_or_open(dir / "profiles.sqlite");
    p.displays().put_calibration(measured("booth-2", power_display(2.2), "2024-05-01"));
    const RunProfiles run{&p.displays(), (dir / "profiles.sqlite").string()};
    store::Store study = store::Store::create_or_open(dir / "study.db");
    const store::CalibrationId own =
        study.put_calibration(measured("booth-2", power_display(2.4, 150.0), "2024-05-20"));
    SessionCalibration s = session_calibration(&study, booth("booth-2"), std::nullopt, "2024-06-01", "study.db", run);
    ASSERT_TRUE(s.calibration.has_value());
    EXPECT_EQ(*s.calibration, own);
    EXPECT_FALSE(s.from_profiles.has_value());
    ASSERT_TRUE(s.display.has_value());
    EXPECT_NEAR(s.display->peak_cd_m2, 150.0, 0.01);
    // Without a profile file (--no-profiles, or none yet), as before.
    s = session_calibration(&study, booth("booth-2"), std::nullopt, "2024-06-01", "study.db");
    EXPECT_EQ(s.calibration, own);
    // A display neither file has: one warning naming both files.
    s = session_calibration(&study, booth("booth-9"), std::nullopt, "2024-06-01", "study.db", run);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("no calibration in the display-profile file"), std::string::npos) << s.warnings[0];
    EXPECT_NE(s.warnings[0].find("study.db"), std::string::npos) << s.warnings[0];
}

TEST(CalibrationProfiles, FailedCheckInTheProfileFileWarns) {
    TempDir dir;
    const display::DisplayModel truth = power_display(2.2);
    store::Profiles p = store::Profiles::create_or_open(dir / "profiles.sqlite");
    const store::CalibrationId id = p.displays().put_calibration(measured("booth-2", truth, "2024-05-01"));
    check(p.displays(), p.displays().calibration(id), truth, 0.9, "2024-05-15");  // the backlight lost 10 %
    const RunProfiles run{&p.displays(), "profiles.sqlite"};
    store::Store study = store::Store::create_or_open(dir / "study.db");
    const SessionCalibration s =
        session_calibration(&study, booth("booth-2"), std::nullopt, "2024-06-01", "study.db", run);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("in the display-profile file profiles.sqlite"), std::string::npos) << s.warnings[0];
    EXPECT_NE(s.warnings[0].find("failed on 2024-05-15 (luminance_percent 10 > 5, peak_percent 10 > 5)"),
              std::string::npos)
        << s.warnings[0];
}

TEST(CalibrationProfiles, DriftTableAndFigureHoldTheStoredChecks) {
    TempDir dir;
    const display::DisplayModel truth = power_display(2.2);
    store::Profiles p = store::Profiles::create_or_open(dir / "profiles.sqlite");
    store::Store& f = p.displays();
    const store::Calibration cal = f.calibration(f.put_calibration(measured("booth-2", truth, "2024-05-01")));
    // Three checks, stored out of date order: 100 %, 97 % and 90 % of the truth.
    const CheckOutcome c2 = check(f, cal, truth, 0.97, "2024-06-01T08:00:00Z");
    const CheckOutcome c1 = check(f, cal, truth, 1.0, "2024-05-02");
    const CheckOutcome c3 = check(f, cal, truth, 0.9, "2024-07-01");
    const std::vector<analysis::DriftPoint> d = analysis::display_drift(f, "booth-2");
    ASSERT_EQ(d.size(), 3u);
    EXPECT_EQ(d[0].checked_at, "2024-05-02");
    EXPECT_EQ(d[1].checked_at, "2024-06-01T08:00:00Z");
    EXPECT_EQ(d[2].checked_at, "2024-07-01");
    const CheckOutcome* outcomes[] = {&c1, &c2, &c3};
    const double scales[] = {1.0, 0.97, 0.9};
    const double white = display::displayed_luminance_cd_m2(truth, glm::ivec3(255), 8);
    const double black = display::displayed_luminance_cd_m2(truth, glm::ivec3(0), 8);
    for (int i = 0; i < 3; ++i) {
        SCOPED_TRACE(i);
        const analysis::DriftPoint& x = d[static_cast<std::size_t>(i)];
        const CheckOutcome& o = *outcomes[i];
        EXPECT_EQ(x.passed, o.passed());
        EXPECT_EQ(x.calibration_id, cal.id.value);
        // The readings as made, through results_json (17 significant digits: exact).
        EXPECT_EQ(x.peak_cd_m2, scales[i] * white);
        EXPECT_EQ(x.black_cd_m2, scales[i] * black);
        EXPECT_EQ(x.peak_predicted_cd_m2, o.patches.back().predicted_cd_m2);
        EXPECT_EQ(x.gamma_measured, o.gamma_measured);
        EXPECT_EQ(x.gamma_predicted, o.gamma_predicted);
        EXPECT_EQ(x.worst_error_percent, o.luminance_percent);
        EXPECT_EQ(x.tol_peak_percent, 5.0);
        EXPECT_EQ(x.tol_black_cd_m2, 0.05);
        EXPECT_EQ(x.tol_gamma, 0.1);
        EXPECT_EQ(x.tol_luminance_percent, 5.0);
    }
    EXPECT_NEAR(d[2].worst_error_percent, 10.0, 1e-6);  // every patch at 90 %: 10 % low
    EXPECT_FALSE(d[2].passed);
    EXPECT_TRUE(d[0].passed && d[1].passed);

    // The table: one line per check, in date order, with its values.
    const std::string table = analysis::drift_table(d);
    const auto at1 = table.find("2024-05-02"), at2 = table.find("2024-06-01T08:00:00Z"), at3 = table.find("2024-07-01");
    ASSERT_NE(at3, std::string::npos) << table;
    EXPECT_LT(at1, at2);
    EXPECT_LT(at2, at3);
    EXPECT_NE(table.find(fmt::format("{:.4g} ({:.4g} ± 5%)", 0.9 * white, white)), std::string::npos) << table;
    EXPECT_NE(table.find("FAILED"), std::string::npos) << table;
    EXPECT_NE(table.find("  10.00 grey-"), std::string::npos) << table;  // every patch 10 % low: any is the worst

    // The figure's data rows: dates as epoch seconds, bands around the prediction.
    const auto rows = analysis::drift_data_rows(d);
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[0][0], "1714608000");  // 2024-05-02T00:00:00Z
    EXPECT_EQ(rows[1][0], "1717228800");  // 2024-06-01T08:00:00Z
    EXPECT_EQ(rows[2][1], "0");
    EXPECT_EQ(std::stod(rows[2][2]), 0.9 * white);
    EXPECT_NEAR(std::stod(rows[2][3]), white * 0.95, 1e-6 * white);
    EXPECT_NEAR(std::stod(rows[2][4]), white * 1.05, 1e-6 * white);

    // The figure, when gnuplot is there (scripts/setup.sh installs it).
    const fs::path svg = dir / "drift.svg";
    const std::string why = analysis::plot_drift(svg, d, "booth-2");
    if (why.find("not installed") != std::string::npos) ATONLAB_SKIP_MISSING_TOOL() << why;
    ASSERT_EQ(why, "");
    const std::string text = file_bytes(svg);
    EXPECT_NE(text.find("<svg"), std::string::npos);
    EXPECT_NE(text.find("peak (cd/m2)"), std::string::npos);
    EXPECT_NE(analysis::plot_drift(dir / "drift.pdf", d, "x").find("not '.pdf'"), std::string::npos);
}

TEST(CalibrationProfiles, TheReportShowsTheChecksTheStudyHolds) {
    TempDir dir;
    const fs::path study = dir / "s.db";
    const display::DisplayModel truth = power_display(2.2);
    store::CalibrationId id;
    {
        store::Store s = store::Store::create_or_open(study);
        id = s.put_calibration(measured("booth-2", truth, "2024-05-01"));
        const store::Calibration cal = s.calibration(id);
        check(s, cal, truth, 0.9, "2024-07-01");
        check(s, cal, truth, 1.0, "2024-05-02");
    }
    analysis::test_data::run_simulated(study, analysis::test_data::constant_stimuli_protocol(5),
                                       analysis::test_data::sim("A", 1.95, 0.12), 7, true, 1u << 30, id);
    const analysis::Dataset d = analysis::read_study(study);
    ASSERT_EQ(d.calibrations.size(), 1u);
    const auto& drift = d.calibrations[0].drift;
    ASSERT_EQ(drift.size(), 2u);
    const double white = display::displayed_luminance_cd_m2(truth, glm::ivec3(255), 8);
    EXPECT_EQ(drift[0].checked_at, "2024-05-02");
    EXPECT_EQ(drift[1].peak_cd_m2, 0.9 * white);
    EXPECT_FALSE(drift[1].passed);

    analysis::AnalysisOptions o;
    o.bootstrap = 20;
    const analysis::StudyResults r = analysis::analyze_study(d, o);
    const fs::path out = dir / "out";
    fs::create_directories(out);
    const analysis::PlotResult plots = analysis::make_figures(out, d, r);
    analysis::ReportContext ctx;
    ctx.data = &d;
    ctx.results = &r;
    ctx.plots = &plots;
    ctx.software_version = "test";
    analysis::write_report(out, ctx);
    const std::string html = file_bytes(out / "report.html");
    EXPECT_NE(html.find("Checks of display booth-2 over time"), std::string::npos);
    const auto first = html.find("<td>2024-05-02</td>"), second = html.find("<td>2024-07-01</td>");
    ASSERT_NE(second, std::string::npos);
    EXPECT_LT(first, second);
    EXPECT_NE(html.find(fmt::format("{:.4g} ({:.4g} &plusmn; 5%)", 0.9 * white, white)), std::string::npos);
    const nlohmann::json j = store::parse_json(file_bytes(out / "summary.json"), "summary.json");
    EXPECT_EQ(store::number_at(j, "/calibrations/0/checks/1/peak_cd_m2"), 0.9 * white);
    EXPECT_EQ(store::boolean_at(j, "/calibrations/0/checks/1/passed"), false);
    if (plots.gnuplot_missing) ATONLAB_SKIP_MISSING_TOOL() << "gnuplot is not installed: no figures";
    bool drawn = false;
    for (const analysis::Figure& f : plots.figures) drawn = drawn || f.kind == "calibration-drift";
    EXPECT_TRUE(drawn);
    EXPECT_TRUE(plots.problems.empty()) << plots.problems.front();
}

TEST(CalibrationProfiles, LocationFollowsOptionThenEnvironmentThenXdg) {
    ::setenv("ATONLAB_PROFILES", "/lab/profiles.sqlite", 1);
    ::setenv("XDG_DATA_HOME", "/data", 1);
    EXPECT_EQ(profiles_location("x.sqlite")->path, "x.sqlite");
    EXPECT_EQ(profiles_location("")->path, "/lab/profiles.sqlite");
    EXPECT_TRUE(profiles_location("")->explicit_path);
    ::unsetenv("ATONLAB_PROFILES");
    EXPECT_EQ(profiles_location("")->path, "/data/atonlab/profiles.sqlite");
    EXPECT_FALSE(profiles_location("")->explicit_path);
    ::setenv("XDG_DATA_HOME", "relative", 1);  // not absolute: ignored (XDG Base Directory 0.8)
    ::setenv("HOME", "/home/lab", 1);
    EXPECT_EQ(profiles_location("")->path, "/home/lab/.local/share/atonlab/profiles.sqlite");
    // An absent default is no profile file; an absent file the user named is an error.
    TempDir dir;
    ::setenv("XDG_DATA_HOME", dir.path().c_str(), 1);
    EXPECT_FALSE(open_profiles_for_run("", false).has_value());
    EXPECT_THROW(open_profiles_for_run((dir / "none.sqlite").string(), false), InputError);
    EXPECT_FALSE(open_profiles_for_run((dir / "none.sqlite").string(), true).has_value());
}

}  // namespace
}  // namespace atonlab::runner
