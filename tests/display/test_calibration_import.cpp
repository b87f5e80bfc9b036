// Calibration CSV files as labs write them (docs/calibration.md, "Importing"):
// drive levels as fractions, 8-bit or 10-bit codes (named by the column or by
// CalibrationFileOptions, i.e. `--drive-scale`), readings in cd/m², fL or
// CIE XYZ. The readings come from a known law, L = 0.2 + 119.8 V^2.2 cd/m².
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "atonlab/display/calibration.h"
#include "input_error.h"
#include "text_contains.h"

namespace atonlab::display {
namespace {

using test::input_error_of;

using ::atonlab::test::contains;

double law_cd_m2(double v) {
    return 0.2 + 119.8 * std::pow(v, 2.2);
}

/// A grey ramp of 9 codes (0, 32, ..., 255 at 8 bits; the same steps at 10
/// bits), one line per code: `level_text(code, max), reading_text(L)`.
template <class Level, class Reading>
std::string ramp_csv(const std::string& header, int max_code, Level level_text, Reading reading_text) {
    std::string out = header + "\n";
    for (int i = 0; i <= 8; ++i) {
        const int code = i == 8 ? max_code : i * (max_code + 1) / 8;
        out += fmt::format("{},grey,{}\n", level_text(code, max_code),
                           reading_text(law_cd_m2(static_cast<double>(code) / max_code)));
    }
    return out;
}

std::string fraction(int code, int max) {
    return fmt::format("{:.17g}", static_cast<double>(code) / max);  // round-trips the double code / max exactly
}
std::string integer(int code, int) {
    return std::to_string(code);
}
std::string cd(double l) {
    return fmt::format("{:.17g}", l);
}

void expect_same_fit(const CalibrationReport& a, const CalibrationReport& b) {
    ASSERT_EQ(a.ramps.size(), 1u);
    ASSERT_EQ(b.ramps.size(), 1u);
    EXPECT_EQ(a.ramps[0].fit.a, b.ramps[0].fit.a);
    EXPECT_EQ(a.ramps[0].fit.b, b.ramps[0].fit.b);
    EXPECT_EQ(a.ramps[0].fit.k, b.ramps[0].fit.k);
    EXPECT_EQ(a.ramps[0].fit.gamma, b.ramps[0].fit.gamma);
    EXPECT_EQ(a.black_cd_m2, b.black_cd_m2);
    EXPECT_EQ(a.white_cd_m2, b.white_cd_m2);
}

TEST(CalibrationImport, EightBitCodesFitExactlyAsTheSameReadingsAsFractions) {
    const auto fractions = parse_calibration_csv(ramp_csv("level,channel,cd_m2", 255, fraction, cd), "f.csv");
    // The scale named by the column, and given as an option to a plain `level` column.
    const auto named = parse_calibration_csv(ramp_csv("level_8bit,channel,cd_m2", 255, integer, cd), "n.csv");
    CalibrationFileOptions eight;
    eight.drive_scale = DriveScale::bits8;
    const auto option = parse_calibration_csv(ramp_csv("level,channel,cd_m2", 255, integer, cd), "o.csv", eight);
    ASSERT_EQ(named.size(), 9u);
    for (std::size_t i = 0; i < named.size(); ++i) {
        EXPECT_EQ(named[i].level, fractions[i].level);
        EXPECT_EQ(option[i].level, fractions[i].level);
    }
    EXPECT_EQ(named[4].level, 128.0 / 255.0);
    const CalibrationReport f = fit_calibration(fractions);
    expect_same_fit(fit_calibration(named), f);
    expect_same_fit(fit_calibration(option), f);
    // The law's gamma is recovered (GOG with b = 0: exactly a power law).
    EXPECT_NEAR(f.ramps[0].fit.gamma, 2.2, 0.01);
}

TEST(CalibrationImport, TenBitCodesAreCodeOver1023) {
    const auto ten = parse_calibration_csv(ramp_csv("level_10bit,channel,cd_m2", 1023, integer, cd), "t.csv");
    const auto fractions = parse_calibration_csv(ramp_csv("level,channel,cd_m2", 1023, fraction, cd), "f.csv");
    EXPECT_EQ(ten[4].level, 512.0 / 1023.0);
    expect_same_fit(fit_calibration(ten), fit_calibration(fractions));
}

TEST(CalibrationImport, FootLambertsAndXyzAreReadInCdM2) {
    // 1 fL = (1/π) cd/ft² = 3.4262591 cd/m² (NIST SP 811, B.9: 1 ft = 0.3048 m).
    const double fl = 1.0 / (std::numbers::pi * 0.3048 * 0.3048);
    const auto in_fl = parse_calibration_csv(
        ramp_csv("level,channel,fL", 255, fraction, [&](double l) { return cd(l / fl); }), "fl.csv");
    const auto in_cd = parse_calibration_csv(ramp_csv("level,channel,cd_m2", 255, fraction, cd), "cd.csv");
    for (std::size_t i = 0; i < in_cd.size(); ++i)
        EXPECT_NEAR(in_fl[i].luminance_cd_m2, in_cd[i].luminance_cd_m2, 1e-12 * in_cd[i].luminance_cd_m2);
    // XYZ: Y is the luminance; X and Z are kept (so are the chromaticities x, y).
    const auto xyz = parse_calibration_csv(
        "X,Y,Z,level,channel\n0.19,0.2,0.22,0,black\n95.1,100,108.9,1,white\n"
        "20.3,21.4,23.3,0.5,grey\n",
        "xyz.csv");
    ASSERT_EQ(xyz.size(), 3u);
    EXPECT_EQ(xyz[1].luminance_cd_m2, 100.0);
    ASSERT_TRUE(xyz[1].xyz_cd_m2.has_value());
    EXPECT_EQ(xyz[1].xyz_cd_m2->x, 95.1);
    EXPECT_EQ(xyz[1].xyz_cd_m2->z, 108.9);
    EXPECT_EQ(xyz[2].level, 0.5);
}

TEST(CalibrationImport, CodesWithoutAScaleNameTheScales) {
    std::string msg = input_error_of([] { parse_calibration_csv("level,channel,cd_m2\n32,grey,3\n", "c.csv"); });
    EXPECT_TRUE(contains(msg, "c.csv:2")) << msg;
    EXPECT_TRUE(contains(msg, "key 'level'")) << msg;
    EXPECT_TRUE(contains(msg, "8-bit codes (0 to 255)")) << msg;
    EXPECT_TRUE(contains(msg, "10-bit codes (0 to 1023)")) << msg;
    EXPECT_TRUE(contains(msg, "--drive-scale")) << msg;
    // A code beyond its scale, a fraction in an 8-bit column, a column and an option that disagree.
    msg = input_error_of([] { parse_calibration_csv("level_8bit,channel,cd_m2\n256,grey,3\n", "b.csv"); });
    EXPECT_TRUE(contains(msg, "whole code from 0 to 255, not 256")) << msg;
    msg = input_error_of([] { parse_calibration_csv("level_8bit,channel,cd_m2\n0.5,grey,3\n", "h.csv"); });
    EXPECT_TRUE(contains(msg, "key 'level_8bit'")) << msg;
    CalibrationFileOptions ten;
    ten.drive_scale = DriveScale::bits10;
    msg = input_error_of([&] { parse_calibration_csv("level_8bit,channel,cd_m2\n5,grey,3\n", "d.csv", ten); });
    EXPECT_TRUE(contains(msg, "the column says the drive levels are 8bit but --drive-scale says 10bit")) << msg;
    // XYZ needs all three; one reading column only.
    msg = input_error_of([] { parse_calibration_csv("level,channel,X,Y\n0,grey,1,2\n", "x.csv"); });
    EXPECT_TRUE(contains(msg, "key 'Z'")) << msg;
    msg = input_error_of([] { parse_calibration_csv("level,channel,cd_m2,fL\n0,grey,1,2\n", "two.csv"); });
    EXPECT_TRUE(contains(msg, "key 'fL'")) << msg;
}

}  // namespace
}  // namespace atonlab::display
