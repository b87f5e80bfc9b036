#pragma once
// A ship simulator's frames (issue 27 item 4; docs/bench.md "simulator_frames"):
// a scripted sequence through stimuli::Pipeline as a simulator drives it, one
// render per frame at a fixed frame time, timing every frame and counting the
// work each one did: PSFs built, kernels interpolated for a moving pupil, area
// layers built, whole-image CPU Fourier transforms. `atonlab bench --only
// simulator_frames` runs the full sequence; GL.SimulatorFrames.* assert the
// counts on a short one. Needs a current GL 4.5 context.
#include <cstdint>
#include <vector>

#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/glare_models/glare_model.h"

namespace atonlab::bench {

struct SimulatorSequence {
    int frames = 600;               ///< at frame_rate_hz: 600 is 10 s at 60 Hz
    double frame_rate_hz = 60.0;
    int width_px = 1920;            ///< the K2012 table 6.2 scene at 45° vertical field, 16:9
    int lights = 100;               ///< placed as bench_common.h Layout::apart (a harbour approach)
    /// The adaptation luminance (cd/m²; the sky's and the eye's) falls
    /// log-linearly from `from` to `to` over the sequence: dusk into night.
    /// The pupil follows it (K2012 eq 3.15, 3.8 → 6.9 mm for 1 → 0.001).
    double adaptation_from_cd_m2 = 1.0;
    double adaptation_to_cd_m2 = 0.001;
    bool hippus = true;             ///< K2012 eq 4.7 on top of the pupil's drift
    stimuli::GlareModel glare = stimuli::GlareModel::wave_optics;  ///< the eye's model for every light
    int psf_size = 0;               ///< 0: the default N
    /// Where the PSF's FFTs and the `cie` veil run ([glare] placement):
    /// automatic is the GPU on a hardware driver, the CPU on llvmpipe.
    stimuli::ComputePlacement placement = stimuli::ComputePlacement::automatic;
};

/// One frame's time and work.
struct SimulatorFrame {
    double wall_ms = 0;               ///< render() with glFinish after it, on a steady clock
    stimuli::FrameTimings timings;    ///< the renderer's stage times (GPU times 0 without timer queries)
    double adaptation_cd_m2 = 0;
    double pupil_mm = 0;              ///< the wave-optics glare's pupil this frame (0 for other models)
    int psf_builds = 0;               ///< PSFs built (GlareBuildCounts::kernels)
    int psf_builds_ahead = 0;         ///< of them, those whose pupil planes a worker drew ahead (kernels_ahead)
    int interpolations = 0;           ///< kernels interpolated between cached pupils
    int layer_builds = 0;             ///< area-layer sets built
    std::uint64_t cpu_ffts = 0;       ///< whole-image CPU transforms (stimuli::cpu_fft_count())
};

/// Runs the sequence through a fresh Pipeline (the adaptation dynamic, the
/// display skips on, as a simulator's). GL timer queries when gpu_timing.
std::vector<SimulatorFrame> run_simulator_sequence(const SimulatorSequence& sequence, bool gpu_timing);

}  // namespace atonlab::bench
