// What the renderer leaves out (docs/bench.md "Skips"), each against the frame
// it would have drawn without the skip:
//  - display skips (frame_renderer.h DisplaySkips): lights too dim to move a
//    code, and billboard tails below the bound. The stated error: no channel of
//    any pixel's code (before dither) moves by more than threshold_codes per
//    skipped light, checked here through the CPU double references of the tone
//    mapper and the display model, on scenes whose lights do not overlap;
//  - exact culls (frustum, occlusion, sector, rhythm): bit-identical frames;
//  - caches (PSF per pupil step, spectral integration per SPD, area layers
//    only for lights that need them) and stages switched off: build counts.
// No timing here: the bench (`atonlab bench`, GL.bench.quick) measures it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>

#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/display_threshold.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/pipeline.h"
#include "atonlab/stimuli/profile.h"
#include "atonlab/stimuli/psf_generator.h"
#include "atonlab/stimuli/rhythm.h"
#include "atonlab/display/colour.h"
#include "atonlab/display/tonemap.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

// 320×240 px at f = 576 px (10 px per degree): a grid of lights 32 px apart
// whose 1° billboards (21 px) never overlap.
constexpr int kW = 320, kH = 240, kStep = 32;

Scene grid_scene(GlareModel model) {
    Scene s;
    s.display = {kW, kH, 0.5, 0.9};
    s.camera.position_m = {0, 0, 0};
    s.environment.background = Background::uniform;
    s.environment.luminance_cd_m2 = 0.01;
    s.adaptation_cd_m2 = 0.01;
    s.output.encode.dither = Dither::none;
    s.glare.model = model;
    s.glare.values["bloom_sigma_deg"] = 0.3;
    s.glare.radius_deg = 1.0;
    s.glare.psf_size = 128;
    s.glare.pupil_mm = 5.0;
    s.glare.eye.gratings.enabled = false;
    s.glare.eye.halo_radius_deg.reset();
    s.glare.eye.defocus_diopters = 0.0;
    s.glare.spectral_samples = 8;
    // Intensities log-spaced over 10 decades at 100 m: the dim end cannot move a
    // code, the bright end lights hundreds of pixels.
    const double f = s.display.focal_px();
    int i = 0;
    const int cols = kW / kStep, rows = kH / kStep;
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c, ++i) {
            const double x = (c + 0.5) * kStep - 0.5 * kW + 0.3, y = (r + 0.5) * kStep - 0.5 * kH - 0.2;
            Light L;
            L.position_m = glm::dvec3(x / f, y / f, -1.0) * 100.0;
            L.intensity_cd = std::pow(10.0, -7.0 + 10.0 * i / (rows * cols - 1));
            L.radius_m = 0.01;
            s.lights.push_back(L);
        }
    return s;
}

struct Frame {
    ImageRGBA32F hdr;
    FrameStats stats;
    std::vector<LightDrawRecord> draws;
};

Frame render(FrameRenderer& r, const Scene& s, const DisplaySkips& skips) {
    FrameOptions o;
    o.skips = skips;
    r.set_options(o);
    r.render(s, 0.0);
    return {r.read_hdr(), r.stats(), r.read_light_draws()};
}

/// The largest change of any channel's continuous code (before dither) between
/// two HDR frames, through the CPU double tone mapper and display model of the scene.
double worst_code_change(const ImageRGBA32F& a, const ImageRGBA32F& b, const Scene& scene) {
    const OutputSettings& out = scene.output;
    double worst = 0;
    for (std::size_t i = 0; i < a.rgba.size(); i += 4) {
        const glm::dvec3 pa{a.rgba[i], a.rgba[i + 1], a.rgba[i + 2]}, pb{b.rgba[i], b.rgba[i + 1], b.rgba[i + 2]};
        if (pa == pb && a.rgba[i + 3] == b.rgba[i + 3]) continue;
        const double L = scene.adaptation_cd_m2;
        // The alpha is the frame's scotopic channel, what the GPU's rods read (docs/tone-mapping.md).
        const glm::dvec3 ca =
            continuous_codes(out.display, tonemap_pixel(pa, a.rgba[i + 3], L, out.tonemap), out.encode.bits);
        const glm::dvec3 cb =
            continuous_codes(out.display, tonemap_pixel(pb, b.rgba[i + 3], L, out.tonemap), out.encode.bits);
        const glm::dvec3 d = glm::abs(ca - cb);
        worst = std::max({worst, d.r, d.g, d.b});
    }
    return worst;
}

