// display.out_of_gamut (docs/tone-mapping.md "Out of gamut: colour or luminance") and the
// navigation-light signal-colour areas (COLREGs 1972 Annex I §7).
#include "atonlab/display/gamut.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace atonlab::display {

namespace {

constexpr std::array<std::string_view, 4> kChoiceNames = {"keep-luminance", "keep-signal-colour", "keep-chromaticity",
                                                          "clip-channels"};
constexpr std::array<std::string_view, kSignalColourCount> kColourNames = {"white", "red", "green", "yellow"};

// COLREGs 1972 Annex I §7, "Colour specification of lights": the corner coordinates of each
// colour's area in the CIE 1931 diagram, in the order the Annex lists them (which walks the
// boundary), except red: the Annex lists (0.680, 0.320), (0.660, 0.320), (0.735, 0.265),
// (0.721, 0.259), and joined in that order its edges cross (a bow tie, which the even-odd
// rule counts wrongly). Walked, the last two swap: (0.660, 0.320)-(0.721, 0.259) is the
// purple boundary y = 0.980 - x and (0.735, 0.265)-(0.680, 0.320) runs along the spectrum
// locus.
const std::array<std::vector<glm::dvec2>, kSignalColourCount>& areas() {
    static const std::array<std::vector<glm::dvec2>, kSignalColourCount> a = {{
        {{0.525, 0.382}, {0.525, 0.440}, {0.452, 0.440}, {0.310, 0.348}, {0.310, 0.283}, {0.443, 0.382}},  // white
        {{0.680, 0.320}, {0.660, 0.320}, {0.721, 0.259}, {0.735, 0.265}},                                  // red
        {{0.028, 0.385}, {0.009, 0.723}, {0.300, 0.511}, {0.203, 0.356}},                                  // green
        {{0.612, 0.382}, {0.618, 0.382}, {0.575, 0.425}, {0.575, 0.406}},                                  // yellow
    }};
    return a;
}

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

glm::dvec2 nearest_on_segment(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
    const glm::dvec2 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return a + t * ab;
}

double distance_to_polygon(glm::dvec2 xy, const std::vector<glm::dvec2>& polygon) {
    return glm::length(nearest_point_of_polygon(xy, polygon) - xy);
}

// Sutherland–Hodgman: `subject` clipped to the convex, counter-clockwise `clip`.
std::vector<glm::dvec2> clip_polygon(std::vector<glm::dvec2> subject, const std::vector<glm::dvec2>& clip) {
    for (std::size_t i = 0; i < clip.size() && !subject.empty(); ++i) {
        const glm::dvec2 a = clip[i], b = clip[(i + 1) % clip.size()];
        const auto inside = [&](glm::dvec2 p) { return cross(b - a, p - a) >= 0.0; };
        std::vector<glm::dvec2> out;
        for (std::size_t j = 0; j < subject.size(); ++j) {
            const glm::dvec2 p = subject[j], q = subject[(j + 1) % subject.size()];
            const bool pin = inside(p), qin = inside(q);
            if (pin) out.push_back(p);
            if (pin != qin) {
                const double t = cross(b - a, p - a) / (cross(b - a, p - a) - cross(b - a, q - a));
                out.push_back(p + t * (q - p));
            }
        }
        subject = std::move(out);
    }
    return subject;
}

// The point of polygon `to` nearest polygon `from` (which it does not meet): the nearest of
// `to`'s points nearest each corner of `from`, and of `to`'s corners.
glm::dvec2 nearest_point_between(const std::vector<glm::dvec2>& to, const std::vector<glm::dvec2>& from) {
    glm::dvec2 best(0.0);
    double best_d = std::numeric_limits<double>::infinity();
    for (const glm::dvec2 f : from) {
        const glm::dvec2 p = nearest_point_of_polygon(f, to);
        if (const double d = glm::length(p - f); d < best_d) best_d = d, best = p;
    }
    for (const glm::dvec2 t : to) {
        if (const double d = distance_to_polygon(t, from); d < best_d) best_d = d, best = t;
    }
    return best;
}

glm::dvec2 chromaticity(Vec3 rgb) {
    const Vec3 xyz = linear_rgb_to_xyz(rgb);
    return glm::dvec2(xyz.x, xyz.y) / (xyz.x + xyz.y + xyz.z);
}

// The colour of chromaticity xy at full drive of its largest channel (channels >= 0).
Vec3 full_drive_rgb(glm::dvec2 xy) {
    Vec3 rgb = glm::max(xyz_to_linear_rgb(xyY_to_xyz(Vec3(xy, 1.0))), Vec3(0.0));
    return rgb / std::max(rgb.r, std::max(rgb.g, rgb.b));
}

}  // namespace

