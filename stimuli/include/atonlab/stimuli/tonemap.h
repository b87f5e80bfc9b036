#pragma once
// Tone mapping of whole images. The tone curve, its settings and the GPU twin's
// parameters are the GL-free CPU reference in atonlab/display/tonemap.h
// (namespace atonlab::display); what is here needs stimuli's image type.
#include "atonlab/display/tonemap.h"
#include "atonlab/stimuli/image_io.h"

namespace atonlab::stimuli {

/// K2012 eq 4.15 over an HDR image (cd/m²): display::log_average_luminance of its
/// pixels. Throws InputError for an empty image or an ε that is not finite and > 0.
double log_average_luminance(const ImageRGBA32F& image, double epsilon_cd_m2 = display::kLogAverageEpsilonCdM2);

/// display::tonemap_pixel over an image (alpha copied). Validates the settings. scotopic_alpha: the
/// image's alpha is each pixel's scotopic luminance (scotopic cd/m²; FrameRenderer::read_hdr's frames),
/// the CPU reference of the GPU path's scotopic channel; false: derived from RGB.
ImageRGBA32F tonemap_image(const ImageRGBA32F& hdr, double adaptation_cd_m2, const display::ToneMapSettings& s,
                           bool scotopic_alpha = false);

}  // namespace atonlab::stimuli
