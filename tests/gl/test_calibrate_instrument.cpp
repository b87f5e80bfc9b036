// `atonlab calibrate measure|check --instrument` end to end (docs/calibration.md,
// "Measuring with an instrument"), through the binary (ATONLAB_BINARY), headless:
//
//  - the virtual instrument on a GOG display (peak 150 cd/m², black 0.3 cd/m²,
//    γ 2.4): every reading is the law at the codes read back from the
//    framebuffer, the fitted model predicts every patch within 0.2 % and the
//    grey ramp's γ within 0.5 %; with 1 % noise every patch lies within 4 of
//    its reported standard uncertainties; `check` passes on the same display
//    and fails, naming peak_percent, when its peak drops 10 %; `atonlab run`
//    uses the measured calibration;
//  - the real spotread code path against tests/data/spotread/spotread, a fake
//    that replays transcripts written from ArgyllCMS's printf calls: readings
//    parsed exactly and stored with their transcripts; a calibration request,
//    an error line, a hang and no instrument each end with one sentence, exit
//    status 5 and nothing stored.
// Skips where the binary finds no GL 4.5 context (exit status 3).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "../support/child_process.h"
#include "atonlab/display/display_model.h"
#include "atonlab/store/json.h"
#include "atonlab/store/store.h"
#include "../support/skip.h"
#include "text_contains.h"

#ifndef ATONLAB_BINARY
#error "ATONLAB_BINARY (the atonlab executable) must be defined by the build"
#endif

namespace atonlab {
namespace {

namespace fs = std::filesystem;
using store::Store;
using store::test_support::file_bytes;
using store::test_support::TempDir;

const fs::path kData = fs::path(ATONLAB_SOURCE_DIR) / "tests/data";

using Result = test::Captured;
using test::atonlab;

using ::atonlab::test::contains;

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

// --- The virtual display's law, independently of the runner ------------------------

/// IEC 61966-2-1 linear sRGB to XYZ (white Y = 1).
constexpr double kM[3][3] = {{0.4124, 0.3576, 0.1805}, {0.2126, 0.7152, 0.0722}, {0.0193, 0.1192, 0.9505}};

struct Law {
    double peak, black, gamma;
    std::array<double, 3> xyz(int r, int g, int b) const {
        const double f[3] = {shape(r), shape(g), shape(b)};
        std::array<double, 3> out{};
        for (int row = 0; row < 3; ++row)
            for (int c = 0; c < 3; ++c) out[static_cast<std::size_t>(row)] += peak * kM[row][c] * f[c];
        return out;
    }
    double shape(int code) const { return (black + (peak - black) * std::pow(code / 255.0, gamma)) / peak; }
};

const Law kDisplay{150.0, 0.3, 2.4};

std::vector<std::string> law_options(const Law& law) {
    return {"--virtual-peak-cd-m2",       fmt::format("{}", law.peak), "--virtual-black-cd-m2",
            fmt::format("{}", law.black), "--virtual-gamma",           fmt::format("{}", law.gamma)};
}

struct PatchCodes {
    std::string name;
    int r, g, b;
};

std::vector<PatchCodes> list_patches(const std::vector<std::string>& extra, const fs::path& dir) {
    const Result res = atonlab(
        with({"calibrate", "measure", "--display", "x", "--db", (dir / "unused.db").string(), "--list-patches"}, extra),
        dir);
    EXPECT_EQ(res.code, 0) << res.err;
    std::vector<PatchCodes> out;
    std::istringstream in(res.out);
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        PatchCodes p;
        std::istringstream ls(line);
        ls >> p.name;
        std::istringstream codes(line.substr(line.find("= ") + 2));
        codes >> p.r >> p.g >> p.b;
        out.push_back(p);
    }
    return out;
}

const std::vector<std::string> kGeometry = {"--width-px", "320", "--height-px",          "180",
                                            "--width-m",  "0.1", "--viewing-distance-m", "0.9"};

display::DisplayModel stored_model(const store::Calibration& c) {
    const nlohmann::json j = store::parse_json(c.fit_json);
    std::array<display::GogParams, 3> p{};
    for (int ch = 0; ch < 3; ++ch) {
        auto v = [&](const char* k) {
            return store::number_at(j, fmt::format("/display/channels/{}/{}", ch, k)).value();
        };
        p[static_cast<std::size_t>(ch)] = {v("a"), v("b"), v("k"), v("gamma")};
    }
    return display::DisplayModel::gog(p);
}

class CalibrateVirtual : public ::testing::Test {
protected:
    void SetUp() override {
        patches_ = list_patches({}, dir_.path());
        ASSERT_EQ(patches_.size(), 41u);
    }
    Result measure(const Law& law, const std::vector<std::string>& extra) {
        Result r = atonlab(with(with({"calibrate", "measure", "--display", "virtual-lcd", "--db", db().string(),
                                      "--headless", "--instrument", "virtual", "--settle-s", "0"},
                                     with(law_options(law), kGeometry)),
                                extra),
                           dir_.path());
        if (r.code == 3) skip_ = "no GL 4.5 context: " + r.err;
        return r;
    }
    Result check(const Law& law) {
        return atonlab(with({"calibrate", "check", "--display", "virtual-lcd", "--db", db().string(), "--headless",
                             "--instrument", "virtual", "--settle-s", "0", "--no-plot"},
                            law_options(law)),
                       dir_.path());
    }
    fs::path db() const { return dir_.path() / "study.db"; }

