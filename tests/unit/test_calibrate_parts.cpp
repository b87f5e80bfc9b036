// The parts of `atonlab calibrate` and `atonlab view` that need no GL
// (docs/calibration.md, docs/view.md): the patch sets, what an operator may
// type, readings files, the check's verdicts against analytic readings, the
// fit_json round trip, pixels per degree, the run-time calibration policy,
// and the view's keys. Expected values are analytic, not the code's output.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "atonlab/common/input_error.h"
#include "atonlab/display/calibration.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/store/json.h"
#include "atonlab/store/store.h"
#include "calibrate/calibration_check.h"
#include "calibrate/calibration_patches.h"
#include "calibrate/calibration_policy.h"
#include "calibrate/calibration_record.h"
#include "calibrate/photometer_input.h"
#include "view_controls.h"

namespace atonlab::runner {
namespace {

namespace fs = std::filesystem;
using store::test_support::TempDir;

// --- Patches ----------------------------------------------------------------------

TEST(CalibratePatches, MeasurementSetHasBlackWhiteAndEvenRamps) {
    const auto p = measurement_patches(17, 9);
    ASSERT_EQ(p.size(), 2u + 15u + 3u * 8u);
    EXPECT_EQ(p[0].name, "black");
    EXPECT_EQ(p[0].rgb, glm::ivec3(0));
    EXPECT_EQ(p[1].name, "white");
    EXPECT_EQ(p[1].rgb, glm::ivec3(255));
    // Grey ramp: round(i * 255 / 16), i = 1..15: 16, 32, ..., 128 (127.5 rounds up), ..., 239.
    EXPECT_EQ(p[2].name, "grey-016");
    EXPECT_EQ(p[9].code, 128);
    EXPECT_EQ(p[16].code, 239);
    // Red ramp: round(i * 255 / 8), i = 1..8: 32 (31.875), 64, 96, 128, 159, 191, 223, 255.
    const int red[] = {32, 64, 96, 128, 159, 191, 223, 255};
    for (int i = 0; i < 8; ++i) {
        const Patch& r = p[17 + static_cast<std::size_t>(i)];
        EXPECT_EQ(r.channel, display::Channel::red);
        EXPECT_EQ(r.rgb, glm::ivec3(red[i], 0, 0));
    }
    EXPECT_EQ(p.back().name, "blue-255");
    EXPECT_EQ(p.back().rgb, glm::ivec3(0, 0, 255));
    EXPECT_DOUBLE_EQ(p[9].level(), 128.0 / 255.0);
}

TEST(CalibratePatches, CheckSetIsBlackQuartersAndWhite) {
    const auto p = check_patches();
    ASSERT_EQ(p.size(), 5u);
    const int codes[] = {0, 64, 128, 191, 255};  // 25, 50, 75 % of 255: 63.75, 127.5, 191.25
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(p[i].rgb, glm::ivec3(codes[i]));
}

TEST(CalibratePatches, TooFewLevelsNameTheOption) {
    try {
        measurement_patches(8, 9);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.where()->option, "--grey-levels");
    }
    try {
        measurement_patches(9, 3);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.where()->option, "--colour-levels");
    }
}

// --- What an operator types ------------------------------------------------------

