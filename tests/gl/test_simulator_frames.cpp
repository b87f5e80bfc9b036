// The simulator-frame sequence (issue 27 item 4; bench/include/atonlab/bench/
// simulator_frames.h): a short dusk-to-night run with hippus through the
// Pipeline a simulator drives, and the work it counts per frame. Times are
// the bench's business; the counts are asserted here, each from what the
// pipeline must do: a moving pupil builds one PSF per grid pupil it crosses
// (not one per frame), a frame that builds nothing runs no CPU transform, and
// the `cie` veil of a frame whose sky is lit is one forward and one inverse
// transform per channel (the FFT path: every pixel is lit, far beyond
// kVeilDirectMaxLitPixels).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "atonlab/bench/simulator_frames.h"
#include "atonlab/stimuli/pupil_kernel_cache.h"
#include "atonlab/stimuli/veiling_glare.h"
#include "gl_test_support.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;
using bench::SimulatorFrame;
using bench::SimulatorSequence;

using SimulatorFrames = GLTest;

SimulatorSequence short_sequence() {
    SimulatorSequence q;
    q.frames = 150;  // 10 s at 15 Hz: the whole dusk-to-night sweep
    q.frame_rate_hz = 15.0;
    q.width_px = 320;
    q.lights = 12;
    q.psf_size = 64;
    return q;
}

TEST_F(SimulatorFrames, MovingPupilBuildsPerGridPupilAndIdleFramesRunNoCpuTransform) {
    const SimulatorSequence q = short_sequence();
    const std::vector<SimulatorFrame> frames = bench::run_simulator_sequence(q, false);
    ASSERT_EQ(frames.size(), 150u);
    double p_min = 1e9, p_max = 0;
    int builds = 0, interpolated = 0;
    for (const SimulatorFrame& f : frames) {
        p_min = std::min(p_min, f.pupil_mm);
        p_max = std::max(p_max, f.pupil_mm);
        builds += f.psf_builds;
        interpolated += f.interpolations;
    }
    // The pupil opens from about 3.8 to 6.9 mm (K2012 eq 3.15 at 1 and 0.001 cd/m²), hippus on top.
    EXPECT_LT(p_min, 4.2);
    EXPECT_GT(p_max, 6.5);
    EXPECT_GE(frames[0].psf_builds, 1) << "the first frame builds its PSF";
    // One PSF per grid pupil the sweep spans, the cubic's stencil (4) at the
    // ends, and the first two frames built exactly (pupil_kernel_cache.h).
    const int bound = static_cast<int>(std::ceil((p_max - p_min) / kPupilGridStepMm)) + 4 + 2;
    std::printf("%zu frames, pupil %.3f … %.3f mm: %d PSFs built (bound %d), %d kernels interpolated\n", frames.size(),
                p_min, p_max, builds, bound, interpolated);
    EXPECT_LE(builds, bound);
    EXPECT_GE(interpolated, static_cast<int>(frames.size()) - 4) << "the moving pupil is interpolated, not rebuilt";
    int idle = 0;
    for (std::size_t i = 1; i < frames.size(); ++i) {
        const SimulatorFrame& f = frames[i];
        idle += f.psf_builds == 0 ? 1 : 0;
        // Area layers of lights smaller than a pixel are the kernel alone (no convolution).
        if (f.psf_builds == 0) {
            EXPECT_EQ(f.cpu_ffts, 0u) << "frame " << i << " built no PSF yet ran CPU transforms";
        }
        if (f.psf_builds > 0) {
            EXPECT_GT(f.cpu_ffts, 0u) << "frame " << i << ": a PSF is built by FFT";
        }
    }
    // Most frames build nothing: the sweep crosses fewer grid pupils than it has frames.
    EXPECT_GE(idle, static_cast<int>(frames.size()) - bound - 1);
}