std::string_view out_of_gamut_name(OutOfGamut g) {
    return kChoiceNames.at(static_cast<std::size_t>(g));
}

std::optional<OutOfGamut> out_of_gamut_from_name(std::string_view name) {
    for (std::size_t i = 0; i < kChoiceNames.size(); ++i)
        if (kChoiceNames[i] == name) return static_cast<OutOfGamut>(i);
    return std::nullopt;
}

std::vector<std::string> out_of_gamut_names() {
    return {kChoiceNames.begin(), kChoiceNames.end()};
}

std::string_view signal_colour_name(SignalColour c) {
    return kColourNames.at(static_cast<std::size_t>(c));
}

const std::vector<glm::dvec2>& signal_colour_area(SignalColour c) {
    return areas().at(static_cast<std::size_t>(c));
}

std::optional<std::vector<glm::dvec2>> signal_colour_area(std::string_view colour) {
    for (std::size_t i = 0; i < kColourNames.size(); ++i)
        if (kColourNames[i] == colour) return areas()[i];
    return std::nullopt;
}

bool inside_polygon(glm::dvec2 xy, const std::vector<glm::dvec2>& polygon) {
    const std::size_t n = polygon.size();
    if (n == 1) return glm::length(xy - polygon[0]) <= 1e-12;
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

glm::dvec2 nearest_point_of_polygon(glm::dvec2 xy, const std::vector<glm::dvec2>& polygon) {
    if (polygon.size() == 1 || inside_polygon(xy, polygon)) return polygon.size() == 1 ? polygon[0] : xy;
    glm::dvec2 best = polygon[0];
    double best_d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < polygon.size(); ++i) {
        const glm::dvec2 p = nearest_on_segment(xy, polygon[i], polygon[(i + 1) % polygon.size()]);
        if (const double d = glm::length(p - xy); d < best_d) best_d = d, best = p;
    }
    return best;
}

std::vector<glm::dvec2> rec709_gamut_xy() {
    // The primaries' chromaticities, from the matrix that was derived from them (colour.cpp).
    return {chromaticity({1.0, 0.0, 0.0}), chromaticity({0.0, 1.0, 0.0}), chromaticity({0.0, 0.0, 1.0})};
}

const std::vector<glm::dvec2>& displayable_signal_area(SignalColour c) {
    static const std::array<std::vector<glm::dvec2>, kSignalColourCount> shown = [] {
        std::array<std::vector<glm::dvec2>, kSignalColourCount> s;
        const std::vector<glm::dvec2> gamut = rec709_gamut_xy();  // counter-clockwise
        for (std::size_t i = 0; i < s.size(); ++i) {
            s[i] = clip_polygon(areas()[i], gamut);
            if (s[i].size() < 3) s[i] = {nearest_point_between(gamut, areas()[i])};
        }
        return s;
    }();
    return shown.at(static_cast<std::size_t>(c));
}