TEST(CalibrateInput, ReadingsCommandsAndTypos) {
    auto reading = [](std::string_view s) {
        const OperatorLine l = parse_operator_line(s);
        EXPECT_TRUE(std::holds_alternative<TypedReading>(l)) << s;
        return std::holds_alternative<TypedReading>(l) ? std::get<TypedReading>(l).reading : PhotometerReading{};
    };
    EXPECT_EQ(reading("21.9").luminance_cd_m2, 21.9);
    EXPECT_EQ(reading("  21.9 cd/m2 ").luminance_cd_m2, 21.9);
    EXPECT_EQ(reading("0").luminance_cd_m2, 0.0);
    // 1 fL = (1/π) cd/ft² = 1 / (π · 0.3048²) cd/m².
    EXPECT_NEAR(reading("2 fL").luminance_cd_m2, 2.0 / (std::numbers::pi * 0.3048 * 0.3048), 1e-12);
    const PhotometerReading xyz = reading("20.5 21.9 23.25");
    EXPECT_EQ(xyz.luminance_cd_m2, 21.9);
    ASSERT_TRUE(xyz.xyz_cd_m2.has_value());
    EXPECT_EQ(xyz.xyz_cd_m2->x, 20.5);
    EXPECT_EQ(xyz.xyz_cd_m2->z, 23.25);

    EXPECT_EQ(std::get<OperatorCommand>(parse_operator_line("r")), OperatorCommand::repeat);
    EXPECT_EQ(std::get<OperatorCommand>(parse_operator_line("b")), OperatorCommand::back);
    EXPECT_EQ(std::get<OperatorCommand>(parse_operator_line("q")), OperatorCommand::quit);
    EXPECT_EQ(std::get<OperatorCommand>(parse_operator_line("?")), OperatorCommand::help);
    auto typo = [](std::string_view s) {
        const OperatorLine l = parse_operator_line(s);
        EXPECT_TRUE(std::holds_alternative<std::string>(l)) << s;
        return std::holds_alternative<std::string>(l) ? std::get<std::string>(l) : std::string();
    };
    EXPECT_NE(typo("2l.9").find("'2l.9' is not a number"), std::string::npos);
    EXPECT_NE(typo("-3").find("negative"), std::string::npos);
    EXPECT_NE(typo("1 2").find("not 2 values"), std::string::npos);
    EXPECT_NE(typo("21.9 lux").find("'lux' is neither a number nor a unit"), std::string::npos);
    EXPECT_NE(typo("").find("nothing"), std::string::npos);
    EXPECT_NE(typo("nan").find("not a number"), std::string::npos);
}

TEST(CalibrateInput, ReadingsFileByOrderAndName) {
    TempDir dir;
    const auto patches = check_patches();
    const fs::path good = dir / "good.txt";
    std::ofstream(good) << "# a comment\n\nblack 0.2\n5.1 # no name\ngrey-128 1 21.5 2\n\ngrey-191 48 cd/m2\n99.5\n";
    const auto r = read_readings_file(good, patches);
    ASSERT_EQ(r.size(), 5u);
    EXPECT_EQ(r[0].luminance_cd_m2, 0.2);
    EXPECT_EQ(r[0].line, 3);
    EXPECT_EQ(r[1].luminance_cd_m2, 5.1);
    EXPECT_EQ(r[2].luminance_cd_m2, 21.5);
    EXPECT_TRUE(r[2].xyz_cd_m2.has_value());
    EXPECT_EQ(r[4].line, 8);

    auto error_of = [&](const std::string& text) {
        const fs::path f = dir / "bad.txt";
        std::ofstream(f) << text;
        try {
            read_readings_file(f, patches);
        } catch (const InputError& e) {
            return *e.where();
        }
        ADD_FAILURE() << "accepted: " << text;
        return SourceLocation{};
    };
    SourceLocation at = error_of("black 0.2\ngrey-128 5.1\n");  // grey-064 expected second
    EXPECT_EQ(at.line, 2);
    EXPECT_EQ(at.column, 1);
    EXPECT_EQ(at.key, "patch");
    at = error_of("0.2\n5.1\n21\n48\n");  // one short
    EXPECT_EQ(at.line, 4);
    at = error_of("0.2\n5.1\n21\n48\n99\n100\n");  // one too many
    EXPECT_EQ(at.line, 6);
    at = error_of("0.2\n5.1\n2l.9\n48\n99\n");
    EXPECT_EQ(at.line, 3);
    EXPECT_EQ(at.key, "cd_m2");
}

