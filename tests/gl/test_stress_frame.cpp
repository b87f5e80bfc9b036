// Numerical stress tests of whole frames on the GPU (issue 8): the direct-light pass,
// the glare billboards and the embeddable Pipeline (adaptation, tone mapping, display
// codes) with lights at the singular points by name — at the camera position, exactly
// behind it, exactly beside it in its plane, inside their own sphere — and swept over
// 0.1 m … 50 km and 0 … 1e7 cd. Every pixel of the HDR frame (RGBA32F, cd/m²) must be
// finite and non-negative, every light record finite, every display code in range;
// where the light is fully in view, the energy rule Σ L·Ω = I·T/d² holds and the
// image's energy never grows with distance. docs/numerical-behaviour.md lists the
// singular points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/light_model.h"
#include "atonlab/stimuli/pipeline.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using namespace atonlab::display;

constexpr double kBackground = 0.01;  // cd/m², uniform: a changed pixel is easy to spot

// 160×120 px at f = 0.9·160/0.05 = 2880 px (about 50 px per degree): small and fast.
Scene stress_scene() {
    Scene s;
    s.display = {160, 120, 0.05, 0.9};
    s.camera.position_m = {5.0, 3.0, -7.0};
    s.environment.background = Background::uniform;
    s.environment.luminance_cd_m2 = kBackground;
    return s;
}

Light light_at(glm::dvec3 p, double intensity_cd, double radius_m) {
    Light L;
    L.position_m = p;
    L.intensity_cd = intensity_cd;
    L.radius_m = radius_m;
    return L;
}

// The camera's axes in the world (camera looks down its -z).
glm::dvec3 forward(const Scene& s) {
    return glm::mat3_cast(s.camera.orientation()) * glm::dvec3(0, 0, -1);
}
glm::dvec3 right(const Scene& s) {
    return glm::mat3_cast(s.camera.orientation()) * glm::dvec3(1, 0, 0);
}
glm::dvec3 up(const Scene& s) {
    return glm::mat3_cast(s.camera.orientation()) * glm::dvec3(0, 1, 0);
}

/// Number of non-finite or negative values in an HDR frame (RGB).
long bad_values(const ImageRGBA32F& img) {
    long bad = 0;
    for (std::size_t i = 0; i < img.rgba.size(); ++i) {
        if (i % 4 == 3) continue;
        const float v = img.rgba[i];
        bad += std::isfinite(v) && v >= 0.0f ? 0 : 1;
    }
    return bad;
}

bool record_finite(const LightDrawRecord& d) {
    const double v[] = {d.centre_px.x,
                        d.centre_px.y,
                        d.view_depth_m,
                        d.area_px2,
                        d.illuminance_rgb_lux.r,
                        d.illuminance_rgb_lux.g,
                        d.illuminance_rgb_lux.b,
                        d.distance_m,
                        d.vertical,
                        d.horizontal,
                        d.rhythm,
                        d.transmittance};
    return std::all_of(std::begin(v), std::end(v), [](double x) { return std::isfinite(x); });
}

class StressDirectLights : public RendererTest {
protected:
    /// Renders and checks the invariants every frame must keep; returns the frame.
    ImageRGBA32F render_checked(const Scene& scene, double time_s, const std::string& what) {
        renderer->render(scene, time_s);
        ImageRGBA32F img = renderer->read_hdr();
        EXPECT_EQ(bad_values(img), 0) << what << ": non-finite or negative HDR values";
        for (const LightDrawRecord& d : renderer->read_light_draws())
            EXPECT_TRUE(record_finite(d)) << what << ": a light record is not finite";
        return img;
    }
    /// True when the frame is the uniform background, pixel for pixel.
    static bool is_background(const ImageRGBA32F& img) {
        return std::all_of(img.rgba.begin(), img.rgba.end(), [i = std::size_t{0}](float v) mutable {
            return i++ % 4 == 3 || v == static_cast<float>(kBackground);
        });
    }
};