    TempDir dir_;
    std::vector<PatchCodes> patches_;
    std::string skip_;
};

TEST_F(CalibrateVirtual, NoiseFreeMeasureRecoversEveryPatchAndGamma) {
    const Result r = measure(kDisplay, {"--quiet"});
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    ASSERT_EQ(r.code, 0) << r.err;
    Store s = Store::open_read_only(db());
    const auto cal = s.latest_calibration("virtual-lcd");
    ASSERT_TRUE(cal.has_value());
    EXPECT_TRUE(contains(cal->source, "virtual instrument")) << cal->source;
    const auto readings = s.calibration_readings(cal->id);
    ASSERT_EQ(readings.size(), patches_.size());
    const display::DisplayModel model = stored_model(*cal);
    for (std::size_t i = 0; i < readings.size(); ++i) {
        const PatchCodes& p = patches_[i];
        const auto want = kDisplay.xyz(p.r, p.g, p.b);
        ASSERT_EQ(readings[i].patch, p.name);
        // The reading is the law at the codes read back: exact but for the
        // transcript's and the double's rounding.
        EXPECT_NEAR(readings[i].luminance_cd_m2, want[1], 1e-9 * want[1]) << p.name;
        EXPECT_NEAR(readings[i].xyz_x_cd_m2.value(), want[0], 1e-9 * want[0] + 1e-12) << p.name;
        EXPECT_NEAR(readings[i].xyz_z_cd_m2.value(), want[2], 1e-9 * want[2] + 1e-12) << p.name;
        ASSERT_TRUE(readings[i].transcript.has_value());
        EXPECT_TRUE(contains(*readings[i].transcript, "Result is XYZ")) << *readings[i].transcript;
        // The bound: the fitted model predicts every patch within 0.2 %.
        const double fitted = display::displayed_luminance_cd_m2(model, {p.r, p.g, p.b}, 8);
        EXPECT_NEAR(fitted, want[1], 2e-3 * want[1]) << p.name;
    }
    // The grey ramp's effective γ is the law's γ (L − L(0) = (peak − black) V^γ exactly), within 0.5 %.
    const nlohmann::json j = store::parse_json(cal->fit_json);
    bool grey = false;
    for (int i = 0; i < 4; ++i) {
        const auto channel = store::string_at(j, fmt::format("/ramps/{}/channel", i));
        if (!channel) break;
        const double gamma = store::number_at(j, fmt::format("/ramps/{}/effective_gamma", i)).value();
        EXPECT_NEAR(gamma, kDisplay.gamma, 5e-3 * kDisplay.gamma) << *channel;
        grey = grey || *channel == "grey";
    }
    EXPECT_TRUE(grey) << cal->fit_json;
}

TEST_F(CalibrateVirtual, NoisyReadingsLieWithinTheirReportedUncertainty) {
    // 1 % per reading, 4 readings a patch: each patch's mean within 4 reported
    // standard uncertainties (all 41 pass with probability 0.99994^41 = 99.7 %
    // when the uncertainty is right); a 6 % repeat tolerance keeps 1 % noise
    // from asking for a patch again.
    const Result r = measure(kDisplay, {"--virtual-noise", "0.01", "--virtual-seed", "7", "--repeats", "4",
                                        "--repeat-tolerance-percent", "6"});
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    ASSERT_EQ(r.code, 0) << r.err;
    std::istringstream in(r.out);
    std::string line;
    std::size_t seen = 0;
    struct GreyReading {
        double drive, cd_m2, u_cd_m2;
    };
    std::vector<GreyReading> grey;
    double black_cd_m2 = 0.0;
    while (std::getline(in, line)) {
        const auto y = line.find(" Y ");
        const auto pm = line.find(" ± ");
        if (y == std::string::npos || pm == std::string::npos) continue;
        ASSERT_LT(seen, patches_.size());
        const double mean = std::stod(line.substr(y + 3));
        const double u = std::stod(line.substr(pm + std::string(" ± ").size()));
        const PatchCodes& p = patches_[seen++];
        const double want = kDisplay.xyz(p.r, p.g, p.b)[1];
        EXPECT_GT(u, 0.0) << line;
        EXPECT_LE(std::abs(mean - want), 4.0 * u) << line << " (law: " << want << ")";
        // and the uncertainty is the noise's: 1 % / sqrt(4) = 0.5 % of the reading, give or take the scatter.
        EXPECT_LT(u, 0.015 * want) << line;
        if (p.r == p.g && p.g == p.b && p.r > 0) grey.push_back({p.r / 255.0, mean, u});
        if (p.r == 0 && p.g == 0 && p.b == 0) black_cd_m2 = mean;
    }
    EXPECT_EQ(seen, patches_.size()) << r.out;
    // The grey ramp's effective γ (the slope of log10(L − L(0)) on log10 V over V in
    // [0.1, 1]) within 4 of the standard errors the reported uncertainties give that
    // slope: weighted least squares, σ of log10(L − L(0)) = u / (ln 10 (L − L(0))).
    double sw = 0, swx = 0, swxx = 0;
    for (const GreyReading& g : grey) {
        if (g.drive < 0.1) continue;
        const double sigma = g.u_cd_m2 / (std::log(10.0) * (g.cd_m2 - black_cd_m2));
        const double w = 1.0 / (sigma * sigma), x = std::log10(g.drive);
        sw += w, swx += w * x, swxx += w * x * x;
    }
    const double se_gamma = std::sqrt(sw / (sw * swxx - swx * swx));
    const Store s = Store::open_read_only(db());
    const nlohmann::json j = store::parse_json(s.latest_calibration("virtual-lcd").value().fit_json);
    for (int i = 0; i < 4; ++i)
        if (store::string_at(j, fmt::format("/ramps/{}/channel", i)) == std::optional<std::string>("grey")) {
            const double gamma = store::number_at(j, fmt::format("/ramps/{}/effective_gamma", i)).value();
            EXPECT_LE(std::abs(gamma - kDisplay.gamma), 4.0 * se_gamma) << gamma << " ± " << se_gamma;
            EXPECT_LT(se_gamma, 0.01);  // 1 % noise leaves γ known to better than 0.01
        }
}

TEST_F(CalibrateVirtual, DisagreeingRepeatsAreMeasuredAgainAtMostThreeTimes) {
    // 1 % noise against a 3 % tolerance: two readings disagree now and then (|difference|
    // > 3 % has probability 3.4 %; with seed 3, three patches), and the patch is measured
    // again; its transcript keeps every attempt.
    Result r = measure(kDisplay, {"--virtual-noise", "0.01", "--virtual-seed", "3", "--repeat-tolerance-percent", "3"});
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    const auto again = r.out.find("; measuring it again (attempt 2 of 3)");
    ASSERT_NE(again, std::string::npos) << r.out;
    const std::string patch = r.out.substr(r.out.rfind('\n', again) + 3,
                                           r.out.find(':', r.out.rfind('\n', again)) - r.out.rfind('\n', again) - 3);
    {
        Store s = Store::open_read_only(db());
        bool found = false;
        for (const auto& reading : s.calibration_readings(s.latest_calibration("virtual-lcd").value().id))
            if (reading.patch == patch) {
                found = true;
                EXPECT_TRUE(contains(reading.transcript.value_or(""), "--- attempt 2, reading 1 of 2"))
                    << reading.transcript.value_or("");
            }
        EXPECT_TRUE(found) << patch;
    }
    // 20 % noise against 0.1 %: they never agree, and the run ends at the first patch.
    const std::string before = file_bytes(db());
    r = measure(kDisplay, {"--virtual-noise", "0.2", "--repeat-tolerance-percent", "0.1"});
    EXPECT_EQ(r.code, 5) << r.out << r.err;
    EXPECT_TRUE(contains(r.err, "patch \"black\" (1 of 41) could not be measured in 3 attempts")) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(file_bytes(db()), before);
}

TEST_F(CalibrateVirtual, ALutDisplayLawIsReadBackThroughItsGreyReadings) {
    // tests/data/calibration/grey_ramp.csv's grey readings, joined by straight lines.
    const std::vector<std::pair<double, double>> lut = {
        {0, 0.2},        {0.0627, 0.7176}, {0.1255, 1.643}, {0.2510, 5.322}, {0.3765, 11.89},
        {0.5020, 21.76}, {0.6275, 35.32},  {0.7529, 52.86}, {0.8784, 74.67}, {1, 100.1}};
    auto law = [&](double v) {
        for (std::size_t i = 1; i < lut.size(); ++i)
            if (v <= lut[i].first)
                return lut[i - 1].second +
                       (v - lut[i - 1].first) / (lut[i].first - lut[i - 1].first) * (lut[i].second - lut[i - 1].second);
        return lut.back().second;
    };
    const Result r = measure(kDisplay, {"--virtual-lut", (kData / "calibration/grey_ramp.csv").string(), "--quiet"});
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    ASSERT_EQ(r.code, 0) << r.err;
    Store s = Store::open_read_only(db());
    const auto readings = s.calibration_readings(s.latest_calibration("virtual-lcd").value().id);
    ASSERT_EQ(readings.size(), patches_.size());
    int greys = 0;
    for (std::size_t i = 0; i < readings.size(); ++i) {
        const PatchCodes& p = patches_[i];
        if (p.r != p.g || p.g != p.b) continue;
        ++greys;
        const double want = law(p.r / 255.0);
        EXPECT_NEAR(readings[i].luminance_cd_m2, want, 1e-9 * want) << p.name;
    }
    EXPECT_EQ(greys, 17);
}

TEST_F(CalibrateVirtual, CheckPassesOnTheSameDisplayAndFailsWhenThePeakDrops) {
    ASSERT_EQ(measure(kDisplay, {"--quiet"}).code, 0);
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    Result r = check(kDisplay);
    EXPECT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(contains(r.out, "PASSED")) << r.out;
    Law dimmer = kDisplay;
    dimmer.peak *= 0.9;
    r = check(dimmer);
    EXPECT_EQ(r.code, 1) << r.out << r.err;
    EXPECT_TRUE(contains(r.out, "FAILED")) << r.out;
    EXPECT_TRUE(contains(r.err, "peak_percent")) << r.err;
    Store s = Store::open_read_only(db());
    const auto cal = s.latest_calibration("virtual-lcd").value();
    const auto checks = s.calibration_checks(cal.id);
    ASSERT_EQ(checks.size(), 2u);
    // Each checked patch keeps the instrument's transcript.
    const nlohmann::json j = store::parse_json(checks[0].results_json);
    EXPECT_TRUE(contains(store::string_at(j, "/patches/4/transcript").value_or(""), "Result is XYZ"))
        << checks[0].results_json;
}

fs::path protocol_for(const fs::path& dir, const std::string& display) {
    std::string text = file_bytes(kData / "run/small_2afc.toml");
    const std::string scene_line = "scene = \"small.scene.toml\"";
    text.replace(text.find(scene_line), scene_line.size(),
                 "scene = \"" + (kData / "run/small.scene.toml").string() + "\"");
    const std::string section = "[display]\n";
    text.insert(text.find(section) + section.size(), "name = \"" + display + "\"\n");
    const fs::path p = dir / "protocol.toml";
    std::ofstream(p) << text;
    return p;
}

TEST_F(CalibrateVirtual, RunUsesTheMeasuredAndCheckedCalibration) {
    ASSERT_EQ(measure(kDisplay, {"--quiet"}).code, 0);
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    ASSERT_EQ(check(kDisplay).code, 0);
    const fs::path protocol = protocol_for(dir_.path(), "virtual-lcd");
    const Result r = atonlab(
        {"run", protocol.string(), "--db", db().string(), "--model-observer", "--headless", "--quiet", "--no-true-pse"},
        dir_.path());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(contains(r.err, "has no calibration")) << r.err;
    EXPECT_FALSE(contains(r.err, "check")) << r.err;
    Store s = Store::open_read_only(db());
    const auto cal = s.latest_calibration("virtual-lcd").value();
    const auto session = s.session(store::SessionId{1});
    ASSERT_TRUE(session.calibration.has_value());
    EXPECT_EQ(*session.calibration, cal.id);
    EXPECT_TRUE(contains(cal.fit_json, "\"gog\"")) << cal.fit_json;
}

// --- The spotread code path against a fake spotread --------------------------------

/// Y (and X, Z) of each " Result is XYZ: X Y Z, ..." line of a transcript, in order.
std::vector<std::array<double, 3>> transcript_results(const fs::path& path) {
    std::vector<std::array<double, 3>> out;
    std::istringstream in(file_bytes(path));
    std::string line;
    while (std::getline(in, line)) {
        std::array<double, 3> v{};
        if (std::sscanf(line.c_str(), " Result is XYZ: %lf %lf %lf,", &v[0], &v[1], &v[2]) == 3) out.push_back(v);
    }
    return out;
}

class CalibrateSpotread : public ::testing::Test {
protected:
    void SetUp() override {
        const char* path = std::getenv("PATH");
        saved_path_ = path ? path : "";
        setenv("PATH", ((kData / "spotread").string() + ":" + saved_path_).c_str(), 1);
        setenv("ATONLAB_FAKE_SPOTREAD_ARGS", (dir_ / "args.txt").c_str(), 1);
    }
    void TearDown() override {
        setenv("PATH", saved_path_.c_str(), 1);
        unsetenv("ATONLAB_FAKE_SPOTREAD");
        unsetenv("ATONLAB_FAKE_SPOTREAD_ARGS");
    }
    /// timeout_s: --instrument-timeout-s. The fake answers at once; 30 s is a
    /// hang's bound on a machine ten times slower or loaded, not a speed test
    /// (the hang test's fake never answers: its 3 s is the time it waits).
    Result measure(const std::string& transcript, const std::string& timeout_s = "30") {
        setenv("ATONLAB_FAKE_SPOTREAD", (kData / "spotread" / transcript).c_str(), 1);
        Result r = atonlab(with({"calibrate", "measure", "--display", "booth", "--db", db().string(), "--headless",
                                 "--instrument", "spotread", "--instrument-args", "-c 1", "--settle-s", "0",
                                 "--instrument-timeout-s", timeout_s, "--grey-levels", "9", "--colour-levels", "4"},
                                kGeometry),
                           dir_.path());
        if (r.code == 3) skip_ = "no GL 4.5 context: " + r.err;
        return r;
    }
    /// One sentence on stderr, saying `what`; exit 5; the study file as it was.
    void expect_refused(const std::string& transcript, const std::string& what,
                        const std::string& timeout_s = "30") {
        const std::string before = fs::exists(db()) ? file_bytes(db()) : std::string();
        const Result r = measure(transcript, timeout_s);
        if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
        EXPECT_EQ(r.code, 5) << r.out << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_TRUE(contains(r.err, what)) << r.err;
        EXPECT_TRUE(contains(r.err, "nothing was stored.")) << r.err;
        EXPECT_EQ(fs::exists(db()) ? file_bytes(db()) : std::string(), before) << "the study file changed";
    }
    fs::path db() const { return dir_.path() / "study.db"; }

