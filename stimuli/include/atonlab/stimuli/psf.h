#pragma once
// The eye's point-spread function on an angular grid (K2012 §4.2.2-4.2.4), and
// its CPU references in double precision.
//
// Grid convention: n×n texels, row 0 at the bottom (+y up), the zero angle at
// texel (n/2, n/2) after the cyclic shift of eq 4.8; texel (i, j) is the visual
// angle ((i - n/2), (j - n/2)) · degrees_per_texel. Values are the fraction of
// the light's energy that lands in each texel, so a PSF sums to 1 (mono), or
// its luminance 0.2126 R + 0.7152 G + 0.0722 B sums to 1 (RGB).
#include <glm/glm.hpp>
#include <vector>

#include "atonlab/display/colour.h"
#include "atonlab/stimuli/eye_model.h"
#include "atonlab/stimuli/fft.h"

namespace atonlab::stimuli {

/// The spectral samples of §4.2.4: `count` equal bins over [first_nm, last_nm],
/// sampled at their centres, each weighted by the CMFs × the SPD × the bin width,
/// scaled so the Y weights sum to 1 (so a wavelength-independent PSF of unit
/// sum integrates to unit luminance).
struct SpectralSamples {
    std::vector<double> wavelength_nm;
    std::vector<glm::dvec3> xyz_weight;

    static constexpr double kFirstNm = 380.0;
    static constexpr double kLastNm = 780.0;
};
/// Throws InputError (key "spectral_samples") for count < 1, and (key "spd")
/// for an SPD with no luminance.
SpectralSamples spectral_samples(const display::Spectrum& spd, int count);

/// A monochromatic PSF (unit sum) at one wavelength.
struct MonoPsf {
    int n = 0;
    double degrees_per_texel = 0;
    double wavelength_nm = kReferenceWavelengthNm;
    std::vector<double> value;  ///< n*n, row-major, centred (eq 4.8)

    double at(int x, int y) const { return value[static_cast<std::size_t>(y) * n + x]; }
};

/// An RGB PSF (linear Rec.709, luminance sums to 1).
struct RgbPsf {
    int n = 0;
    double degrees_per_texel = 0;
    std::vector<glm::dvec3> rgb;  ///< n*n, row-major, centred

    const glm::dvec3& at(int x, int y) const { return rgb[static_cast<std::size_t>(y) * n + x]; }
    glm::dvec3 channel_sums() const;
    double luminance_sum() const;
};

/// |F|² of a field's FFT, cyclically shifted (eq 4.8) and normalised to unit
/// sum (§4.2.3). The field is the FFT output (origin at index 0).
MonoPsf mono_psf_from_spectrum(const ComplexImage<double>& fft_of_pupil, double degrees_per_texel,
                               double wavelength_nm);

/// The two parts of an EyeScale::two_scales PSF at one wavelength (docs/glare.md),
/// each |F|² of its pupil_parts() field, centred (eq 4.8), scaled by the same
/// factor so that core_fraction + scatter sum = 1: the core on its own grid
/// (core_degrees_per_texel, physical), the scatter on the eye's PSF grid
/// (psf_degrees_per_texel).
struct MonoPsfParts {
    MonoPsf core;     ///< unit sum; carries core_fraction of the energy
    MonoPsf scatter;  ///< sums to 1 - core_fraction
    double core_fraction = 1.0;
};
MonoPsfParts mono_psf_parts(const EyeModel& eye, int n, double wavelength_nm, double time_s = 0.0);

/// Adds `fine` (a centred PSF on a grid of fine.degrees_per_texel) into `coarse`
/// (centred, coarse.degrees_per_texel ≥ fine's) times `weight`: each fine texel's
/// energy is shared among the coarse texels its square overlaps, by area, so the
/// sum is kept exactly and the centre texel maps onto the centre texel.
void bin_into(const MonoPsf& fine, double weight, MonoPsf& coarse);

/// The monochromatic PSF of an eye at one wavelength, exactly (FFTW double):
/// the pupil plane is drawn over W·λ/λ0 so the result lands on λ0's grid.
/// has_two_scales: the core binned onto the scatter's grid plus the scatter
/// (mono_psf_parts); otherwise one FFT of P·E at psf_degrees_per_texel.
MonoPsf mono_psf_reference(const EyeModel& eye, int n, double wavelength_nm, double time_s = 0.0);

/// The fast spectral integration of §4.2.4 in double (the CPU twin of
/// shaders/psf_spectral.comp): for each sample λ, F_λ(x) = F_λ0(x·λ0/λ)·(λ0/λ)²
/// looked up with trilinear filtering (levels 0 and 1 of a 2×2 box mip chain,
/// LOD = max(0, log2(λ0/λ))), weighted, XYZ → linear Rec.709, normalised to
/// unit luminance sum.
RgbPsf spectral_psf_resampled(const MonoPsf& psf_at_reference_wavelength, const SpectralSamples& samples);

/// The exact reference: every sample wavelength gets its own pupil plane (its
/// own E) and its own double-precision FFT on λ0's angular grid; weighted,
/// XYZ → linear Rec.709, normalised to unit luminance sum.
RgbPsf spectral_psf_exact(const EyeModel& eye, int n, const SpectralSamples& samples, double time_s = 0.0);

/// The 2×2 box-filtered next mip level of an n×n image (n/2 × n/2), as the GPU
/// path builds it.
std::vector<double> box_downsample(const std::vector<double>& image, int n);

/// Bilinear lookup in an n×n image at continuous texel coordinates (texel
/// centres at integers), zero outside (the PSF has no energy beyond its grid).
double bilinear_zero_border(const std::vector<double>& image, int n, double x, double y);

/// Relative L2 distance ‖a − b‖ / ‖b‖ over all channels.
double relative_l2(const RgbPsf& a, const RgbPsf& b);

}  // namespace atonlab::stimuli
