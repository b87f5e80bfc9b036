// The `wave-optics` glare model on the GPU (stimuli/src/glare_models/wave_optics/).
// Its anchored spectral path (GpuPsfGenerator::generate_anchored,
// psf_anchored.comp) held to the CPU's spectral_psf_anchored (anchors in
// double by FFTW, samples summed in fp32) on this GL driver (issue 27 item 1:
// relative L2 ≤ 1e-5), with the GPU's fp32 FFT forced even on llvmpipe; and
// its eyes in a frame: the focused eye's core on the light, the k2012 preset's
// ring, the light's energy kept. Without GL: tests/unit/glare_models/wave_optics.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <future>
#include <stdexcept>
#include <utility>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/psf_generator.h"
#include "atonlab/stimuli/spectral_path.h"
#include "gl_test_support.h"
#include "glare_frames.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using PsfAnchoredGpu = GLTest;

constexpr double kBound = 1e-5;  // issue 27 item 1

struct Compared {
    double relative_l2 = 0, luminance_sum = 0;
};

Compared compare(const EyeModel& eye, int n, const display::Spectrum& spd, double time_s = 0.0,
                 ComputePlacement fft = ComputePlacement::gpu) {
    const GlareSettings defaults;
    const SpectralSamples samples = spectral_samples(spd, defaults.spectral_samples);
    GpuPsfGenerator gen(n, TwiddleSource::table_from_double, fft);
    gen.generate_anchored(eye, samples, defaults.spectral_anchors, time_s);
    const RgbPsf gpu = gen.read_rgb();
    const RgbPsf cpu = spectral_psf_anchored(eye, n, samples, defaults.spectral_anchors, time_s);
    EXPECT_EQ(gpu.n, cpu.n);
    EXPECT_DOUBLE_EQ(gpu.degrees_per_texel, cpu.degrees_per_texel);
    return {stimuli::relative_l2(gpu, cpu), gpu.luminance_sum()};
}

TEST_F(PsfAnchoredGpu, TheDefaultEyesTwoScalesMatchTheCpuPath) {
    // The default eye: two scales (core at its physical scale, scatter
    // stretched to the 4° halo), gratings, lens and vitreous particles.
    EyeModel eye;
    eye.pupil_diameter_mm = 6.0;
    ASSERT_TRUE(has_two_scales(eye));
    for (int n : {64, 256}) {
        const Compared c = compare(eye, n, display::d65_spectrum());
        std::printf("default eye, D65, n = %d: GPU vs CPU relative L2 %.3g\n", n, c.relative_l2);
        EXPECT_LT(c.relative_l2, kBound) << "n = " << n;
        EXPECT_NEAR(c.luminance_sum, 1.0, 1e-6);
    }
}

TEST_F(PsfAnchoredGpu, ARedAndAGreenSignalLightAtANightPupilMatchTheCpuPath) {
    // Narrow spectra put most samples in the faint tails (one or two anchors)
    // and the anchors close together; a 7 mm night pupil.
    EyeModel eye;
    eye.pupil_diameter_mm = 7.0;
    for (const auto& [name, spd] : {std::pair{"red", display::gaussian_spectrum(630.0, 20.0)},
                                    std::pair{"green", display::gaussian_spectrum(520.0, 30.0)}}) {
        const Compared c = compare(eye, 128, spd);
        std::printf("default eye, %s light, 7 mm: GPU vs CPU relative L2 %.3g\n", name, c.relative_l2);
        EXPECT_LT(c.relative_l2, kBound) << name;
        EXPECT_NEAR(c.luminance_sum, 1.0, 1e-6);
    }
}

TEST_F(PsfAnchoredGpu, AOneScaleEyeWithDefocusAndHippusMatchesTheCpuPath) {
    // K2012's single-scale eye (one field per anchor, no binning), defocused,
    // with hippus at t = 3.7 s: the pupil planes are the CPU's either way.
    EyeModel eye = EyeModel::k2012();
    eye.pupil_diameter_mm = 5.0;
    eye.hippus.enabled = true;
    ASSERT_FALSE(has_two_scales(eye));
    const Compared c = compare(eye, 128, display::d65_spectrum(), 3.7);
    std::printf("k2012 eye, hippus at 3.7 s: GPU vs CPU relative L2 %.3g\n", c.relative_l2);
    EXPECT_LT(c.relative_l2, kBound);
}