using Skips = GLTest;

DisplaySkips both(double threshold = 0.25) {
    return {true, true, threshold};
}

TEST_F(Skips, InvisibleLightsAreCulledWithinTheStatedBound) {
    for (GlareModel model : {GlareModel::none, GlareModel::gaussian_bloom, GlareModel::wave_optics}) {
        FrameRenderer r;
        const Scene scene = grid_scene(model);
        const Frame exact = render(r, scene, {});
        const Frame culled = render(r, scene, {true, false, 0.25});
        const double change = worst_code_change(exact.hdr, culled.hdr, scene);
        std::printf("%-14s: %d of %d lights drawn with the cull (%d without); worst code change %.4f (bound 0.25)\n",
                    std::string(glare_model_name(model)).c_str(), culled.stats.drawn, culled.stats.lights,
                    exact.stats.drawn, change);
        EXPECT_LT(culled.stats.drawn, exact.stats.drawn) << "the dim end must be culled";
        EXPECT_GT(culled.stats.drawn, 0);
        // Lights never overlap here, so one skipped light per pixel at most; 1e-3
        // codes allow for fp32 blending.
        EXPECT_LE(change, 0.25 + 1e-3) << glare_model_name(model);
        // A culled light's brightest pixel: E_Y times the kernel's peak (glare)
        // or E_Y / max(A, 1) (direct image), per unit solid angle.
        const double peak = model == GlareModel::none ? 1.0 : r.glare().report()[0].kernel_peak;
        for (std::size_t i = 0; i < culled.draws.size(); ++i)
            if (exact.draws[i].area_px2 > 0 && culled.draws[i].area_px2 == 0) {
                EXPECT_GT(culled.draws[i].invisible_lux, 0.0);
                EXPECT_LT(luminance_of_linear_rgb(culled.draws[i].illuminance_rgb_lux) * peak,
                          culled.draws[i].invisible_lux * (1 + 1e-6))
                    << "light " << i << " was culled although brighter than its bound";
            }
    }
}

// A light whose rods see more than its drawn colour tells them: IALA green's die (S/P 5.38) drawn
// with the display's green primary (whose RGB weights give 1.80). Under the perceptual operator at
// night and under cie191, the rods weigh most, so the bound must use the light's own S/P, as the
// frame's scotopic channel does; with the colour's RGB weights it would cull lights that move a
// code by up to about three times the bound.
TEST_F(Skips, InvisibleGreenLightsAreCulledWithinTheBoundWhereTheRodsWeighMost) {
    for (const MesopicModel mesopic : {MesopicModel::k2012, MesopicModel::cie191}) {
        FrameRenderer r;
        Scene scene = grid_scene(GlareModel::none);
        scene.output.tonemap.tone_operator = ToneOperator::perceptual;
        scene.output.tonemap.mesopic = mesopic;
        for (Light& L : scene.lights) {
            L.rgb_per_cd = *iala_colour_rgb("green");
            L.spd = *iala_colour_spectrum_name("green");
        }
        const Frame exact = render(r, scene, {});
        const Frame culled = render(r, scene, {true, false, 0.25});
        const double change = worst_code_change(exact.hdr, culled.hdr, scene);
        std::printf("green, perceptual %s: %d of %d lights drawn with the cull; worst code change %.4f (bound 0.25)\n",
                    std::string(mesopic_model_name(mesopic)).c_str(), culled.stats.drawn, culled.stats.lights, change);
        EXPECT_LT(culled.stats.drawn, exact.stats.drawn) << "the dim end must be culled";
        EXPECT_LE(change, 0.25 + 1e-3) << mesopic_model_name(mesopic);
    }
}

