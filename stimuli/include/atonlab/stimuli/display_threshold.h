#pragma once
// How little light a display cannot show (docs/bench.md "Skips"): the largest
// luminance that a light may add to a pixel without moving that pixel's code
// value by more than a given fraction of a code, before dither. The frame
// renderer's display skips (frame_renderer.h, DisplaySkips) leave out lights
// and glare tails that stay below it. CPU, double precision, no GL.
#include <glm/glm.hpp>

#include "atonlab/stimuli/output_settings.h"

namespace atonlab::stimuli {

/// The code value of each channel before dither and rounding: V · (2^bits − 1),
/// V the drive that makes channel c emit relative_rgb[c] · L_c(1), clipped to
/// [L_c(0), L_c(1)] (exactly what encode_pixel() quantises). NaN counts as 0.
glm::dvec3 continuous_codes(const display::DisplayModel& display, glm::dvec3 relative_rgb, int bits);

/// The largest luminance ΔY (cd/m²) of colour rgb_per_cd (linear Rec.709, any
/// scale; normalised here to Y = 1) that, added to a uniform D65 background
/// (R = G = B) of any luminance L_b ≥ floor_cd_m2, moves no channel's
/// continuous code by more than `codes`:
///     max over L_b, c of |code_c(L_b + ΔY · colour) − code_c(L_b)| ≤ codes,
/// through out.tonemap at adaptation L_wa (cd/m²) and out.display at
/// out.encode.bits. The maximum over backgrounds is taken at L_b = floor and on
/// a log grid of 16 points per decade from max(floor, 1e-7) to 1e10 cd/m² (the
/// tone curves are steepest at their dark end, which the grid starts at); ΔY
/// is bracketed by decades and bisected to 1% (rounded down). Returns 0 when
/// even 1e-12 cd/m² moves a code too far, and 1e12 when nothing below it does.
/// The rods see what the frame's scotopic channel carries (docs/tone-mapping.md
/// "The scotopic channel"): the background's S/P × L_b plus the light's S/P ×
/// ΔY (light_s_p_ratio), as the GPU tone mapper reads them.
double invisible_luminance_cd_m2(const OutputSettings& out, double adaptation_cd_m2, double floor_cd_m2,
                                 glm::dvec3 rgb_per_cd, double light_s_p, double background_s_p, double codes);

}  // namespace atonlab::stimuli