TEST(CalibrateInput, ArgyllXyzIsKeptOnTheLuminanceScale) {
    // display.ti3 line 32: "1 0 0 0 0.118813 0.125000 0.136125", normalised to white Y = 100,
    // LUMINANCE_XYZ_CDM2 Y = 120: absolute = value × 1.2.
    const auto ms = display::read_argyll_ti3(fs::path(ATONLAB_SOURCE_DIR) / "tests/data/calibration/display.ti3");
    ASSERT_TRUE(ms[0].xyz_cd_m2.has_value());
    EXPECT_NEAR(ms[0].xyz_cd_m2->x, 0.118813 * 1.2, 1e-12);
    EXPECT_NEAR(ms[0].xyz_cd_m2->y, ms[0].luminance_cd_m2, 1e-15);
    EXPECT_NEAR(ms[0].xyz_cd_m2->z, 0.136125 * 1.2, 1e-12);
    const auto csv =
        display::read_calibration_csv(fs::path(ATONLAB_SOURCE_DIR) / "tests/data/calibration/grey_ramp.csv");
    EXPECT_FALSE(csv[0].xyz_cd_m2.has_value());
}

// --- The check against analytic readings ---------------------------------------------

/// A GOG display with b = 0 on every channel: L_c(V) = a_c + (k_c V)^γ, so the
/// effective gamma of grey above black is exactly γ.
display::DisplayModel power_display(double gamma, double peak = 100.0, double black = 0.2) {
    std::array<display::GogParams, 3> p{};
    const double w[3] = {0.2126, 0.7152, 0.0722};
    for (int c = 0; c < 3; ++c)
        p[static_cast<std::size_t>(c)] = {w[c] * black, 0.0, std::pow(w[c] * (peak - black), 1.0 / gamma), gamma};
    return display::DisplayModel::gog(p, "power");
}

std::vector<PhotometerReading> readings_from(const display::DisplayModel& truth, double scale = 1.0,
                                             double add_cd_m2 = 0.0) {
    std::vector<PhotometerReading> out;
    for (const Patch& p : check_patches()) {
        PhotometerReading r;
        r.luminance_cd_m2 = scale * display::displayed_luminance_cd_m2(truth, p.rgb, 8) + add_cd_m2;
        out.push_back(r);
    }
    return out;
}

TEST(CalibrateCheck, ExactReadingsPassAndEachDriftFailsItsOwnTolerance) {
    const auto model = power_display(2.2);
    const CheckTolerances tol;
    const CheckOutcome same = evaluate_check(model, check_patches(), readings_from(model), tol);
    EXPECT_TRUE(same.passed());
    EXPECT_EQ(same.luminance_percent, 0.0);
    EXPECT_NEAR(same.gamma_predicted, 2.2, 1e-12);  // b = 0: log-linear
    EXPECT_NEAR(same.gamma, 0.0, 1e-12);

    // The backlight lost 10 %: every patch × 0.9. Luminance and peak fail (10 % > 5 %); black
    // moves by 0.02 cd/m² (< 0.05) and the slope of log(L - L0) is unchanged.
    const CheckOutcome dim = evaluate_check(model, check_patches(), readings_from(model, 0.9), tol);
    EXPECT_EQ(dim.failed, (std::vector<std::string>{"luminance_percent", "peak_percent"}));
    EXPECT_NEAR(dim.peak_percent, 10.0, 1e-9);
    EXPECT_NEAR(dim.black_cd_m2, 0.02, 1e-12);
    EXPECT_NEAR(dim.gamma, 0.0, 1e-9);

    // Black raised by 0.1 cd/m² (ambient light on the screen): only black fails; the
    // darkest grey (code 64, (64/255)^2.2 · 99.8 + 0.2 ≈ 4.87 cd/m²) is off by ~2 %.
    const CheckOutcome flare = evaluate_check(model, check_patches(), readings_from(model, 1.0, 0.1), tol);
    EXPECT_EQ(flare.failed, std::vector<std::string>{"black_cd_m2"});
    EXPECT_NEAR(flare.black_cd_m2, 0.1, 1e-12);

    // A display now at gamma 2.6 against a calibration at 2.2: the slope is off by 0.4.
    const CheckOutcome steep = evaluate_check(model, check_patches(), readings_from(power_display(2.6)), tol);
    EXPECT_NEAR(steep.gamma_measured, 2.6, 1e-9);
    EXPECT_NEAR(steep.gamma, 0.4, 1e-9);
    EXPECT_NE(std::find(steep.failed.begin(), steep.failed.end(), "gamma"), steep.failed.end());

    // results_json is JSON with the failed names.
    store::Calibration cal;
    cal.id = store::CalibrationId{7};
    cal.measured_at = "2024-05-01";
    const nlohmann::json j = store::parse_json(check_results_json(dim, tol, cal));
    EXPECT_EQ(store::number_at(j, "/calibration_id"), 7.0);
    EXPECT_EQ(store::array_at(j, "/failed").size(), 2u);
    EXPECT_EQ(store::string_at(j, "/failed/1"), "peak_percent");
    EXPECT_EQ(store::number_at(j, "/tolerances/peak_percent"), 5.0);
    EXPECT_EQ(store::array_at(j, "/patches").size(), 5u);
}

