#pragma once
// The extended reference (scene.h Disc; docs/scene-file.md "[[disc]]"): where a
// uniform disc of visual angle falls on the image and how much of each pixel
// it covers. The CPU reference of shaders/disc.frag, in double precision;
// tests compare the two.
//
// A pixel's coverage is clamp(0.5 − (θ − r) / |∇θ|, 0, 1): θ the angle between
// the ray through the pixel's centre and the disc's centre direction, r half
// the diameter, |∇θ| how much θ changes across one pixel (central differences
// over ±0.5 px in x and y). For an edge crossing the pixel parallel to its
// sides this is exactly the area the disc covers; for other orientations it is
// the usual first-order area estimate, exact at the pixel's centre line, so the
// disc's edge falls where its diameter says, to a small fraction of a pixel.
#include <glm/glm.hpp>

#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {

/// The disc's centre direction in view space (unit; the camera looks down −z),
/// or zero when its position is the eye's (then it draws nothing).
glm::dvec3 disc_direction_view(const Disc& disc, const CameraProjection& p);

/// The angle (rad) between the view ray through window point `window_px`
/// (pixels, origin lower-left; a pixel's centre is at x + 0.5, y + 0.5) and the
/// unit view-space direction `centre_view`.
double ray_angle_rad(const CameraProjection& p, glm::dvec2 window_px, glm::dvec3 centre_view);

/// The fraction (0 to 1) of pixel (x, y), window coordinates, that a disc of
/// angular radius radius_rad around centre_view covers (see above).
double disc_coverage(const CameraProjection& p, glm::dvec3 centre_view, double radius_rad, int x, int y);

/// The scene's discs drawn over `hdr` (cd/m², linear Rec.709, row 0 at the top),
/// in order, as FrameRenderer draws them: L = (1 − c) L_below + c L_disc.
void draw_discs_cpu(ImageRGBA32F& hdr, const Scene& scene, const CameraProjection& p);

}  // namespace atonlab::stimuli
