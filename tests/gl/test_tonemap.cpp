// The GLSL twin of the tone-mapping operators (shaders/tonemap.glsl) against the double
// reference (display/src/tonemap.cpp), for random HDR pixels over 1e-6 … 1e9 cd/m²
// (log-uniform), random chromaticities with the pure primaries among them, and adaptation
// levels over 1e-6 … 1e6 cd/m², for every operator × hue preservation × blueshift.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/display/tonemap.h"
#include "blueshift_modes.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

// Pixels: rgb (cd/m²) and, in a, the adaptation luminance (cd/m²).
std::vector<glm::vec4> random_pixels(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const std::array<glm::dvec3, 7> pure = {
        {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}, {1, 1, 1}}};
    std::vector<glm::vec4> px(n);
    for (std::size_t i = 0; i < n; ++i) {
        glm::dvec3 colour;
        if (i % 5 == 0) {
            colour = pure[(i / 5) % pure.size()];
        } else {
            // Random chromaticity, often very saturated: each channel log-uniform over 6 decades.
            colour = {std::pow(10.0, -6.0 * u(rng)), std::pow(10.0, -6.0 * u(rng)), std::pow(10.0, -6.0 * u(rng))};
        }
        const double lum = std::pow(10.0, -6.0 + 15.0 * u(rng));
        const glm::dvec3 rgb = colour * (lum / luminance_of_linear_rgb(colour));
        const double adaptation = std::pow(10.0, -6.0 + 12.0 * u(rng));
        px[i] = glm::vec4(glm::vec3(rgb), static_cast<float>(adaptation));
    }
    // Exact zeros too.
    px[1] = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    px[2] = glm::vec4(0.0f, 0.0f, 0.0f, 1e-6f);
    return px;
}

using ToneMapGpu = GLTest;