TEST_F(StressDirectLights, LightAtCameraPosition) {
    // d = 0: the light model returns zero illuminance (light_model.h), the renderer draws
    // nothing: the eye is inside the lantern, whose inverse-square law is singular.
    for (double yaw : {0.0, 90.0, 213.7}) {
        for (double radius : {1e-3, 0.1, 10.0}) {
            Scene scene = stress_scene();
            scene.camera.yaw_deg = yaw;
            scene.lights = {light_at(scene.camera.position_m, 1e7, radius)};
            const ImageRGBA32F img = render_checked(scene, 0.0, "light at the camera");
            EXPECT_TRUE(is_background(img)) << "yaw " << yaw << " radius " << radius;
            EXPECT_EQ(renderer->stats().drawn, 0);
            const LightDrawRecord d = renderer->read_light_draws().at(0);
            EXPECT_EQ(d.distance_m, 0.0);
            EXPECT_EQ(d.illuminance_rgb_lux, glm::dvec3(0.0));
        }
    }
}

TEST_F(StressDirectLights, LightExactlyBehindTheCamera) {
    // On the camera's backward axis, at every distance and for yaws whose rotation
    // matrices carry rounding residues (90°, 180°): not drawn, frame untouched.
    for (double yaw : {0.0, 90.0, 180.0, 270.0, 37.5}) {
        for (double d : {0.1, 1.0, 1000.0, 5e4}) {
            Scene scene = stress_scene();
            scene.camera.yaw_deg = yaw;
            scene.lights = {light_at(scene.camera.position_m - forward(scene) * d, 1e7, 0.01)};
            const ImageRGBA32F img = render_checked(scene, 0.0, "light behind the camera");
            EXPECT_TRUE(is_background(img)) << "yaw " << yaw << " d " << d;
            EXPECT_EQ(renderer->stats().drawn, 0) << "yaw " << yaw << " d " << d;
        }
    }
}

TEST_F(StressDirectLights, LightExactlyBesideTheCameraInItsPlane) {
    // 90° off the axis, in the camera's plane: a pinhole cannot image it. Rounding of the
    // camera's rotation may leave it a hair in front (view z ~ -1e-16 m): it must still
    // not be drawn as a disc whose projected centre and area run off to infinity.
    for (double yaw : {0.0, 90.0, 180.0, 270.0, 45.0, 123.4}) {
        for (double d : {0.5, 10.0, 5e4}) {
            for (int axis = 0; axis < 4; ++axis) {
                Scene scene = stress_scene();
                scene.camera.yaw_deg = yaw;
                const glm::dvec3 side = axis == 0   ? right(scene)
                                        : axis == 1 ? -right(scene)
                                        : axis == 2 ? up(scene)
                                                    : -up(scene);
                scene.lights = {light_at(scene.camera.position_m + side * d, 1e7, 0.01)};
                const ImageRGBA32F img = render_checked(scene, 0.0, "light beside the camera");
                EXPECT_TRUE(is_background(img)) << "yaw " << yaw << " d " << d << " axis " << axis;
                EXPECT_EQ(renderer->stats().drawn, 0) << "yaw " << yaw << " d " << d << " axis " << axis;
            }
        }
    }
}

TEST_F(StressDirectLights, EyeInsideTheLightSphere) {
    // d <= radius (documented: not drawn) and just outside it.
    Scene scene = stress_scene();
    scene.lights = {light_at(scene.camera.position_m + forward(scene) * 0.1, 1e7, 0.1),
                    light_at(scene.camera.position_m + forward(scene) * 0.05, 1e7, 0.1)};
    const ImageRGBA32F img = render_checked(scene, 0.0, "eye inside the light");
    EXPECT_TRUE(is_background(img));
    EXPECT_EQ(renderer->stats().drawn, 0);
}

