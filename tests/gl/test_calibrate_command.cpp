// `atonlab calibrate` end to end (docs/calibration.md), through the binary
// (ATONLAB_BINARY, set by tests/e2e/CMakeLists.txt), headless:
//
//  - a synthetic display with a known gain-offset-gamma law per channel is
//    "measured" from scripted readings made from that law: without noise the
//    stored model reproduces the law; with 1 % noise each ramp's black, peak
//    and effective gamma lie within 4 standard errors of the fit (delta
//    method, σ²(JᵀJ)⁻¹), and the whole model within 3 % at every patch;
//  - `check` passes on the same display (fresh noise) and fails, naming
//    peak_percent, on the display with its peak down 10 %; both are stored
//    and plotted;
//  - `import` of tests/data/calibration files stores a calibration with its
//    readings; malformed files exit 2 naming the file and line, storing nothing;
//  - `atonlab run` warns (no calibration, failed check, too old), records
//    the calibration it used and encodes for it.
// Skips where the binary finds no GL 4.5 context (exit status 3).
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
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

int lines(const std::string& s) {
    return static_cast<int>(std::count(s.begin(), s.end(), '\n'));
}

// --- The synthetic display ---------------------------------------------------------

/// One channel's law, L(V) = a + (b + k V)^gamma where b + k V > 0, else a (cd/m²).
struct Gog {
    double a, b, k, gamma;
    double at(double v) const {
        const double base = b + k * v;
        return base > 0.0 ? a + std::pow(base, gamma) : a;
    }
};

/// A 120 cd/m² LCD-like display: a different law per channel, one with a cut-off (b < 0).
const std::array<Gog, 3> kTruth = {Gog{0.05, 0.02, 2.9, 2.3}, Gog{0.10, -0.03, 7.5, 2.2}, Gog{0.02, 0.01, 2.45, 2.4}};

double truth_cd_m2(int r, int g, int b, double scale = 1.0) {
    return scale * (kTruth[0].at(r / 255.0) + kTruth[1].at(g / 255.0) + kTruth[2].at(b / 255.0));
}

struct PatchCodes {
    std::string name;
    int r, g, b;
};

/// The patches in the order shown, from `--list-patches` (name, then "# n: R G B = r g b").
std::vector<PatchCodes> list_patches(const std::string& mode, const fs::path& dir) {
    const Result res =
        atonlab({"calibrate", mode, "--display", "x", "--db", (dir / "unused.db").string(), "--list-patches"}, dir);
    EXPECT_EQ(res.code, 0) << res.err;
    std::vector<PatchCodes> out;
    std::istringstream in(res.out);
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        PatchCodes p;
        std::istringstream ls(line);
        ls >> p.name;
        const auto eq = line.find("= ");
        std::istringstream codes(line.substr(eq + 2));
        codes >> p.r >> p.g >> p.b;
        out.push_back(p);
    }
    EXPECT_FALSE(fs::exists(dir / "unused.db")) << "--list-patches touches no study file";
    return out;
}

/// A readings file: each patch's truth × scale, times (1 + noise · N(0, 1)).
fs::path write_readings(const fs::path& path, const std::vector<PatchCodes>& patches, double noise, std::uint64_t seed,
                        double scale = 1.0) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n01;
    std::ofstream f(path);
    f << "# synthetic readings, cd/m2\n";
    for (const PatchCodes& p : patches) {
        const double y = truth_cd_m2(p.r, p.g, p.b, scale) * (1.0 + noise * n01(rng));
        f << p.name << ' ' << fmt::format("{}", y) << '\n';
    }
    return path;
}

std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

const std::vector<std::string> kGeometry = {"--width-px", "1920",  "--height-px",          "1080",
                                            "--width-m",  "0.598", "--viewing-distance-m", "0.9"};

/// The stored model, read from fit_json as docs/calibration.md lays it out
/// (independently of the runner's own reader).
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