// --- fit_json, geometry ------------------------------------------------------------------

std::vector<display::Measurement> synthetic_measurements(const display::DisplayModel& truth) {
    std::vector<display::Measurement> out;
    int line = 1;
    for (const Patch& p : measurement_patches()) {
        out.push_back(display::Measurement{p.level(), p.channel, display::displayed_luminance_cd_m2(truth, p.rgb, 8),
                                           ++line, glm::dvec3(p.rgb) / 255.0, "synthetic"});
    }
    return out;
}

TEST(CalibrateRecord, FitJsonRoundTripsTheDisplayModel) {
    const auto report = display::fit_calibration(synthetic_measurements(power_display(2.3)));
    const auto model = display::display_from_calibration(report, "lab");
    display::DisplayGeometry g{1920, 1080, 0.598, 0.9,
                               0.336};  // width, height px; width m; distance m; measured height m
    store::Calibration c;
    c.id = store::CalibrationId{3};
    c.display_name = "lab";
    c.fit_json = display::measured_fit_json(report, model, g, "measured");
    EXPECT_TRUE(is_measured(c));
    const display::DisplayModel back = display_model_of(c);
    for (int ch = 0; ch < 3; ++ch) {
        const auto a = display::gog_params_of(model.channels[static_cast<std::size_t>(ch)]);
        const auto b = display::gog_params_of(back.channels[static_cast<std::size_t>(ch)]);
        EXPECT_EQ(a.a, b.a);  // shortest round-trip decimal, read back by SQLite's JSON
        EXPECT_EQ(a.b, b.b);
        EXPECT_EQ(a.k, b.k);
        EXPECT_EQ(a.gamma, b.gamma);
    }
    EXPECT_EQ(back.peak_cd_m2, model.peak_cd_m2);
    c.fit_json = R"({"model":"nominal","peak_cd_m2":100})";
    EXPECT_FALSE(is_measured(c));
    EXPECT_THROW(display_model_of(c), InputError);
}

TEST(CalibrateRecord, PixelsPerDegreeAtTheCentre) {
    // One pixel of pitch p at distance d subtends 2 atan(p / 2d); choose d so that it is 1/60°.
    const double pitch = 0.5 / 1000.0;
    const double d = pitch / (2.0 * std::tan(std::numbers::pi / 180.0 / 120.0));
    const display::DisplayGeometry g{1000, 500, 0.5, d, 0.25};
    EXPECT_NEAR(g.pixels_per_degree(), 60.0, 1e-9);
}

// --- The session's calibration ---------------------------------------------------------