TEST_F(StressDirectLights, DistanceSweepFromTenCentimetresToFiftyKilometres) {
    // A 1 mm lantern (a 29 px disc at 0.1 m, 6e-5 px² at 50 km) slightly off-axis, at
    // 0 … 1e7 cd: finite frames, the energy rule, and energy non-increasing in distance.
    Scene scene = stress_scene();
    scene.environment.luminance_cd_m2 = 0.0;
    const double focal = CameraProjection::from_scene(scene).focal_px;
    const glm::dvec3 dir = glm::normalize(forward(scene) + 0.004 * right(scene) - 0.003 * up(scene));
    for (double intensity : {0.0, 1.0, 1e7}) {
        double prev = std::numeric_limits<double>::infinity();
        float peak = 0.0f;
        for (double d = 0.1; d <= 5.0001e4; d *= 2.7) {
            scene.lights = {light_at(scene.camera.position_m + dir * d, intensity, 1e-3)};
            const ImageRGBA32F img = render_checked(scene, 0.0, "distance sweep");
            const double got = image_illuminance_lux(img, focal);
            const double expected = intensity / (d * d);
            if (intensity == 0.0) {
                EXPECT_EQ(got, 0.0) << d;
                EXPECT_EQ(renderer->stats().drawn, 0) << d;
            } else {
                EXPECT_NEAR(got / expected, 1.0, 0.01) << "I " << intensity << " d " << d;
                EXPECT_LE(got, prev * 1.001) << "I " << intensity << " d " << d;
            }
            prev = got;
            for (std::size_t i = 0; i < img.rgba.size(); ++i)
                if (i % 4 != 3) peak = std::max(peak, img.rgba[i]);
        }
        std::printf(
            "I = %g cd, 0.1 m .. 50 km: brightest pixel %.3g cd/m2 (finite in fp32; half floats end at 65504)\n",
            intensity, static_cast<double>(peak));
    }
}

TEST_F(StressDirectLights, RhythmOnTheGpuOverLongTimesMatchesTheCpu) {
    // B(t) of the light pass (time in double on the GPU) at 0 … 30 years of simulated time.
    Scene scene = stress_scene();
    const Rhythm rhythm = parse_rhythm("Q(6)+LFl 15s");
    Light L = light_at(scene.camera.position_m + forward(scene) * 500.0, 100.0, 0.1);
    L.rhythm = rhythm.channels[0].knots;
    L.rhythm_period_s = rhythm.period_s;
    scene.lights = {L};
    for (double t : {0.0, 0.15, 7.77, 3600.0, 86400.0 + 2.3, 3.2e8 + 13.1, 1e9 + 0.35}) {
        render_checked(scene, t, "rhythm");
        const double gpu = renderer->read_light_draws().at(0).rhythm;
        // fp32 knots, double time: the phase keeps ~1e-7 s at 1e9 s, a 20 ms ramp 5e-6.
        EXPECT_NEAR(gpu, rhythm.level(t), 1e-4) << "t " << t;
    }
}

// ---------------------------------------------------------------------------
// The glare billboards with the same singular points.

class StressGlare : public StressDirectLights {};

TEST_F(StressGlare, ExtremeLightsWithEveryCheapModelAndPupil) {
    // Gaussian bloom, Spencer, and the wave-optics PSF (a small eye at N = 128) with the
    // pupil from eq 3.15 at adaptation 1e-6 (7.9 mm) and 1e6 cd/m² (1.9 mm): finite frames,
    // singular lights draw nothing, the far and near lights keep their energy.
    for (GlareModel model : {GlareModel::gaussian_bloom, GlareModel::spencer, GlareModel::wave_optics}) {
        for (double adaptation : {1e-6, 1e6}) {
            Scene scene = stress_scene();
            scene.environment.luminance_cd_m2 = 0.0;
            scene.adaptation_cd_m2 = adaptation;
            scene.glare.model = model;
            scene.glare.psf_size = 128;
            scene.glare.eye.gratings.enabled = false;
            scene.glare.eye.halo_radius_deg.reset();
            scene.glare.eye.defocus_diopters = 0.5;
            scene.glare.radius_deg = 0.5;
            scene.glare.values["bloom_sigma_deg"] = 0.1;
            const glm::dvec3 c = scene.camera.position_m;
            scene.lights = {light_at(c, 1e7, 0.1),                          // at the camera
                            light_at(c - forward(scene) * 10.0, 1e7, 0.1),  // behind
                            light_at(c + right(scene) * 10.0, 1e7, 0.01)};  // beside, in the plane
            const std::string what = std::string(glare_model_name(model)) + " at " + std::to_string(adaptation);
            const ImageRGBA32F none = render_checked(scene, 0.0, what + ", singular lights");
            EXPECT_EQ(image_illuminance_lux(none, renderer->projection().focal_px), 0.0) << what;
            EXPECT_EQ(renderer->stats().drawn, 0) << what;
            const double pupil = glare_pupil_mm(scene);
            EXPECT_TRUE(pupil >= 1.9 && pupil <= 7.9) << pupil;
            for (double d : {0.1, 5e4}) {
                scene.lights = {light_at(c + forward(scene) * d, 1e7, 1e-3)};
                const ImageRGBA32F img = render_checked(scene, 0.0, what + ", d " + std::to_string(d));
                const double got = image_illuminance_lux(img, renderer->projection().focal_px);
                // The billboard window's cut is restored by renormalisation; the near light's
                // 29 px disc and its glare stay inside the 160×120 frame at 0.5° radius.
                EXPECT_NEAR(got / (1e7 / (d * d)), 1.0, 0.02) << what << " d " << d;
            }
        }
    }
}

