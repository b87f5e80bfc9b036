// The condition snapshot keeps the frame's scotopic channel, and the report's
// stimulus picture uses it (docs/analysis.md, "Stimulus pictures"): the binary
// (ATONLAB_BINARY) runs tests/data/run/green-scotopic.toml (IALA green lights
// with wave-optics glare under the perceptual operator at 0.05 cd/m²) with the
// model observer, headless, and analyses the study. The stored EXR must carry
// A, each pixel's scotopic luminance: at the test light's core A / Y is the
// 505 nm die's S/P, 5.38 (docs/tone-mapping.md "The scotopic channel", from
// the CIE tables), not the RGB weights'. The picture's top row must be the
// CPU reference display::tonemap_pixel(rgb, scotopic, L_wa, settings) of the
// stored pixels with the settings the protocol gives (perceptual, 0.05 cd/m²,
// the rest the scene's defaults), sRGB-encoded to 8 bits; the RGB weights'
// rod signal would give other codes (the difference is printed). Skips where
// the binary finds no GL 4.5 context (exit status 3).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "../store/store_test_support.h"
#include "../support/child_process.h"
#include "../support/skip.h"
#include "atonlab/display/colour.h"
#include "atonlab/display/tonemap.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/store/store.h"
#include "session/snapshot.h"

#ifndef ATONLAB_BINARY
#error "ATONLAB_BINARY (the atonlab executable) must be defined by the build"
#endif

namespace atonlab {
namespace {

namespace fs = std::filesystem;
using store::test_support::file_bytes;
using store::test_support::TempDir;

const fs::path kProtocol = fs::path(ATONLAB_SOURCE_DIR) / "tests/data/run/green-scotopic.toml";
constexpr double kGreenSp =
    5.38;  // IALA green's 505 nm die (unit.ScotopicChannel.EachLightCarriesItsDiesSpFromTheCieTables)

/// 8-bit codes of a w × h window of `rgb` (width `stride` px, values 0-1) at column x0.
std::vector<int> window_codes(const std::vector<float>& rgb, int stride, int x0, int w, int h) {
    std::vector<int> out;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int k = 0; k < 3; ++k)
                out.push_back(static_cast<int>(
                    std::lround(rgb[(static_cast<std::size_t>(y) * stride + x0 + x) * 3 + k] * 255.0)));
    return out;
}

/// 8-bit codes of the EXR's w × h window at column x0 (rows 0..h-1) through the CPU reference.
std::vector<int> reference_codes(const stimuli::ImageRGBA32F& hdr, int x0, int w, int h, double adaptation,
                                 const display::ToneMapSettings& tm, bool scotopic) {
    std::vector<int> out;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float* p = hdr.pixel(x0 + x, y);
            const glm::dvec3 rgb(p[0], p[1], p[2]);
            const glm::dvec3 d = scotopic ? display::tonemap_pixel(rgb, p[3], adaptation, tm)
                                          : display::tonemap_pixel(rgb, adaptation, tm);
            for (int k = 0; k < 3; ++k)
                out.push_back(static_cast<int>(std::lround(display::srgb_encode(std::clamp(d[k], 0.0, 1.0)) * 255.0)));
        }
    return out;
}

int max_difference(const std::vector<int>& a, const std::vector<int>& b) {
    int worst = 0;
    for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
    return worst;
}

