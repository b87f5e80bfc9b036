#pragma once
// The default spectral integration of the wave-optics PSF (K2012 §4.2.4): exact
// per-wavelength PSFs at a few anchor wavelengths, and every spectral sample
// made from its nearest anchors, each rescaled by eq 4.9 only across the small
// step from the anchor to the sample.
//
// Why: eq 4.9 (psf.h spectral_psf_resampled) rescales the one λ0 PSF to every
// wavelength. That is exact for the diffraction pattern of a fixed aperture
// (angles scale with λ), but not for anything whose phase depends on λ
// otherwise — the Fresnel term E of eq 4.6 (defocus, exp(iπr²/(λd))) — nor for
// the resampling across a factor of 2 (380 … 780 nm around 575 nm). With the
// default eye it is 0.49 (relative L2) from the exact path. Here a sample λ
// between the outer anchors is the Lagrange cubic in 1/λ (the variable E's
// phase is linear in) through its four nearest anchors λk,
//
//   F_λ(x) = Σk ℓk(1/λ) · F_λk(x λk/λ) (λk/λ)²,
//
// each term eq 4.9 from λk by separable Lanczos-3; beyond the outer anchors the
// two nearest extrapolate linearly (the nearest alone for a sample under 1% of
// the brightest's weight), and between them a sample under a quarter of the
// brightest's weight is linear in its two nearest. Anchors sit at quantiles of the samples' weight
// (x̄ + ȳ + z̄ of CMF × SPD), so they are dense where the light is.
// docs/glare.md "The spectral path" gives the measured errors and times.
#include <vector>

#include "atonlab/stimuli/eye_model.h"
#include "atonlab/stimuli/psf.h"

namespace atonlab::stimuli {

/// `count` anchor wavelengths (nm, ascending) for these samples: the first and
/// last at the 1% and 99% quantiles of the samples' weight, the others evenly
/// between in that weight, each rounded to the nearest sample's wavelength
/// (duplicates merged). Throws InputError (key "spectral_anchors") for count < 1.
std::vector<double> spectral_anchor_wavelengths(const SpectralSamples& samples, int count);

/// The anchored spectral path: mono_psf_reference() at every anchor, then each
/// sample from its anchors (above), weighted, XYZ → linear Rec.709 clipped at 0,
/// unit luminance sum; on λ0's angular grid like spectral_psf_exact().
RgbPsf spectral_psf_anchored(const EyeModel& eye, int n, const SpectralSamples& samples, int anchors,
                             double time_s = 0.0);

/// The same from anchor PSFs already computed (each on λ0's grid, unit sum,
/// wavelength_nm set, ascending): for tests and the bench.
RgbPsf spectral_psf_from_anchors(const std::vector<MonoPsf>& anchors, const SpectralSamples& samples);

}  // namespace atonlab::stimuli
