#pragma once
// Wide-angle veiling glare over a whole frame (the `cie` glare model): the
// lights' direct images convolved with the CIE glare spread function (CIE 135/1-1999)
// (cie_glare.h), in double precision: summed directly over the lit pixels when
// few are lit, by a frame-sized FFT convolution (FFTW) otherwise.
//
// Energy: each pixel's light is its illuminance e = L·Ω (lux; L in cd/m², Ω the
// pixel's exact pinhole solid angle); the kernel K(d) is the GSF integrated over
// the solid angle of the pixel at offset d from a source on the optical axis, so
// e_out(q) = Σ_p e(p) K(q − p) and L_out(q) = e_out(q) / Ω(q). Σ_q K over the
// whole plane and the hemisphere behind it is 1, so Σ L_out·Ω over the frame is
// Σ e minus what falls outside the frame, which apply() reports.
//
// The convolution is linear (zero-padded to at least 2W − 1 × 2H − 1), so a
// light anywhere in the frame reaches every pixel, and nothing wraps around.
// Like the billboards' kernels, the kernel is the one of a source on the optical
// axis, used for every source (shift-invariant): off axis the pinhole's
// stretching of angles makes it approximate (at 15° off axis, angles on the
// image plane are stretched by about 1/cos²15° = 7% radially).
#include <glm/glm.hpp>
#include <memory>
#include <string>
#include <vector>

#include "atonlab/stimuli/cie_glare.h"
#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/placement.h"

namespace atonlab::stimuli {

/// The kernel K of one frame: (2W − 1) × (2H − 1) energy fractions, offsets
/// (dx, dy) ∈ [−(W−1), W−1] × [−(H−1), H−1] px, K(dx, dy) = ∫ GSF dΩ over the pixel
/// square centred at (dx, dy) on the image plane at focal length f (px). Exposed
/// for tests and the bench; the convolution builds its own.
struct VeilKernelQuadrant {
    int width = 0, height = 0;  ///< W, H: offsets 0 … W−1, 0 … H−1 (the kernel is symmetric in x and y)
    std::vector<double> value;  ///< H*W, row-major: value[dy * W + dx]
    double at(int dx, int dy) const { return value[static_cast<std::size_t>(dy) * width + dx]; }
};
VeilKernelQuadrant veil_kernel_quadrant(const CieGlareSpread& gsf, int width, int height, double focal_px);

/// Pixel (i, j)'s exact solid angle (sr) in a W×H frame of focal length f (px),
/// the principal point at the frame's centre.
double frame_pixel_solid_angle_sr(int i, int j, int width, int height, double focal_px);

/// What the `cie` model did in the last frame (FrameRenderer::veil_report()).
struct VeilReport {
    bool applied = false;  ///< false unless the last frame's glare model was `cie`
    CieObserver observer;
    glm::dvec3 outside_frame{0.0};  ///< per channel: energy fraction the GSF carried outside the frame
    double cpu_ms = 0;              ///< read-back, convolution (kernel build included) and upload
    ComputePlacement placement = ComputePlacement::cpu;  ///< where the convolution ran (gpu or cpu)
};

/// How apply() convolves (issue 27 item 3). Both are the same linear
/// convolution with the same kernel; they differ only in rounding (the FFT's
/// ≈ 1e-16 of the frame's brightest pixel; the direct sum is exact to the
/// sum's own rounding, which matters where the veil is 1e-9 of the light).
enum class VeilMethod {
    automatic,  ///< direct while at most kVeilDirectMaxLitPixels pixels are lit, the FFT beyond
    direct,     ///< Σ over lit pixels of e(p) K(q − p): O(pixels × lit pixels), exact
    fft,        ///< the linear FFT convolution (pruned rows, columns on every core)
};

/// The crossover of VeilMethod::automatic: a frame with at most this many lit
/// pixels (any channel > 0) is summed directly. Measured by the `cie_veil_crossover`
/// bench on the 2-core VM at 1920×1080 (docs/bench.md): the direct sum's time per
/// lit pixel against the FFT's time per frame.
constexpr int kVeilDirectMaxLitPixels = 120;

class VeilingGlare {
public:
    VeilingGlare();
    ~VeilingGlare();
    VeilingGlare(const VeilingGlare&) = delete;
    VeilingGlare& operator=(const VeilingGlare&) = delete;

