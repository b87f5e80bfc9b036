// Adaptation, tone mapping and display encoding on the GPU against the CPU
// double references (tonemap.h, display_model.h): 8-bit codes, log-average,
// temporal adaptation and the LDR path.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/pipeline.h"
#include "atonlab/stimuli/tonemap.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

constexpr int kW = 128, kH = 96;
// The eye's adaptation level (Scene::adaptation_cd_m2's default), passed where the
// adaptation is dynamic: the tone mapper then measures the frames and does not read it.
constexpr double kEyeCdM2 = 0.001;

// Random HDR pixels, rows in GL order (row 0 at the bottom): luminance log-uniform over
// 1e-6 … 1e9 cd/m², random chromaticities, pure primaries, exact zeros.
std::vector<float> random_hdr(std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<float> px(static_cast<std::size_t>(kW) * kH * 4, 0.0f);
    for (std::size_t i = 0; i < px.size() / 4; ++i) {
        const double L = std::pow(10.0, -6.0 + 15.0 * u(rng));
        glm::dvec3 c{u(rng), u(rng), u(rng)};
        switch (i % 16) {
            case 0:
                c = {0, 0, 0};
                break;
            case 1:
                c = {1, 0, 0};
                break;
            case 2:
                c = {0, 1, 0};
                break;
            case 3:
                c = {0, 0, 1};
                break;
            default:
                break;
        }
        const double y = luminance_of_linear_rgb(c);
        if (y > 0) c *= L / y;
        for (int k = 0; k < 3; ++k) px[i * 4 + k] = static_cast<float>(c[k]);
    }
    return px;
}

gl::Texture2D texture_of(const std::vector<float>& px) {
    gl::Texture2D t(kW, kH, gl::PixelFormat::rgba32f);
    t.upload(px.data());
    return t;
}

ImageRGBA32F image_of(const std::vector<float>& px) {
    ImageRGBA32F img;
    img.width = kW;
    img.height = kH;
    img.rgba = px;  // row order does not matter for the log-average
    return img;
}

// Fraction of identical codes and the largest difference, GPU vs CPU.
struct Agreement {
    double identical = 0;
    int max_diff = 0;
};
Agreement compare(const EncodedImage& gpu, const std::vector<float>& hdr, double adaptation, const OutputSettings& s,
                  std::uint32_t frame, const std::vector<float>* glare = nullptr, double ldr_scale = 0) {
    std::size_t same = 0, total = 0;
    int worst = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const std::size_t i = (static_cast<std::size_t>(y) * kW + x) * 4;
            const glm::dvec3 in{hdr[i], hdr[i + 1], hdr[i + 2]};
            glm::dvec3 rel;
            if (glare) {
                glm::dvec3 scene = glm::max(in, glm::dvec3(0.0));
                if (ldr_scale > 0) scene = glm::min(scene * ldr_scale, glm::dvec3(1.0));
                rel = scene + tonemap_pixel({(*glare)[i], (*glare)[i + 1], (*glare)[i + 2]}, adaptation, s.tonemap);
            } else {
                rel = tonemap_pixel(in, adaptation, s.tonemap);
            }
            const glm::ivec3 cpu = encode_pixel(s.display, rel, {x, y}, frame, s.encode);
            const std::size_t o = (static_cast<std::size_t>(kH - 1 - y) * kW + x) * 3;  // codes: top row first
            for (int c = 0; c < 3; ++c) {
                const int d = std::abs(static_cast<int>(gpu.rgb[o + c]) - cpu[c]);
                worst = std::max(worst, d);
                same += d == 0 ? 1 : 0;
                ++total;
            }
        }
    return {static_cast<double>(same) / static_cast<double>(total), worst};
}

using DisplayPipelineGL = GLTest;

