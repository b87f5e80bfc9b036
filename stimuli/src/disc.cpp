#include "atonlab/stimuli/disc.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace atonlab::stimuli {

glm::dvec3 disc_direction_view(const Disc& disc, const CameraProjection& p) {
    const glm::dvec3 v = p.view_from_world(disc.position_m - p.eye_position_m);
    const double n = glm::length(v);
    return n > 0.0 && std::isfinite(n) ? v / n : glm::dvec3(0.0);
}

double ray_angle_rad(const CameraProjection& p, glm::dvec2 window_px, glm::dvec3 centre_view) {
    const glm::dvec2 principal{0.5 * p.width_px, 0.5 * p.height_px};
    const glm::dvec3 d = glm::normalize(glm::dvec3((window_px - principal) / p.focal_px, -1.0));
    // atan2 of |d × c| and d · c: accurate at small angles, where acos is not.
    return std::atan2(glm::length(glm::cross(d, centre_view)), glm::dot(d, centre_view));
}

double disc_coverage(const CameraProjection& p, glm::dvec3 centre_view, double radius_rad, int x, int y) {
    if (!(radius_rad > 0.0) || glm::length(centre_view) == 0.0) return 0.0;
    const glm::dvec2 c{x + 0.5, y + 0.5};
    const double theta = ray_angle_rad(p, c, centre_view);
    const double gx = ray_angle_rad(p, c + glm::dvec2(0.5, 0.0), centre_view) -
                      ray_angle_rad(p, c - glm::dvec2(0.5, 0.0), centre_view);
    const double gy = ray_angle_rad(p, c + glm::dvec2(0.0, 0.5), centre_view) -
                      ray_angle_rad(p, c - glm::dvec2(0.0, 0.5), centre_view);
    const double w = std::hypot(gx, gy);  // rad per pixel across the edge
    if (!(w > 0.0)) return theta <= radius_rad ? 1.0 : 0.0;
    return std::clamp(0.5 - (theta - radius_rad) / w, 0.0, 1.0);
}

void draw_discs_cpu(ImageRGBA32F& hdr, const Scene& scene, const CameraProjection& p) {
    for (const Disc& disc : scene.discs) {
        const glm::dvec3 centre = disc_direction_view(disc, p);
        const double radius = 0.5 * disc.diameter_deg * std::numbers::pi / 180.0;
        const glm::dvec3 rgb = disc.rgb_per_cd_m2 * disc.luminance_cd_m2;
        for (int y = 0; y < hdr.height; ++y)
            for (int x = 0; x < hdr.width; ++x) {
                const double c = disc_coverage(p, centre, radius, x, hdr.height - 1 - y);
                if (c <= 0.0) continue;
                float* px = hdr.pixel(x, y);
                for (int k = 0; k < 3; ++k) px[k] = static_cast<float>((1.0 - c) * px[k] + c * rgb[k]);
            }
    }
}

}  // namespace atonlab::stimuli
