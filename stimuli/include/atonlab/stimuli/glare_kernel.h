#pragma once
// From a PSF on its own angular grid to what a glare billboard draws on the
// display's pixel grid (K2012 §4.2.5-4.2.6, §4.3): the PSF resampled by visual
// angle to the display's pixels per degree (so glare subtends the same angle on
// any monitor), multiplied by a radial falloff window, renormalised per channel
// so the billboard conserves the light's energy, and convolved with discs for
// lights that cover several pixels (area layers).
//
// Kernel convention: M×M texels, M odd, row 0 at the bottom; texel (i, j) is the
// display pixel at offset (i - (M-1)/2, j - (M-1)/2) from a light centred on a
// pixel centre. Each channel sums to 1: a light of illuminance E_c (lux) puts
// E_c · K_c(i, j) lux into that pixel. A light between pixel centres uses the
// bilinear interpolation of the kernel, which keeps every channel's sum.
#include <functional>
#include <glm/glm.hpp>
#include <string_view>
#include <vector>

#include "atonlab/stimuli/psf.h"

namespace atonlab::stimuli {

/// Radial falloff of the billboard (K2012 eq 4.11, 4.12), as a window on the
/// normalised radius ρ = r / R: Epanechnikov (1 - ρ²), Silverman's second order
/// (1 - ρ²)², or none (the kernel is cut at the disc of radius R). The constant
/// factors 2/π and 3/π of the thesis make those kernels integrate to 1; as
/// windows they cancel in the renormalisation.
enum class GlareWindow { none, epanechnikov, silverman };
GlareWindow glare_window_from_name(std::string_view name);  ///< throws InputError (key "window")
std::string_view glare_window_name(GlareWindow w);
double glare_window_weight(GlareWindow w, double rho);

struct GlareKernel {
    int size = 0;  ///< M (odd)
    double pixels_per_degree = 0;
    double radius_px = 0;         ///< R: the window's radius
    std::vector<glm::vec4> rgba;  ///< M*M; a unused (0)
    /// Fraction of each channel's energy that the window and the grid cut off,
    /// before the renormalisation put it back (reported, K2012 §4.2.5).
    glm::dvec3 window_cut{0.0};

    int half() const { return (size - 1) / 2; }
    const glm::vec4& at(int i, int j) const { return rgba[static_cast<std::size_t>(j) * size + i]; }
};

/// The widest kernel a billboard may have, px (M): 4097 = 2 · 2048 + 1, the
/// largest PSF (psf_size 2048) at one display pixel per PSF texel.
inline constexpr int kMaxGlareKernelPx = 4097;

/// The kernel width M (px) a billboard of radius_deg needs at
/// pixels_per_degree: 2⌈R · ppd⌉ + 1 (any size; may exceed kMaxGlareKernelPx,
/// +∞ for a non-finite product).
double glare_kernel_width_px(double pixels_per_degree, double radius_deg);
/// The kernel's width, 2⌈R·ppd⌉ + 1 pixels, for a billboard of radius_deg at
/// pixels_per_degree. Throws InputError (key "radius_deg") for a radius ≤ 0 or
/// a kernel wider than 4097 px, and (key "pixels_per_degree") for a
/// non-positive pixel density: the checks every kernel builder makes.
int glare_kernel_size_px(double pixels_per_degree, double radius_deg);

/// Resamples an RGB PSF to display pixels by exact box overlap (each pixel
/// receives the PSF energy of the angles it covers), windows it at radius_deg
/// and renormalises each channel to unit sum. Throws InputError (key
/// "radius_deg") for a radius ≤ 0 or one that needs a kernel wider than 4097 px.
GlareKernel glare_kernel_from_psf(const RgbPsf& psf, double pixels_per_degree, double radius_deg, GlareWindow window);

/// A radially symmetric analytic PSF (Spencer et al. 1995, a Gaussian bloom):
/// density(θ_deg, λ_nm) per unit solid angle, any scale. Each pixel integrates
/// the density over its area (finely near the centre, where the PSF is steep),
/// weighted by the spectral samples; cut is reported against the integral over
/// the hemisphere (0 … 90°).
using RadialDensity = std::function<double(double theta_deg, double wavelength_nm)>;
GlareKernel glare_kernel_from_radial(const RadialDensity& density, const SpectralSamples& samples,
                                     double pixels_per_degree, double radius_deg, GlareWindow window);

/// Precomputed convolutions of the kernel with discs of radius r_k = k·step
/// (px), k = 0 … layers-1 (K2012 §4.2.6): layer 0 is the kernel itself; each
/// layer sums to 1 per channel, so interpolating linearly between layers by
/// projected radius (eq 4.13) conserves energy. Size = kernel size + 2·⌈r_max⌉.
struct AreaLayers {
    int size = 0;
    int layers = 1;
    double radius_step_px = 0;    ///< 0 when only layer 0 exists
    std::vector<glm::vec4> rgba;  ///< layer-major, each size*size, same convention as GlareKernel

    double max_radius_px() const { return radius_step_px * (layers - 1); }
    int half() const { return (size - 1) / 2; }
};
/// Builds layers up to max_radius_px (the largest projected radius the scene
/// needs) with at most max_layers layers (≥ 2 when max_radius_px > 0).
AreaLayers build_area_layers(const GlareKernel& kernel, double max_radius_px, int max_layers);

}  // namespace atonlab::stimuli
