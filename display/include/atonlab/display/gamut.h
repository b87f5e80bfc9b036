#pragma once
// What the display shows of a colour it cannot show: the choice `display.out_of_gamut`
// (docs/tone-mapping.md "Out of gamut: colour or luminance"), and the navigation-light
// signal-colour areas that one of its choices keeps.
//
// The areas are those of the International Regulations for Preventing Collisions at Sea
// (COLREGs 1972, Annex I §7, "Colour specification of lights"), as corners in CIE 1931 xy:
// the CIE areas for signal lights (CIE S 004/E-2001), narrowed for ships. IALA
// Recommendation E-200-1 gives its own areas for marine aids to navigation, after the
// CIE's; they were not at hand, so COLREGs' corners serve both here.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/display/colour.h"

namespace atonlab::display {

/// `display.out_of_gamut`: what happens to a pixel with a channel above full drive.
enum class OutOfGamut : std::uint32_t {
    keep_luminance = 0,      ///< towards the grey of its own luminance; white beyond white (the default)
    keep_signal_colour = 1,  ///< the chromaticity into its signal-colour area as far as the gamut allows
    keep_chromaticity = 2,   ///< scaled down until it fits: colour kept, luminance lost
    clip_channels = 3,       ///< each channel clipped at full drive (pfstools): the hue shifts
};
std::string_view out_of_gamut_name(OutOfGamut g);  ///< "keep-luminance", ...
std::optional<OutOfGamut> out_of_gamut_from_name(std::string_view name);
std::vector<std::string> out_of_gamut_names();

/// The navigation-light colours with a COLREGs area. Blue has none.
enum class SignalColour : int { white = 0, red = 1, green = 2, yellow = 3 };
inline constexpr int kSignalColourCount = 4;
std::string_view signal_colour_name(SignalColour c);  ///< "white", "red", "green", "yellow"

/// The chromaticity area (CIE 1931 xy, corners in boundary order) of a navigation light
/// of colour "white", "green", "red" or "yellow" (COLREGs 1972 Annex I §7); nullopt for any
/// other name (blue has no area there).
std::optional<std::vector<glm::dvec2>> signal_colour_area(std::string_view colour);
const std::vector<glm::dvec2>& signal_colour_area(SignalColour c);

/// Whether xy lies inside (or on the edge of) a simple polygon, convex or not.
bool inside_polygon(glm::dvec2 xy, const std::vector<glm::dvec2>& polygon);
/// Whether two simple polygons overlap (share any point).
bool polygons_overlap(const std::vector<glm::dvec2>& a, const std::vector<glm::dvec2>& b);
/// The point of a polygon (inside or on its edge) nearest xy: xy itself when inside; a
/// one-corner polygon is that point.
glm::dvec2 nearest_point_of_polygon(glm::dvec2 xy, const std::vector<glm::dvec2>& polygon);

/// The Rec.709 gamut triangle in xy (red, green, blue primaries).
std::vector<glm::dvec2> rec709_gamut_xy();

/// The part of a colour's area the display can show: the area clipped to the Rec.709
/// triangle (Sutherland–Hodgman), or, where they do not meet (red and yellow), the one
/// point of the triangle nearest the area.
const std::vector<glm::dvec2>& displayable_signal_area(SignalColour c);

/// The signal colour a chromaticity is taken for (docs/tone-mapping.md "Which light a pixel
/// belongs to"): white inside white's area, or less than kSignalMinSaturation from the display's
/// white (D65) in xy; else the coloured area (red, green, yellow) whose span of hue angles, as
/// seen from the white, lies nearest its own, if within kSignalMaxAngleDeg; else white.
SignalColour nearest_signal_colour(glm::dvec2 xy);
inline constexpr double kSignalMinSaturation = 0.05;  ///< xy distance from D65
inline constexpr double kSignalMaxAngleDeg = 15.0;    ///< hue angle beyond a colour's span

/// A coloured area's span of directions from the white: unit vectors, counter-clockwise from
/// `first` to `last` (white's entry is unused).
struct SignalSpan {
    glm::dvec2 first{0.0}, last{0.0};
};
const std::array<SignalSpan, kSignalColourCount>& signal_colour_spans();

/// Brings relative linear Rec.709 RGB (1 = full drive) into the gamut by `choice`, with
/// `channel_weights` the display's luminance per unit of each channel (summing to 1).
/// NaN and negative channels are black; a colour with no channel above 1 is returned
/// as it is under every choice. keep_luminance is fit_to_gamut_keeping_luminance.
Vec3 fit_to_gamut(Vec3 rgb, Vec3 channel_weights, OutOfGamut choice);

/// The GLSL twin's constants (the areas, the displayable areas, the Rec.709 matrices),
/// for the shader include "signal_colour_areas.glsl" (display_encode.glsl).
std::string signal_colour_areas_glsl();

}  // namespace atonlab::display