TEST_F(PsfAnchoredGpu, TheCpuPlacedTransformGivesTheSamePsf) {
    // FFTW double on the CPU, then the same shaders: the binning and the
    // spectral sum alone against the CPU's.
    EyeModel eye;
    eye.pupil_diameter_mm = 6.0;
    const Compared c = compare(eye, 64, display::d65_spectrum(), 0.0, ComputePlacement::cpu);
    EXPECT_LT(c.relative_l2, kBound);
}

TEST_F(PsfAnchoredGpu, AFrameRendererPlacedOnTheGpuBuildsTheCpusKernelAndSaysSo) {
    // The glare stage's billboard kernel of a default-eye light, placement
    // "gpu" against "cpu": the same kernel within the PSF's bound, and the
    // record names where the PSF was built.
    Scene s;
    s.display = {320, 240, 0.1, 0.9};
    s.environment.luminance_cd_m2 = 0.001;
    s.glare.model = GlareModel::wave_optics;
    s.glare.psf_size = 64;
    s.glare.pupil_mm = 6.0;
    Light L;
    L.position_m = {0, 0, -1000};
    L.intensity_cd = 10.0;
    s.lights = {L};
    RgbPsf psf[2];
    GlareKernel kernel[2];
    for (int i = 0; i < 2; ++i) {
        s.glare.placement = i == 0 ? ComputePlacement::cpu : ComputePlacement::gpu;
        FrameRenderer r;
        r.render(s, 0.0);
        ASSERT_NE(r.glare().psf(0), nullptr);
        psf[i] = *r.glare().psf(0);
        kernel[i] = *r.glare().kernel(0);
        ASSERT_EQ(r.glare().report().size(), 1u);
        EXPECT_EQ(r.glare().report()[0].psf_fft, s.glare.placement);
        EXPECT_EQ(frame_placements(s, 320, 240).psf_fft, s.glare.placement);
    }
    EXPECT_LT(stimuli::relative_l2(psf[1], psf[0]), kBound);
    ASSERT_EQ(kernel[0].size, kernel[1].size);
    double num = 0, den = 0;
    for (std::size_t i = 0; i < kernel[0].rgba.size(); ++i) {
        const glm::dvec4 d = glm::dvec4(kernel[1].rgba[i]) - glm::dvec4(kernel[0].rgba[i]);
        num += glm::dot(d, d);
        den += glm::dot(glm::dvec4(kernel[0].rgba[i]), glm::dvec4(kernel[0].rgba[i]));
    }
    EXPECT_LT(std::sqrt(num / den), kBound);
}

TEST_F(PsfAnchoredGpu, PupilPlanesDrawnAheadOnAWorkerGiveTheSameKernelBitForBit) {
    // A moving pupil's next grid pupil (pupil_kernel_cache.h): the model's
    // work without GL (work_ahead: the pupil planes) runs on another thread,
    // and the build handed its result must be the build without it.
    Scene s;
    s.glare.model = GlareModel::wave_optics;
    s.glare.psf_size = 64;
    s.glare.placement = ComputePlacement::gpu;
    const SpectralSamples samples = spectral_samples(display::d65_spectrum(), s.glare.spectral_samples);
    GpuPsfGenerator gen(64, TwiddleSource::table_from_double, ComputePlacement::gpu);
    auto gpu = [&](int) -> GpuPsfGenerator& { return gen; };
    const GlareModelType& type = glare_model_type(GlareModel::wave_optics);
    const GlareKernelRequest request{s.glare, s, samples, 20.0, 5.35, 1.5, gpu};
    GlareKernelAheadJob job = type.work_ahead(request);
    ASSERT_TRUE(job) << "the GPU placement's pupil planes are work a worker can do";
    std::future<std::shared_ptr<const GlareKernelAhead>> drawn = std::async(std::launch::async, job);
    const GlareModelKernel without = type.billboard_kernel(request);
    GlareKernelRequest with_request = request;
    const std::shared_ptr<const GlareKernelAhead> ahead = drawn.get();
    ASSERT_NE(ahead, nullptr);
    with_request.ahead = ahead.get();
    const GlareModelKernel with = type.billboard_kernel(with_request);
    ASSERT_EQ(with.kernel.size, without.kernel.size);
    EXPECT_EQ(with.kernel.rgba, without.kernel.rgba);
    ASSERT_TRUE(with.psf && without.psf);
    EXPECT_EQ(stimuli::relative_l2(*with.psf, *without.psf), 0.0);

    // Planes drawn for another size are refused, not transformed.
    EyeModel eye = s.glare.eye;
    eye.pupil_diameter_mm = 5.35;
    const AnchoredPupilPlanes small = anchored_pupil_planes(eye, 32, samples, s.glare.spectral_anchors);
    EXPECT_THROW(gen.generate_anchored(eye, samples, s.glare.spectral_anchors, 0.0, &small), std::invalid_argument);
    // Spectra made for a generator whose FFT runs on the CPU are not this generator's fields.
    const AnchoredPupilPlanes spectra =
        anchored_pupil_planes(eye, 64, samples, s.glare.spectral_anchors, 0.0, ComputePlacement::cpu);
    EXPECT_THROW(gen.generate_anchored(eye, samples, s.glare.spectral_anchors, 0.0, &spectra), std::invalid_argument);
    // A worker has no GL context to resolve automatic by.
    EXPECT_THROW(anchored_pupil_planes(eye, 64, samples, s.glare.spectral_anchors, 0.0, ComputePlacement::automatic),
                 std::invalid_argument);
    // On the CPU placement there is nothing to do ahead: its build keeps the cores busy in the frame.
    s.glare.placement = ComputePlacement::cpu;
    EXPECT_FALSE(type.work_ahead({s.glare, s, samples, 20.0, 5.35, 1.5, gpu}));
}