protocols::Display protocol_display(const std::string& name, std::optional<double> max_days = std::nullopt) {
    protocols::Display d;
    d.width_px = 1920;
    d.height_px = 1080;
    d.width_m = 0.598;
    d.viewing_distance_m = 0.9;
    d.name = name;
    d.max_calibration_age_days = max_days;
    return d;
}

bool any_contains(const std::vector<std::string>& lines, const std::string& what) {
    for (const auto& l : lines)
        if (l.find(what) != std::string::npos) return true;
    return false;
}

TEST(CalibratePolicy, DaysBetweenDates) {
    EXPECT_EQ(days_between("2024-01-31T10:00:00Z", "2024-03-01"), 30);  // 2024 is a leap year
    EXPECT_EQ(days_between("2023-01-31", "2023-03-01"), 29);
    EXPECT_EQ(days_between("2024-05-01", "2024-05-01"), 0);
    EXPECT_FALSE(days_between("yesterday", "2024-05-01").has_value());
    EXPECT_FALSE(days_between("2024-02-30", "2024-05-01").has_value());
}

TEST(CalibratePolicy, WarnsAndChoosesTheMeasuredCalibration) {
    TempDir dir;
    store::Store db = store::Store::create_or_open(dir / "study.db");
    // No name in the protocol.
    SessionCalibration s = session_calibration(&db, protocol_display(""), std::nullopt, "2024-06-01", "study.db");
    EXPECT_FALSE(s.calibration.has_value());
    EXPECT_TRUE(s.warnings.empty());
    EXPECT_TRUE(any_contains(s.notes, "names no display"));
    // A name, but only a nominal row under it.
    store::Calibration nominal;
    nominal.display_name = "lab";
    nominal.width_px = 1920;
    nominal.height_px = 1080;
    nominal.width_m = 0.598;
    nominal.height_m = 0.336;
    nominal.viewing_distance_m = 0.9;
    nominal.fit_json = R"({"model":"nominal"})";
    nominal.source = "scene";
    nominal.measured_at = "2024-05-30";
    db.put_calibration(nominal);
    s = session_calibration(&db, protocol_display("lab"), std::nullopt, "2024-06-01", "study.db");
    EXPECT_FALSE(s.calibration.has_value());
    EXPECT_FALSE(s.display.has_value());
    EXPECT_TRUE(any_contains(s.warnings, "display \"lab\" has no calibration in study.db"));

    // A measured calibration, 40 days old, then a nominal row after it (still skipped).
    const auto report = display::fit_calibration(synthetic_measurements(power_display(2.2)));
    const auto model = display::display_from_calibration(report, "lab");
    store::Calibration measured = nominal;
    measured.fit_json = display::measured_fit_json(report, model, {1920, 1080, 0.598, 0.9, 0.336}, "measured");
    measured.source = "measured";
    measured.measured_at = "2024-04-22T09:00:00Z";
    const store::CalibrationId id = db.put_calibration(measured);
    s = session_calibration(&db, protocol_display("lab"), std::nullopt, "2024-06-01", "study.db");
    ASSERT_TRUE(s.calibration.has_value());
    EXPECT_EQ(*s.calibration, id);
    ASSERT_TRUE(s.display.has_value());
    EXPECT_EQ(s.display->peak_cd_m2, model.peak_cd_m2);
    EXPECT_TRUE(any_contains(s.warnings, "is 40 days old, older than max_calibration_age_days = 30 (the default)"));
    s = session_calibration(&db, protocol_display("lab", 60.0), std::nullopt, "2024-06-01", "study.db");
    EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();

    // Its latest check failed.
    store::CalibrationCheck check;
    check.calibration = id;
    check.checked_at = "2024-05-20";
    check.passed = false;
    check.results_json =
        R"({"failed":["peak_percent"],"values":{"peak_percent":10.2},"tolerances":{"peak_percent":5}})";
    check.source = "measured";
    db.put_calibration_check(check);
    s = session_calibration(&db, protocol_display("lab", 60.0), std::nullopt, "2024-06-01", "study.db");
    EXPECT_TRUE(any_contains(s.warnings, "failed on 2024-05-20 (peak_percent 10.2 > 5)"));

    // Another geometry in the protocol.
    protocols::Display other = protocol_display("lab", 60.0);
    other.width_px = 1280;
    s = session_calibration(&db, other, std::nullopt, "2024-06-01", "study.db");
    EXPECT_TRUE(any_contains(s.warnings, "the protocol's [display] says 1280 x 1080 px"));

    // A resumed session keeps what it began with: the nominal row stays nominal.
    std::optional<store::CalibrationId> nominal_id;
    for (const auto& row : db.calibrations("lab"))
        if (row.source == "scene") nominal_id = row.id;
    ASSERT_TRUE(nominal_id.has_value());
    s = session_calibration(&db, protocol_display("lab"), nominal_id, "2024-06-01", "study.db");
    EXPECT_FALSE(s.calibration.has_value());
    EXPECT_TRUE(s.warnings.empty());

    // apply_display_model: the encoder and the tone mapper's L_dmax follow the model.
    stimuli::Scene scene;
    apply_display_model(scene, model);
    EXPECT_EQ(scene.output.display.name, "lab");
    EXPECT_EQ(scene.output.tonemap.display_peak_cd_m2, model.peak_cd_m2);
}

