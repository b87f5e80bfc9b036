#pragma once
// A moving pupil without a PSF rebuild per frame (issue 27 item 2): glare
// kernels built at grid pupils k·step (mm) and, for a pupil between them, the
// Lagrange cubic in the pupil diameter through the four grid pupils around it,
// texel by texel on the display's pixel grid.
//
// Why it is close: the kernel is a smooth function of the diameter p (the
// Airy core scales as 1/p, the scatter's angular scale as 1/p, the aperture's
// area-sampled edge moves continuously), so the cubic's error would fall as
// step⁴; the box-overlap resampling onto the PSF's and the display's grids is
// only piecewise linear in p, which leaves a floor of a few 1e-4 that a finer
// step hardly lowers. Measured (docs/glare.md "A moving pupil"), the worst
// relative L2 of the kernel against the exact pupil's over a dusk-to-night
// sweep (adaptation 1 → 0.001 cd/m², pupil 3.8 → 6.9 mm, K2012 eq 3.15) at
// N = 256: 0.95e-3 at a 0.1 mm step (too close to the 1e-3 the cache is held
// to), 0.51e-3 at 0.05 mm (the default), 1.1e-3 at 0.2 mm (unit.PupilKernelCache.*).
//
// Work ahead: a model whose build has a part without GL (the GPU placement's
// pupil planes, GlareModelType::work_ahead) has it done on worker threads for
// the grid pupils the pupil is heading for: beyond the four nodes in use, as
// many as it moved steps since the last call (at least one, at most
// kMaxAhead), so that the frame crossing into them finds that part ready. The
// result is the same bits as a build without it (the work is the same
// function of the same pupil); only where the time goes changes.
//
// The interpolated kernel is clipped at 0 (the cubic's negative weights can
// dip below 0 where the kernels' zeros move) and keeps each channel's sum as
// the weights give it (each grid kernel sums to 1 per channel; the weights sum
// to 1).
#include <functional>
#include <future>
#include <map>
#include <memory>

#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/glare_models/glare_model.h"

namespace atonlab::stimuli {

/// The grid step of GlareSettings' default moving-pupil cache (mm).
inline constexpr double kPupilGridStepMm = 0.05;

class PupilKernelCache {
public:
    /// Builds the kernel of an exact pupil (mm), given the work done ahead
    /// for it (null: none); may throw (an eye refused at that pupil).
    using Builder = std::function<GlareKernel(double pupil_mm, const GlareKernelAhead* ahead)>;
    /// The job that does a grid pupil's work ahead (empty: none), made on the
    /// calling thread, run on a worker.
    using Planner = std::function<GlareKernelAheadJob(double pupil_mm)>;
    /// At most this many grid kernels are kept (those farthest from the pupil asked for go first).
    static constexpr std::size_t kMaxGridKernels = 8;
    /// At most this many grid pupils' work ahead is started at one call.
    static constexpr int kMaxAhead = 4;

    explicit PupilKernelCache(double step_mm = kPupilGridStepMm) : step_mm_(step_mm) {}

    /// The kernel at pupil_mm: the grid kernel itself on a grid pupil, else the
    /// Lagrange cubic through the grid pupils ⌊p/step⌋ − 1 … ⌊p/step⌋ + 2,
    /// building those not yet cached. With a planner, then starts the work
    /// ahead for the next grid pupils in the direction the pupil moved since
    /// the last call (none on the first call or a pupil that stayed).
    GlareKernel kernel_at(double pupil_mm, const Builder& build, const Planner& plan = {});

    double step_mm() const { return step_mm_; }
    int builds() const { return builds_; }  ///< grid kernels built since construction or clear()
    /// Of builds(), those handed the work done ahead for them.
    int builds_ahead() const { return builds_ahead_; }
    /// Waits for work ahead still running, drops it and every kernel.
    void clear();

private:
    using Ahead = std::shared_ptr<const GlareKernelAhead>;
    const GlareKernel& grid_kernel(long k, const Builder& build);
    void start_ahead(double x, long k0, double previous_pupil_mm, const Planner& plan);
    double step_mm_;
    int builds_ = 0, builds_ahead_ = 0;
    std::map<long, GlareKernel> grid_;     // by k: the kernel at pupil k·step
    std::map<long, std::future<Ahead>> ahead_;  // by k: work ahead for grid pupil k, running or done
    double last_pupil_mm_ = 0;
    bool has_last_ = false;
};

/// Relative L2 of a kernel against a reference over their RGB texels, both
/// centred in the larger size: √(Σ|a − b|² / Σ|b|²).
double kernel_relative_l2(const GlareKernel& a, const GlareKernel& reference);

/// Σ weight_k · kernel_k texel by texel, each centred in the largest size,
/// clipped at 0; radius and window cut interpolated alike.
GlareKernel combine_kernels(const std::vector<const GlareKernel*>& kernels, const std::vector<double>& weights);

}  // namespace atonlab::stimuli