/// The effective gamma of a law: least-squares slope of log10(L(V) − L(0)) on
/// log10 V over 46 log-spaced V in [0.1, 1] (docs/display-calibration.md).
double effective_gamma(const Gog& g) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i <= 45; ++i) {
        const double lv = -1.0 + i / 45.0;
        const double y = std::log10(g.at(std::pow(10.0, lv)) - g.at(0.0));
        sx += lv, sy += y, sxx += lv * lv, sxy += lv * y;
    }
    return (46 * sxy - sx * sy) / (46 * sxx - sx * sx);
}

/// One ramp as the photometer sees it: channel c's law with the other two
/// channels' black added, L(V) = A + (b + k V)^gamma, θ = (A, b, k, gamma).
using Theta = std::array<double, 4>;

Theta ramp_truth(int c) {
    double others = 0.0;
    for (int o = 0; o < 3; ++o)
        if (o != c) others += kTruth[static_cast<std::size_t>(o)].at(0.0);
    const Gog& g = kTruth[static_cast<std::size_t>(c)];
    return {g.a + others, g.b, g.k, g.gamma};
}

double ramp_at(const Theta& t, double v) {
    return Gog{t[0], t[1], t[2], t[3]}.at(v);
}

double ramp_effective_gamma(const Theta& t) {
    return effective_gamma(Gog{t[0], t[1], t[2], t[3]});
}

/// The delta-method standard error of f(θ) for a least-squares fit in log10
/// luminance of readings at `levels` with relative noise `noise`:
/// Cov θ = σ² (JᵀJ)⁻¹, σ = noise / ln 10, J = ∂ log10 L(V_i) / ∂θ_j; SE = sqrt(∇fᵀ Cov ∇f).
template <class F>
double standard_error(const Theta& t, const std::vector<double>& levels, double noise, F&& f) {
    auto step = [&](int j) { return 1e-6 * std::max(std::abs(t[static_cast<std::size_t>(j)]), 1e-3); };
    auto nudged = [&](int j, double h) {
        Theta u = t;
        u[static_cast<std::size_t>(j)] += h;
        return u;
    };
    double jtj[4][8] = {};  // [JᵀJ | I], inverted in place by Gauss-Jordan
    std::vector<std::array<double, 4>> J(levels.size());
    for (std::size_t i = 0; i < levels.size(); ++i)
        for (int j = 0; j < 4; ++j)
            J[i][static_cast<std::size_t>(j)] = (std::log10(ramp_at(nudged(j, step(j)), levels[i])) -
                                                 std::log10(ramp_at(nudged(j, -step(j)), levels[i]))) /
                                                (2.0 * step(j));
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c)
            for (const auto& row : J) jtj[r][c] += row[static_cast<std::size_t>(r)] * row[static_cast<std::size_t>(c)];
        jtj[r][4 + r] = 1.0;
    }
    for (int c = 0; c < 4; ++c) {
        int pivot = c;
        for (int r = c + 1; r < 4; ++r)
            if (std::abs(jtj[r][c]) > std::abs(jtj[pivot][c])) pivot = r;
        std::swap(jtj[c], jtj[pivot]);
        const double d = jtj[c][c];
        for (double& x : jtj[c]) x /= d;
        for (int r = 0; r < 4; ++r)
            if (r != c) {
                const double m = jtj[r][c];
                for (int k = 0; k < 8; ++k) jtj[r][k] -= m * jtj[c][k];
            }
    }
    const double sigma = noise / std::log(10.0);
    std::array<double, 4> grad{};
    for (int j = 0; j < 4; ++j)
        grad[static_cast<std::size_t>(j)] = (f(nudged(j, step(j))) - f(nudged(j, -step(j)))) / (2.0 * step(j));
    double var = 0.0;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
            var +=
                grad[static_cast<std::size_t>(r)] * sigma * sigma * jtj[r][4 + c] * grad[static_cast<std::size_t>(c)];
    return std::sqrt(var);
}

