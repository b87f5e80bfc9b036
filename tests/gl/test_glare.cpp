// The glare stage on the GPU: the PSF pipeline against its double-precision
// CPU references, and the billboards against docs/architecture.md's "Physical invariants" (glare
// redistributes a light's energy; it neither creates nor loses it). A model's
// own frames: tests/gl/glare_models/NAME.cpp, in the same GlareFrames suite
// (tests/support/glare_frames.h).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>

#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/light_model.h"
#include "atonlab/stimuli/profile.h"
#include "atonlab/stimuli/psf_generator.h"
#include "gl_test_support.h"
#include "glare_frames.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

double relative_l2(const std::vector<double>& a, const std::vector<double>& b) {
    double num = 0, den = 0;
    for (std::size_t i = 0; i < b.size(); ++i) {
        num += (a[i] - b[i]) * (a[i] - b[i]);
        den += b[i] * b[i];
    }
    return std::sqrt(num / den);
}

using GlarePsf = GLTest;

TEST_F(GlarePsf, GpuMonoAndRgbMatchTheirCpuReferences) {
    const EyeModel eye = small_eye();
    const int n = 256;
    const SpectralSamples samples = spectral_samples(d65_spectrum(), 30);
    GpuPsfGenerator gen(n);
    gen.generate(pupil_plane(eye, n, kReferenceWavelengthNm, eye.plane_width_mm), psf_degrees_per_texel(eye), samples);
    const MonoPsf gpu_mono = gen.read_mono();
    const MonoPsf cpu_mono = mono_psf_reference(eye, n, kReferenceWavelengthNm);
    const double e_mono = relative_l2(gpu_mono.value, cpu_mono.value);
    const RgbPsf gpu_rgb = gen.read_rgb();
    const RgbPsf cpu_rgb = spectral_psf_resampled(cpu_mono, samples);
    const double e_rgb = stimuli::relative_l2(gpu_rgb, cpu_rgb);
    std::printf("GPU vs CPU double, n=%d: mono PSF relative L2 %.3g, RGB PSF relative L2 %.3g\n", n, e_mono, e_rgb);
    EXPECT_LT(e_mono, 1e-4);
    EXPECT_LT(e_rgb, 1e-4);
    EXPECT_NEAR(gpu_rgb.luminance_sum(), 1.0, 1e-5);
    double mono_sum = 0;
    for (double v : gpu_mono.value) mono_sum += v;
    EXPECT_NEAR(mono_sum, 1.0, 1e-5);
}

TEST_F(GlarePsf, DefaultEyeAtN512MatchesCpuAndIsBitIdenticalForASeed) {
    EyeModel eye;  // the default eye: two scales, gratings, particles, in focus; halo at 4°
    eye.pupil_diameter_mm = 6.0;
    const int n = 512;
    const SpectralSamples samples = spectral_samples(d65_spectrum(), 30);
    GpuPsfGenerator gen(n);
    gen.generate(eye, samples);
    const RgbPsf first = gen.read_rgb();
    gen.generate(eye, samples);
    const RgbPsf second = gen.read_rgb();
    ASSERT_EQ(first.rgb.size(), second.rgb.size());
    EXPECT_TRUE(first.rgb == second.rgb) << "same seed, same machine: the PSF must be bit-identical";
    const RgbPsf cpu = spectral_psf_resampled(mono_psf_reference(eye, n, kReferenceWavelengthNm), samples);
    EXPECT_LT(stimuli::relative_l2(first, cpu), 1e-4);
    // The scale puts the ring diffracted by the gratings at the pupil's edge
    // (r = 3 mm) at 4°: dpt = 4° / (count/(2π r) · W).
    EXPECT_NEAR(first.degrees_per_texel, 4.0 / (eye.gratings.count / (2 * std::numbers::pi * 3.0) * eye.plane_width_mm),
                1e-9);
    // A different seed draws a different eye.
    eye.seed = 2;
    gen.generate(eye, samples);
    EXPECT_FALSE(gen.read_rgb().rgb == first.rgb);
}

// ---------------------------------------------------------------------------
// Billboards in frames.

