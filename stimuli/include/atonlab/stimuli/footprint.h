#pragma once
// Where a light's direct image lands on the pixel grid, and how much of each
// pixel it covers: the CPU reference of shaders/footprint.glsl.
//
// K2012 eq 4.5 attenuates a sub-pixel light's radiance by its projected area
// in pixels so the energy reaching the image is continuous. We generalise it
// so that Σ L·Ω over the image equals the illuminance at the eye exactly
// (docs/architecture.md "Physical invariants"), at any size and anywhere in the field:
//  - the footprint area A (px²) is the light's solid angle times f²/cos³α
//    (the image-plane area of a small solid angle seen α off-axis);
//  - A >= 1 px²: a disc of that area (the sphere's projection, K2012 §4.1.3);
//  - A < 1 px²: a 1×1 px box centred on the projected centre (Persson's
//    minimum pixel size, K2012 eq 4.5), i.e. bilinear weights over 2×2 pixels,
//    which keeps the total constant as the light moves (no flicker);
//  - each pixel receives L = E · c / (max(A, 1) · Ω_pixel), c its covered area
//    (px²); the footprint holds max(A, 1) px² in all.
#include <glm/glm.hpp>

namespace atonlab::stimuli {

/// Exact area (px²) of the intersection of a disc (centre cx, cy, radius r, in
/// pixels) with the pixel square [x0, x0+1] × [y0, y0+1].
double disc_pixel_coverage(double cx, double cy, double r, double x0, double y0);

/// Area (px²) of the overlap of the unit square centred at (cx, cy) with the
/// pixel square [x0, x0+1] × [y0, y0+1] (bilinear weight).
double box_pixel_coverage(double cx, double cy, double x0, double y0);

/// Solid angle (sr) of the light sphere of radius r at distance d: 2π(1 − cos β),
/// sin β = r/d, written to stay accurate for r ≪ d. Returns 2π for d <= r.
double sphere_solid_angle_sr(double radius_m, double distance_m);

/// Exact solid angle (sr) of the pinhole pixel [x0, x0+1] × [y0, y0+1] (pixel
/// coordinates relative to the principal point) for focal length f (px).
double pixel_solid_angle_sr(double x0, double y0, double focal_px);

/// A light's image on the pixel grid.
struct Footprint {
    bool visible = false;      ///< the light's whole sphere in front of the camera's plane (view depth > radius)
    glm::dvec2 centre_px{0};   ///< projected centre, pixel coordinates (origin at the image's lower-left corner)
    double area_px2 = 0;       ///< footprint area A
    double radius_px = 0;      ///< disc radius sqrt(A/π) (disc footprints)
    bool disc = false;         ///< A >= 1 px²: disc; else unit box
};

/// light_view_m: the light centre in camera space (camera looks down −z), metres.
/// width/height: image size in pixels; focal_px: f = (h/2)/tan(fov_y/2).
Footprint light_footprint(glm::dvec3 light_view_m, double radius_m, double focal_px, int width, int height);

}  // namespace atonlab::stimuli