TEST(SnapshotScotopic, TheReportsPictureOfAGreenLightIsToneMappedWithTheStoredScotopicChannel) {
    TempDir dir;
    const fs::path db = dir / "study.db";
    const int run = test::run_to_files(
        {ATONLAB_BINARY, "run", kProtocol.string(), "--db", db.string(), "--headless", "--model-observer"},
        dir / "run.out", dir / "run.err");
    if (run == 3) ATONLAB_SKIP_NO_GPU() << "no GL 4.5 context: " << file_bytes(dir / "run.err");
    ASSERT_EQ(run, 0) << file_bytes(dir / "run.err");

    // The stored snapshot: RGB and A.
    stimuli::ExrImage exr;
    {
        const store::Store s = store::Store::open_read_only(db);
        const auto sessions = s.sessions();
        ASSERT_EQ(sessions.size(), 1u);
        const auto snap = s.get_snapshot(sessions[0].id, "green");
        ASSERT_TRUE(snap.has_value());
        std::printf("[ snapshot ] %zu bytes\n", snap->data.size());
        const fs::path file = dir / "snapshot.exr";
        {
            std::FILE* f = std::fopen(file.c_str(), "wb");
            ASSERT_NE(f, nullptr);
            ASSERT_EQ(std::fwrite(snap->data.data(), 1, snap->data.size(), f), snap->data.size());
            std::fclose(f);
        }
        exr = stimuli::read_exr(file);
    }
    ASSERT_TRUE(exr.has_alpha) << "the snapshot keeps the scotopic channel";
    const stimuli::ImageRGBA32F& hdr = exr.image;
    ASSERT_EQ(hdr.width, 320);
    ASSERT_EQ(hdr.height, 360);  // two frames of 180 rows: test, reference
    // The test light's core (frame 0's brightest pixel): its A / Y above the sky's is the green die's S/P.
    int bx = 0, by = 0;
    double best = -1.0;
    for (int y = 0; y < 180; ++y)
        for (int x = 0; x < hdr.width; ++x) {
            const float* p = hdr.pixel(x, y);
            const double lum = display::luminance_of_linear_rgb(glm::dvec3(p[0], p[1], p[2]));
            if (lum > best) best = lum, bx = x, by = y;
        }
    // Above the sky (its own S/P, D65's): the frame's corner, far from the light.
    const float* core = hdr.pixel(bx, by);
    const float* sky = hdr.pixel(0, 0);
    const double sky_y = display::luminance_of_linear_rgb(glm::dvec3(sky[0], sky[1], sky[2]));
    const double sp = (core[3] - sky[3]) / (best - sky_y);
    const glm::dvec3 light_rgb = glm::dvec3(core[0], core[1], core[2]) - glm::dvec3(sky[0], sky[1], sky[2]);
    std::printf(
        "[ core ] (%d, %d): Y %.4g cd/m², A %.4g scotopic cd/m² over the sky's %.4g, %.4g: S/P %.4f; the RGB "
        "weights' %.4f\n",
        bx, by, best, core[3], sky_y, sky[3], sp, display::scotopic_luminance_rgb(light_rgb) / (best - sky_y));
    EXPECT_NEAR(sp, kGreenSp, 0.03 * kGreenSp);
    // The settings the frames were shown with, recorded beside the pixels.
    ASSERT_TRUE(exr.meta.strings.count("tonemap"));
    const auto recorded = runner::read_snapshot_tonemap(exr.meta.strings.at("tonemap"));
    ASSERT_TRUE(recorded.has_value()) << exr.meta.strings.at("tonemap");
    ASSERT_EQ(recorded->size(), 2u);
    EXPECT_EQ((*recorded)[0].tonemap.tone_operator, display::ToneOperator::perceptual);
    EXPECT_EQ((*recorded)[0].adaptation_cd_m2, 0.05);

    const fs::path out = dir / "report";
    const int analyze = test::run_to_files(
        {ATONLAB_BINARY, "analyze", db.string(), "--out", out.string(), "--bootstrap", "0", "--quiet"}, dir / "an.out",
        dir / "an.err");
    ASSERT_EQ(analyze, 0) << file_bytes(dir / "an.err");
    int pw = 0, ph = 0;
    const std::vector<float> png = stimuli::read_png_rgb(out / "figures" / "snapshot-green.png", pw, ph);
    // The first tile: frame 0 around the test light, 6° (302 px at 0.0199°/px) wide, all 180 rows.
    const int w = std::min(hdr.width, 2 * static_cast<int>(std::lround(3.0 / exr.meta.degrees_per_pixel))), h = 180;
    ASSERT_GE(pw, w);
    ASSERT_GE(ph, h);
    const std::vector<int> shown = window_codes(png, pw, 0, w, h);
    // The protocol's settings, not read from the file: perceptual at 0.05 cd/m², the scene's defaults otherwise.
    display::ToneMapSettings tm;
    tm.tone_operator = display::ToneOperator::perceptual;
    // Where the tile lies is the report's business: the column offset that matches best.
    int best_x0 = 0, best_error = 256;
    for (int x0 = 0; x0 + w <= hdr.width; ++x0) {
        const int e = max_difference(shown, reference_codes(hdr, x0, w, h, 0.05, tm, true));
        if (e < best_error) best_error = e, best_x0 = x0;
    }
    const int rgb_shift = max_difference(reference_codes(hdr, best_x0, w, h, 0.05, tm, true),
                                         reference_codes(hdr, best_x0, w, h, 0.05, tm, false));
    std::printf(
        "[ picture ] tile at x0 %d: max %d codes from the CPU reference with A; with A vs the RGB weights: "
        "max %d codes\n",
        best_x0, best_error, rgb_shift);
    EXPECT_EQ(best_error, 0) << "the picture is each stored pixel tone-mapped with its scotopic channel";
    EXPECT_GE(rgb_shift, 3) << "the green light's own rod signal should change its displayed codes";
    const std::string html = file_bytes(out / "report.html");
    EXPECT_NE(html.find("own scotopic luminance"), std::string::npos) << "the caption says which rod signal";
}

}  // namespace
}  // namespace atonlab