TEST_F(GlareFrames, EveryModelPutsTheLightsIlluminanceIntoTheFrame) {
    for (GlareModel model : {GlareModel::wave_optics, GlareModel::gaussian_bloom, GlareModel::spencer}) {
        // Sub-pixel (1 km) and area lights (10 m: a 29 px disc, K2012 fig 6.17), slightly off-axis.
        for (double d : {1000.0, 100.0, 10.0}) {
            Scene scene = black_scene(model);
            scene.lights = {light_at(glm::dvec3(0.013, -0.007, -1.0) * d)};
            const double expected = 100.0 / glm::dot(scene.lights[0].position_m, scene.lights[0].position_m);
            const double got = energy(scene);
            EXPECT_NEAR(got / expected, 1.0, 0.01) << glare_model_name(model) << " at " << d << " m";
            const auto& report = renderer->glare().report();
            ASSERT_EQ(report.size(), 1u);
            std::printf("%-14s d = %6.0f m: energy ratio %.6f, window cut %.4f, layers %d up to %.0f px\n",
                        std::string(glare_model_name(model)).c_str(), d, got / expected, report[0].window_cut.g,
                        report[0].area_layers, report[0].area_max_radius_px);
        }
    }
}

TEST_F(GlareFrames, GlareAndNoGlareFramesHoldTheSameEnergy) {
    // K2012 fig 6.17: four 100 cd lights at 10, 20, 50 and 100 m, plus colour and fog.
    // Every model: the billboards keep all of it, `cie` all but what it reports outside the frame.
    for (GlareModel model :
         {GlareModel::wave_optics, GlareModel::gaussian_bloom, GlareModel::spencer, GlareModel::cie}) {
        Scene scene = black_scene(model);
        scene.environment.extinction_per_m = 1e-3;
        const double xs[] = {-0.02, -0.007, 0.007, 0.02};
        const double ds[] = {10, 20, 50, 100};
        for (int i = 0; i < 4; ++i) scene.lights.push_back(light_at(glm::dvec3(xs[i], 0.0, -1.0) * ds[i]));
        scene.lights[1].rgb_per_cd = *iala_colour_rgb("red");
        scene.lights[2].rgb_per_cd = *iala_colour_rgb("green");
        const double with_glare = energy(scene);
        const glm::dvec3 rgb_glare = image_illuminance_rgb_lux(renderer->read_hdr(), renderer->projection().focal_px);
        const glm::dvec3 kept = glm::dvec3(1.0) - renderer->veil_report().outside_frame;
        EXPECT_EQ(renderer->veil_report().applied, model == GlareModel::cie);
        scene.glare.model = GlareModel::none;
        const double without = energy(scene);
        const glm::dvec3 rgb_direct = image_illuminance_rgb_lux(renderer->read_hdr(), renderer->projection().focal_px);
        const std::string name(glare_model_name(model));
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(rgb_glare[c] / (rgb_direct[c] * kept[c]), 1.0, 0.01) << name << " channel " << c;
        double expected = 0;
        for (const Light& L : scene.lights)
            expected += illuminance_lux(evaluate_light(L, scene.profiles, scene.camera.position_m, 0.0, 1e-3));
        const double kept_y = luminance_of_linear_rgb(rgb_glare) / luminance_of_linear_rgb(rgb_direct);
        EXPECT_NEAR(with_glare / (expected * kept_y), 1.0, 0.01) << name;
        EXPECT_NEAR(with_glare / without, kept_y, 1e-6) << name;
        std::printf("%-14s glare/no-glare energy %.6f, outside the frame %.4f\n", name.c_str(), with_glare / without,
                    1.0 - kept.g);
    }
}

