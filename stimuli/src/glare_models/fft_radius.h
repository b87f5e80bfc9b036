#pragma once
// The default billboard radius of the FFT models (wave-optics, aperture).
#include "atonlab/stimuli/eye_model.h"
#include "atonlab/stimuli/psf.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {

/// The part of the PSF's field every wavelength covers. Eq 4.9 shrinks the λ0
/// grid by λ/λ0 for the shortest wavelength, so beyond (N/2)·(380/575) texels
/// the blue end of the spectrum is missing.
inline double fft_glare_radius_deg(const GlareSettings& g, double psf_degrees_per_texel) {
    return (g.psf_size / 2 - 1) * psf_degrees_per_texel * SpectralSamples::kFirstNm / kReferenceWavelengthNm;
}

}  // namespace atonlab::stimuli
