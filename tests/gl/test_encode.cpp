// The GLSL display encoder (display_encode.glsl, through test_encode.comp)
// against the CPU reference encode_pixel(): every display encoding, dither on and
// off, 8 and 10 bits, the std430 and std140 layouts of DisplayParams. Inputs
// are random relative RGB in [0, 1.2] with exact 0 and 1 and a few NaN,
// negative and infinite values. The contract: >= 99.9 % of 8-bit codes
// identical and none more than one code apart (in practice all are identical:
// the inverse runs in double with a double exp/log, the dither is integer-only).
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "atonlab/display/display_encodings.h"
#include "atonlab/display/display_model.h"
#include "atonlab/display/fit_json.h"
#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/scene_file.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;
using GpuEncode = GLTest;

constexpr int kWidth = 192;
constexpr int kHeight = 128;
constexpr std::uint32_t kFrame = 12345;

std::vector<LutPoint> measured_lut(double scale) {
    return {{0.0, 0.05 * scale}, {0.05, 0.05 * scale}, {0.1, 0.12 * scale},  {0.25, 1.1 * scale},
            {0.5, 5.0 * scale},  {0.7, 11.0 * scale},  {0.85, 16.5 * scale}, {1.0, 22.0 * scale}};
}

std::vector<DisplayModel> every_kind() {
    return {
        DisplayModel::srgb(120.0, 0.2),
        DisplayModel::gog(
            {GogParams{0.05, 0.04, 4.0, 2.4}, GogParams{0.1, 0.0, 7.0, 2.2}, GogParams{0.02, -0.02, 2.0, 2.3}}, "GOG"),
        DisplayModel::pq(1000.0, 0.005),
        DisplayModel::lut({measured_lut(1.0), measured_lut(3.3), measured_lut(0.35)}, "LUT")};
}

/// Random relative RGB in [0, 1.2]; every 53rd component exactly 0, every 59th exactly 1,
/// and a handful of NaN, negative and infinite values.
std::vector<float> make_inputs() {
    std::mt19937 rng(2024);
    std::uniform_real_distribution<float> u(0.0f, 1.2f);
    std::vector<float> rgba(static_cast<std::size_t>(kWidth * kHeight * 4), 0.0f);
    for (std::size_t i = 0; i < rgba.size(); ++i) {
        if (i % 4 == 3) continue;
        rgba[i] = i % 53 == 0 ? 0.0f : i % 59 == 0 ? 1.0f : u(rng);
    }
    const float specials[] = {std::numeric_limits<float>::quiet_NaN(), -0.25f, -std::numeric_limits<float>::infinity(),
                              std::numeric_limits<float>::infinity(),  1e30f,  1.0e-7f};
    for (std::size_t k = 0; k < std::size(specials); ++k) rgba[4 * (1000 + 37 * k) + k % 3] = specials[k];
    return rgba;
}

struct Agreement {
    long identical = 0, total = 0;
    int max_diff = 0;
};