TEST_F(ToneMapGpu, GlslTwinMatchesTheDoubleReference) {
    constexpr std::size_t n = 8192;
    const std::vector<glm::vec4> px = random_pixels(n, 20240611u);
    auto in = gl::Buffer::from(std::span<const glm::vec4>(px));
    gl::Buffer out(n * sizeof(glm::vec4), nullptr, gl::BufferUsage::dynamic_read);
    gl::Buffer params(sizeof(ToneMapGpuParams), nullptr, gl::BufferUsage::dynamic_draw);
    auto prog = gl::Program::build({{gl::ShaderStage::compute, "test_tonemap.comp"}});
    prog.use();
    prog.set("count", static_cast<unsigned>(n));
    prog.set("scotopic_scale", 0.0f);
    in.bind_storage(0);
    out.bind_storage(1);
    params.bind_uniform(0);

    const std::array<ToneOperator, 6> ops = {ToneOperator::empirical, ToneOperator::perceptual, ToneOperator::reinhard,
                                             ToneOperator::kakimoto,  ToneOperator::linear,     ToneOperator::clamp};
    const std::array<HuePreservation, 3> hues = {HuePreservation::none, HuePreservation::xyY, HuePreservation::rgb};
    std::vector<glm::vec4> got(n);
    std::printf(
        "GPU (fp32 GLSL) vs CPU (double), %zu pixels per setting: worst relative error where the CPU value "
        "exceeds 1e-6, worst absolute error below\n",
        n);
    for (ToneOperator op : ops) {
        double worst_op = 0.0, worst_op_abs = 0.0;
        for (HuePreservation h : hues) {
            for (const int blue : atonlab::test::kBlueshiftModes) {
                for (const MesopicModel mes : {MesopicModel::k2012, MesopicModel::cie191}) {
                    ToneMapSettings s;
                    s.tone_operator = op;
                    s.hue_preservation = h;
                    s.mesopic = mes;
                    atonlab::test::set_blueshift(s, blue);
                    if (op == ToneOperator::reinhard) s.reinhard_white_relative = 4.0;  // exercise eq 4
                    const ToneMapGpuParams p = tonemap_gpu_params(s);
                    params.upload(0, sizeof(p), &p);
                    glMemoryBarrier(GL_UNIFORM_BARRIER_BIT);
                    glDispatchCompute(static_cast<unsigned>((n + 63) / 64), 1, 1);
                    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
                    out.download(0, n * sizeof(glm::vec4), got.data());
                    double worst = 0.0, worst_abs = 0.0;
                    std::size_t worst_i = 0;
                    int failures = 0;
                    for (std::size_t i = 0; i < n; ++i) {
                        // The CPU gets exactly the fp32 values the GPU saw.
                        const glm::dvec3 ref = tonemap_pixel(glm::dvec3(glm::vec3(px[i])), px[i].a, s);
                        for (int c = 0; c < 3; ++c) {
                            const double g = got[i][c], r = ref[c];
                            ASSERT_TRUE(std::isfinite(g) && g >= 0.0) << i;
                            const double diff = std::abs(g - r);
                            // Relative 1e-4, or absolute 1e-6 near 0 (display-relative units).
                            if (diff > 1e-4 * std::abs(r) && diff > 1e-6 && failures++ < 5) {
                                ADD_FAILURE()
                                    << tone_operator_name(op) << " " << hue_preservation_name(h) << " blueshift "
                                    << atonlab::test::blueshift_label(blue) << " mesopic " << mesopic_model_name(mes)
                                    << " pixel " << i << " channel " << c << ": gpu " << g << " cpu " << r << " (rgb "
                                    << px[i].r << "," << px[i].g << "," << px[i].b << " adaptation " << px[i].a << ")";
                            }
                            if (std::abs(r) > 1e-6) {
                                if (diff / std::abs(r) > worst) {
                                    worst = diff / std::abs(r);
                                    worst_i = i;
                                }
                            } else {
                                worst_abs = std::max(worst_abs, diff);
                            }
                        }
                    }
                    worst_op = std::max(worst_op, worst);
                    worst_op_abs = std::max(worst_op_abs, worst_abs);
                    std::printf(
                        "  %-10s hue %-4s blueshift %-10s mesopic %-6s relative %.2e (pixel %zu: L %.3g, L_wa %.3g), "
                        "absolute %.2e\n",
                        std::string(tone_operator_name(op)).c_str(), std::string(hue_preservation_name(h)).c_str(),
                        atonlab::test::blueshift_label(blue), std::string(mesopic_model_name(mes)).c_str(), worst,
                        worst_i, luminance_of_linear_rgb(glm::dvec3(glm::vec3(px[worst_i]))),
                        static_cast<double>(px[worst_i].a), worst_abs);
                }
            }
        }
        std::printf("worst GPU-vs-CPU error, %-10s: relative %.2e, absolute (near 0) %.2e\n",
                    std::string(tone_operator_name(op)).c_str(), worst_op, worst_op_abs);
    }
}