TEST_F(DisplayPipelineGL, EightBitCodesMatchTheCpuReferenceForEveryOperator) {
    const std::vector<float> hdr = random_hdr(1);
    const gl::Texture2D tex = texture_of(hdr);
    DisplayPipeline pipeline;
    for (ToneOperator op : {ToneOperator::empirical, ToneOperator::perceptual, ToneOperator::reinhard,
                            ToneOperator::kakimoto, ToneOperator::linear, ToneOperator::clamp})
        for (double adaptation : {1e-6, 1e-3, 1.0, 1e3, 1e6}) {
            OutputSettings s;
            s.tonemap.tone_operator = op;
            const std::uint32_t frame = 7;
            pipeline.process(tex, s, adaptation, 0.0, frame);
            const Agreement a = compare(pipeline.read_codes(), hdr, adaptation, s, frame);
            EXPECT_GE(a.identical, 0.999) << tone_operator_name(op) << " at " << adaptation;
            EXPECT_LE(a.max_diff, 1) << tone_operator_name(op) << " at " << adaptation;
            if (adaptation == 1.0)
                std::printf("%-10s: %.5f of codes identical, max difference %d\n",
                            std::string(tone_operator_name(op)).c_str(), a.identical, a.max_diff);
        }
}

TEST_F(DisplayPipelineGL, LogAverageMatchesTheCpuReference) {
    DisplayPipeline pipeline;
    OutputSettings s;
    s.adaptation.mode = AdaptationMode::dynamic;
    auto check = [&](const std::vector<float>& px, const char* what) {
        pipeline.reset_adaptation();
        pipeline.process(texture_of(px), s, kEyeCdM2, 0.0, 0);
        const double cpu = atonlab::stimuli::log_average_luminance(image_of(px), s.adaptation.epsilon_cd_m2);
        EXPECT_NEAR(pipeline.log_average_cd_m2() / cpu, 1.0, 1e-4) << what;
        EXPECT_NEAR(pipeline.adaptation_cd_m2() / cpu, 1.0, 1e-4) << what << ": the first frame adopts it";
    };
    std::vector<float> zeros(static_cast<std::size_t>(kW) * kH * 4, 0.0f);
    check(zeros, "all zeros");
    std::vector<float> spike = zeros;
    spike[4 * 1000] = spike[4 * 1000 + 1] = spike[4 * 1000 + 2] = 1e9f;
    check(spike, "one 1e9 pixel");
    std::vector<float> uniform(zeros.size(), 0.03f);
    check(uniform, "uniform 0.03");
    check(random_hdr(2), "random");
}

TEST_F(DisplayPipelineGL, TemporalAdaptationReachesSixtyThreePercentAfterTau) {
    // A step from 0.01 to 10 cd/m²: τ(10) from eq 4.17; frames at 60 Hz.
    DisplayPipeline pipeline;
    OutputSettings s;
    s.adaptation.mode = AdaptationMode::dynamic;
    const std::vector<float> dark(static_cast<std::size_t>(kW) * kH * 4, 0.01f);
    const std::vector<float> bright(dark.size(), 10.0f);
    pipeline.process(texture_of(dark), s, kEyeCdM2, 0.0, 0);
    const double start = pipeline.adaptation_cd_m2();
    const gl::Texture2D b = texture_of(bright);
    const double target = atonlab::stimuli::log_average_luminance(image_of(bright), s.adaptation.epsilon_cd_m2);
    const double tau = adaptation_time_constant_s(target);
    const double dt = 1.0 / 60.0;
    const int frames = static_cast<int>(std::lround(tau / dt));
    for (int f = 0; f < frames; ++f) pipeline.process(b, s, kEyeCdM2, dt, static_cast<std::uint32_t>(f));
    const double reached = (pipeline.adaptation_cd_m2() - start) / (target - start);
    const double expected = 1.0 - std::exp(-frames * dt / tau);
    EXPECT_NEAR(reached, expected, 1e-4);
    EXPECT_NEAR(reached, 1.0 - std::exp(-1.0), 0.02);
    // Δt = 0 holds still; a huge Δt lands on the target.
    const double held = pipeline.adaptation_cd_m2();
    pipeline.process(b, s, kEyeCdM2, 0.0, 0);
    EXPECT_DOUBLE_EQ(pipeline.adaptation_cd_m2(), held);
    pipeline.process(b, s, kEyeCdM2, 1e6, 0);
    EXPECT_NEAR(pipeline.adaptation_cd_m2() / target, 1.0, 1e-6);
}

