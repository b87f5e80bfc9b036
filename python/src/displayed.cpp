// What a Frame's display shows (docs/python.md "What the observer sees"): the
// display as numbers, the codes decoded through its model to the luminance
// each pixel shows, and the light a judged light adds within the observer's
// window, computed by the same code as `atonlab check` (displayability.h).
#include <pybind11/eval.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "atonlab/common/input_error.h"
#include "atonlab/display/colour.h"
#include "atonlab/display/display_encodings.h"
#include "atonlab/protocols/observer.h"
#include "atonlab/runner/session/scene_queries.h"
#include "atonlab/runner/session/stimulus_renderer.h"
#include "atonlab/stimuli/signal_colour.h"
#include "bindings.h"

namespace atonlab::python {

namespace {

/// Frame.display's type: a dict whose key "transfer" (the old name of "encoding")
/// still reads "encoding", with a DeprecationWarning.
py::object display_dict_type() {
    static const py::object* type = [] {
        py::dict scope;
        py::exec(R"(
import warnings

class DisplayDict(dict):
    """Frame.display: "transfer" is the deprecated old name of "encoding"."""

    def _key(self, key):
        if key == "transfer":
            warnings.warn('Frame.display["transfer"] is deprecated; read ["encoding"]', DeprecationWarning,
                          stacklevel=3)
            return "encoding"
        return key

    def __getitem__(self, key):
        return dict.__getitem__(self, self._key(key))

    def get(self, key, default=None):
        return dict.get(self, self._key(key), default)

    def __contains__(self, key):
        return dict.__contains__(self, self._key(key))
)",
                 scope);
        return new py::object(scope["DisplayDict"]);  // kept for the process: no destructor after Python's end
    }();
    return *type;
}

}  // namespace

py::dict display_dict(const stimuli::Scene& scene, int bits) {
    const display::DisplayModel& m = scene.output.display;
    py::dict d = display_dict_type()();
    d["name"] = m.name;
    d["peak_cd_m2"] = m.peak_cd_m2;
    d["black_cd_m2"] = m.black_cd_m2;
    std::vector<std::string> encoding;
    py::list white, black;
    for (const display::ChannelEncoding& c : m.channels) {
        encoding.emplace_back(c.encoding->name);
        white.append(c.max_cd_m2());
        black.append(c.min_cd_m2());
    }
    // One law for all three channels (every display but a mixed calibration): its name.
    if (encoding[0] == encoding[1] && encoding[1] == encoding[2])
        d["encoding"] = encoding[0];
    else
        d["encoding"] = encoding;
    d["channel_white_cd_m2"] = white;
    d["channel_black_cd_m2"] = black;
    d["bits"] = bits;
    // The channels' chromaticities: the display's primaries are Rec.709's with a D65 white
    // (display_model.h, signal_colour.h displayed_xyz).
    const std::vector<glm::dvec2> gamut = stimuli::rec709_gamut_xy();
    py::dict primaries;
    const char* names[] = {"red", "green", "blue"};
    for (std::size_t i = 0; i < 3; ++i) primaries[names[i]] = py::make_tuple(gamut[i].x, gamut[i].y);
    const glm::dvec2 white_xy = display::d65_white_xy();
    primaries["white"] = py::make_tuple(white_xy.x, white_xy.y);
    d["primaries_xy"] = primaries;
    const display::DisplayGeometry& g = scene.display;
    d["width_px"] = g.width_px;
    d["height_px"] = g.height_px;
    d["width_m"] = g.width_m;
    d["viewing_distance_m"] = g.viewing_distance_m;
    d["focal_px"] = g.focal_px();
    return d;
}

py::array displayed_cd_m2(const py::array& codes, const display::DisplayModel& model, int bits) {
    // Each channel emits by its own code alone (display_model.h: the channels
    // add), so one table per channel over the 2^bits codes decodes the frame.
    const std::size_t levels = std::size_t{1} << bits;
    std::vector<float> table(3 * levels);
    for (std::size_t v = 0; v < levels; ++v) {
        const int code = static_cast<int>(v);
        const glm::dvec3 rgb = display::displayed_luminance_rgb(model, glm::ivec3(code), bits);
        for (int c = 0; c < 3; ++c) table[static_cast<std::size_t>(c) * levels + v] = static_cast<float>(rgb[c]);
    }
    const py::ssize_t h = codes.shape(0), w = codes.shape(1);
    py::array_t<float> out({h, w, py::ssize_t{3}});
    float* dst = out.mutable_data();
    const auto n = static_cast<std::size_t>(h * w * 3);
    auto decode = [&](const auto* src) {
        for (std::size_t i = 0; i < n; ++i) dst[i] = table[(i % 3) * levels + static_cast<std::size_t>(src[i])];
    };
    if (bits <= 8)
        decode(static_cast<const std::uint8_t*>(codes.data()));
    else
        decode(static_cast<const std::uint16_t*>(codes.data()));
    return out;
}

double added_lux(const stimuli::SceneTemplate& scene_template, const std::vector<SceneOverride>& overrides,
                 const stimuli::Scene& scene, const std::string& light, double radius_deg) {
    if (!(radius_deg > 0.0) || !std::isfinite(radius_deg))
        throw InputError(SourceLocation::command_line("radius_deg"),
                         "the observer's window radius must be a finite number of degrees > 0");
    if (!runner::find_light(scene, light) && !runner::find_disc(scene, light)) {
        std::string names;
        for (const stimuli::Light& l : scene.lights) names += (names.empty() ? "" : ", ") + l.name;
        for (const stimuli::Disc& d : scene.discs) names += (names.empty() ? "" : ", ") + d.name;
        throw InputError(SourceLocation::command_line("light"),
                         "the scene has no light or disc named \"" + light + "\" (it has: " + names + ")");
    }
    py::gil_scoped_release release;
    GlUse gl;
    // `atonlab check`'s renderer and sum (displayability.cpp): the frame with
    // and without the light at the same moment and dither frame, both decoded
    // through the display model, Σ (L − L_off) · Ω_px over the window.
    runner::StimulusRenderer renderer(scene_template, radius_deg, 0.0, 1);
    protocols::Frame frame;
    frame.overrides = overrides;
    const auto views = renderer.views(frame, {light});
    const runner::LightWindow& w = views->windows.at(0);
    return protocols::increment_illuminance_lux(w.image, w.light_px, radius_deg);
}

}  // namespace atonlab::python