// ---- In a frame ----------------------------------------------------------------------

TEST_F(GlareFrames, FocusedEyePeaksAtTheLightAndBothEyesKeepItsEnergy) {
    // One 100 cd light at 1 km, the 6.89 mm pupil of 0.001 cd/m² (eq 3.15).
    // The default two-scale eye draws its core where the light is: the
    // frame's brightest pixel is the light's own (the no-glare frame's). The
    // k2012 preset's core, two waves out of focus (0.2 D) and stretched with
    // the halo (blur radius 6.89 mm · 0.2 D / 2 × 10.2 = 0.40°, ~20 px), is a
    // ring around a dark centre (at an odd number of half waves, 6 mm, the
    // centre would be bright again). Both frames hold the light's illuminance
    // within 1% (the window's cut is renormalised).
    Scene scene = black_scene(GlareModel::none);
    scene.glare.pupil_mm = pupil_diameter_mm_from_adaptation(0.001);
    scene.lights = {light_at(glm::dvec3(0.013, -0.007, -1.0) * 1000.0)};
    const double direct = energy(scene);
    const ImageRGBA32F no_glare = renderer->read_hdr();
    auto brightest = [](const ImageRGBA32F& img) {
        std::pair<int, int> best{0, 0};
        float v = -1;
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x)
                if (img.pixel(x, y)[1] > v) {
                    v = img.pixel(x, y)[1];
                    best = {x, y};
                }
        return best;
    };
    const auto light_pixel = brightest(no_glare);
    scene.glare.model = GlareModel::wave_optics;
    for (const EyeModel& eye : {EyeModel{}, EyeModel::k2012()}) {
        scene.glare.eye = eye;
        // The preset draws with the thesis's spectral method (scene_file.cpp, eye_preset).
        scene.glare.spectral_path = eye.scale == EyeScale::two_scales ? SpectralPath::anchored : SpectralPath::rescaled;
        const double with_glare = energy(scene);
        const ImageRGBA32F img = renderer->read_hdr();
        const auto peak = brightest(img);
        const float centre = img.pixel(light_pixel.first, light_pixel.second)[1];
        const float top = img.pixel(peak.first, peak.second)[1];
        const bool focused = eye.scale == EyeScale::two_scales;
        std::printf("%s eye: energy ratio %.5f, brightest pixel (%d, %d), light's pixel (%d, %d), centre / max %.3f\n",
                    focused ? "focused" : "k2012", with_glare / direct, peak.first, peak.second, light_pixel.first,
                    light_pixel.second, centre / top);
        EXPECT_NEAR(with_glare / direct, 1.0, 0.01);
        if (focused) {
            EXPECT_EQ(peak, light_pixel);
        } else {
            EXPECT_LT(centre / top, 0.5);
        }
    }
}

}  // namespace
}  // namespace atonlab::test