    /// Convolves the RGBA image (width × height, 4 floats per pixel, luminance in
    /// cd/m², any row order) in place with the observer's GSF; alpha is left as
    /// it is. Returns per channel the fraction of the image's energy that the GSF
    /// carried outside the frame (0 for a channel without energy). The kernel's
    /// spectrum is cached for the last (size, focal length, observer).
    /// Throws InputError (cie_glare_spread()) for a bad observer.
    /// `method` chooses the convolution (VeilMethod; automatic by default).
    glm::dvec3 apply(std::vector<float>& rgba, int width, int height, double focal_px, const CieObserver& observer,
                     VeilMethod method = VeilMethod::automatic);

    /// How often the kernel was built (since construction).
    int kernel_builds() const;
    /// The method the last apply() used (direct or fft; automatic before any).
    VeilMethod last_method() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// The same linear convolution as compute shaders in fp32 (issue 27 item 1;
/// shaders/veil_gpu.comp): the kernel split at the square |dx|, |dy| ≤
/// kNearRadiusPx into a near part summed directly and a far part convolved by
/// the GPU FFT (zero-padded to powers of two ≥ 2W − 1 and 2H − 1), so that the
/// fp32 FFT's rounding is relative to the far part only. Held on llvmpipe to
/// the double-precision CPU path (GL.VeilGpu.*: within 1e-4 at 1°, 2°, 5°, 10°,
/// 15°; measured ≤ 7e-6 there at 1920×1080 and 421×221, and 4.6e-4 at 28°,
/// where the FFT's rounding floor meets a veil still falling as θ⁻²).
/// The outside fraction is Σ e·S / Σ e, S the share of a light at each pixel
/// that the frame keeps (from the kernel in double, once per build); reading
/// its per-workgroup partial sums back waits for the frame's veil. At
/// 1920×1080 the transforms are 4096 × 4096: about 0.4 GB of GPU buffers, and
/// a build (the kernel's quadrant and its far part's spectrum by FFTW double)
/// of a few seconds on the 2-core VM, once per size, focal length and
/// observer. Needs a current GL 4.5 context for its whole life.
class GpuVeilingGlare {
public:
    /// The near window's half-width (px): (2R + 1)² taps per pixel. The FFT's
    /// rounding floor scales with ‖K_far‖₂ ≈ R·K(R): R = 8 left 7e-5 at 15° and
    /// 2.3e-3 at 25° of a 1920×1080 frame; R = 16 gives 7e-7 and 4.6e-4.
    static constexpr int kNearRadiusPx = 16;

    GpuVeilingGlare();
    ~GpuVeilingGlare();
    GpuVeilingGlare(const GpuVeilingGlare&) = delete;
    GpuVeilingGlare& operator=(const GpuVeilingGlare&) = delete;

    /// Why a width × height frame cannot be convolved on this context's GPU
    /// (its transform lengths exceed what a workgroup's shared memory holds);
    /// empty when it can.
    static std::string unsupported_reason(int width, int height);

    /// Convolves `light` (RGBA32F, cd/m²) with the observer's GSF; the result
    /// replaces light's rgb (add_to == nullptr) or is added × scale to add_to's
    /// rgb (RGBA32F or RGBA16F, light's size); its scotopic luminance (the RGB
    /// weights, display::scotopic_weights_rgb) replaces or is added to alpha,
    /// the frame's scotopic channel. Returns the outside
    /// fractions as VeilingGlare::apply. The kernel is cached for the last
    /// (size, focal length, observer). Throws InputError for a bad observer,
    /// std::runtime_error for an unsupported size (unsupported_reason()).
    glm::dvec3 apply(gl::Texture2D& light, gl::Texture2D* add_to, double scale, double focal_px,
                     const CieObserver& observer);

    int kernel_builds() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace atonlab::stimuli