TEST_F(GlareFrames, LightsWithTheirOwnGlareModelsShareAFrameEachKeepingItsEnergy) {
    // Issue 14: a glare light ("a", 1.5° left) and a no-glare light ("b", 1.5°
    // right) in one frame, for each model `a` may ask for (its own key, and once
    // inherited from the eye while `b` asks for none). Each keeps its
    // illuminance (Σ L·Ω, minus what `cie` reports outside the frame), and the
    // frame is exactly the sum of the frames of each light alone: b's pixels
    // get b's direct image plus a's real glare spill, nothing else (none at
    // all from a billboard of 1° radius, 3° away).
    struct Case {
        GlareModel eye;
        std::optional<GlareModel> a;
    };
    const Case cases[] = {{GlareModel::none, GlareModel::wave_optics},
                          {GlareModel::none, GlareModel::gaussian_bloom},
                          {GlareModel::none, GlareModel::spencer},
                          {GlareModel::none, GlareModel::cie},
                          {GlareModel::wave_optics, std::nullopt}};
    const double d = 1000.0, x = std::tan(1.5 * std::numbers::pi / 180.0);
    for (const Case& k : cases) {
        Scene scene = black_scene(k.eye);
        Light a = light_at(glm::dvec3(-x, 0.003, -1.0) * d, 100.0);
        a.name = "a";
        a.glare = k.a;
        Light b = light_at(glm::dvec3(x, 0.003, -1.0) * d, 40.0);
        b.name = "b";
        b.glare = GlareModel::none;
        const GlareModel a_model = light_glare_model(scene, a);
        const std::string name = fmt::format("a {} (eye {})", glare_model_name(a_model), glare_model_name(k.eye));
        const double e_a = 100.0 / glm::dot(a.position_m, a.position_m);
        const double e_b = 40.0 / glm::dot(b.position_m, b.position_m);
        const double f = 2880.0;

        auto frame = [&](double a_cd, double b_cd, double& kept_a) {
            scene.lights = {a, b};
            scene.lights[0].intensity_cd = a_cd;
            scene.lights[1].intensity_cd = b_cd;
            renderer->render(scene, 0.0);
            const VeilReport& v = renderer->veil_report();
            EXPECT_EQ(v.applied, light_glare_model(scene, scene.lights[0]) == GlareModel::cie) << name;
            kept_a = v.applied ? luminance_of_linear_rgb(glm::dvec3(1.0) - v.outside_frame) : 1.0;
            return renderer->read_hdr();
        };
        double kept_a = 1, kept_none = 1, kept_both = 1;
        const ImageRGBA32F only_a = frame(100.0, 0.0, kept_a);
        const ImageRGBA32F only_b = frame(0.0, 40.0, kept_none);
        const ImageRGBA32F both = frame(100.0, 40.0, kept_both);
        const double got_a = image_illuminance_lux(only_a, f), got_b = image_illuminance_lux(only_b, f);
        const double got_both = image_illuminance_lux(both, f);
        std::printf("%-34s a: Σ L·Ω / E %.6f (kept %.4f), b: %.6f, both: %.6f\n", name.c_str(), got_a / e_a, kept_a,
                    got_b / e_b, got_both / (e_a * kept_a + e_b));
        EXPECT_NEAR(got_a / (e_a * kept_a), 1.0, 1e-3) << name;
        EXPECT_NEAR(got_b / e_b, 1.0, 1e-3) << name;
        EXPECT_NEAR(got_both / (e_a * kept_a + e_b), 1.0, 1e-3) << name;
        EXPECT_NEAR(kept_both, kept_a, 1e-9) << name << ": the veil is a's alone";
        // a's model is really applied: a alone differs from a drawn without glare.
        {
            const std::optional<GlareModel> own = a.glare;
            a.glare = GlareModel::none;
            double unused = 1;
            const ImageRGBA32F plain_a = frame(100.0, 0.0, unused);
            a.glare = own;
            float plain_peak = 0.0f, glare_peak = 0.0f;
            for (std::size_t i = 0; i < plain_a.rgba.size(); ++i)
                if (i % 4 != 3) {
                    plain_peak = std::max(plain_peak, plain_a.rgba[i]);
                    glare_peak = std::max(glare_peak, only_a.rgba[i]);
                }
            EXPECT_LT(glare_peak, 0.9f * plain_peak) << name << ": a's glare spreads its light";
        }

        // The frame is the sum of the two lights' frames, pixel by pixel (RGB; alpha is not light).
        float peak = 0.0f;
        double worst = 0.0;
        for (std::size_t i = 0; i < both.rgba.size(); ++i) {
            if (i % 4 == 3) continue;
            peak = std::max(peak, both.rgba[i]);
            worst = std::max(worst, std::abs(double(both.rgba[i]) - double(only_a.rgba[i]) - double(only_b.rgba[i])));
        }
        EXPECT_LE(worst, 1e-5 * peak) << name;
        // Around b (its centre ± 12 px): b's direct image and a's spill, which a
        // billboard 1° wide does not have there; b's pixels are b's own.
        const int bx = 160 + static_cast<int>(std::lround(f * x)), by = 120;
        double b_sum = 0.0, a_spill = 0.0;
        for (int yy = by - 12; yy <= by + 12; ++yy)
            for (int xx = bx - 12; xx <= bx + 12; ++xx) {
                b_sum += luminance_of_linear_rgb(
                    {only_b.pixel(xx, yy)[0], only_b.pixel(xx, yy)[1], only_b.pixel(xx, yy)[2]});
                a_spill += luminance_of_linear_rgb(
                    {only_a.pixel(xx, yy)[0], only_a.pixel(xx, yy)[1], only_a.pixel(xx, yy)[2]});
                if (glare_path(a_model) == GlarePath::billboard) {
                    for (int c = 0; c < 3; ++c) {
                        EXPECT_EQ(both.pixel(xx, yy)[c], only_b.pixel(xx, yy)[c]) << name;
                    }
                }
            }
        EXPECT_GT(b_sum, 0.0) << name << ": b is drawn within ±12 px of its centre";
        if (a_model == GlareModel::cie) {
            EXPECT_GT(a_spill, 0.0) << name << ": the veil reaches b";
        }
        if (glare_path(a_model) == GlarePath::billboard) {
            EXPECT_EQ(a_spill, 0.0) << name;
        }
    }
}