class CalibrateCommand : public ::testing::Test {
protected:
    void SetUp() override {
        patches_ = list_patches("measure", dir_.path());
        ASSERT_EQ(patches_.size(), 41u);
    }
    /// measure --headless with the readings; skips on exit status 3.
    Result measure(const fs::path& readings, const std::string& display, std::vector<std::string> extra = {}) {
        Result r = atonlab(with({"calibrate", "measure", "--display", display, "--db", db().string(), "--headless",
                                 "--readings", readings.string(), "--quiet"},
                                with(kGeometry, extra)),
                           dir_.path());
        if (r.code == 3) skip_ = "no GL 4.5 context: " + r.err;
        return r;
    }
    fs::path db() const { return dir_.path() / "study.db"; }

    /// Every patch and 200 random code triples: the stored model against the truth.
    double worst_relative_error(const display::DisplayModel& m) const {
        double worst = 0.0;
        auto at = [&](int r, int g, int b) {
            const double want = truth_cd_m2(r, g, b);
            const double got = display::displayed_luminance_cd_m2(m, {r, g, b}, 8);
            worst = std::max(worst, std::abs(got - want) / want);
        };
        for (const PatchCodes& p : patches_) at(p.r, p.g, p.b);
        std::mt19937 rng(3);
        std::uniform_int_distribution<int> code(0, 255);
        for (int i = 0; i < 200; ++i) at(code(rng), code(rng), code(rng));
        return worst;
    }

    TempDir dir_;
    std::vector<PatchCodes> patches_;
    std::string skip_;
};

TEST_F(CalibrateCommand, ExactReadingsGiveBackTheDisplaysLaw) {
    const Result r = measure(write_readings(dir_ / "exact.txt", patches_, 0.0, 1), "synthetic");
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "calibration 1 stored")) << r.out;
    EXPECT_TRUE(contains(r.out, "contrast")) << r.out;
    Store s = Store::open_read_only(db());
    const auto cal = s.latest_calibration("synthetic");
    ASSERT_TRUE(cal.has_value());
    EXPECT_EQ(cal->width_px, 1920);
    EXPECT_NEAR(cal->height_m, 0.598 * 1080 / 1920, 1e-12);  // square pixels
    const display::DisplayModel m = stored_model(*cal);
    // GOG data fitted with a GOG law: what is left is the optimiser's tolerance.
    EXPECT_LT(worst_relative_error(m), 2e-3);
    EXPECT_NEAR(m.black_cd_m2, kTruth[0].a + kTruth[1].a + kTruth[2].at(0.0), 1e-3 * m.black_cd_m2);
    EXPECT_NEAR(m.peak_cd_m2, truth_cd_m2(255, 255, 255), 1e-3 * m.peak_cd_m2);
    const nlohmann::json j = store::parse_json(cal->fit_json);
    for (int i = 0; i < 3; ++i) {
        const std::string ramp = fmt::format("/ramps/{}", i);
        ASSERT_EQ(store::string_at(j, ramp + "/channel"), (std::array<const char*, 3>{"red", "green", "blue"})[i]);
        EXPECT_NEAR(store::number_at(j, ramp + "/effective_gamma").value(), effective_gamma(kTruth[i]), 2e-3) << ramp;
        EXPECT_LT(store::number_at(j, ramp + "/rmse_log10").value(), 1e-3);
    }
    // The 41 readings are stored with their codes.
    const auto readings = s.calibration_readings(cal->id);
    ASSERT_EQ(readings.size(), 41u);
    EXPECT_EQ(readings[9].patch, "grey-128");
    EXPECT_EQ(readings[9].code, 128);
    EXPECT_EQ(readings[9].bits, 8);
    EXPECT_EQ(readings[9].source_line, 11);
    EXPECT_EQ(readings.back().channel, "blue");
    EXPECT_EQ(readings.back().drive_b, 1.0);
}