TEST(CalibratePolicy, ProtocolDisplayNameAndMaximumAge) {
    const fs::path run = fs::path(ATONLAB_SOURCE_DIR) / "tests/data/run";
    std::string text = store::test_support::file_bytes(run / "small_2afc.toml");
    const std::string scene = "scene = \"small.scene.toml\"";
    text.replace(text.find(scene), scene.size(), "scene = \"" + (run / "small.scene.toml").string() + "\"");
    auto with_keys = [&](const std::string& keys) {
        std::string t = text;
        t.insert(t.find("[display]\n") + 10, keys);
        return t;
    };
    const protocols::Protocol plain = protocols::parse_protocol(text, "p.toml");
    EXPECT_TRUE(plain.display.name.empty());
    EXPECT_FALSE(plain.display.max_calibration_age_days.has_value());
    const protocols::Protocol named =
        protocols::parse_protocol(with_keys("name = \"booth-2\"\nmax_calibration_age_days = 14.5\n"), "p.toml");
    EXPECT_EQ(named.display.name, "booth-2");
    EXPECT_EQ(named.display.max_calibration_age_days, 14.5);
    // Neither key becomes a scene override (the scene's [display] has no such keys).
    for (const SceneOverride& o : named.display_overrides())
        EXPECT_EQ(o.text().find("name"), std::string::npos) << o.text();
    auto error_key = [&](const std::string& keys) {
        try {
            protocols::parse_protocol(with_keys(keys), "p.toml");
        } catch (const InputError& e) {
            EXPECT_EQ(e.where()->line, 18) << e.what();  // [display] is line 15; 16 and 17 are blank
            return e.where()->key;
        }
        ADD_FAILURE() << keys;
        return std::string();
    };
    EXPECT_EQ(error_key("\n\nname = \"\"\n"), "display.name");
    EXPECT_EQ(error_key("\n\nmax_calibration_age_days = 0\n"), "display.max_calibration_age_days");
    EXPECT_EQ(error_key("\n\nmax_calibration_age_days = \"30\"\n"), "display.max_calibration_age_days");
    // display.max_out_of_gamut_loss: R5's share (docs/running.md), 5 % unless given, 0 … 1.
    EXPECT_EQ(plain.display.max_out_of_gamut_loss, 0.05);
    EXPECT_EQ(
        protocols::parse_protocol(with_keys("max_out_of_gamut_loss = 0.2\n"), "p.toml").display.max_out_of_gamut_loss,
        0.2);
    EXPECT_EQ(error_key("\n\nmax_out_of_gamut_loss = 1.5\n"), "display.max_out_of_gamut_loss");
}