TEST_F(GlareFrames, LdrPathTakesTheGlareOfTheGlareLightsOnly) {
    // K2012 §6.2.2 with lights of their own models: every direct image in the
    // HDR frame, and in the glare buffer only the glare of the light that has a
    // model (a), none of b's.
    const double d = 1000.0, x = std::tan(1.5 * std::numbers::pi / 180.0), f = 2880.0;
    Scene scene = black_scene(GlareModel::none);
    scene.output.ldr_glare = true;
    Light a = light_at(glm::dvec3(-x, 0.003, -1.0) * d, 100.0);
    a.glare = GlareModel::gaussian_bloom;
    Light b = light_at(glm::dvec3(x, 0.003, -1.0) * d, 40.0);
    scene.lights = {a, b};
    const double e_a = 100.0 / glm::dot(a.position_m, a.position_m);
    const double e_b = 40.0 / glm::dot(b.position_m, b.position_m);
    renderer->render(scene, 0.0);
    const double direct = image_illuminance_lux(renderer->read_hdr(), f);
    ASSERT_NE(renderer->glare_texture(), nullptr);
    ImageRGBA32F glare;
    glare.width = renderer->glare_texture()->width();
    glare.height = renderer->glare_texture()->height();
    glare.rgba = renderer->glare_texture()->download_floats();  // rows bottom-up: Σ L·Ω is the same
    const double glare_lux = image_illuminance_lux(glare, f);
    std::printf("ldr path: HDR Σ L·Ω / (E_a + E_b) %.6f, glare buffer / E_a %.6f\n", direct / (e_a + e_b),
                glare_lux / e_a);
    EXPECT_NEAR(direct / (e_a + e_b), 1.0, 1e-3);
    EXPECT_NEAR(glare_lux / e_a, 1.0, 1e-3);
}