TEST_F(CalibrateCommand, NoisyReadingsAreRecoveredAndChecked) {
    // 1 % per reading: the fitted law within three readings' noise everywhere.
    const Result r =
        measure(write_readings(dir_ / "noisy.txt", patches_, 0.01, 42), "lab-lcd", {"--date", "2024-05-01"});
    if (!skip_.empty()) ATONLAB_SKIP_NO_GPU() << skip_;
    ASSERT_EQ(r.code, 0) << r.err;
    store::Calibration cal;
    {
        Store s = Store::open_read_only(db());
        cal = s.latest_calibration("lab-lcd").value();
    }
    EXPECT_EQ(cal.measured_at, "2024-05-01");
    const display::DisplayModel m = stored_model(cal);
    EXPECT_LT(worst_relative_error(m), 0.03);
    EXPECT_NEAR(m.black_cd_m2, truth_cd_m2(0, 0, 0), 0.03 * truth_cd_m2(0, 0, 0));
    EXPECT_NEAR(m.peak_cd_m2, truth_cd_m2(255, 255, 255), 0.03 * truth_cd_m2(255, 255, 255));
    // Each ramp's black, peak and effective gamma within 4 standard errors of the
    // fit, the errors that 1 % noise on these levels (black once, 8 ramp levels) allows.
    const nlohmann::json j = store::parse_json(cal.fit_json);
    std::vector<double> levels = {0.0};
    for (const PatchCodes& p : patches_)
        if (p.g == 0 && p.b == 0 && p.r > 0) levels.push_back(p.r / 255.0);
    ASSERT_EQ(levels.size(), 9u);
    for (int i = 0; i < 3; ++i) {
        SCOPED_TRACE(fmt::format("ramp {}", i));
        const Theta t = ramp_truth(i);
        const std::string ramp = fmt::format("/ramps/{}", i);
        const double se_gamma = standard_error(t, levels, 0.01, ramp_effective_gamma);
        const double se_black = standard_error(t, levels, 0.01, [](const Theta& u) { return ramp_at(u, 0.0); });
        const double se_peak = standard_error(t, levels, 0.01, [](const Theta& u) { return ramp_at(u, 1.0); });
        EXPECT_NEAR(store::number_at(j, ramp + "/effective_gamma").value(), ramp_effective_gamma(t), 4.0 * se_gamma)
            << "SE " << se_gamma;
        EXPECT_NEAR(store::number_at(j, ramp + "/black_cd_m2").value(), ramp_at(t, 0.0), 4.0 * se_black)
            << "SE " << se_black;
        EXPECT_NEAR(store::number_at(j, ramp + "/peak_cd_m2").value(), ramp_at(t, 1.0), 4.0 * se_peak)
            << "SE " << se_peak;
        std::printf(
            "  ramp %d: effective gamma %.4f (true %.4f, SE %.4f), black %.5f (true %.5f, SE %.5f), "
            "peak %.4f (true %.4f, SE %.4f) cd/m²\n",
            i, store::number_at(j, ramp + "/effective_gamma").value(), ramp_effective_gamma(t), se_gamma,
            store::number_at(j, ramp + "/black_cd_m2").value(), ramp_at(t, 0.0), se_black,
            store::number_at(j, ramp + "/peak_cd_m2").value(), ramp_at(t, 1.0), se_peak);
        // The residuals are the noise: 1 % is 0.0043 in log10.
        const double rmse = store::number_at(j, ramp + "/rmse_log10").value();
        EXPECT_GT(rmse, 0.0015);
        EXPECT_LT(rmse, 0.009);
    }

    // The same display re-measured (fresh noise): the check passes and is stored.
    const std::vector<PatchCodes> check = list_patches("check", dir_.path());
    ASSERT_EQ(check.size(), 5u);
    const fs::path plot_ok = dir_ / "ok.svg";
    Result c = atonlab({"calibrate", "check", "--display", "lab-lcd", "--db", db().string(), "--headless", "--readings",
                        write_readings(dir_ / "same.txt", check, 0.01, 7).string(), "--plot", plot_ok.string(),
                        "--date", "2024-06-01"},
                       dir_.path());
    ASSERT_EQ(c.code, 0) << c.out << c.err;
    EXPECT_TRUE(contains(c.out, "PASSED")) << c.out;
    // Plotting needs gnuplot (scripts/setup.sh); without it the check still stands, with a warning.
    if (!contains(c.err, "gnuplot is not installed")) {
        EXPECT_TRUE(contains(file_bytes(plot_ok), "<svg")) << c.err;
    }

    // The backlight lost 10 %: every patch × 0.9. Fails on peak_percent (and luminance_percent).
    c = atonlab({"calibrate", "check", "--display", "lab-lcd", "--db", db().string(), "--headless", "--readings",
                 write_readings(dir_ / "dim.txt", check, 0.01, 8, 0.9).string(), "--date", "2024-06-02"},
                dir_.path());
    ASSERT_EQ(c.code, 1) << c.out << c.err;
    EXPECT_TRUE(contains(c.out, "FAILED")) << c.out;
    EXPECT_TRUE(contains(c.out, "FAIL peak_percent")) << c.out;
    EXPECT_TRUE(contains(c.err, "failed its calibration check (")) << c.err;
    EXPECT_TRUE(contains(c.err, "peak_percent")) << c.err;
    EXPECT_FALSE(contains(c.out, "FAIL black_cd_m2")) << c.out;
    EXPECT_TRUE(fs::exists(dir_ / "study-check-lab-lcd-2.svg") || contains(c.err, "gnuplot")) << c.out;

    Store s = Store::open_read_only(db());
    const auto checks = s.calibration_checks(cal.id);
    ASSERT_EQ(checks.size(), 2u);
    EXPECT_FALSE(checks[0].passed);  // the latest (2024-06-02)
    EXPECT_EQ(checks[0].checked_at, "2024-06-02");
    EXPECT_TRUE(checks[1].passed);
    const nlohmann::json failed = store::parse_json(checks[0].results_json);
    bool names_peak = false;
    for (std::size_t i = 0; i < store::array_at(failed, "/failed").size(); ++i)
        names_peak = names_peak || store::string_at(failed, fmt::format("/failed/{}", i)) == "peak_percent";
    EXPECT_TRUE(names_peak) << checks[0].results_json;
    EXPECT_NEAR(store::number_at(failed, "/values/peak_percent").value(), 10.0, 3.0);
    EXPECT_EQ(store::number_at(failed, "/tolerances/peak_percent"), 5.0);
}

