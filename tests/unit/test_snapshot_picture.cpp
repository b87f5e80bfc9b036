// The report's stimulus pictures (runner/src/snapshot_picture.cpp; docs/analysis.md,
// "Stimulus pictures") tone-map a stored snapshot as the session's display pass
// did: each pixel's rod signal from the EXR's scotopic channel (A), and the
// frame's recorded tone-mapping settings. The snapshots here are made by hand
// (a green light on a dim D65 background, its A the die's S/P times its
// luminance), so the expected picture is the CPU reference
// display::tonemap_pixel(rgb, scotopic, L_wa, settings) of each pixel,
// sRGB-encoded to 8 bits; a snapshot stored without the channel or the record
// keeps the RGB weights and the defaults.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "atonlab/display/colour.h"
#include "atonlab/display/tonemap.h"
#include "atonlab/stimuli/image_io.h"
#include "session/snapshot.h"
#include "snapshot_picture.h"

namespace atonlab {
namespace {

namespace fs = std::filesystem;
using store::test_support::file_bytes;
using store::test_support::TempDir;

constexpr int kSize = 48;  // px
constexpr double kDegPerPx =
    0.1;  // a 6° tile is 60 px > kSize: the one tile is the whole image, PNG (x, y) = EXR (x, y)
constexpr double kGreenSp = 5.38;  // S/P of IALA green's 505 nm die (docs/tone-mapping.md "The scotopic channel")
constexpr double kD65Sp = 2.4645;  // S/P of D65, the background's
const glm::dvec3 kGreen(0.0, 0.04, 0.012);  // cd/m², a green light's core
constexpr double kBackground = 0.002;       // cd/m² per channel

/// The light's luminance (cd/m²) at (x, y): a disc of radius 4 px at the centre, else 0.
double light_weight(int x, int y) {
    const double dx = x - 24.0, dy = y - 24.0;
    return dx * dx + dy * dy <= 16.0 ? 1.0 : 0.0;
}

stimuli::ImageRGBA32F green_light_image() {
    stimuli::ImageRGBA32F img;
    img.width = img.height = kSize;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const glm::dvec3 rgb = glm::dvec3(kBackground) + light_weight(x, y) * kGreen;
            const double lum_green = display::luminance_of_linear_rgb(kGreen);
            const double scotopic = kD65Sp * kBackground + light_weight(x, y) * kGreenSp * lum_green;
            for (int k = 0; k < 3; ++k) img.rgba.push_back(static_cast<float>(rgb[k]));
            img.rgba.push_back(static_cast<float>(scotopic));
        }
    return img;
}

/// The snapshot as `atonlab run` stores it (with_record: the "tonemap" attribute).
store::Snapshot snapshot_of(const stimuli::ImageRGBA32F& img, bool alpha, const runner::SnapshotToneMap* record,
                            const fs::path& dir) {
    stimuli::ExrMetadata meta;
    meta.degrees_per_pixel = kDegPerPx;
    meta.strings["frames"] = fmt::format("rows 0-{}: frame 0 (both)", kSize - 1);
    meta.strings["lights"] = "frame 0 test at 24.0,24.0 (test)";
    if (record) meta.strings["tonemap"] = runner::snapshot_tonemap_json({*record});
    const fs::path exr = dir / "snapshot.exr";
    stimuli::write_exr(exr, img, meta, stimuli::ExrPixelType::float32, alpha);
    const std::string bytes = file_bytes(exr);
    store::Snapshot s;
    s.format = "exr";
    for (char ch : bytes) s.data.push_back(static_cast<std::byte>(ch));
    return s;
}

/// The picture's top row (as displayed), 8-bit codes 0-255 per channel, row-major.
std::vector<int> top_row_codes(const fs::path& png) {
    int w = 0, h = 0;
    const std::vector<float> rgb = stimuli::read_png_rgb(png, w, h);
    EXPECT_EQ(w, kSize);
    EXPECT_GE(h, kSize);
    std::vector<int> codes;
    for (std::size_t i = 0; i < static_cast<std::size_t>(kSize) * kSize * 3; ++i)
        codes.push_back(static_cast<int>(std::lround(rgb[i] * 255.0)));
    return codes;
}

/// The expected codes: each pixel through the CPU reference (scotopic: with its A), clipped, sRGB, 8 bits.
std::vector<int> expected_codes(const stimuli::ImageRGBA32F& img, double adaptation, const display::ToneMapSettings& tm,
                                bool scotopic) {
    std::vector<int> codes;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const float* p = img.pixel(x, y);
            const glm::dvec3 rgb(p[0], p[1], p[2]);
            const glm::dvec3 d = scotopic ? display::tonemap_pixel(rgb, p[3], adaptation, tm)
                                          : display::tonemap_pixel(rgb, adaptation, tm);
            for (int k = 0; k < 3; ++k)
                codes.push_back(
                    static_cast<int>(std::lround(display::srgb_encode(std::clamp(d[k], 0.0, 1.0)) * 255.0)));
        }
    return codes;
}