TEST_F(SimulatorFrames, OnTheGpuPlacementNoFrameRunsACpuTransform) {
    // Issue 27 item 4: placed on the GPU (as automatic is on a hardware
    // driver), the moving pupil's PSF builds transform on the GPU too
    // (GpuPsfGenerator::generate_anchored); the pupil planes stay on the CPU.
    SimulatorSequence q = short_sequence();
    q.frames = 30;  // 2 s of the sweep: the pupil crosses several grid pupils
    q.placement = ComputePlacement::gpu;
    const std::vector<SimulatorFrame> frames = bench::run_simulator_sequence(q, false);
    ASSERT_EQ(frames.size(), 30u);
    int builds = 0;
    for (std::size_t i = 0; i < frames.size(); ++i) {
        builds += frames[i].psf_builds;
        EXPECT_EQ(frames[i].cpu_ffts, 0u) << "frame " << i << " (" << frames[i].psf_builds << " PSFs built)";
    }
    EXPECT_GT(builds, 1) << "the sequence must build PSFs for this to say anything";
}

TEST_F(SimulatorFrames, OnTheGpuPlacementAnOpeningPupilsBuildsFindTheirPupilPlanesDrawnAhead) {
    // The CPU's share of a GPU build, the pupil planes, is drawn on a worker
    // thread for the next grid pupil (pupil_kernel_cache.h) so that the frame
    // that crosses into it waits only for the GPU. Without hippus the pupil
    // only opens, about 0.02 mm a frame against the 0.05 mm grid step: only
    // the first two frames (each built for its exact pupil, glare_stage.cpp)
    // and the first interpolation's stencil of four (no direction known yet)
    // draw their planes in the frame.
    SimulatorSequence q = short_sequence();  // the whole sweep in 150 frames
    q.hippus = false;
    q.placement = ComputePlacement::gpu;
    const std::vector<SimulatorFrame> frames = bench::run_simulator_sequence(q, false);
    int builds = 0, ahead = 0;
    for (std::size_t i = 0; i < frames.size(); ++i) {
        builds += frames[i].psf_builds;
        ahead += frames[i].psf_builds_ahead;
        EXPECT_LE(frames[i].psf_builds_ahead, frames[i].psf_builds);
        if (i < 3) {
            EXPECT_EQ(frames[i].psf_builds_ahead, 0) << "frame " << i;
        }
        if (i >= 3) {
            EXPECT_EQ(frames[i].psf_builds_ahead, frames[i].psf_builds) << "frame " << i << " drew its planes itself";
        }
    }
    std::printf("%d PSFs built, %d of them with their pupil planes drawn ahead\n", builds, ahead);
    EXPECT_EQ(frames[0].psf_builds + frames[1].psf_builds + frames[2].psf_builds, 2 + 4);
    EXPECT_GT(ahead, 2) << "the sweep must cross grid pupils for this to say anything";
    EXPECT_EQ(ahead, builds - 6);
}

TEST_F(SimulatorFrames, CieVeilOfFewLightsIsSummedWithoutTransforms) {
    // 12 lights light far fewer than kVeilDirectMaxLitPixels pixels: the direct sum.
    SimulatorSequence q = short_sequence();
    q.frames = 4;
    q.glare = GlareModel::cie;
    const std::vector<SimulatorFrame> frames = bench::run_simulator_sequence(q, false);
    ASSERT_EQ(frames.size(), 4u);
    for (std::size_t i = 0; i < frames.size(); ++i) {
        EXPECT_EQ(frames[i].psf_builds, 0) << "the cie model has no PSF";
        EXPECT_GT(frames[i].timings.veil_cpu_ms, 0.0);
        EXPECT_EQ(frames[i].cpu_ffts, 0u) << "frame " << i;
    }
}

TEST_F(SimulatorFrames, CieVeilOfManyLightsIsTwoTransformsPerChannel) {
    // 200 lights over about 320 × 70 px light more than kVeilDirectMaxLitPixels
    // pixels (distinct but for a few coincidences): the FFT path, one forward
    // and one inverse transform per channel (each has energy: white lights).
    static_assert(kVeilDirectMaxLitPixels < 180);
    SimulatorSequence q = short_sequence();
    q.frames = 4;
    q.lights = 200;
    q.glare = GlareModel::cie;
    const std::vector<SimulatorFrame> frames = bench::run_simulator_sequence(q, false);
    ASSERT_EQ(frames.size(), 4u);
    // Frame 0 also transforms the kernel once (its spectrum, cached from then on).
    EXPECT_EQ(frames[0].cpu_ffts, 7u);
    for (std::size_t i = 1; i < frames.size(); ++i) EXPECT_EQ(frames[i].cpu_ffts, 6u) << "frame " << i;
}

}  // namespace
}  // namespace atonlab::test