TEST_F(CalibrateCommand, BadReadingsAndOptionsExitTwoStoringNothing) {
    // A readings file out of step with the patches: its file, line and the patch expected.
    const fs::path bad = dir_ / "bad.txt";
    std::ofstream(bad) << "black 0.2\ngrey-128 60\n";
    Result r = measure(bad, "x");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "bad.txt:2: key 'patch'")) << r.err;
    EXPECT_TRUE(contains(r.err, "\"white\"")) << r.err;
    EXPECT_EQ(lines(r.err), 1) << r.err;
    // Readings that are not monotonic: the fit refuses them, naming the line.
    const fs::path mixed = write_readings(dir_ / "mixed.txt", patches_, 0.0, 1);
    {
        // Line 6 (patch 5, grey-048) gets line 4's reading (grey-016's): far below grey-032's.
        std::vector<std::string> text;
        std::ifstream in(mixed);
        for (std::string l; std::getline(in, l);) text.push_back(l);
        text[5] = "grey-048 " + text[3].substr(text[3].find(' ') + 1);
        std::ofstream out(mixed);
        for (const auto& l : text) out << l << '\n';
    }
    r = measure(mixed, "x");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(contains(r.err, "mixed.txt:6")) << r.err;
    EXPECT_TRUE(contains(r.err, "not monotonic")) << r.err;
    // --headless needs --readings; geometry must be known.
    r = atonlab({"calibrate", "measure", "--display", "x", "--db", db().string(), "--headless"}, dir_.path());
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--headless")) << r.err;
    r = atonlab({"calibrate", "measure", "--display", "x", "--db", db().string(), "--headless", "--readings",
                 write_readings(dir_ / "ok.txt", patches_, 0.0, 1).string(), "--width-px", "1920", "--height-px",
                 "1080", "--viewing-distance-m", "0.9"},
                dir_.path());
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "--width-m")) << r.err;
    // check: no measured calibration to check against.
    r = atonlab(
        {"calibrate", "import", (kData / "calibration/grey_ramp.csv").string(), "--display", "other", "--db",
         db().string(), "--width-px", "800", "--height-px", "600", "--width-m", "0.3", "--viewing-distance-m", "0.6"},
        dir_.path());
    ASSERT_EQ(r.code, 0) << r.err;
    r = atonlab({"calibrate", "check", "--display", "x", "--db", db().string(), "--headless", "--readings",
                 (dir_ / "ok.txt").string()},
                dir_.path());
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(contains(r.err, "display \"x\" has no measured calibration")) << r.err;
    Store s = Store::open_read_only(db());
    EXPECT_FALSE(s.latest_calibration("x").has_value());
    EXPECT_TRUE(s.latest_calibration("other").has_value());
}