int max_difference(const std::vector<int>& a, const std::vector<int>& b) {
    int worst = 0;
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
    return a.size() == b.size() ? worst : 256;
}

/// The green light's centre pixel, G channel.
int centre_green(const std::vector<int>& codes) {
    return codes[(24u * kSize + 24u) * 3 + 1];
}

analysis::ConditionInfo condition(const std::string& op, std::optional<double> adaptation) {
    analysis::ConditionInfo c;
    c.condition = "green";
    c.tone_operator = op;
    c.adaptation_cd_m2 = adaptation;
    return c;
}

TEST(SnapshotPicture, AGreenLightUnderThePerceptualOperatorIsMappedWithItsOwnScotopicChannel) {
    TempDir dir;
    const stimuli::ImageRGBA32F img = green_light_image();
    for (const display::MesopicModel mesopic : {display::MesopicModel::k2012, display::MesopicModel::cie191}) {
        runner::SnapshotToneMap record;
        record.tonemap.tone_operator = display::ToneOperator::perceptual;
        record.tonemap.mesopic = mesopic;
        record.adaptation_cd_m2 = 0.01;  // mesopic: the rods matter
        // The condition says nothing of its adaptation: the record's is used.
        const store::Snapshot snap = snapshot_of(img, true, &record, dir.path());
        std::string caption;
        ASSERT_EQ(runner::snapshot_png(snap, condition("perceptual", std::nullopt), dir / "p.png", caption), "");
        const std::vector<int> got = top_row_codes(dir / "p.png");
        const std::vector<int> with_rods = expected_codes(img, 0.01, record.tonemap, true);
        const std::vector<int> rgb_only = expected_codes(img, 0.01, record.tonemap, false);
        const int error = max_difference(got, with_rods);
        const int shift = max_difference(with_rods, rgb_only);
        std::printf(
            "[ mesopic %s ] picture vs CPU reference with A: max %d codes; with A vs RGB weights: max %d "
            "codes (centre G %d vs %d)\n",
            std::string(display::mesopic_model_name(mesopic)).c_str(), error, shift, centre_green(with_rods),
            centre_green(rgb_only));
        EXPECT_LE(error, 0) << "the picture is the CPU reference with each pixel's scotopic channel";
        // The test can tell the two apart: the light's own S/P (5.38) against the RGB weights' moves it visibly.
        EXPECT_GE(shift, 5) << "the green light's rod signal should change its displayed codes";
        EXPECT_NE(caption.find("each pixel's own scotopic luminance"), std::string::npos) << caption;
        EXPECT_NE(caption.find(std::string("mesopic ") + std::string(display::mesopic_model_name(mesopic))),
                  std::string::npos)
            << caption;
        EXPECT_NE(caption.find("perceptual at 0.01 cd/m²"), std::string::npos) << caption;
    }
}

TEST(SnapshotPicture, TheFramesRecordedSettingsAreAppliedNotTheDefaults) {
    TempDir dir;
    const stimuli::ImageRGBA32F img = green_light_image();
    runner::SnapshotToneMap record;
    record.tonemap.tone_operator = display::ToneOperator::perceptual;
    record.tonemap.blueshift = false;
    record.tonemap.hue_preservation = display::HuePreservation::rgb;
    record.tonemap.out_of_gamut = display::OutOfGamut::keep_chromaticity;
    record.tonemap.display_peak_cd_m2 = 250.0;
    record.adaptation_cd_m2 = 0.03;
    const store::Snapshot snap = snapshot_of(img, true, &record, dir.path());
    std::string caption;
    // The condition's own column (0.5 cd/m²) loses to what the session's frame recorded.
    ASSERT_EQ(runner::snapshot_png(snap, condition("perceptual", 0.5), dir / "p.png", caption), "");
    const std::vector<int> got = top_row_codes(dir / "p.png");
    display::ToneMapSettings defaults;
    defaults.tone_operator = display::ToneOperator::perceptual;
    const int error = max_difference(got, expected_codes(img, 0.03, record.tonemap, true));
    const int from_defaults =
        max_difference(expected_codes(img, 0.03, record.tonemap, true), expected_codes(img, 0.03, defaults, true));
    std::printf("[ settings ] picture vs CPU reference: max %d codes; recorded vs default settings: max %d codes\n",
                error, from_defaults);
    EXPECT_LE(error, 0);
    EXPECT_GE(from_defaults, 5);
    EXPECT_NE(caption.find("blueshift off, hue preservation rgb"), std::string::npos) << caption;
    EXPECT_NE(caption.find("out of gamut keep-chromaticity, display peak 250 cd/m²"), std::string::npos) << caption;
}

