// The moving pupil's kernel cache (pupil_kernel_cache.h, issue 27 item 2): the
// kernel interpolated between grid pupils 0.05 mm apart against the exact
// pupil's kernel over a dusk-to-night sweep, and how many kernels it builds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <thread>
#include <vector>

#include "atonlab/stimuli/eye_model.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/placement.h"
#include "atonlab/stimuli/pupil_kernel_cache.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::test {
namespace {

using namespace atonlab::stimuli;

// The default eye's wave-optics kernel at a pupil, as the glare stage builds it
// (anchored spectral path, on the CPU), at N = 256 (the error at N = 128 is
// larger: 0.9e-3 at a 0.05 mm grid) or smaller where only counts matter.
struct KernelMaker {
    Scene scene;
    SpectralSamples samples;
    explicit KernelMaker(int n) {
        scene.glare.model = GlareModel::wave_optics;
        scene.glare.psf_size = n;
        samples = spectral_samples(display::d65_spectrum(), scene.glare.spectral_samples);
    }
    GlareKernel operator()(double pupil_mm, const GlareKernelAhead* = nullptr) const {
        return glare_model_type(GlareModel::wave_optics)
            .billboard_kernel(
                {scene.glare, scene, samples, scene.display.pixels_per_degree_at_centre(), pupil_mm, 0.0, {}})
            .kernel;
    }
};

// A 10-s dusk-to-night sequence: the adaptation falls log-linearly from 1 to
// 0.001 cd/m², the pupil follows K2012 eq 3.15 (3.76 → 6.89 mm).
double dusk_pupil_mm(double t_s) {
    return pupil_diameter_mm_from_adaptation(std::pow(10.0, -3.0 * t_s / 10.0));
}

TEST(PupilKernelCache, WithoutAGlContextTheAutomaticPlacementIsTheCpu) {
    // These tests build kernels with no GL context and no GPU generator: the
    // default eye's PSF (anchored) must then be the CPU's, and say so.
    EXPECT_EQ(resolve_placement(ComputePlacement::automatic), ComputePlacement::cpu);
    EXPECT_EQ(resolve_placement(ComputePlacement::gpu), ComputePlacement::gpu);  // forced stays forced
    GlareSettings g;
    g.model = GlareModel::wave_optics;
    EXPECT_EQ(glare_model_type(g.model).psf_fft_placement(g), ComputePlacement::cpu);
}

TEST(PupilKernelCache, InterpolatedKernelIsWithinATenthOfAPercentOfTheExactPupilsOverDuskToNight) {
    const KernelMaker make(256);
    PupilKernelCache cache(kPupilGridStepMm);
    double worst = 0, worst_pupil = 0;
    // 7 pupils of the sweep, none on the grid (the times are not round).
    for (int k = 0; k < 7; ++k) {
        const double p = dusk_pupil_mm(0.37 + 1.43 * k);
        const GlareKernel exact = make(p);
        const GlareKernel interpolated = cache.kernel_at(p, std::cref(make));
        const double err = kernel_relative_l2(interpolated, exact);
        if (err > worst) worst = err, worst_pupil = p;
        // Energy: each channel sums as the grid kernels (1) up to the clip at 0.
        glm::dvec3 sum(0.0);
        for (const glm::vec4& v : interpolated.rgba) sum += glm::dvec3(v.r, v.g, v.b);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(sum[c], 1.0, 1e-3) << p << " mm, channel " << c;
    }
    std::printf("worst relative L2 of the interpolated kernel: %.3g at %.3f mm (%d grid kernels built)\n", worst,
                worst_pupil, cache.builds());
    // The bound. A 1 mm grid exceeds it (next test), and so did a
    // 0.1 mm grid at N = 128 (1.05e-3; docs/glare.md "A moving pupil"), so the
    // test can fail.
    EXPECT_LT(worst, 1e-3);
    EXPECT_GT(worst, 0.0);  // it is an interpolation, not the exact kernel
}

TEST(PupilKernelCache, OnTheGridItIsTheGridKernelAndACoarseGridFailsTheBound) {
    const KernelMaker make(128);
    PupilKernelCache cache(kPupilGridStepMm);
    const GlareKernel at = cache.kernel_at(5.0, std::cref(make));
    EXPECT_EQ(cache.builds(), 1);
    EXPECT_EQ(kernel_relative_l2(at, make(5.0)), 0.0);
    // Between 1 mm grid pupils the cubic is far from the exact kernel: what
    // the bound above guards against.
    PupilKernelCache coarse(1.0);
    EXPECT_GT(kernel_relative_l2(coarse.kernel_at(5.5, std::cref(make)), make(5.5)), 1e-3);
}

TEST(PupilKernelCache, ADuskToNightSequenceBuildsOneKernelPerGridPupilItCrosses) {
    const KernelMaker make(64);  // the count does not depend on N
    PupilKernelCache cache(kPupilGridStepMm);
    int frames = 0;
    for (double t = 0; t <= 10.0; t += 1.0 / 30) {  // 30 Hz for 10 s: 301 frames
        cache.kernel_at(dusk_pupil_mm(t), std::cref(make));
        ++frames;
    }
    const double range = dusk_pupil_mm(10.0) - dusk_pupil_mm(0.0);
    const int bound = static_cast<int>(std::ceil(range / kPupilGridStepMm)) + 4;
    std::printf("%d frames, pupil %.3f → %.3f mm: %d kernels built (bound %d)\n", frames, dusk_pupil_mm(0.0),
                dusk_pupil_mm(10.0), cache.builds(), bound);
    EXPECT_LE(cache.builds(), bound);
    EXPECT_LT(cache.builds(), frames / 4);  // 66 of 301 at 0.05 mm, instead of one per frame
}

// Work ahead (pupil_kernel_cache.h): a stand-in model whose "work without GL"
// records the pupil it was done for and the thread that did it, and whose
// kernel is a single texel holding the pupil, so that the cubic of a cache with
// work ahead can be compared bit for bit with one without.
struct TaggedWork final : GlareKernelAhead {
    double pupil_mm = 0;
    std::thread::id thread;
};

GlareKernel one_texel(double pupil_mm) {
    GlareKernel k;
    k.size = 1;
    k.pixels_per_degree = 1;
    k.rgba = {glm::vec4(static_cast<float>(pupil_mm), 1.0f, 2.0f, 0.0f)};
    return k;
}

struct Recorder {
    int call = 0;                     // the caller's frame, set before each kernel_at
    std::vector<int> built_at;        // each build's frame
    std::vector<double> asked, handed;  // each build's pupil, and the pupil of the work handed to it (NaN: none)
    int planned = 0;
    PupilKernelCache::Builder builder() {
        return [this](double p, const GlareKernelAhead* a) {
            const auto* work = dynamic_cast<const TaggedWork*>(a);
            EXPECT_EQ(work == nullptr, a == nullptr) << "only the model's own work is handed back";
            if (work) {
                EXPECT_NE(work->thread, std::this_thread::get_id()) << "work ahead runs on a worker thread";
            }
            built_at.push_back(call);
            asked.push_back(p);
            handed.push_back(work ? work->pupil_mm : std::numeric_limits<double>::quiet_NaN());
            return one_texel(p);
        };
    }
    PupilKernelCache::Planner planner() {
        return [this](double p) -> GlareKernelAheadJob {
            ++planned;
            return [p] {
                auto w = std::make_shared<TaggedWork>();
                w->pupil_mm = p;
                w->thread = std::this_thread::get_id();
                return std::shared_ptr<const GlareKernelAhead>(std::move(w));
            };
        };
    }
};

// A pupil sweeping one way, frame by frame, through a cache with work ahead
// and one without. From the third frame on (the first knows no direction, the
// second only then starts work) every grid pupil it needs was started ahead by
// the frame before: as many nodes beyond the stencil as the pupil moved steps,
// and the pupil moves about as far each frame as the frame before.
template <class Pupil>
void sweep_with_and_without_work_ahead(int frames, Pupil pupil_mm) {
    Recorder with, without;
    PupilKernelCache ahead(kPupilGridStepMm), plain(kPupilGridStepMm);
    for (int i = 0; i < frames; ++i) {
        const double p = pupil_mm(i);
        with.call = without.call = i;
        const GlareKernel a = ahead.kernel_at(p, with.builder(), with.planner());
        const GlareKernel b = plain.kernel_at(p, without.builder());
        ASSERT_EQ(a.rgba.size(), 1u);
        // The same bits: work ahead moves time, never the kernel.
        EXPECT_EQ(a.rgba[0], b.rgba[0]) << "frame " << i << ", " << p << " mm";
    }
    EXPECT_EQ(with.asked, without.asked) << "the same grid pupils are built, in the same order";
    ASSERT_GT(ahead.builds(), 10);
    int in_first_two = 0;
    for (std::size_t b = 0; b < with.asked.size(); ++b) {
        if (with.built_at[b] < 2) {
            ++in_first_two;
            if (with.built_at[b] == 0) {
                EXPECT_TRUE(std::isnan(with.handed[b])) << "build " << b;
            }
        } else {
            EXPECT_EQ(with.handed[b], with.asked[b]) << "build " << b << " (frame " << with.built_at[b]
                                                     << ") was not handed its own work";
        }
    }
    EXPECT_GE(in_first_two, 4) << "the first frame builds its stencil's four grid pupils";
    EXPECT_EQ(ahead.builds_ahead(), ahead.builds() - in_first_two);
    // Work is started once per node, and at the end at most kMaxAhead for nodes the sweep never reached.
    EXPECT_GE(with.planned, ahead.builds_ahead());
    EXPECT_LE(with.planned, ahead.builds_ahead() + PupilKernelCache::kMaxAhead);
}

TEST(PupilKernelCache, AnOpeningPupilFindsEachNextGridPupilsWorkDoneAheadAndTheSameKernels) {
    // Dusk to night at 30 Hz: 3.76 → 6.89 mm, about 0.01 mm (a fifth of a step) a frame.
    sweep_with_and_without_work_ahead(301, [](int i) { return dusk_pupil_mm(i / 30.0); });
}

TEST(PupilKernelCache, AClosingPupilFindsItsWorkDoneAheadToo) {
    // Night to dusk: the nodes below the stencil.
    sweep_with_and_without_work_ahead(301, [](int i) { return dusk_pupil_mm(10.0 - i / 30.0); });
}

TEST(PupilKernelCache, APupilMovingSeveralGridStepsAFrameHasWorkStartedForEachNodeItWillCross) {
    // 0.12 mm a frame, 2.4 steps: three nodes beyond the stencil each frame.
    sweep_with_and_without_work_ahead(25, [](int i) { return 3.503 + 0.12 * i; });
}

TEST(PupilKernelCache, APupilThatTurnsBackAndForthGetsTheSameKernelsAsWithoutWorkAhead) {
    // Hippus-like swings of ±0.2 mm (4 grid steps) with a period of about 31
    // frames: the direction flips every 16 frames, work started for nodes
    // the pupil turns away from is dropped or handed over later, and every
    // kernel stays the one a cache without work ahead gives.
    Recorder with, without;
    PupilKernelCache ahead(kPupilGridStepMm), plain(kPupilGridStepMm);
    for (int i = 0; i < 200; ++i) {
        const double p = 5.013 + 0.2 * std::sin(i / 5.0);
        with.call = without.call = i;
        EXPECT_EQ(ahead.kernel_at(p, with.builder(), with.planner()).rgba[0],
                  plain.kernel_at(p, without.builder()).rgba[0])
            << "frame " << i;
    }
    EXPECT_EQ(with.asked, without.asked);
    for (std::size_t b = 0; b < with.asked.size(); ++b) {
        if (!std::isnan(with.handed[b])) {
            EXPECT_EQ(with.handed[b], with.asked[b]) << "build " << b;
        }
    }
    EXPECT_GT(ahead.builds_ahead(), 0);
}

TEST(PupilKernelCache, WorkThatFailsAheadIsDoneAgainByTheBuildOnTheCallingThread) {
    Recorder r;
    int failed = 0;
    PupilKernelCache::Planner failing = [&](double) -> GlareKernelAheadJob {
        return [&failed]() -> std::shared_ptr<const GlareKernelAhead> {
            ++failed;  // one job at a time: each is waited for before the next starts
            throw std::runtime_error("no memory on the worker");
        };
    };
    PupilKernelCache cache(kPupilGridStepMm), plain(kPupilGridStepMm);
    Recorder p;
    for (int i = 0; i <= 60; ++i) {
        const double pupil = dusk_pupil_mm(i / 30.0);
        EXPECT_EQ(cache.kernel_at(pupil, r.builder(), failing).rgba[0],
                  plain.kernel_at(pupil, p.builder()).rgba[0]);
    }
    EXPECT_GT(failed, 0);
    EXPECT_EQ(cache.builds_ahead(), 0);
    EXPECT_EQ(r.asked, p.asked);
    // An error of the build itself still reaches the caller.
    PupilKernelCache refusing(kPupilGridStepMm);
    EXPECT_THROW(refusing.kernel_at(5.01, [](double, const GlareKernelAhead*) -> GlareKernel {
        throw std::invalid_argument("refused");
    }),
                 std::invalid_argument);
}

}  // namespace
}  // namespace atonlab::test
