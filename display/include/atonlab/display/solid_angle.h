#pragma once
// The solid angle a pixel of a flat screen subtends at the eye: the one home
// of that geometry (the observer's window sums, protocols/observer.h; the
// renderer's light footprints and veiling glare, stimuli/footprint.h).

namespace atonlab::display {

/// Exact solid angle (sr) that the pixel [x0, x0+1] × [y0, y0+1] subtends at
/// the eye (or a pinhole camera's centre), pixel coordinates relative to the
/// point straight ahead of it (the principal point) on a flat pixel grid at
/// focal length focal_px (pixels: the viewing distance in pixel pitches,
/// DisplayGeometry::focal_px()). The rectangle [0,x]×[0,y] on the plane z = f
/// subtends atan(x y / (f √(x² + y² + f²))) at the origin (the sum of its two
/// triangles' solid angles, Van Oosterom & Strackee 1983, IEEE Trans. Biomed.
/// Eng. BME-30:125); a pixel is the four corners' signed sum. About
/// (1/f)² cos³θ at θ off-axis.
double pixel_solid_angle_sr(double x0, double y0, double focal_px);

}  // namespace atonlab::display