// ---------------------------------------------------------------------------
// The half-float HDR target (FrameOptions::hdr_format = rgba16f) with a pre-exposure.

class StressHalfFloatTarget : public StressDirectLights {};

TEST_F(StressHalfFloatTarget, ExtremeLightsNeverOverflowTheRgba16fTarget) {
    // Half floats end at 65504. With the automatic pre-exposure 1/L_wa, a 1e7 cd lantern of
    // 1 mm at 0.1 m (3.2e12 cd/m²) seen at L_wa = 1e-3 is stored as 3.2e15: far beyond.
    // Documented: the frame is clamped at the half range, never +inf, so read_hdr() and the
    // display pipeline stay finite; at L_wa = 1e6 the dim background (1e-9 after
    // pre-exposure) underflows to 0 instead. Direct images and glare, several lights adding
    // up on one pixel (blending must not overflow either).
    for (GlareModel model : {GlareModel::none, GlareModel::gaussian_bloom}) {
        for (double adaptation : {1e-3, 1e6}) {
            Scene scene = stress_scene();
            scene.environment.luminance_cd_m2 = 1e-3;
            scene.adaptation_cd_m2 = adaptation;
            scene.glare.model = model;
            scene.glare.radius_deg = 0.5;
            scene.glare.values["bloom_sigma_deg"] = 0.1;
            const glm::dvec3 c = scene.camera.position_m;
            for (int k = 0; k < 4; ++k)
                scene.lights.push_back(light_at(c + forward(scene) * 0.1 + right(scene) * (1e-5 * k), 1e7, 1e-3));
            scene.lights.push_back(light_at(c + forward(scene) * 5e4 + up(scene) * 30.0, 1e7, 0.1));
            FrameOptions options;
            options.hdr_format = HdrFormat::rgba16f;
            options.pre_exposure = 0.0;  // automatic: 1 / L_wa
            renderer->set_options(options);
            const std::string what = std::string(glare_model_name(model)) + " at L_wa " + std::to_string(adaptation);
            const ImageRGBA32F img = render_checked(scene, 0.0, what);
            EXPECT_DOUBLE_EQ(renderer->pre_exposure(), 1.0 / adaptation) << what;
            float peak = 0.0f;
            for (std::size_t i = 0; i < img.rgba.size(); ++i)
                if (i % 4 != 3) peak = std::max(peak, img.rgba[i]);
            std::printf("RGBA16F, %s: brightest pixel %.4g cd/m2 (= %.4g stored)\n", what.c_str(),
                        static_cast<double>(peak), static_cast<double>(peak) / adaptation);
            Pipeline pipeline;
            pipeline.set_frame_options(options);
            pipeline.render(scene, 0.0, 0.0);
            EXPECT_EQ(bad_values(pipeline.frame().read_hdr()), 0) << what;
            EXPECT_TRUE(std::isfinite(pipeline.display().adaptation_cd_m2())) << what;
        }
    }
    renderer->set_options(FrameOptions{});
}

// ---------------------------------------------------------------------------
// The whole pipeline: HDR frame -> adaptation -> tone mapping -> display codes.

class StressPipeline : public GLTest {};