TEST_F(ToneMapGpu, ScotopicChannelTwinMatchesTheDoubleReference) {
    // The rod signal from the frame's scotopic channel (tonemap_pixel_scotopic) rather than the RGB
    // weights: V = 5.38 × G (the green die's S/P on the green channel), the same fp32 product on both.
    constexpr std::size_t n = 8192;
    const std::vector<glm::vec4> px = random_pixels(n, 20261207u);
    auto in = gl::Buffer::from(std::span<const glm::vec4>(px));
    gl::Buffer out(n * sizeof(glm::vec4), nullptr, gl::BufferUsage::dynamic_read);
    gl::Buffer params(sizeof(ToneMapGpuParams), nullptr, gl::BufferUsage::dynamic_draw);
    auto prog = gl::Program::build({{gl::ShaderStage::compute, "test_tonemap.comp"}});
    prog.use();
    prog.set("count", static_cast<unsigned>(n));
    const float scale = 5.38f;
    prog.set("scotopic_scale", scale);
    in.bind_storage(0);
    out.bind_storage(1);
    params.bind_uniform(0);
    std::vector<glm::vec4> got(n);
    for (const ToneOperator op : {ToneOperator::perceptual, ToneOperator::empirical}) {
        for (const MesopicModel mes : {MesopicModel::k2012, MesopicModel::cie191}) {
            ToneMapSettings s;
            s.tone_operator = op;
            s.mesopic = mes;
            const ToneMapGpuParams p = tonemap_gpu_params(s);
            params.upload(0, sizeof(p), &p);
            glMemoryBarrier(GL_UNIFORM_BARRIER_BIT);
            glDispatchCompute(static_cast<unsigned>((n + 63) / 64), 1, 1);
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            out.download(0, n * sizeof(glm::vec4), got.data());
            double worst = 0.0;
            int failures = 0;
            for (std::size_t i = 0; i < n; ++i) {
                const float v = scale * px[i].g;
                const glm::dvec3 ref = tonemap_pixel(glm::dvec3(glm::vec3(px[i])), v, px[i].a, s);
                for (int c = 0; c < 3; ++c) {
                    const double diff = std::abs(got[i][c] - ref[c]);
                    if (std::abs(ref[c]) > 1e-6) worst = std::max(worst, diff / std::abs(ref[c]));
                    // As GlslTwinMatchesTheDoubleReference: relative 1e-4, or absolute 1e-6 near 0.
                    if (diff > 1e-4 * std::abs(ref[c]) && diff > 1e-6 && failures++ < 5)
                        ADD_FAILURE() << tone_operator_name(op) << " " << mesopic_model_name(mes) << " pixel " << i
                                      << " channel " << c << ": gpu " << got[i][c] << " cpu " << ref[c];
                }
            }
            std::printf("scotopic channel, %-10s %-6s: worst relative error %.2e\n",
                        std::string(tone_operator_name(op)).c_str(), std::string(mesopic_model_name(mes)).c_str(),
                        worst);
        }
    }
}

TEST_F(ToneMapGpu, HostileInputsStayFiniteOnTheGpu) {
    const float inf = std::numeric_limits<float>::infinity();
    const std::vector<glm::vec4> px = {
        {1e9f, 0.0f, 0.0f, 1e-6f},    {0.0f, 0.0f, 5.0f, 1e6f}, {-1.0f, 2.0f, -3.0f, 1.0f}, {inf, 0.0f, 0.0f, 1.0f},
        {3e38f, 3e38f, 3e38f, 1e-6f}, {1.0f, 1.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 1.0f, -5.0f},  {1.0f, 1.0f, 1.0f, inf},
        {1e-38f, 0.0f, 0.0f, 1.0f},   {0.0f, 0.0f, 0.0f, 0.0f},
    };
    const std::size_t n = px.size();
    auto in = gl::Buffer::from(std::span<const glm::vec4>(px));
    gl::Buffer out(n * sizeof(glm::vec4), nullptr, gl::BufferUsage::dynamic_read);
    gl::Buffer params(sizeof(ToneMapGpuParams), nullptr, gl::BufferUsage::dynamic_draw);
    auto prog = gl::Program::build({{gl::ShaderStage::compute, "test_tonemap.comp"}});
    prog.use();
    prog.set("count", static_cast<unsigned>(n));
    in.bind_storage(0);
    out.bind_storage(1);
    params.bind_uniform(0);
    std::vector<glm::vec4> got(n);
    for (int op = 0; op < 6; ++op) {
        for (int h = 0; h < 3; ++h) {
            ToneMapSettings s;
            s.tone_operator = static_cast<ToneOperator>(op);
            s.hue_preservation = static_cast<HuePreservation>(h);
            const ToneMapGpuParams p = tonemap_gpu_params(s);
            params.upload(0, sizeof(p), &p);
            glMemoryBarrier(GL_UNIFORM_BARRIER_BIT);
            glDispatchCompute(1, 1, 1);
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            out.download(0, n * sizeof(glm::vec4), got.data());
            for (std::size_t i = 0; i < n; ++i) {
                for (int c = 0; c < 3; ++c) {
                    EXPECT_TRUE(std::isfinite(got[i][c]) && got[i][c] >= 0.0f)
                        << tone_operator_name(s.tone_operator) << " " << hue_preservation_name(s.hue_preservation)
                        << " input " << i << " channel " << c << " = " << got[i][c];
                }
            }
        }
    }
}

}  // namespace
}  // namespace atonlab::test