const std::array<SignalSpan, kSignalColourCount>& signal_colour_spans() {
    static const std::array<SignalSpan, kSignalColourCount> spans = [] {
        std::array<SignalSpan, kSignalColourCount> out{};
        const glm::dvec2 white = chromaticity(Vec3(1.0));
        for (std::size_t i = 1; i < out.size(); ++i) {
            // The corners' directions from the white; the span's ends are the two whose
            // directions every other corner's lies between (the area subtends < 180°).
            const std::vector<glm::dvec2>& area = areas()[i];
            for (const glm::dvec2 a : area)
                for (const glm::dvec2 b : area) {
                    const glm::dvec2 da = glm::normalize(a - white), db = glm::normalize(b - white);
                    bool spans_all = cross(da, db) > 0.0;
                    for (const glm::dvec2 c : area) {
                        const glm::dvec2 dc = c - white;
                        spans_all = spans_all && cross(da, dc) >= -1e-15 && cross(dc, db) >= -1e-15;
                    }
                    if (spans_all) out[i] = {da, db};
                }
        }
        return out;
    }();
    return spans;
}

SignalColour nearest_signal_colour(glm::dvec2 xy) {
    if (inside_polygon(xy, areas()[0])) return SignalColour::white;
    const glm::dvec2 v = xy - chromaticity(Vec3(1.0));
    const double s = glm::length(v);
    if (!(s >= kSignalMinSaturation)) return SignalColour::white;
    const glm::dvec2 u = v / s;
    SignalColour best = SignalColour::white;
    double best_cos = std::cos(kSignalMaxAngleDeg * std::numbers::pi / 180.0);
    for (int i = 1; i < kSignalColourCount; ++i) {
        const SignalSpan& span = signal_colour_spans()[static_cast<std::size_t>(i)];
        // cos of the angle from u to the span: 1 inside it, else to its nearer end.
        const bool inside = cross(span.first, u) >= 0.0 && cross(u, span.last) >= 0.0;
        const double c = inside ? 1.0 : std::max(glm::dot(u, span.first), glm::dot(u, span.last));
        if (c > best_cos) best_cos = c, best = static_cast<SignalColour>(i);
    }
    return best;
}

Vec3 fit_to_gamut(Vec3 rgb, Vec3 w, OutOfGamut choice) {
    for (int c = 0; c < 3; ++c) rgb[c] = rgb[c] > 0.0 ? rgb[c] : 0.0;  // NaN and negatives: black
    const double m = std::max(rgb.r, std::max(rgb.g, rgb.b));
    if (m <= 1.0) return rgb;
    switch (choice) {
        case OutOfGamut::keep_luminance:
            return fit_to_gamut_keeping_luminance(rgb, w);
        case OutOfGamut::clip_channels:
            return glm::min(rgb, Vec3(1.0));
        case OutOfGamut::keep_chromaticity:
            return std::isfinite(m) ? rgb / m : Vec3(rgb.r == m, rgb.g == m, rgb.b == m);
        case OutOfGamut::keep_signal_colour: {
            if (!std::isfinite(m)) return fit_to_gamut_keeping_luminance(rgb, w);
            const SignalColour c = nearest_signal_colour(chromaticity(rgb));
            if (c == SignalColour::white) return fit_to_gamut_keeping_luminance(rgb, w);
            // The area's displayable point nearest the pixel's chromaticity, as bright as the
            // display gives it there but no brighter than the pixel asked for.
            const Vec3 full = full_drive_rgb(nearest_point_of_polygon(chromaticity(rgb), displayable_signal_area(c)));
            return full * std::min(1.0, glm::dot(w, rgb) / glm::dot(w, full));
        }
    }
    return fit_to_gamut_keeping_luminance(rgb, w);
}