    TempDir dir_;
    std::string saved_path_;
    std::string skip_;
};

TEST_F(CalibrateSpotread, ReadingsAreParsedExactlyAndStoredWithTheirTranscripts) {
    const Result r = measure("normal.txt");
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_EQ(file_bytes(dir_ / "args.txt"), "-e -x -c 1\n");
    const auto results = transcript_results(kData / "spotread/normal.txt");
    ASSERT_EQ(results.size(), 36u);
    Store s = Store::open_read_only(db());
    const auto cal = s.latest_calibration("booth").value();
    EXPECT_TRUE(contains(cal.source, "spotread -e -x -c 1")) << cal.source;
    const auto readings = s.calibration_readings(cal.id);
    ASSERT_EQ(readings.size(), 18u);
    for (std::size_t i = 0; i < readings.size(); ++i) {
        // Two readings a patch, averaged: the transcript's numbers exactly.
        const auto& a = results[2 * i];
        const auto& b = results[2 * i + 1];
        EXPECT_DOUBLE_EQ(readings[i].luminance_cd_m2, (a[1] + b[1]) / 2) << readings[i].patch;
        EXPECT_DOUBLE_EQ(readings[i].xyz_x_cd_m2.value(), (a[0] + b[0]) / 2) << readings[i].patch;
        EXPECT_DOUBLE_EQ(readings[i].xyz_z_cd_m2.value(), (a[2] + b[2]) / 2) << readings[i].patch;
        ASSERT_TRUE(readings[i].transcript.has_value());
        EXPECT_TRUE(
            contains(*readings[i].transcript, fmt::format("Result is XYZ: {:.6f} {:.6f} {:.6f}", a[0], a[1], a[2])))
            << *readings[i].transcript;
        EXPECT_TRUE(contains(*readings[i].transcript, "any other key to take a reading")) << *readings[i].transcript;
    }
}

TEST_F(CalibrateSpotread, ANegativeReadingIsRefusedAndThePatchMeasuredAgain) {
    const Result r = measure("negative.txt");
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    ASSERT_EQ(r.code, 0) << r.out << r.err;
    EXPECT_TRUE(contains(r.out,
                         "black: X = -0.21 cd/m² is not a reading (finite, >= -0.01 cd/m²); measuring it "
                         "again (attempt 2 of 3)"))
        << r.out;
    const auto results = transcript_results(kData / "spotread/normal.txt");
    Store s = Store::open_read_only(db());
    const auto readings = s.calibration_readings(s.latest_calibration("booth").value().id);
    ASSERT_EQ(readings.size(), 18u);
    EXPECT_DOUBLE_EQ(readings[0].luminance_cd_m2, (results[0][1] + results[1][1]) / 2);
    EXPECT_TRUE(contains(readings[0].transcript.value_or(""), "Result is XYZ: -0.210000")) << *readings[0].transcript;
    EXPECT_TRUE(contains(readings[0].transcript.value_or(""), "--- attempt 2, reading 2 of 2"))
        << *readings[0].transcript;
}

TEST_F(CalibrateSpotread, ACalibrationRequestIsRelayedToTheOperatorOnATerminal) {
    // atonlab on a terminal (util-linux `script` gives it a pseudo-terminal), Enter typed:
    // the instruction is shown once, spotread is let go on, and the 18 patches are measured.
    if (access("/usr/bin/script", X_OK) != 0)
        ATONLAB_SKIP_MISSING_TOOL() << "no /usr/bin/script (util-linux) to give atonlab a terminal";
    setenv("ATONLAB_FAKE_SPOTREAD", (kData / "spotread/calibrate_then_read.txt").c_str(), 1);
    std::ofstream(dir_ / "enter.txt") << "\n";
    std::string command = std::string(ATONLAB_BINARY) + " calibrate measure --display booth --db " + db().string() +
                          " --headless --instrument spotread --settle-s 0 --instrument-timeout-s 30 --grey-levels 9 "
                          "--colour-levels 4 --quiet";
    for (const std::string& g : kGeometry) command += " " + g;
    const int code = test::run_to_files(
        {"/bin/bash", "-c", "script -qec '" + command + "' /dev/null < " + (dir_ / "enter.txt").string()},
        dir_ / "out.txt", dir_ / "err.txt");
    std::string out = file_bytes(dir_ / "out.txt");
    std::erase(out, '\r');  // the terminal's line ends
    if (contains(out, "OpenGL")) ATONLAB_SKIP_NO_GPU() << out;
    ASSERT_EQ(code, 0) << out << file_bytes(dir_ / "err.txt");
    EXPECT_TRUE(contains(out,
                         "the instrument needs calibrating: Place cap on the instrument, or place on a dark "
                         "surface, or place on the calibration reference.\n  Do it, then press Enter"))
        << out;
    Store s = Store::open_read_only(db());
    EXPECT_EQ(s.calibration_readings(s.latest_calibration("booth").value().id).size(), 18u);
}

TEST_F(CalibrateSpotread, ACalibrationRequestWithNoTerminalEndsInOneSentence) {
    expect_refused("calibrate.txt",
                   "the instrument needs calibrating before it can measure (spotread: \"Place cap on "
                   "the instrument, or place on a dark surface, or place on the calibration reference");
}

TEST_F(CalibrateSpotread, AnErrorLineEndsInOneSentence) {
    expect_refused("error.txt", "\"Spot read failed due to communication problem.\" at patch \"white\" (2 of 18)");
}

TEST_F(CalibrateSpotread, AHangEndsInOneSentence) {
    expect_refused("hang.txt",
                   "spotread did not answer within 3 s (--instrument-timeout-s; is the instrument connected and lying "
                   "on the screen?) when asked to give a reading at patch \"black\" (1 of 18)",
                   "3");
}

TEST_F(CalibrateSpotread, NoInstrumentEndsInOneSentence) {
    expect_refused("no_instrument.txt",
                   "no instrument was found (spotread: \"spotread: Error - No instrument at port 1\")");
}

TEST_F(CalibrateSpotread, ErrorsAfterAGoodMeasurementLeaveTheStudyFileAsItWas) {
    ASSERT_EQ(measure("normal.txt").code, 0);
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    expect_refused("error.txt", "communication problem");
    expect_refused("hang.txt", "did not answer");
}

}  // namespace
}  // namespace atonlab
