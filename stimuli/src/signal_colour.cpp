#include "atonlab/stimuli/signal_colour.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "atonlab/display/colour.h"

namespace atonlab::stimuli {

glm::dvec2 uv_prime(glm::dvec3 xyz) {
    const double d = xyz.x + 15.0 * xyz.y + 3.0 * xyz.z;
    if (!(d > 0.0)) return glm::dvec2(0.0);
    return {4.0 * xyz.x / d, 9.0 * xyz.y / d};
}

glm::dvec3 displayed_xyz(const display::DisplayModel& display, glm::ivec3 code, int bits) {
    const glm::dvec3 y = display::displayed_luminance_rgb(display, code, bits);
    const glm::dvec3 weights = glm::dvec3(display::luminance_of_linear_rgb({1, 0, 0}), display::luminance_of_linear_rgb({0, 1, 0}),
                                          display::luminance_of_linear_rgb({0, 0, 1}));
    return display::linear_rgb_to_xyz(y / weights);
}

SignalColourCheck check_signal_colour(std::string_view colour, glm::dvec3 displayed, glm::dvec3 photopic) {
    const std::optional<std::vector<glm::dvec2>> area = signal_colour_area(colour);
    if (!area)
        throw std::invalid_argument("no navigation-light chromaticity area for the colour \"" + std::string(colour) +
                                    "\" (white, green, red or yellow)");
    SignalColourCheck c;
    c.displayed_uv = uv_prime(displayed);
    c.photopic_uv = uv_prime(photopic);
    c.delta_uv = glm::length(c.displayed_uv - c.photopic_uv);
    c.area_meets_gamut = polygons_overlap(*area, rec709_gamut_xy());
    const double sum = displayed.x + displayed.y + displayed.z;
    c.inside_area = sum > 0.0 && inside_polygon(glm::dvec2(displayed.x, displayed.y) / sum, *area);
    return c;
}

}  // namespace atonlab::stimuli
