#pragma once
// The observer's display as geometry: its pixels, the visible picture's size and
// the viewing distance. Scenes render for it (stimuli::Scene::display) and a
// calibration records it (runner/src/calibrate/calibration_record.h).
#include <optional>
#include <string>

namespace atonlab::display {

/// The display's size, resolution and viewing distance. With square pixels and a
/// veridical camera the pinhole's focal length in pixels is
/// viewing_distance * width_px / width_m.
struct DisplayGeometry {
    DisplayGeometry() = default;
    /// {width_px, height_px, width_m, viewing_distance_m}, and the measured height when there is one.
    DisplayGeometry(int width_px_, int height_px_, double width_m_, double viewing_distance_m_,
                    std::optional<double> measured_height_m_ = std::nullopt)
        : width_px(width_px_),
          height_px(height_px_),
          width_m(width_m_),
          viewing_distance_m(viewing_distance_m_),
          measured_height_m(measured_height_m_) {}

    int width_px = 1920;
    int height_px = 1080;
    double width_m = 0.598;           ///< visible width of the picture, metres
    double viewing_distance_m = 0.9;  ///< eye to screen, metres
    /// Visible height of the picture when it was measured (`atonlab calibrate
    /// --height-m`), metres; unset: square pixels.
    std::optional<double> measured_height_m;

    /// measured_height_m, else width_m · height_px / width_px (square pixels), metres.
    double height_m() const { return measured_height_m.value_or(width_m * height_px / width_px); }
    double focal_px() const { return viewing_distance_m * width_px / width_m; }
    double fov_x_rad() const;                    ///< visual angle the display subtends horizontally
    double fov_y_rad() const;                    ///< ... vertically
    double pixels_per_degree_at_centre() const;  ///< focal_px · π/180 (small-angle, at the centre)
    /// Pixels per degree of visual angle at the screen's centre, exactly: one
    /// pixel of pitch p = width_m / width_px subtends 2 atan(p / 2d) there.
    double pixels_per_degree() const;
    /// "1920 x 1080 px, 0.598 x 0.336 m at 0.9 m: 42.1 px/deg at the centre".
    std::string describe() const;
};

}  // namespace atonlab::display