// --- import -----------------------------------------------------------------------

TEST(CalibrateImport, ArgyllAndCsvFilesAreStoredWithTheirReadings) {
    TempDir dir;
    const fs::path db = dir / "study.db";
    Result r = atonlab({"calibrate", "import", (kData / "calibration/display.ti3").string(), "--display", "lcd", "--db",
                        db.string(), "--width-px", "1920", "--height-px", "1080", "--width-m", "0.598",
                        "--viewing-distance-m", "0.9", "--date", "2024-03-12"},
                       dir.path());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.out, "calibration 1 stored")) << r.out;
    // The same display again, geometry from its latest calibration.
    r = atonlab({"calibrate", "import", (kData / "calibration/grey_ramp.csv").string(), "--display", "lcd", "--db",
                 db.string(), "--date", "2024-04-01"},
                dir.path());
    ASSERT_EQ(r.code, 0) << r.err;
    Store s = Store::open_read_only(db);
    const auto all = s.calibrations("lcd");
    ASSERT_EQ(all.size(), 2u);
    EXPECT_EQ(all[1].source, "imported " + (kData / "calibration/display.ti3").string());
    EXPECT_EQ(all[0].width_m, 0.598);
    const auto ti3 = s.calibration_readings(all[1].id);
    ASSERT_EQ(ti3.size(), 25u);  // the .ti3's 25 sets
    EXPECT_EQ(ti3[0].patch, "black");
    EXPECT_TRUE(ti3[0].xyz_x_cd_m2.has_value());  // X and Z kept from the .ti3
    EXPECT_FALSE(ti3[0].code.has_value());        // imports carry fractions, not codes
    const auto csv = s.calibration_readings(all[0].id);
    ASSERT_EQ(csv.size(), 10u);
    EXPECT_EQ(csv[1].luminance_cd_m2, 0.7176);  // grey_ramp.csv line 6
    EXPECT_EQ(csv[1].source_line, 6);
    EXPECT_FALSE(csv[1].xyz_x_cd_m2.has_value());
    // The .ti3's white: LUMINANCE_XYZ_CDM2 says Y = 120 cd/m²; the fit's white is near it.
    const nlohmann::json j = store::parse_json(all[1].fit_json);
    EXPECT_NEAR(store::number_at(j, "/white_cd_m2").value(), 120.0, 1.2);
}

TEST(CalibrateImport, MalformedFilesExitTwoNamingFileAndLine) {
    const std::pair<const char*, const char*> cases[] = {
        {"non_monotonic.csv", "non_monotonic.csv:7"}, {"bad_channel.csv", "bad_channel.csv:5"},
        {"not_a_number.csv", "not_a_number.csv:5"},   {"wrong_field_count.ti3", "wrong_field_count.ti3:40"},
        {"not_a_number.ti3", "not_a_number.ti3:45"},  {"missing_end_data.ti3", "missing_end_data.ti3:"},
    };
    for (const auto& [file, where] : cases) {
        SCOPED_TRACE(file);
        TempDir dir;
        const fs::path db = dir / "study.db";
        const Result r = atonlab(
            {"calibrate", "import", (kData / "calibration" / file).string(), "--display", "lcd", "--db", db.string(),
             "--width-px", "1920", "--height-px", "1080", "--width-m", "0.598", "--viewing-distance-m", "0.9"},
            dir.path());
        EXPECT_EQ(r.code, 2) << r.err;
        EXPECT_TRUE(contains(r.err, where)) << r.err;
        EXPECT_EQ(lines(r.err), 1) << r.err;
        EXPECT_FALSE(fs::exists(db)) << "bad input created the study file";
    }
}

