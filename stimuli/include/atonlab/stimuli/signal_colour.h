#pragma once
// Is a displayed navigation light still the colour it signals? The check of
// docs/tone-mapping.md "Colour at night": the displayed chromaticity of a
// light's core (the code values decoded through the display model) must stay
// within Δu′v′ ≤ 0.01 of its photopic rendering (the same frame with the
// blueshift off), and inside the chromaticity area of its colour wherever that
// area meets the display's gamut.
//
// The areas are those the International Regulations for Preventing Collisions
// at Sea (COLREGs 1972, Annex I §7) give for navigation lights, as corners in
// CIE 1931 xy: the CIE areas for signal lights, narrowed for ships.
#include <glm/glm.hpp>
#include <optional>
#include <string_view>
#include <vector>

#include "atonlab/display/display_model.h"
#include "atonlab/display/gamut.h"

namespace atonlab::stimuli {

// The areas and their geometry live with the display's gamut choice (display/gamut.h).
using display::inside_polygon;
using display::polygons_overlap;
using display::rec709_gamut_xy;
using display::signal_colour_area;

/// CIE 1976 u′v′ of an XYZ (u′ = 4X/(X+15Y+3Z), v′ = 9Y/(X+15Y+3Z)); (0, 0) for black.
glm::dvec2 uv_prime(glm::dvec3 xyz);

/// What the display emits for a code triple, as CIE XYZ (cd/m² in Y): each
/// channel's emitted luminance (displayed_luminance_rgb) over its Rec.709
/// luminance weight is its linear drive on the absolute scale, and the Rec.709
/// matrix gives XYZ. The display's primaries are Rec.709 (DisplayModel's).
glm::dvec3 displayed_xyz(const display::DisplayModel& display, glm::ivec3 code, int bits);

/// One light's check.
struct SignalColourCheck {
    glm::dvec2 displayed_uv{0.0};   ///< u′v′ of the light's displayed core
    glm::dvec2 photopic_uv{0.0};    ///< u′v′ of the same core rendered without blueshift
    double delta_uv = 0.0;          ///< |displayed − photopic| in u′v′
    bool area_meets_gamut = false;  ///< the colour's area overlaps the Rec.709 gamut
    bool inside_area = false;       ///< the displayed core's xy lies in the area
    /// Δu′v′ within `tolerance`, and inside the area wherever the area meets the gamut.
    bool passes(double tolerance = 0.01) const { return delta_uv <= tolerance && (!area_meets_gamut || inside_area); }
};

/// The check of a light of `colour` ("white", "green", "red", "yellow") whose
/// core was displayed as `displayed_xyz` and, in the photopic rendering, as
/// `photopic_xyz` (XYZ of what the light adds: the core minus the background).
/// Throws std::invalid_argument for a colour without an area.
SignalColourCheck check_signal_colour(std::string_view colour, glm::dvec3 displayed_xyz, glm::dvec3 photopic_xyz);

}  // namespace atonlab::stimuli