// --- The view's keys ---------------------------------------------------------------------

TEST(ViewKeys, NamesMoveTurnAndToggle) {
    EXPECT_EQ(view_key_from_name("w"), ViewKey::forward);
    EXPECT_EQ(view_key_from_name("escape"), ViewKey::quit);
    EXPECT_FALSE(view_key_from_name("F13").has_value());
    EXPECT_TRUE(is_held_key(ViewKey::pitch_down));
    EXPECT_FALSE(is_held_key(ViewKey::pause));

    stimuli::Scene scene;
    scene.camera.yaw_deg = 90.0;  // east: +x
    scene.glare.model = stimuli::GlareModel::wave_optics;
    scene.adaptation_cd_m2 = 0.01;
    ViewControls v(scene);
    const ViewKey fwd[] = {ViewKey::forward};
    v.hold(fwd, 2.0, 1.0);  // 10 m/s for 2 s
    EXPECT_NEAR(v.scene().camera.position_m.x, 20.0, 1e-12);
    EXPECT_NEAR(v.scene().camera.position_m.z, 0.0, 1e-12);
    const ViewKey turn[] = {ViewKey::yaw_left};
    v.hold(turn, 1.0, 10.0);  // 20 °/s × 10 for 1 s: 90 - 200 = -110, i.e. 250
    EXPECT_NEAR(v.scene().camera.yaw_deg, 250.0, 1e-12);
    v.drag(100.0, 0.0, 0.05);  // 100 px at 0.05 °/px: the view turns left 5°
    EXPECT_NEAR(v.scene().camera.yaw_deg, 245.0, 1e-12);

    v.press(ViewKey::glare_toggle, 0.0);
    EXPECT_EQ(v.scene().glare.model, stimuli::GlareModel::none);
    v.press(ViewKey::glare_toggle, 0.0);
    EXPECT_EQ(v.scene().glare.model, stimuli::GlareModel::wave_optics);
    v.press(ViewKey::glare_cycle, 0.0);
    EXPECT_EQ(v.scene().glare.model, stimuli::GlareModel::gaussian_bloom);
    v.press(ViewKey::glare_cycle, 0.0);
    v.press(ViewKey::glare_cycle, 0.0);
    EXPECT_EQ(v.scene().glare.model, stimuli::GlareModel::cie);  // spencer, then the CIE veil
    v.press(ViewKey::glare_cycle, 0.0);
    EXPECT_EQ(v.scene().glare.model, stimuli::GlareModel::wave_optics);

    v.press(ViewKey::adapt_up, 0.0);
    EXPECT_NEAR(v.scene().adaptation_cd_m2, 0.01 * std::pow(10.0, 0.25), 1e-15);
    v.press(ViewKey::adapt_mode, 0.0);
    EXPECT_EQ(v.scene().output.adaptation.mode, stimuli::AdaptationMode::dynamic);
    v.press(ViewKey::adapt_down, 0.5);  // leaves dynamic at the adapted 0.5 cd/m²
    EXPECT_NEAR(v.scene().adaptation_cd_m2, 0.5 / std::pow(10.0, 0.25), 1e-15);

    v.press(ViewKey::pause, 0.0);
    v.advance(1.0);
    EXPECT_EQ(v.time_s(), 0.0);
    v.press(ViewKey::step_forward, 0.0);
    EXPECT_NEAR(v.time_s(), 0.1, 1e-15);
    v.press(ViewKey::reset_camera, 0.0);
    EXPECT_EQ(v.scene().camera.position_m, scene.camera.position_m);
    v.press(ViewKey::quit, 0.0);
    EXPECT_TRUE(v.quit_requested());
}

}  // namespace
}  // namespace atonlab::runner