// --- atonlab run ---------------------------------------------------------------------

/// tests/data/run/small_2afc.toml with `keys` added to its [display] table and
/// its scene given by absolute path, written to dir.
fs::path protocol_with(const fs::path& dir, const std::string& keys) {
    std::string text = file_bytes(kData / "run/small_2afc.toml");
    const std::string scene_line = "scene = \"small.scene.toml\"";
    text.replace(text.find(scene_line), scene_line.size(),
                 "scene = \"" + (kData / "run/small.scene.toml").string() + "\"");
    const std::string display = "[display]\n";
    text.insert(text.find(display) + display.size(), keys);
    const fs::path p = dir / "protocol.toml";
    std::ofstream(p) << text;
    return p;
}

TEST(CalibrateRun, SessionsWarnAndRecordTheCalibrationTheyUsed) {
    TempDir dir;
    const fs::path db = dir / "study.db";
    // 1. The display has no calibration yet: a warning, and the nominal row as before.
    const fs::path protocol = protocol_with(dir.path(), "name = \"booth-2\"\nmax_calibration_age_days = 30\n");
    const std::vector<std::string> run = {
        "run", protocol.string(), "--db", db.string(), "--model-observer", "--headless", "--quiet", "--no-true-pse"};
    Result r = atonlab(run, dir.path());
    if (r.code == 3) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << r.err;
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "warning: display \"booth-2\" has no calibration in")) << r.err;
    {
        Store s = Store::open_read_only(db);
        const auto session = s.session(store::SessionId{1});
        ASSERT_TRUE(session.calibration.has_value());
        EXPECT_TRUE(contains(s.calibration(*session.calibration).fit_json, "\"nominal\""));
    }

    // 2. An old calibration (2020) of a dim display (12 cd/m² white, where the
    //    scene's nominal display has 100) whose latest check failed: both
    //    warnings, the session records that calibration, and the frames are
    //    encoded for it: the model observer, seeing other luminances, answers
    //    differently from session 1 (same protocol, same seed).
    const fs::path dim = dir / "dim.csv";
    std::ofstream(dim) << "level,channel,cd_m2\n0,black,0.05\n0.25,grey,0.6\n0.5,grey,2.6\n0.75,grey,6.4\n1,white,12\n";
    r = atonlab({"calibrate", "import", dim.string(), "--display", "booth-2", "--db", db.string(), "--width-px", "320",
                 "--height-px", "180", "--width-m", "0.1", "--viewing-distance-m", "0.9", "--date", "2020-01-02"},
                dir.path());
    ASSERT_EQ(r.code, 0) << r.err;
    const fs::path low = dir / "low.txt";
    std::ofstream(low) << "0.1\n1\n2\n3\n4\n";  // white 4 against 12 cd/m²
    r = atonlab({"calibrate", "check", "--display", "booth-2", "--db", db.string(), "--headless", "--readings",
                 low.string(), "--no-plot", "--date", "2020-02-01"},
                dir.path());
    ASSERT_EQ(r.code, 1) << r.out << r.err;
    r = atonlab(run, dir.path());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(contains(r.err, "warning: the latest check of calibration 2 of display \"booth-2\"")) << r.err;
    EXPECT_TRUE(contains(r.err, "peak_percent")) << r.err;
    EXPECT_TRUE(contains(r.err, "days old, older than max_calibration_age_days = 30")) << r.err;
    EXPECT_FALSE(contains(r.err, "has no calibration")) << r.err;
    Store s = Store::open_read_only(db);
    const auto session = s.session(store::SessionId{2});
    ASSERT_TRUE(session.calibration.has_value());
    EXPECT_EQ(session.calibration->value, 2);
    EXPECT_TRUE(contains(s.calibration(*session.calibration).source, "dim.csv"));
    std::string first, second;
    for (const auto& t : s.trials(store::SessionId{1})) first += t.response + " ";
    for (const auto& t : s.trials(store::SessionId{2})) second += t.response + " ";
    EXPECT_NE(first, second) << "the measured display model did not change what the observer saw";
}

}  // namespace
}  // namespace atonlab