TEST_F(Skips, CroppedBillboardsStayWithinTheStatedBound) {
    for (GlareModel model : {GlareModel::gaussian_bloom, GlareModel::wave_optics}) {
        FrameRenderer r;
        Scene scene = grid_scene(model);
        scene.glare.radius_deg = 1.4;  // 29 px billboards, 32 px apart: still apart
        const Frame exact = render(r, scene, {});
        const Frame cropped = render(r, scene, {false, true, 0.25});
        EXPECT_EQ(cropped.stats.drawn, exact.stats.drawn);
        int crops = 0;
        const double full = r.glare().kernel(0)->half() + 2.0;
        for (const auto& d : cropped.draws)
            if (d.area_px2 > 0 && d.crop_half_extent_px > 0 && d.crop_half_extent_px < full) ++crops;
        const double change = worst_code_change(exact.hdr, cropped.hdr, scene);
        std::printf("%-14s: %d of %d drawn billboards cropped; worst code change %.4f (bound 0.25)\n",
                    std::string(glare_model_name(model)).c_str(), crops, cropped.stats.drawn, change);
        EXPECT_GT(crops, 0);
        EXPECT_LE(change, 0.25 + 1e-3);
    }
}

TEST_F(Skips, BothSkipsTogetherOnASkyAndSeaBackground) {
    // The darkest background is the sea (f0 · sky): the bound is taken there.
    FrameRenderer r;
    Scene scene = grid_scene(GlareModel::gaussian_bloom);
    scene.environment.background = Background::sky_sea;
    scene.camera.position_m = {0, 3, 0};
    for (Light& L : scene.lights) L.position_m += glm::dvec3(0, 3, 0);
    // The lower rows are behind the sea: put the dim end in the sky.
    for (std::size_t i = 0; i < scene.lights.size() / 2; ++i)
        std::swap(scene.lights[i].intensity_cd, scene.lights[scene.lights.size() - 1 - i].intensity_cd);
    const Frame exact = render(r, scene, {});
    const Frame skipped = render(r, scene, both());
    const double change = worst_code_change(exact.hdr, skipped.hdr, scene);
    std::printf("sky-sea: %d of %d drawn with skips (%d without); worst code change %.4f\n", skipped.stats.drawn,
                skipped.stats.lights, exact.stats.drawn, change);
    EXPECT_LT(skipped.stats.drawn, exact.stats.drawn);
    EXPECT_LE(change, 0.25 + 1e-3);
}

TEST_F(Skips, SmallerThresholdSkipsLessAndStaysWithinItsBound) {
    FrameRenderer r;
    const Scene scene = grid_scene(GlareModel::gaussian_bloom);
    const Frame exact = render(r, scene, {});
    int previous = 0;
    for (double t : {1.0, 0.25, 1.0 / 16}) {
        const Frame f = render(r, scene, both(t));
        const double change = worst_code_change(exact.hdr, f.hdr, scene);
        std::printf("threshold %.4f codes: %d lights drawn, worst code change %.4f\n", t, f.stats.drawn, change);
        EXPECT_LE(change, t + 1e-3);
        EXPECT_GE(f.stats.drawn, previous);
        previous = f.stats.drawn;
    }
}

TEST_F(Skips, DisplaySkipsStayOffWhereTheAdaptationIsNotKnownBeforehand) {
    FrameRenderer r;
    Scene scene = grid_scene(GlareModel::gaussian_bloom);
    scene.output.adaptation.mode = AdaptationMode::dynamic;
    const Frame exact = render(r, scene, {});
    const Frame skipped = render(r, scene, both());
    EXPECT_TRUE(exact.hdr.rgba == skipped.hdr.rgba) << "dynamic adaptation: no display skip may apply";
    scene.output.adaptation.mode = AdaptationMode::fixed;
    scene.output.ldr_glare = true;
    EXPECT_TRUE(render(r, scene, {}).hdr.rgba == render(r, scene, both()).hdr.rgba) << "LDR glare path";
}

