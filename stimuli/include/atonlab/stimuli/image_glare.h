#pragma once
// Glare added to an HDR image that atonlab did not render (`atonlab glare`,
// docs/tone-mapping.md "HDR images in and out"): the image is convolved with
// the glare model's kernel (glare_kernel.h) at the image's own degrees per
// pixel, on the CPU in double precision (FFTW), no GL.
//
// Units: pixel values are luminance (cd/m²; any linear scale works). The image
// is taken as a flat grid of equal solid angles Ω = (degrees_per_pixel · π/180)²
// sr (the small-angle approximation; at the edge of a 60° wide perspective
// image a pixel's true Ω is ~25% smaller). Each kernel channel sums to 1, so the
// convolution keeps Σ L·Ω per channel; what the kernel carries beyond the
// image's edge is lost and reported (edge_cut), as is what the kernel's window
// cut before its renormalisation (window_cut, K2012 §4.2.5).
#include <glm/glm.hpp>
#include <string>

#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {

/// The kernel of a glare model for an image of degrees_per_pixel, adapted to
/// adaptation_cd_m2 (the pupil by K2012 eq 3.15 unless glare.pupil_mm is set,
/// Spencer's vision class): wave-optics (the CPU spectral path, `anchored` or
/// `exact`; `rescaled` runs on the GPU and is taken as `anchored`), gaussian-bloom,
/// spencer, and cie (the CIE glare spread function as a radial kernel, radius_deg or by
/// default 20°). The spectrum is D65. Throws InputError (key "model") for none
/// and aperture, and the kernel builders' errors (radius, size).
GlareKernel image_glare_kernel(const GlareSettings& glare, double adaptation_cd_m2, double degrees_per_pixel);

struct ImageGlareResult {
    ImageRGBA32F image;        ///< same size as the input; alpha copied
    glm::dvec3 input_sum{0};   ///< Σ L per channel of the input (× Ω for Σ L·Ω)
    glm::dvec3 output_sum{0};  ///< Σ L per channel of the output
    /// Per channel, the fraction of the input's Σ L·Ω that the convolution
    /// carried beyond the image's edge: (Σ full convolution − Σ inside) / Σ input
    /// (0 for a black channel).
    glm::dvec3 edge_cut{0};
};

/// Convolves each channel (R, G, B) with the kernel's channel by FFT in double
/// (linear, zero outside the image). Negative and non-finite inputs are taken
/// as 0. Throws InputError when the padded transform would exceed 8192 px a side.
ImageGlareResult convolve_image_glare(const ImageRGBA32F& hdr, const GlareKernel& kernel);

}  // namespace atonlab::stimuli