std::string signal_colour_areas_glsl() {
    const auto num = [](double v) { return fmt::format("{:.17e}LF", v); };  // always a double literal
    const auto polygon = [&](const std::vector<glm::dvec2>& p) {
        // The shader's tables hold 8 corners (a shorter polygon repeats its last); clipping an area by the
        // gamut triangle can add up to 3 corners, so more than 8 is an error here, not a truncated area.
        if (p.empty() || p.size() > 8)
            throw std::logic_error(
                fmt::format("a signal-colour area has {} corners; the GLSL tables hold 1 to 8", p.size()));
        std::string s;
        for (std::size_t i = 0; i < 8; ++i) {
            const glm::dvec2 v = p[std::min(i, p.size() - 1)];
            s += fmt::format("{}dvec2({}, {})", i ? ", " : "", num(v.x), num(v.y));
        }
        return s;
    };
    std::string s =
        "// Generated by signal_colour_areas_glsl() (display/src/gamut.cpp): the COLREGs signal-colour\n"
        "// areas (white, red, green, yellow), their displayable parts in the Rec.709 triangle, each\n"
        "// padded to 8 corners with its last, and the Rec.709 matrices (rows).\n";
    s += "const int SIGNAL_AREA_CORNERS[4] = int[4](";
    for (int i = 0; i < kSignalColourCount; ++i) s += fmt::format("{}{}", i ? ", " : "", areas()[i].size());
    s += ");\nconst int SIGNAL_SHOWN_CORNERS[4] = int[4](";
    for (int i = 0; i < kSignalColourCount; ++i)
        s += fmt::format("{}{}", i ? ", " : "", displayable_signal_area(static_cast<SignalColour>(i)).size());
    s += ");\nconst dvec2 SIGNAL_AREA[32] = dvec2[32](";
    for (int i = 0; i < kSignalColourCount; ++i) s += (i ? ",\n    " : "\n    ") + polygon(areas()[i]);
    s += ");\nconst dvec2 SIGNAL_SHOWN[32] = dvec2[32](";
    for (int i = 0; i < kSignalColourCount; ++i)
        s += (i ? ",\n    " : "\n    ") + polygon(displayable_signal_area(static_cast<SignalColour>(i)));
    s += ");\n";
    const auto matrix = [&](std::string_view name, const Mat3& m) {
        // glm is column-major (m[column][row]); a GLSL dmat3 constructor takes columns too.
        std::string t = fmt::format("const dmat3 {} = dmat3(", name);
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) t += fmt::format("{}{}", c + r ? ", " : "", num(m[c][r]));
        return t + ");\n";
    };
    s += "const dvec2 SIGNAL_SPAN_FIRST[4] = dvec2[4](";
    for (int i = 0; i < kSignalColourCount; ++i) {
        const glm::dvec2 v = signal_colour_spans()[static_cast<std::size_t>(i)].first;
        s += fmt::format("{}dvec2({}, {})", i ? ", " : "", num(v.x), num(v.y));
    }
    s += ");\nconst dvec2 SIGNAL_SPAN_LAST[4] = dvec2[4](";
    for (int i = 0; i < kSignalColourCount; ++i) {
        const glm::dvec2 v = signal_colour_spans()[static_cast<std::size_t>(i)].last;
        s += fmt::format("{}dvec2({}, {})", i ? ", " : "", num(v.x), num(v.y));
    }
    const glm::dvec2 white = chromaticity(Vec3(1.0));
    s += fmt::format(");\nconst dvec2 SIGNAL_WHITE = dvec2({}, {});\n", num(white.x), num(white.y));
    s += fmt::format("const double SIGNAL_MIN_SATURATION = {};\n", num(kSignalMinSaturation));
    s += fmt::format("const double SIGNAL_MAX_ANGLE_COS = {};\n",
                     num(std::cos(kSignalMaxAngleDeg * std::numbers::pi / 180.0)));
    s += matrix("SIGNAL_RGB_TO_XYZ", rec709_rgb_to_xyz());
    s += matrix("SIGNAL_XYZ_TO_RGB", rec709_xyz_to_rgb());
    return s;
}

}  // namespace atonlab::display