TEST_F(Skips, ThePipelineTurnsTheDisplaySkipsOnAndItsCodesAgree) {
    Scene scene = grid_scene(GlareModel::gaussian_bloom);
    Pipeline pipeline;
    EXPECT_TRUE(pipeline.frame().options().skips.cull_invisible_lights);
    EXPECT_TRUE(pipeline.frame().options().skips.crop_billboards);
    pipeline.render(scene, 0.0, 0.0);
    const EncodedImage skipped = pipeline.display().read_codes();
    const int drawn = pipeline.frame().stats().drawn;
    pipeline.set_frame_options({});
    pipeline.render(scene, 0.0, 0.0);
    const EncodedImage exact = pipeline.display().read_codes();
    ASSERT_EQ(skipped.rgb.size(), exact.rgb.size());
    int worst = 0;
    std::size_t changed = 0;
    for (std::size_t i = 0; i < exact.rgb.size(); ++i) {
        const int d = std::abs(static_cast<int>(exact.rgb[i]) - static_cast<int>(skipped.rgb[i]));
        worst = std::max(worst, d);
        changed += d > 0 ? 1 : 0;
    }
    std::printf("Pipeline: %d of %zu lights drawn; %zu of %zu code values differ, by at most %d\n", drawn,
                scene.lights.size(), changed, exact.rgb.size(), worst);
    EXPECT_LT(drawn, pipeline.frame().stats().drawn);
    // Rounding a continuous code that moved by ≤ 0.25 changes it by at most one.
    EXPECT_LE(worst, 1);
}

// ---- exact culls ---------------------------------------------------------------

TEST_F(Skips, DarkInItsRhythmOrOutsideItsSectorEmitsNothing) {
    FrameRenderer r;
    Scene scene = grid_scene(GlareModel::gaussian_bloom);
    scene.lights.resize(1);
    scene.lights[0].intensity_cd = 1e4;
    Scene empty = scene;
    empty.lights.clear();
    r.render(empty, 0.0);
    const ImageRGBA32F background = r.read_hdr();
    // Fl 10s: a 1 s flash at the start of each period; at t = 5 s it is dark.
    const Rhythm rhythm = parse_rhythm("Fl 10s");
    scene.lights[0].rhythm = rhythm.channels[0].knots;
    scene.lights[0].rhythm_period_s = rhythm.period_s;
    r.render(scene, 5.0);
    EXPECT_TRUE(r.read_hdr().rgba == background.rgba) << "dark in its rhythm";
    EXPECT_EQ(r.stats().drawn, 0);
    r.render(scene, 0.5);
    EXPECT_EQ(r.stats().drawn, 1) << "lit during its flash";
    // Lit only over bearings 200 … 300°; the eye looks at it from its bearing 180°.
    const Sector sector{200.0, 300.0, 1.0, 0.0};
    scene.profiles.horizontal.push_back(HorizontalProfile::from_sectors(std::span<const Sector>(&sector, 1)));
    scene.lights[0].horizontal_profile = static_cast<int>(scene.profiles.horizontal.size()) - 1;
    r.render(scene, 0.5);
    EXPECT_TRUE(r.read_hdr().rgba == background.rgba) << "outside its sector";
    EXPECT_EQ(r.stats().drawn, 0);
}

// ---- caches and stages switched off --------------------------------------------

TEST_F(Skips, PsfIsRebuiltOnlyWhenThePupilMovesBeyondItsTolerance) {
    FrameRenderer r;
    Scene scene = grid_scene(GlareModel::wave_optics);
    scene.lights.resize(3);
    scene.glare.pupil_tolerance_mm = 0.1;
    scene.glare.pupil_mm = 5.0;
    r.render(scene, 0.0);
    const int first = r.glare().build_counts().kernels;
    EXPECT_EQ(first, 1);
    const RgbPsf at_grid = *r.glare().psf(0);
    scene.glare.pupil_mm = 5.04;  // rounds to 5.0: the cached PSF
    r.render(scene, 0.0);
    EXPECT_EQ(r.glare().build_counts().kernels, first);
    EXPECT_DOUBLE_EQ(r.glare().report()[0].pupil_mm, 5.0);
    scene.glare.pupil_mm = 5.06;  // rounds to 5.1: rebuilt
    r.render(scene, 0.0);
    EXPECT_EQ(r.glare().build_counts().kernels, first + 1);
    EXPECT_DOUBLE_EQ(r.glare().report()[0].pupil_mm, 5.1);
    // The error the tolerance allows: the PSF of 5.0 mm against that of 5.04 mm
    // (a 0.8% change of scale), relative L2 over the PSF.
    scene.glare.pupil_tolerance_mm = 0.0;
    scene.glare.pupil_mm = 5.04;
    r.render(scene, 0.0);
    const double err = relative_l2(at_grid, *r.glare().psf(0));
    std::printf("PSF at 5.0 mm vs 5.04 mm (N = 128): relative L2 %.4f\n", err);
    EXPECT_GT(err, 0.0);
    EXPECT_LT(err, 0.1);
    // Tolerance 0: any change rebuilds; no change does not.
    const int before = r.glare().build_counts().kernels;
    r.render(scene, 0.0);
    EXPECT_EQ(r.glare().build_counts().kernels, before);
    scene.glare.pupil_mm = 5.0400001;
    r.render(scene, 0.0);
    EXPECT_EQ(r.glare().build_counts().kernels, before + 1);
}