TEST_F(DisplayPipelineGL, LdrPathAddsToneMappedGlareToTheDisplayReferredFrame) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<float> ldr(static_cast<std::size_t>(kW) * kH * 4, 0.0f);
    for (float& v : ldr) v = static_cast<float>(0.8 * u(rng));
    const std::vector<float> glare = random_hdr(4);
    DisplayPipeline pipeline;
    OutputSettings s;
    pipeline.process_ldr(texture_of(ldr), texture_of(glare), s, 0.03, 5);
    const Agreement a = compare(pipeline.read_codes(), ldr, 0.03, s, 5, &glare);
    EXPECT_GE(a.identical, 0.999);
    EXPECT_LE(a.max_diff, 1);
    // An HDR scene shown by exposure (× scale, clipped) in the same path.
    const std::vector<float> hdr = random_hdr(5);
    pipeline.process_ldr(texture_of(hdr), texture_of(glare), s, 0.03, 5, 1.0 / 0.06);
    const Agreement b = compare(pipeline.read_codes(), hdr, 0.03, s, 5, &glare, 1.0 / 0.06);
    EXPECT_GE(b.identical, 0.999);
    EXPECT_LE(b.max_diff, 1);
}

TEST_F(DisplayPipelineGL, BadSettingsAreInputErrors) {
    DisplayPipeline pipeline;
    const gl::Texture2D tex = texture_of(random_hdr(6));
    OutputSettings s;
    EXPECT_THROW(pipeline.process(tex, s, kEyeCdM2, -1.0, 0), InputError);
    EXPECT_THROW(pipeline.process(tex, s, kEyeCdM2, std::nan(""), 0), InputError);
    s.encode.bits = 0;
    EXPECT_THROW(validate_output_settings(s), InputError);
    s.encode.bits = 8;
    s.display.black_cd_m2 = 200.0;  // above its peak
    EXPECT_THROW(validate_output_settings(s), InputError);
}

TEST_F(DisplayPipelineGL, AFixedLevelIsThePositiveLevelPassedIn) {
    // The level is the scene's (Scene::adaptation_cd_m2), passed to each frame: refused where
    // it is used (fixed adaptation, the LDR path) unless positive and finite, under its key.
    DisplayPipeline pipeline;
    const gl::Texture2D tex = texture_of(random_hdr(7));
    OutputSettings s;
    for (const double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
        EXPECT_THROW(pipeline.process(tex, s, bad, 0.0, 0), InputError) << bad;
        EXPECT_THROW(pipeline.process_ldr(tex, tex, s, bad, 0), InputError) << bad;
        try {
            validate_output_settings(s, bad);
            ADD_FAILURE() << bad << " was accepted";
        } catch (const InputError& e) {
            ASSERT_TRUE(e.where().has_value());
            EXPECT_EQ(e.where()->key, "eye.adaptation_cd_m2");
        }
    }
    EXPECT_NO_THROW(validate_output_settings(s, 0.03));
    pipeline.process(tex, s, 0.03, 0.0, 0);
    EXPECT_EQ(pipeline.adaptation_cd_m2(), 0.03);
    // Dynamic adaptation measures the frame: the level passed in is not read.
    s.adaptation.mode = AdaptationMode::dynamic;
    pipeline.reset_adaptation();
    EXPECT_NO_THROW(pipeline.process(tex, s, 0.0, 0.0, 0));
    const double log_average =
        atonlab::stimuli::log_average_luminance(image_of(random_hdr(7)), s.adaptation.epsilon_cd_m2);
    EXPECT_NEAR(pipeline.adaptation_cd_m2() / log_average, 1.0, 1e-4);
}

}  // namespace
}  // namespace atonlab::test
