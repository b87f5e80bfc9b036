// The `cie` veil's two convolutions (issue 27 item 3): the direct sum over lit
// pixels and the pruned, parallel FFT are the same linear convolution, so they
// agree to the FFT's rounding; the direct sum gives the CIE equation; the
// automatic choice takes the direct sum for few lit pixels only.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "atonlab/stimuli/cie_glare.h"
#include "atonlab/stimuli/veiling_glare.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;

constexpr double kDeg = std::numbers::pi / 180.0;

struct Frame {
    int w, h;
    double f;
    std::vector<float> rgba;
    float& at(int i, int j, int c) {
        return rgba[(static_cast<std::size_t>(j) * w + i) * 4 + static_cast<std::size_t>(c)];
    }
};

// A w×h frame (301×201 unless said) at 12 px per degree with `count` lights of
// different colours and illuminances spread over it (one in the centre pixel).
Frame lights_frame(int count, int w = 301, int h = 201) {
    Frame fr{w, h, 12.0 / kDeg, {}};
    fr.rgba.assign(static_cast<std::size_t>(fr.w) * fr.h * 4, 0.0f);
    for (int k = 0; k < count; ++k) {
        const int i = k == 0 ? fr.w / 2 : (37 * k + 11) % fr.w, j = k == 0 ? fr.h / 2 : (53 * k + 7) % fr.h;
        const double e_lux = 0.5 + 0.25 * (k % 7);
        const double omega = frame_pixel_solid_angle_sr(i, j, fr.w, fr.h, fr.f);
        const double colour[3] = {1.0, 0.3 + 0.1 * (k % 5), k % 3 == 0 ? 0.0 : 0.7};  // blue absent in some
        for (int c = 0; c < 3; ++c) fr.at(i, j, c) += static_cast<float>(e_lux * colour[c] / omega);
    }
    return fr;
}

// The worst per-pixel |direct − FFT| / (|direct| + 1e-12 of the peak).
double direct_vs_fft(Frame a, glm::dvec3* out_direct = nullptr, glm::dvec3* out_fft = nullptr) {
    Frame b = a;
    VeilingGlare veil;
    const glm::dvec3 d = veil.apply(a.rgba, a.w, a.h, a.f, {25, 0.5}, VeilMethod::direct);
    EXPECT_EQ(veil.last_method(), VeilMethod::direct);
    const glm::dvec3 f = veil.apply(b.rgba, b.w, b.h, b.f, {25, 0.5}, VeilMethod::fft);
    EXPECT_EQ(veil.last_method(), VeilMethod::fft);
    EXPECT_EQ(veil.kernel_builds(), 1);  // both read the one kernel
    if (out_direct) *out_direct = d;
    if (out_fft) *out_fft = f;
    float peak = 0;
    for (float v : a.rgba) peak = std::max(peak, v);
    double worst = 0;
    for (std::size_t p = 0; p < a.rgba.size(); ++p) {
        if (p % 4 == 3) continue;
        const double diff = std::abs(static_cast<double>(a.rgba[p]) - b.rgba[p]);
        worst = std::max(worst, diff / (std::abs(static_cast<double>(a.rgba[p])) + 1e-12 * peak));
    }
    return worst;
}

TEST(VeilMethods, OddTransformLengthsAndFramesNarrowerThanAColumnBlockAgreeToo) {
    // 4×5 px: transform lengths 7 × 9 (odd: the rows and columns padded to
    // keep every one aligned as the plans'), 4 spectrum columns (one partial
    // block of the FFT's column pass); 13×3 and 1×1 likewise small and odd.
    for (const auto& [w, h] : {std::pair{4, 5}, std::pair{13, 3}, std::pair{1, 1}, std::pair{17, 2}}) {
        EXPECT_LT(direct_vs_fft(lights_frame(std::min(3, w * h), w, h)), 1e-6) << w << "×" << h;
    }
}

TEST(VeilMethods, DirectSumEqualsTheFftPixelByPixel) {
    for (int count : {1, 7, 40}) {
        glm::dvec3 out_direct, out_fft;
        // The FFT's rounding is ≈ 1e-16 of the brightest pixel's energy, spread
        // over every pixel; the veil's darkest pixels here are ≈ 1e-7 of the
        // peak, so 1e-6 relative (plus 1e-12 of the peak absolute) bounds it with
        // room, and a wrong shift, wrap or missing light is far beyond it.
        EXPECT_LT(direct_vs_fft(lights_frame(count), &out_direct, &out_fft), 1e-6) << count << " lights";
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(out_direct[c], out_fft[c], 1e-9) << count << " lights, channel " << c;
    }
}

TEST(VeilMethods, DirectSumGivesTheCieEquation) {
    Frame fr = lights_frame(1);
    const int ci = fr.w / 2, cj = fr.h / 2;
    const double e_lux = 0.5;
    VeilingGlare veil;
    veil.apply(fr.rgba, fr.w, fr.h, fr.f, {25, 0.5});  // automatic: one lit pixel
    EXPECT_EQ(veil.last_method(), VeilMethod::direct);
    for (int dx : {12, 24, 60, 120}) {  // 1°, 2°, 5°, 10°
        const double theta = std::atan(dx / fr.f) / kDeg;
        const double l = fr.at(ci + dx, cj, 0);
        // 1% as the FFT's own test (unit.VeilingGlare.*): the pixel's mean of
        // the equation against its value at the pixel's angle.
        EXPECT_NEAR(l / e_lux / cie_gsf_veil_per_lux(theta, {25, 0.5}), 1.0, 0.01) << theta << "°";
    }
}

TEST(VeilMethods, AutomaticTakesTheDirectSumForFewLitPixelsOnly) {
    VeilingGlare veil;
    Frame few = lights_frame(kVeilDirectMaxLitPixels);
    veil.apply(few.rgba, few.w, few.h, few.f, {25, 0.5});
    EXPECT_EQ(veil.last_method(), VeilMethod::direct);
    Frame many = lights_frame(1);
    for (int j = 0; j < 20; ++j)
        for (int i = 0; i < 20; ++i) many.at(100 + i, 50 + j, 1) = 1.0f;  // 400 lit pixels
    veil.apply(many.rgba, many.w, many.h, many.f, {25, 0.5});
    EXPECT_EQ(veil.last_method(), VeilMethod::fft);
}

}  // namespace
}  // namespace atonlab::test