TEST_F(StressPipeline, DisplayCodesInRangeForExtremeLightsEveryOperatorAndAdaptation) {
    // Lights at 0.1 m and 50 km at 1e7 cd, plus the singular ones, through every operator,
    // fixed adaptation 1e-6 and 1e6 cd/m² and dynamic adaptation with Δt = 0 and 10 s, into
    // 8- and 10-bit codes of an sRGB and a PQ display.
    Pipeline pipeline;
    long frames = 0;
    for (int op = 0; op < 6; ++op) {
        for (int mode = 0; mode < 4; ++mode) {
            Scene scene = stress_scene();
            const glm::dvec3 c = scene.camera.position_m;
            scene.lights = {light_at(c + forward(scene) * 0.1 + right(scene) * 2e-4, 1e7, 1e-3),
                            light_at(c + forward(scene) * 5e4, 1e7, 0.1), light_at(c, 1e7, 0.1),
                            light_at(c - forward(scene) * 3.0, 1e7, 0.1)};
            scene.output.tonemap.tone_operator = static_cast<ToneOperator>(op);
            scene.output.tonemap.hue_preservation = static_cast<HuePreservation>(op % 3);
            scene.output.encode.bits = mode % 2 ? 10 : 8;
            if (mode >= 2) scene.output.display = DisplayModel::pq(1000.0, 0.005);
            double dt = 0.0;
            if (mode == 0) scene.adaptation_cd_m2 = 1e-6;
            if (mode == 1) scene.adaptation_cd_m2 = 1e6;
            if (mode >= 2) {
                scene.output.adaptation.mode = AdaptationMode::dynamic;
                pipeline.display().reset_adaptation();
                dt = mode == 2 ? 0.0 : 10.0;
            }
            for (int f = 0; f < 2; ++f) {
                pipeline.render(scene, 0.0, f == 0 ? 0.0 : dt);
                ++frames;
                const std::string what = std::string(tone_operator_name(scene.output.tonemap.tone_operator)) +
                                         " mode " + std::to_string(mode) + " frame " + std::to_string(f);
                EXPECT_EQ(bad_values(pipeline.frame().read_hdr()), 0) << what;
                const double adapted = pipeline.display().adaptation_cd_m2();
                EXPECT_TRUE(std::isfinite(adapted) && adapted > 0.0) << what << ": adaptation " << adapted;
                const EncodedImage codes = pipeline.display().read_codes();
                const int max_code = (1 << codes.bits) - 1;
                ASSERT_EQ(codes.rgb.size(), static_cast<std::size_t>(codes.width) * codes.height * 3);
                EXPECT_TRUE(std::all_of(codes.rgb.begin(), codes.rgb.end(), [&](std::uint16_t v) {
                    return static_cast<int>(v) <= max_code;
                })) << what;
                // The near light's disc centre (3e12 cd/m²): the GPU's code is the CPU
                // reference's (tonemap_pixel at the adapted level, encode_pixel) within one code.
                const glm::dvec2 ctr = pipeline.frame().read_light_draws().at(0).centre_px;
                const glm::ivec2 gl_px(static_cast<int>(ctr.x), static_cast<int>(ctr.y));
                const ImageRGBA32F hdr = pipeline.frame().read_hdr();
                const float* p = hdr.pixel(gl_px.x, hdr.height - 1 - gl_px.y);
                const glm::dvec3 rel =
                    tonemap_pixel(glm::dvec3(p[0], p[1], p[2]), static_cast<float>(adapted), scene.output.tonemap);
                const glm::ivec3 cpu =
                    encode_pixel(scene.output.display, rel, gl_px, pipeline.frame_index() - 1, scene.output.encode);
                const std::size_t o =
                    (static_cast<std::size_t>(codes.height - 1 - gl_px.y) * codes.width + gl_px.x) * 3;
                for (int k = 0; k < 3; ++k)
                    EXPECT_LE(std::abs(static_cast<int>(codes.rgb[o + k]) - cpu[k]), 1) << what << " channel " << k;
            }
        }
    }
    std::printf("pipeline: %ld frames with extreme lights, every HDR value finite, every code in range\n", frames);
}

}  // namespace
}  // namespace atonlab::test