TEST_F(GlareFrames, CieVeilOfOneLightIsTheCieGlareSpreadFunctionAndKeepsItsEnergy) {
    // 261×121 px at 12 px per degree (±10.9° × ±5°); a 10⁴ cd light 1 km straight
    // ahead (E = 0.01 lx) lands in the centre pixel. L/E at 1°, 3° and 10° to the
    // right is the CIE glare spread function of Vos & van den Berg (CIE 135/1-1999;
    // age 25, p = 0.5), written out here independently of cie_glare.cpp.
    const double kDeg = std::numbers::pi / 180.0;
    const double f = 12.0 / kDeg;
    Scene scene = black_scene(GlareModel::cie);
    scene.display = {261, 121, 0.9 * 261 / f, 0.9};
    scene.lights = {light_at({0.0, 0.0, -1000.0}, 1e4, 0.01)};
    const double e_lux = 1e4 / 1e6;
    renderer->render(scene, 0.0);
    ASSERT_NEAR(renderer->projection().focal_px, f, 1e-6 * f);
    const ImageRGBA32F img = renderer->read_hdr();
    const double a = std::pow(25.0 / 70.0, 4), p = 0.5;
    auto cie = [&](double t) {
        const double x1 = 1 + std::pow(t / 0.0046, 2), x2 = 1 + std::pow(t / 0.045, 2), x3 = 1 + std::pow(t / 0.1, 2);
        return (1 - 0.08 * a) * (9.2e6 / std::pow(x1, 1.5) + 1.5e5 / std::pow(x2, 1.5)) +
               (1 + 1.6 * a) * (400 / x3 + 3e-8 * t * t + p * (1300 / std::pow(x3, 1.5) + 0.8 / std::sqrt(x3))) +
               2.5e-3 * p;
    };
    const int ci = 130, cj = 60;
    for (int dx : {12, 36, 120}) {
        const double theta = std::atan(dx / f) / kDeg;
        const float* px = img.pixel(ci + dx, cj);
        const double y = luminance_of_linear_rgb({px[0], px[1], px[2]});
        std::printf("cie veil at %.3f°: L/E %.6g sr⁻¹, equation %.6g, ratio %.5f\n", theta, y / e_lux, cie(theta),
                    y / e_lux / cie(theta));
        EXPECT_NEAR(y / e_lux / cie(theta), 1.0, 0.01) << theta << "°";
    }
    const VeilReport& v = renderer->veil_report();
    ASSERT_TRUE(v.applied);
    const double kept = image_illuminance_lux(img, f) / e_lux;
    std::printf("cie: frame holds %.6f of E, reported outside %.6f\n", kept, v.outside_frame.g);
    EXPECT_NEAR(kept, 1.0 - v.outside_frame.g, 1e-3);
    EXPECT_GT(v.outside_frame.g, 0.05);  // the veil reaches far beyond ±5°
    EXPECT_LT(v.outside_frame.g, 0.5);
}

TEST_F(GlareFrames, HiddenLightsEmitNothing) {
    Scene scene = black_scene(GlareModel::wave_optics);
    scene.camera.position_m = {0, 3, 0};
    scene.environment.background = Background::sky_sea;
    scene.environment.luminance_cd_m2 = 1.0;
    renderer->render(scene, 0.0);
    const ImageRGBA32F background = renderer->read_hdr();

    // Below the sea surface, in view: the sea hides it (occlusion by linear depth).
    scene.lights = {light_at({0.0, -5.0, -1000.0}, 1e5)};
    renderer->render(scene, 0.0);
    EXPECT_TRUE(renderer->read_hdr().rgba == background.rgba) << "occluded light";
    // Behind the camera.
    scene.lights = {light_at({0.0, 3.0, 50.0}, 1e5)};
    renderer->render(scene, 0.0);
    EXPECT_TRUE(renderer->read_hdr().rgba == background.rgba) << "light behind the camera";
    // Outside its sector: lit only over bearings 200..300°, and the observer is due south of it.
    Light sectored = light_at({0.0, 3.0, -500.0}, 1e5);
    const Sector sector{200.0, 300.0, 1.0, 0.0};
    scene.profiles.horizontal.push_back(HorizontalProfile::from_sectors(std::span<const Sector>(&sector, 1)));
    sectored.horizontal_profile = static_cast<int>(scene.profiles.horizontal.size()) - 1;
    scene.lights = {sectored};
    renderer->render(scene, 0.0);
    EXPECT_TRUE(renderer->read_hdr().rgba == background.rgba) << "light outside its sector";
    EXPECT_EQ(renderer->stats().drawn, 0);
}

TEST_F(GlareFrames, GlareOfALightJustOffTheImageReachesIn) {
    // Centre 5 px beyond the right edge: its direct image is culled, its glare is not.
    Scene scene = black_scene(GlareModel::gaussian_bloom);
    const double f = 2880.0, x_px = 160.0 + 5.0;
    scene.lights = {light_at({x_px / f * 1000.0, 0.0, -1000.0}, 1e4)};
    const double got = energy(scene);
    const double e = 1e4 / glm::dot(scene.lights[0].position_m, scene.lights[0].position_m);
    EXPECT_GT(got, 0.1 * e);
    EXPECT_LT(got, 0.6 * e);
    scene.glare.model = GlareModel::none;
    EXPECT_EQ(energy(scene), 0.0);
}

}  // namespace
}  // namespace atonlab::test
