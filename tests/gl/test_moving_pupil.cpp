// A moving pupil in the glare stage (issue 27 item 2): with the default cache
// (GlareSettings::pupil_tolerance_mm not given) a dusk-to-night sequence and
// hippus build a bounded number of PSFs, not one per frame, while a still pupil
// and a pupil that changes once (a new trial) are built exactly as before.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "atonlab/stimuli/eye_model.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/pupil_kernel_cache.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;

using MovingPupil = GLTest;

Scene moving_scene() {
    Scene s;
    s.display = {160, 120, 0.25, 0.9};
    s.environment.background = Background::uniform;
    s.environment.luminance_cd_m2 = 0.01;
    s.adaptation_cd_m2 = 1.0;
    s.glare.model = GlareModel::wave_optics;
    s.glare.psf_size = 64;
    s.glare.spectral_samples = 8;
    Light L;
    L.position_m = {0, 0, -100};
    s.lights = {L};
    return s;
}

TEST_F(MovingPupil, DuskToNightBuildsOnePsfPerGridPupilNotOnePerFrame) {
    Scene scene = moving_scene();
    FrameRenderer r;
    const int frames = 100;  // 10 s at 10 Hz
    double p_first = 0, p_last = 0;
    for (int i = 0; i < frames; ++i) {
        const double t = 10.0 * i / (frames - 1);
        scene.adaptation_cd_m2 = std::pow(10.0, -3.0 * t / 10.0);  // 1 → 0.001 cd/m²
        r.render(scene, t);
        (i == 0 ? p_first : p_last) = r.glare().report()[0].pupil_mm;
    }
    const GlareBuildCounts c = r.glare().build_counts();
    // The first two frames are built exactly (a pupil that changed once is a
    // new trial, not yet a moving one); then one PSF per grid pupil crossed,
    // plus the stencil's four at the start.
    const int bound = 2 + static_cast<int>(std::ceil((p_last - p_first) / kPupilGridStepMm)) + 4;
    std::printf("%d frames, pupil %.3f → %.3f mm: %d PSFs built (bound %d), %d kernels interpolated\n", frames, p_first,
                p_last, c.kernels, bound, c.interpolations);
    EXPECT_LE(c.kernels, bound);
    // Every frame after the first two but a few (measured: 97 of 98; a frame
    // whose stencil the eye refuses is built exactly instead).
    EXPECT_GE(c.interpolations, frames - 4);
}

TEST_F(MovingPupil, HippusInterpolatesFromTheFirstFrame) {
    Scene scene = moving_scene();
    scene.adaptation_cd_m2 = 0.01;
    scene.glare.eye.hippus.enabled = true;
    FrameRenderer r;
    for (int i = 0; i < 30; ++i) r.render(scene, i / 60.0);
    const GlareBuildCounts c = r.glare().build_counts();
    std::printf("hippus, 30 frames at 60 Hz: %d PSFs built, %d kernels interpolated\n", c.kernels, c.interpolations);
    EXPECT_EQ(c.interpolations, 30);
    EXPECT_LE(c.kernels, 15);  // the swing spans a few grid pupils, not 30
}

TEST_F(MovingPupil, AStillPupilAndAOneOffChangeAreBuiltExactly) {
    Scene scene = moving_scene();
    FrameRenderer r;
    for (int i = 0; i < 3; ++i) r.render(scene, i / 60.0);
    scene.adaptation_cd_m2 = 0.01;  // a new trial at another adaptation
    for (int i = 0; i < 3; ++i) r.render(scene, i / 60.0);
    const GlareBuildCounts c = r.glare().build_counts();
    EXPECT_EQ(c.kernels, 2);
    EXPECT_EQ(c.interpolations, 0);
    ASSERT_NE(r.glare().psf(0), nullptr);  // the exact pupil's PSF
}

TEST_F(MovingPupil, StimuliRenderedAtOneTimeGetTheKernelOfAFreshRenderer) {
    // A session's pre-check renders every condition at t = 0, alternating
    // pupils; a resumed session renders only the rest. Each kernel must be the
    // one a fresh renderer builds for that stimulus, bit for bit, or a resumed
    // session would show other images than the uninterrupted one.
    Scene dusk = moving_scene();
    Scene night = moving_scene();
    night.adaptation_cd_m2 = 0.001;
    FrameRenderer r;
    for (int i = 0; i < 3; ++i) {
        r.render(dusk, 0.0);
        r.render(night, 0.0);
    }
    EXPECT_EQ(r.glare().build_counts().interpolations, 0);
    FrameRenderer fresh;
    fresh.render(night, 0.0);
    ASSERT_NE(r.glare().kernel(0), nullptr);
    ASSERT_NE(fresh.glare().kernel(0), nullptr);
    EXPECT_TRUE(r.glare().kernel(0)->rgba == fresh.glare().kernel(0)->rgba);
}

TEST_F(MovingPupil, CrossingIntoScotopicRebuildsOnlyTheKernelsThatReadTheVisionClass) {
    // The adaptation crosses 0.001 cd/m² (Spencer's scotopic limit, CIE 191)
    // with the pupil held: Spencer's PSF changes with the vision class and is
    // rebuilt; the wave-optics eye's does not read it and is kept.
    for (GlareModel model : {GlareModel::wave_optics, GlareModel::spencer}) {
        Scene scene = moving_scene();
        scene.glare.model = model;
        scene.glare.pupil_mm = 5.0;
        scene.adaptation_cd_m2 = 0.002;  // mesopic
        FrameRenderer r;
        r.render(scene, 0.0);
        scene.adaptation_cd_m2 = 0.0005;  // scotopic
        r.render(scene, 0.0);
        EXPECT_EQ(r.glare().build_counts().kernels, model == GlareModel::spencer ? 2 : 1)
            << glare_model_type(model).name();
    }
}

}  // namespace
}  // namespace atonlab::test