TEST_F(Skips, HippusRebuildsThePsfOnlyAsOftenAsTheToleranceAllows) {
    FrameRenderer r;
    Scene scene = grid_scene(GlareModel::wave_optics);
    scene.lights.resize(1);
    scene.glare.eye.hippus.enabled = true;
    scene.glare.pupil_tolerance_mm = 0.0;
    for (int i = 0; i < 5; ++i) r.render(scene, 0.05 * i);
    const int exact = r.glare().build_counts().kernels;
    FrameRenderer tolerant;
    scene.glare.pupil_tolerance_mm = 0.5;  // wider than the hippus swing here
    for (int i = 0; i < 5; ++i) tolerant.render(scene, 0.05 * i);
    std::printf("hippus, 5 frames: %d PSF builds exact, %d with a 0.5 mm step\n", exact,
                tolerant.glare().build_counts().kernels);
    EXPECT_EQ(exact, 5);
    EXPECT_LT(tolerant.glare().build_counts().kernels, exact);
}

TEST_F(Skips, SpectralIntegrationRunsOncePerSpd) {
    FrameRenderer r;
    Scene scene = grid_scene(GlareModel::wave_optics);
    for (std::size_t i = 0; i < scene.lights.size(); ++i) scene.lights[i].spd = i % 2 ? "led-white" : "";
    r.render(scene, 0.0);
    EXPECT_EQ(r.glare().build_counts().kernels, 2) << "two SPDs, many lights";
    r.render(scene, 1.0);
    EXPECT_EQ(r.glare().build_counts().kernels, 2) << "nothing changed: nothing rebuilt";
}

TEST_F(Skips, AreaLayersAreBuiltOnlyForLightsThatNeedThem) {
    FrameRenderer r;
    Scene scene = grid_scene(GlareModel::gaussian_bloom);
    r.render(scene, 0.0);  // every light well below a pixel
    EXPECT_EQ(r.glare().report()[0].area_layers, 1);
    const int layers = r.glare().build_counts().layers;
    scene.lights[0].radius_m = 2.0;  // 11 px across at 100 m
    r.render(scene, 0.0);
    EXPECT_GT(r.glare().report()[0].area_layers, 1);
    EXPECT_EQ(r.glare().build_counts().layers, layers + 1);
    r.render(scene, 0.0);
    EXPECT_EQ(r.glare().build_counts().layers, layers + 1) << "the same need: the layers are reused";
}

TEST_F(Skips, StagesThatAreSwitchedOffDoNoWork) {
    FrameRenderer r;
    Scene scene = grid_scene(GlareModel::none);
    r.render(scene, 0.0);
    EXPECT_EQ(r.glare().build_counts().kernels, 0) << "no glare: no kernel";
    EXPECT_EQ(r.glare().build_counts().layers, 0);
    EXPECT_EQ(r.glare().envelope_stride(), 0u);
    EXPECT_EQ(r.glare_texture(), nullptr) << "no LDR glare path: no glare buffer";
    const FrameTimings t = r.timings();
    EXPECT_EQ(t.gpu_ms(), 0.0) << "timer queries only when asked for";
}