Agreement run_case(const gl::Program& prog, bool ubo, const DisplayModel& display, const EncodeSettings& settings,
                   const std::vector<float>& inputs) {
    const std::size_t n = inputs.size() / 4;
    const GpuDisplayParams params = gpu_display_params(display, settings);
    const std::vector<double> lut = gpu_display_lut(display);
    auto b_in = gl::Buffer::from(std::span<const float>(inputs));
    gl::Buffer b_params(sizeof(params), &params, gl::BufferUsage::static_draw);
    auto b_lut = gl::Buffer::from(std::span<const double>(lut));
    gl::Buffer b_out(n * 4 * sizeof(std::uint32_t), nullptr, gl::BufferUsage::dynamic_read);
    prog.use();
    prog.set("count", static_cast<unsigned>(n));
    prog.set("width", kWidth);
    prog.set("frame", static_cast<unsigned>(kFrame));
    b_in.bind_storage(0);
    if (ubo) {
        b_params.bind_uniform(1);
    } else {
        b_params.bind_storage(1);
    }
    b_out.bind_storage(2);
    b_lut.bind_storage(3);
    glDispatchCompute(static_cast<unsigned>((n + 63) / 64), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<std::uint32_t> codes(n * 4);
    b_out.download(0, codes.size() * sizeof(std::uint32_t), codes.data());

    Agreement a;
    const int max_code = (1 << settings.bits) - 1;
    for (std::size_t i = 0; i < n; ++i) {
        const glm::ivec2 pixel(static_cast<int>(i) % kWidth, static_cast<int>(i) / kWidth);
        const glm::dvec3 rel(inputs[4 * i], inputs[4 * i + 1], inputs[4 * i + 2]);
        const glm::ivec3 cpu = encode_pixel(display, rel, pixel, kFrame, settings);
        for (int c = 0; c < 3; ++c) {
            const int gpu = static_cast<int>(codes[4 * i + static_cast<std::size_t>(c)]);
            EXPECT_GE(gpu, 0);
            EXPECT_LE(gpu, max_code);
            a.max_diff = std::max(a.max_diff, std::abs(gpu - cpu[c]));
            a.identical += gpu == cpu[c] ? 1 : 0;
            ++a.total;
        }
    }
    return a;
}

TEST_F(GpuEncode, MatchesTheCpuReferenceForEveryEncoding) {
    const auto ssbo = gl::Program::build({{gl::ShaderStage::compute, "test_encode.comp"}});
    const auto ubo = gl::Program::build({{gl::ShaderStage::compute, "test_encode.comp"}}, {"PARAMS_IN_UBO"});
    const auto inputs = make_inputs();
    for (const auto& display : every_kind()) {
        for (const int bits : {8, 10}) {
            for (const Dither dither : {Dither::none, Dither::spatiotemporal}) {
                for (const bool use_ubo : {false, true}) {
                    const EncodeSettings settings{bits, dither, 77};
                    const Agreement a = run_case(use_ubo ? ubo : ssbo, use_ubo, display, settings, inputs);
                    const double fraction = static_cast<double>(a.identical) / static_cast<double>(a.total);
                    std::printf("%-5s %2d bits dither %-3s %s: %ld/%ld codes identical (%.5f %%), max diff %d\n",
                                display.name.c_str(), bits, dither == Dither::none ? "off" : "on",
                                use_ubo ? "std140" : "std430", a.identical, a.total, 100.0 * fraction, a.max_diff);
                    EXPECT_GE(fraction, 0.999) << display.name << " " << bits << " bits";
                    EXPECT_LE(a.max_diff, 1) << display.name << " " << bits << " bits";
                }
            }
        }
    }
}

// display.out_of_gamut on the GPU (display_encode.glsl) against fit_to_gamut() (gamut.cpp):
// every choice, on inputs mostly out of gamut (up to 6× full drive), on a nominal and a
// measured (GOG) display.
TEST_F(GpuEncode, EveryOutOfGamutChoiceMatchesTheCpuReference) {
    const auto ssbo = gl::Program::build({{gl::ShaderStage::compute, "test_encode.comp"}});
    std::vector<float> inputs = make_inputs();
    for (std::size_t i = 0; i < inputs.size(); ++i)
        if (i % 4 != 3 && std::isfinite(inputs[i])) inputs[i] *= 5.0f;
    const std::vector<DisplayModel> displays = every_kind();
    for (const auto& name : out_of_gamut_names()) {
        for (const DisplayModel& display : {displays[0], displays[1]}) {
            EncodeSettings settings{8, Dither::spatiotemporal, 77};
            settings.out_of_gamut = *out_of_gamut_from_name(name);
            const Agreement a = run_case(ssbo, false, display, settings, inputs);
            const double fraction = static_cast<double>(a.identical) / static_cast<double>(a.total);
            std::printf("out_of_gamut %-18s %-5s: %ld/%ld codes identical (%.5f %%), max diff %d\n",
                        std::string(name).c_str(), display.name.c_str(), a.identical, a.total, 100.0 * fraction,
                        a.max_diff);
            EXPECT_GE(fraction, 0.999) << name << " " << display.name;
            EXPECT_LE(a.max_diff, 1) << name << " " << display.name;
        }
    }
}

// An encoding of one file outside the library (toy_display_encoding/toy_gamma.cpp, its
// one registry line there): a scene file names it, the GPU encodes with the GLSL its file
// gives as the CPU does, its codes are its law's, and its parameter goes through the fit JSON.
TEST_F(GpuEncode, AnEncodingOfOneFileIsReadEncodedAndStoredAsTheLibrarysAre) {
    const DisplayEncoding* toy = display_encoding_named("toy-gamma");
    ASSERT_NE(toy, nullptr) << "the toy encoding's registry line did not run";
    const stimuli::Scene scene = stimuli::parse_scene(
        "[display]\nwidth_px = 64\nheight_px = 48\nwidth_m = 0.4\nviewing_distance_m = 0.6\n"
        "peak_cd_m2 = 120\nblack_cd_m2 = 0.2\nencoding = \"toy-gamma\"\n",
        "toy.toml");
    const DisplayModel& display = scene.output.display;
    ASSERT_EQ(display_encoding_of(display), toy);
    EXPECT_EQ(display.name, "Toy");
    // Its law, by hand: relative 0.25 over black is V = 0.25^(1/2) = 0.5, code 0.5 · 255 rounded = 128.
    const double L = display.black_cd_m2 + 0.25 * (display.peak_cd_m2 - display.black_cd_m2);
    const glm::ivec3 code =
        encode_pixel(display, glm::dvec3(L / display.peak_cd_m2), {0, 0}, 0, EncodeSettings{8, Dither::none, 0});
    EXPECT_EQ(code, glm::ivec3(128));
    // The GPU, with the GLSL from the toy's file, against the CPU.
    const auto ssbo = gl::Program::build({{gl::ShaderStage::compute, "test_encode.comp"}});
    for (const Dither dither : {Dither::none, Dither::spatiotemporal}) {
        const Agreement a = run_case(ssbo, false, display, EncodeSettings{10, dither, 77}, make_inputs());
        EXPECT_GE(static_cast<double>(a.identical) / static_cast<double>(a.total), 0.999);
        EXPECT_LE(a.max_diff, 1);
    }
    // Its parameter in the fit JSON, by its declared key, read back as it was; a bad one is refused by its check.
    DisplayModel steeper = display;
    for (auto& ch : steeper.channels) ch.parameter[0] = 2.4;
    const std::string json = nominal_fit_json(steeper, EncodeSettings{});
    EXPECT_NE(json.find(R"("encoding":"toy-gamma")"), std::string::npos) << json;
    EXPECT_NE(json.find(R"("gamma":2.4)"), std::string::npos) << json;
    const DisplayModel back = display_model_from_fit_json(json, "back");
    for (const auto& ch : back.channels) EXPECT_EQ(ch.parameter[0], 2.4);
    for (auto& ch : steeper.channels) ch.parameter[0] = -1.0;
    EXPECT_THROW(steeper.validate(), InputError);
}

}  // namespace
}  // namespace atonlab::test