TEST(SnapshotPicture, ASnapshotStoredWithoutTheChannelOrTheRecordKeepsTheRgbWeightsAndTheConditionsOperator) {
    TempDir dir;
    const stimuli::ImageRGBA32F img = green_light_image();
    const store::Snapshot snap = snapshot_of(img, false, nullptr, dir.path());
    std::string caption;
    ASSERT_EQ(runner::snapshot_png(snap, condition("perceptual", 0.01), dir / "p.png", caption), "");
    display::ToneMapSettings tm;
    tm.tone_operator = display::ToneOperator::perceptual;
    EXPECT_LE(max_difference(top_row_codes(dir / "p.png"), expected_codes(img, 0.01, tm, false)), 0);
    EXPECT_NE(caption.find("without the scotopic channel"), std::string::npos) << caption;
}

TEST(SnapshotPicture, TheToneMapRecordReadsBackAndRefusesWhatIsNotOne) {
    runner::SnapshotToneMap a;
    a.tonemap.tone_operator = display::ToneOperator::reinhard;
    a.tonemap.reinhard_white_relative = 3.5;
    a.tonemap.white_cd_m2 = 12.0;
    a.tonemap.display_adaptation_cd_m2 = 40.0;
    a.tonemap.blueshift_luminance = display::BlueshiftLuminance::adaptation;
    a.tonemap.blueshift_xy = {0.31, 0.32};
    a.tonemap.mesopic = display::MesopicModel::cie191;
    a.dynamic = true;
    a.epsilon_cd_m2 = 1e-4;
    a.ldr_glare = true;
    runner::SnapshotToneMap b;  // the defaults: Reinhard's white infinite, no white, no display adaptation
    const auto back = runner::read_snapshot_tonemap(runner::snapshot_tonemap_json({a, b}));
    ASSERT_TRUE(back.has_value());
    ASSERT_EQ(back->size(), 2u);
    const runner::SnapshotToneMap& x = (*back)[0];
    EXPECT_EQ(x.tonemap.tone_operator, display::ToneOperator::reinhard);
    EXPECT_EQ(x.tonemap.reinhard_white_relative, 3.5);
    EXPECT_EQ(x.tonemap.white_cd_m2, std::optional<double>(12.0));
    EXPECT_EQ(x.tonemap.display_adaptation_cd_m2, std::optional<double>(40.0));
    EXPECT_EQ(x.tonemap.blueshift_luminance, display::BlueshiftLuminance::adaptation);
    EXPECT_EQ(x.tonemap.blueshift_xy, glm::dvec2(0.31, 0.32));
    EXPECT_EQ(x.tonemap.mesopic, display::MesopicModel::cie191);
    EXPECT_TRUE(x.dynamic);
    EXPECT_EQ(x.epsilon_cd_m2, 1e-4);
    EXPECT_TRUE(x.ldr_glare);
    const runner::SnapshotToneMap& y = (*back)[1];
    EXPECT_TRUE(std::isinf(y.tonemap.reinhard_white_relative));
    EXPECT_FALSE(y.tonemap.white_cd_m2.has_value());
    EXPECT_FALSE(y.tonemap.display_adaptation_cd_m2.has_value());
    EXPECT_FALSE(y.dynamic);
    for (const char* bad : {"", "{}", "[]", "[1]", "[{\"operator\": \"perceptual\"}]", "not json"})
        EXPECT_FALSE(runner::read_snapshot_tonemap(bad).has_value()) << bad;
    // An invalid setting (kakimoto_k must exceed 1) is no record either.
    std::string text = runner::snapshot_tonemap_json({b});
    text.replace(text.find("\"kakimoto_k\":20.0"), 17, "\"kakimoto_k\":0.5");
    EXPECT_FALSE(runner::read_snapshot_tonemap(text).has_value()) << text;
}

}  // namespace
}  // namespace atonlab