TEST_F(Skips, PsfWithItsFftOnTheCpuMatchesTheGpuFft) {
    // A software rasteriser transforms the pupil plane with FFTW (double,
    // rounded to float) instead of the fp32 compute shaders
    // (ComputePlacement::automatic): the PSFs agree to fp32 rounding.
    EyeModel eye = grid_scene(GlareModel::wave_optics).glare.eye;
    eye.pupil_diameter_mm = 5.0;
    const int n = 128;
    const SpectralSamples samples = spectral_samples(d65_spectrum(), 8);
    const auto field = pupil_plane(eye, n, kReferenceWavelengthNm, eye.plane_width_mm);
    GpuPsfGenerator gpu(n, TwiddleSource::table_from_double, ComputePlacement::gpu);
    GpuPsfGenerator cpu(n, TwiddleSource::table_from_double, ComputePlacement::cpu);
    EXPECT_EQ(gpu.fft_placement(), ComputePlacement::gpu);
    EXPECT_EQ(cpu.fft_placement(), ComputePlacement::cpu);
    gpu.generate(field, psf_degrees_per_texel(eye), samples);
    cpu.generate(field, psf_degrees_per_texel(eye), samples);
    const double err = relative_l2(cpu.read_rgb(), gpu.read_rgb());
    std::printf("PSF with the FFT on the CPU vs on the GPU: relative L2 %.3g\n", err);
    EXPECT_LT(err, 1e-5);
    const bool software = gl_context()->info().software;
    EXPECT_EQ(GpuPsfGenerator(n).fft_placement(), software ? ComputePlacement::cpu : ComputePlacement::gpu);
}

TEST_F(Skips, PreExposedHalfFloatTargetMatchesTheFloatTarget) {
    // Not a skip but the same kind of trade: RGBA16F with pre-exposure 1/L_a
    // stores every value with 11 significant bits (2^-11 relative) up to the
    // largest half float, 65504, i.e. 65504 / pre-exposure cd/m²; beyond it the
    // target saturates: at 65504 (llvmpipe) or +inf (the GL spec leaves the
    // overflow of a float16 conversion to the driver), never NaN.
    FrameRenderer r;
    const Scene scene = grid_scene(GlareModel::gaussian_bloom);
    r.render(scene, 0.0);
    const ImageRGBA32F full = r.read_hdr();
    FrameOptions o;
    o.hdr_format = HdrFormat::rgba16f;
    o.pre_exposure = 0.0;  // 1 / adaptation
    r.set_options(o);
    r.render(scene, 0.0);
    EXPECT_DOUBLE_EQ(r.pre_exposure(), 1.0 / scene.adaptation_cd_m2);
    const ImageRGBA32F half = r.read_hdr();
    const double ceiling = 65504.0 / r.pre_exposure();
    double worst = 0;
    int saturated = 0;
    for (std::size_t i = 0; i < full.rgba.size(); ++i) {
        if (i % 4 == 3) continue;
        ASSERT_FALSE(std::isnan(half.rgba[i]));
        if (full.rgba[i] < 0.5 * ceiling) {
            if (full.rgba[i] > 0) worst = std::max(worst, std::abs(half.rgba[i] / full.rgba[i] - 1.0));
        } else if (full.rgba[i] > ceiling) {
            EXPECT_TRUE(std::isinf(half.rgba[i]) || std::abs(half.rgba[i] - ceiling) <= 1e-6 * ceiling)
                << half.rgba[i] << " where RGBA32F holds " << full.rgba[i];
            ++saturated;
        }
    }
    std::printf("RGBA16F with pre-exposure vs RGBA32F: worst relative difference %.3g below %.0f cd/m2, %d values "
                "saturated above\n",
                worst, 0.5 * ceiling, saturated);
    // Blending adds several rounded values: a few half-float ulps (2^-11 each).
    EXPECT_LT(worst, 4.0 / 2048.0);
    EXPECT_GT(worst, 0.0);
    EXPECT_GT(saturated, 0) << "the brightest light's core exceeds the half-float range here";
}

}  // namespace
}  // namespace atonlab::test
