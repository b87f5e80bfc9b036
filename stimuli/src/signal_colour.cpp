#include "atonlab/stimuli/signal_colour.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "atonlab/display/colour.h"

namespace atonlab::stimuli {

namespace {

// COLREGs 1972 Annex I §7, "Colour specification of lights": the corner
// coordinates of each colour's area in the CIE 1931 diagram, in the order the
// Annex lists them (which walks the boundary), except red: the Annex lists
// (0.680, 0.320), (0.660, 0.320), (0.735, 0.265), (0.721, 0.259), and joined in
// that order its edges cross (a bow tie, which the even-odd rule below counts
// wrongly). Walked, the last two swap: (0.660, 0.320)-(0.721, 0.259) is the
// purple boundary y = 0.980 - x and (0.735, 0.265)-(0.680, 0.320) runs along
// the spectrum locus.
const std::vector<glm::dvec2> kWhite = {{0.525, 0.382}, {0.525, 0.440}, {0.452, 0.440},
                                        {0.310, 0.348}, {0.310, 0.283}, {0.443, 0.382}};
const std::vector<glm::dvec2> kGreen = {{0.028, 0.385}, {0.009, 0.723}, {0.300, 0.511}, {0.203, 0.356}};
const std::vector<glm::dvec2> kRed = {{0.680, 0.320}, {0.660, 0.320}, {0.721, 0.259}, {0.735, 0.265}};
const std::vector<glm::dvec2> kYellow = {{0.612, 0.382}, {0.618, 0.382}, {0.575, 0.425}, {0.575, 0.406}};

double cross(glm::dvec2 a, glm::dvec2 b) {
    return a.x * b.y - a.y * b.x;
}

bool on_segment(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
    constexpr double kEps = 1e-12;
    return std::abs(cross(b - a, p - a)) <= kEps && p.x >= std::min(a.x, b.x) - kEps &&
           p.x <= std::max(a.x, b.x) + kEps && p.y >= std::min(a.y, b.y) - kEps && p.y <= std::max(a.y, b.y) + kEps;
}

bool segments_cross(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, glm::dvec2 d) {
    const double d1 = cross(d - c, a - c), d2 = cross(d - c, b - c);
    const double d3 = cross(b - a, c - a), d4 = cross(b - a, d - a);
    if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
    return on_segment(a, c, d) || on_segment(b, c, d) || on_segment(c, a, b) || on_segment(d, a, b);
}

}  // namespace

std::optional<std::vector<glm::dvec2>> signal_colour_area(std::string_view colour) {
    if (colour == "white") return kWhite;
    if (colour == "green") return kGreen;
    if (colour == "red") return kRed;
    if (colour == "yellow") return kYellow;
    return std::nullopt;
}

bool inside_polygon(glm::dvec2 xy, const std::vector<glm::dvec2>& polygon) {
    const std::size_t n = polygon.size();
    bool inside = false;
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
        const glm::dvec2 a = polygon[i], b = polygon[j];
        if (on_segment(xy, a, b)) return true;
        // Even-odd rule: count the edges a ray towards +x crosses.
        if ((a.y > xy.y) != (b.y > xy.y) && xy.x < (b.x - a.x) * (xy.y - a.y) / (b.y - a.y) + a.x) inside = !inside;
    }
    return inside;
}

bool polygons_overlap(const std::vector<glm::dvec2>& a, const std::vector<glm::dvec2>& b) {
    for (std::size_t i = 0; i < a.size(); ++i)
        for (std::size_t j = 0; j < b.size(); ++j)
            if (segments_cross(a[i], a[(i + 1) % a.size()], b[j], b[(j + 1) % b.size()])) return true;
    // No edges cross: one lies wholly inside the other, or they are apart.
    return inside_polygon(a.front(), b) || inside_polygon(b.front(), a);
}

std::vector<glm::dvec2> rec709_gamut_xy() {
    return {{0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}};
}

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
