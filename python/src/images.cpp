// atonlab.tonemap, atonlab.glare, atonlab.psf, atonlab.light and EXR files
// (docs/python.md "Images"): the command line's cores (runner/src/
// image_commands.h, psf and light) on numpy arrays, with the same checks and
// sentences; the numpy helpers of bindings.h.
#include <fmt/format.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

#include "atonlab/common/input_error.h"
#include "atonlab/common/toml_value.h"
#include "atonlab/display/display_encodings.h"
#include "atonlab/runner/image_commands.h"
#include "atonlab/runner/light_command.h"
#include "atonlab/runner/psf_command.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/image_io.h"
#include "bindings.h"

namespace atonlab::python {

namespace {

std::optional<std::string> on_off(const std::optional<bool>& v) {
    if (!v) return std::nullopt;
    return std::string(*v ? "on" : "off");
}

/// A TOML basic string.
std::string toml_string(const std::string& s) {
    std::string out = "\"";
    for (const char c : s) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
            out += fmt::format("\\u{:04X}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        } else {
            out += c;
        }
    }
    return out + "\"";
}

py::array tonemap(const py::array& hdr, const std::optional<std::string>& tone_operator,
                  const std::optional<double>& adaptation_cd_m2, const std::optional<std::string>& encoding,
                  const std::optional<double>& peak_cd_m2, const std::optional<double>& black_cd_m2,
                  const std::optional<bool>& dither, const std::optional<bool>& blueshift,
                  const std::optional<std::string>& hue_preservation, const std::optional<double>& key,
                  const std::optional<py::object>& reinhard_white, const std::optional<double>& white_cd_m2,
                  const std::optional<double>& epsilon_cd_m2, const std::optional<double>& scale,
                  const std::optional<std::string>& scene, const std::optional<std::string>& display) {
    runner::TonemapOptions o;
    if (display) {  // the keyword's old name
        if (encoding) throw py::value_error("give encoding= alone: display= is its old name");
        if (PyErr_WarnEx(PyExc_DeprecationWarning, "tonemap(display=...) is deprecated; write encoding=...", 1) != 0)
            throw py::error_already_set();
    }
    o.input = "hdr";
    o.scene = scene.value_or("");
    o.scale = scale;
    o.adaptation_cd_m2 = adaptation_cd_m2;
    o.epsilon_cd_m2 = epsilon_cd_m2;
    o.tone_operator = tone_operator;
    o.encoding = encoding ? encoding : display;
    o.peak_cd_m2 = peak_cd_m2;
    o.black_cd_m2 = black_cd_m2;
    o.dither = on_off(dither);
    o.blueshift = on_off(blueshift);
    o.hue_preservation = hue_preservation;
    o.key = key;
    if (reinhard_white) o.reinhard_white = py::str(*reinhard_white);
    o.white_cd_m2 = white_cd_m2;
    stimuli::ExrImage in;
    in.image = image_from_array(hdr, "hdr");
    in.meta.units = "cd/m2";
    runner::ToneMapped t;
    {
        py::gil_scoped_release release;
        t = runner::tonemap_image(o, [&in] { return std::move(in); });
    }
    py::array_t<std::uint8_t> out({py::ssize_t{t.height}, py::ssize_t{t.width}, py::ssize_t{3}});
    std::copy(t.codes.begin(), t.codes.end(), out.mutable_data());
    return out;
}

/// glare()'s docstring: its models and their settings from the registry (glare_models/glare_model.h).
std::string glare_docstring() {
    std::string models, keys;
    for (const stimuli::GlareModelType* m : stimuli::glare_models()) {
        if (!m->on_images()) continue;
        models += fmt::format("{}{}", models.empty() ? "" : ", ", m->name());
        for (const stimuli::GlareSetting& s : m->settings())
            keys += fmt::format("\n  {} ({}, {}; default {}): {}", s.key, m->name(), s.unit, s.default_text, s.doc);
    }
    return fmt::format(
        "Adds the eye's glare to an H×W×3 (or ×4) scene-referred array (cd/m²) as `atonlab glare` does: the image "
        "convolved with a glare model's PSF, energy conserved. deg_per_px: degrees of visual angle per pixel; "
        "model: {} (default {}); adaptation_cd_m2 (cd/m²): the pupil (K2012 eq 3.15) and Spencer's vision "
        "class (default: the image's log-average); pupil_mm, radius_deg, window (silverman, epanechnikov, none), "
        "psf_size; scene: take [glare] from a scene file. Returns H×W×3 float32 cd/m². The GIL is released. Any "
        "other keyword is a model's own setting, as the scene file's key of that name:{}",
        models, stimuli::glare_model_name(runner::kDefaultImageGlareModel), keys);
}

py::array glare(const py::array& hdr, double deg_per_px, const std::optional<std::string>& model,
                const std::optional<double>& adaptation_cd_m2, const std::optional<double>& pupil_mm,
                const std::optional<double>& radius_deg, const std::optional<std::string>& window,
                const std::optional<int>& psf_size, const std::optional<std::string>& scene,
                const py::kwargs& settings) {
    runner::GlareImageOptions o;
    o.input = "hdr";
    o.scene = scene.value_or("");
    o.model = model;
    o.degrees_per_pixel = deg_per_px;
    o.adaptation_cd_m2 = adaptation_cd_m2;
    o.pupil_mm = pupil_mm;
    o.radius_deg = radius_deg;
    // Each other keyword is a model's own setting (bloom_sigma_deg=0.1), as its model declares it.
    for (const auto& [k, v] : settings) {
        const std::string key = py::str(k);
        if (py::isinstance<py::bool_>(v))
            o.settings.insert_or_assign(key, TomlValue::of(v.cast<bool>()));
        else if (py::isinstance<py::int_>(v))
            o.settings.insert_or_assign(key, TomlValue::of(v.cast<std::int64_t>()));
        else if (py::isinstance<py::float_>(v))
            o.settings.insert_or_assign(key, TomlValue::of(v.cast<double>()));
        else if (py::isinstance<py::str>(v))
            o.settings.insert_or_assign(key, TomlValue::of(v.cast<std::string>()));
        else
            throw py::type_error(fmt::format("glare(): {} takes a bool, a number or a string", key));
    }
    o.window = window;
    o.psf_size = psf_size;
    stimuli::ExrImage in;
    in.image = image_from_array(hdr, "hdr");
    in.meta.units = "cd/m2";
    runner::ImageGlared g;
    {
        py::gil_scoped_release release;
        g = runner::glare_image(o, [&in] { return std::move(in); });
    }
    return rgb_view(std::move(g.image.image));
}

py::tuple read_exr(const std::filesystem::path& path) {
    stimuli::ExrImage in;
    {
        py::gil_scoped_release release;
        in = stimuli::read_exr(path);
    }
    py::dict meta = metadata_dict(in.meta);
    return py::make_tuple(rgb_view(std::move(in.image)), meta);
}

void write_exr(const std::filesystem::path& path, const py::array& hdr, const std::optional<double>& deg_per_px,
               const std::optional<double>& adaptation_cd_m2, const std::string& units,
               const std::optional<std::map<std::string, std::string>>& strings) {
    stimuli::ExrMetadata meta;
    meta.units = units;
    meta.degrees_per_pixel = deg_per_px.value_or(0.0);
    meta.adaptation_cd_m2 = adaptation_cd_m2;
    if (strings) meta.strings = *strings;
    const stimuli::ImageRGBA32F image = image_from_array(hdr, "hdr");
    py::gil_scoped_release release;
    stimuli::write_exr(path, image, meta, stimuli::ExrPixelType::float32);
}

py::tuple psf(const std::optional<double>& pupil_mm, const std::optional<double>& adaptation_cd_m2,
              const std::optional<std::string>& eye_preset, bool clear, const std::string& spd, int size, int samples,
              const std::optional<std::uint64_t>& seed, double time_s, const std::optional<std::string>& scene) {
    runner::PsfOptions o;
    o.pupil_mm = pupil_mm;
    o.adaptation_cd_m2 = adaptation_cd_m2;
    o.eye_preset = eye_preset;
    o.clear = clear;
    o.spd = spd;
    o.size = size;
    o.samples = samples;
    o.seed = seed;
    o.time_s = time_s;
    o.scene = scene.value_or("");
    o.exr = "psf.exr";
    runner::PsfImages images;
    {
        py::gil_scoped_release release;
        std::optional<GlUse> gl;
        images = runner::psf_images(o, [&gl] { gl.emplace(); });
    }
    py::dict meta = metadata_dict(images.metas.front());
    return py::make_tuple(rgb_view(std::move(images.files.front().second)), meta);
}

runner::LightOptions light_options(const std::string& colour, const std::optional<double>& visibility_nmi,
                                   const std::optional<double>& transmissivity_per_nmi, const std::string& period,
                                   const std::string& background) {
    runner::LightOptions o;
    o.colour = colour;
    o.visibility_nmi = visibility_nmi;
    o.transmissivity_per_nmi = transmissivity_per_nmi;
    o.period = period;
    o.background = background;
    return o;
}

void bind_light(py::module_& m) {
    py::module_ light = m.def_submodule(
        "light", "Allard's law for one light (K2012 eq 2.1; IALA E200-2), as `atonlab light` (docs/light.md).");
    const char* conditions =
        " colour: white, red, green, yellow or blue (a label); visibility_nmi: meteorological visibility V (default "
        "10 nmi) or transmissivity_per_nmi T; period: night (E_t = 2e-7 lx) or day (1e-3 lx); background: none, "
        "minor or substantial (E_t x 1, 10, 100).";
    light.def(
        "range_nmi",
        [](double intensity_cd, const std::string& colour, const std::optional<double>& visibility_nmi,
           const std::optional<double>& transmissivity_per_nmi, const std::string& period,
           const std::string& background) {
            runner::LightOptions o = light_options(colour, visibility_nmi, transmissivity_per_nmi, period, background);
            o.intensity_cd = intensity_cd;
            return runner::light_answer(o).range_nmi;
        },
        py::arg("intensity_cd"), py::kw_only(), py::arg("colour") = "white", py::arg("visibility_nmi") = py::none(),
        py::arg("transmissivity_per_nmi") = py::none(), py::arg("period") = "night", py::arg("background") = "none",
        (std::string("The range (nmi) at which a light of intensity_cd (cd) gives the threshold illuminance.") +
         conditions)
            .c_str());
    light.def(
        "intensity_cd",
        [](double range_nmi, const std::string& colour, const std::optional<double>& visibility_nmi,
           const std::optional<double>& transmissivity_per_nmi, const std::string& period,
           const std::string& background) {
            runner::LightOptions o = light_options(colour, visibility_nmi, transmissivity_per_nmi, period, background);
            o.range_nmi = range_nmi;
            return runner::light_answer(o).intensity_cd;
        },
        py::arg("range_nmi"), py::kw_only(), py::arg("colour") = "white", py::arg("visibility_nmi") = py::none(),
        py::arg("transmissivity_per_nmi") = py::none(), py::arg("period") = "night", py::arg("background") = "none",
        (std::string("The intensity (cd) a light needs to reach range_nmi (nmi): range_nmi's inverse.") + conditions)
            .c_str());
}

}  // namespace

py::array rgb_view(stimuli::ImageRGBA32F&& image) {
    auto* owned = new stimuli::ImageRGBA32F(std::move(image));
    py::capsule base(owned, [](void* p) { delete static_cast<stimuli::ImageRGBA32F*>(p); });
    const py::ssize_t h = owned->height, w = owned->width, f = sizeof(float);
    return py::array(py::dtype::of<float>(), {h, w, py::ssize_t{3}}, {w * 4 * f, 4 * f, f}, owned->rgba.data(), base);
}

stimuli::ImageRGBA32F image_from_array(const py::array& array, const char* name) {
    if (array.ndim() != 3 || (array.shape(2) != 3 && array.shape(2) != 4) || array.shape(0) < 1 || array.shape(1) < 1)
        throw InputError(
            SourceLocation::command_line(name),
            fmt::format("the image must be an H×W×3 (RGB) or H×W×4 (RGBA) array, not {} dimensions{}", array.ndim(),
                        array.ndim() == 3 ? fmt::format(" of {} channels", array.shape(2)) : std::string()));
    const auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(array);
    if (!a) throw InputError(SourceLocation::command_line(name), "the image must hold real numbers (cd/m²)");
    stimuli::ImageRGBA32F image;
    image.height = static_cast<int>(a.shape(0));
    image.width = static_cast<int>(a.shape(1));
    const py::ssize_t channels = a.shape(2);
    image.rgba.assign(static_cast<std::size_t>(image.width) * image.height * 4, 1.0f);
    const float* p = a.data();
    for (std::size_t i = 0, n = static_cast<std::size_t>(image.width) * image.height; i < n; ++i)
        for (py::ssize_t c = 0; c < channels; ++c) image.rgba[i * 4 + c] = p[i * channels + c];
    return image;
}

namespace {

/// text as a number when all of it is one (C locale), else nullopt.
std::optional<double> number_of(const std::string& text) {
    if (text.empty()) return std::nullopt;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (end != text.c_str() + text.size()) return std::nullopt;
    return v;
}

/// One metadata value typed: a number as a float, "[a, b, c]" as a list of them, else the text.
py::object typed_value(const std::string& text) {
    if (const std::optional<double> v = number_of(text)) return py::float_(*v);
    if (text.size() >= 2 && text.front() == '[' && text.back() == ']') {
        py::list items;
        std::string item;
        for (const char c : text.substr(1, text.size() - 2) + ",") {
            if (c != ',') {
                item += c;
                continue;
            }
            const std::size_t a = item.find_first_not_of(' '), b = item.find_last_not_of(' ');
            const std::string trimmed = a == std::string::npos ? std::string() : item.substr(a, b - a + 1);
            if (!trimmed.empty()) items.append(typed_value(trimmed));
            item.clear();
        }
        return items;
    }
    return py::str(text);
}

/// "k=v k=[a, b] ..." (the camera and tonemap attributes) as a dict of typed values.
py::dict key_values(const std::string& text) {
    py::dict d;
    std::size_t i = 0;
    while (i < text.size()) {
        while (i < text.size() && text[i] == ' ') ++i;
        const std::size_t eq = text.find('=', i);
        if (eq == std::string::npos) break;
        const std::string key = text.substr(i, eq - i);
        std::size_t end = eq + 1;
        if (end < text.size() && text[end] == '[') {
            end = text.find(']', end);
            end = end == std::string::npos ? text.size() : end + 1;
        } else {
            end = std::min(text.find(' ', end), text.size());
        }
        d[py::str(key)] = typed_value(text.substr(eq + 1, end - eq - 1));
        i = end;
    }
    return d;
}

}  // namespace

py::dict metadata_dict(const stimuli::ExrMetadata& meta) {
    py::dict d;
    d["units"] = meta.units;
    d["degreesPerPixel"] = meta.degrees_per_pixel;
    if (meta.adaptation_cd_m2) d["adaptationLuminance"] = *meta.adaptation_cd_m2;
    if (meta.wavelength_nm) d["wavelength"] = *meta.wavelength_nm;
    // Typed (docs/python.md): the camera and the tone mapper as dicts of their
    // settings, a number (time_s) as a float, any other text as it is.
    for (const auto& [k, v] : meta.strings) {
        if (k == "camera" || k == "tonemap")
            d[py::str(k)] = key_values(v);
        else if (const std::optional<double> number = number_of(v))
            d[py::str(k)] = *number;
        else
            d[py::str(k)] = v;
    }
    return d;
}

std::string toml_value(const py::handle& value, const std::string& key) {
    if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
    if (py::isinstance<py::int_>(value)) return py::str(value);
    if (py::isinstance<py::float_>(value)) {
        const double v = value.cast<double>();
        if (std::isnan(v)) return "nan";
        if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
        std::string text = fmt::format("{}", v);
        if (text.find_first_of(".e") == std::string::npos) text += ".0";  // a float stays a float in TOML
        return text;
    }
    if (py::isinstance<py::str>(value)) return toml_string(value.cast<std::string>());
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
        std::string text = "[";
        for (const py::handle item : value) text += (text.size() > 1 ? ", " : "") + toml_value(item, key);
        return text + "]";
    }
    if (py::isinstance<py::dict>(value)) {
        std::string text = "{";
        for (const auto& [k, v] : value.cast<py::dict>())
            text += (text.size() > 1 ? ", " : " ") + std::string(py::str(k)) + " = " + toml_value(v, key);
        return text + " }";
    }
    // numpy scalars (np.int64, np.float32, np.bool_) and 0-d arrays: their
    // Python value, so an integer stays an integer and a bool a bool.
    if (py::hasattr(value, "dtype") && py::hasattr(value, "item") &&
        (!py::isinstance<py::array>(value) || value.cast<py::array>().ndim() == 0))
        return toml_value(value.attr("item")(), key);
    // Other numbers: as a float
    if (PyNumber_Check(value.ptr()) && py::hasattr(value, "__float__"))
        return toml_value(py::float_(py::reinterpret_borrow<py::object>(value)), key);
    throw InputError(SourceLocation::command_line("overrides", key),
                     fmt::format("a {} cannot be a scene value (give a bool, int, float, str or a list of them)",
                                 std::string(py::str(value.get_type().attr("__name__")))));
}

void bind_images(py::module_& m) {
    // The encodings' names from the registry (display_encodings.h), as `atonlab tonemap --encoding`'s help.
    static const std::string tonemap_doc = fmt::format(
        "Tone-maps and display-encodes an H×W×3 (or ×4) scene-referred array (linear Rec.709, cd/m², or "
        "cd/m² = value × scale) as `atonlab tonemap` does, on the CPU in double precision; returns the H×W×3 "
        "uint8 codes an 8-bit display is sent. operator: empirical (default), perceptual, reinhard, kakimoto, "
        "linear, clamp; adaptation_cd_m2: L_wa (default: the log-average, K2012 eq 4.15); encoding: the display's, {} "
        "(default {}; display= is its deprecated old name), with peak_cd_m2 (100) and black_cd_m2 (0.1); dither, "
        "blueshift: bools; "
        "hue_preservation: none, xyY, rgb; key, reinhard_white (a number or \"max\"): reinhard; white_cd_m2: "
        "linear and clamp; scene: take [display] and [tonemap] from a scene file. The GIL is released.",
        display::display_encoding_choices(""), display::display_encoding_srgb().name);
    m.def("tonemap", &tonemap, py::arg("hdr"), py::kw_only(), py::arg("operator") = py::none(),
          py::arg("adaptation_cd_m2") = py::none(), py::arg("encoding") = py::none(),
          py::arg("peak_cd_m2") = py::none(), py::arg("black_cd_m2") = py::none(), py::arg("dither") = py::none(),
          py::arg("blueshift") = py::none(), py::arg("hue_preservation") = py::none(), py::arg("key") = py::none(),
          py::arg("reinhard_white") = py::none(), py::arg("white_cd_m2") = py::none(),
          py::arg("epsilon_cd_m2") = py::none(), py::arg("scale") = py::none(), py::arg("scene") = py::none(),
          py::arg("display") = py::none(), tonemap_doc.c_str());
    static const std::string glare_doc = glare_docstring();
    m.def("glare", &glare, py::arg("hdr"), py::arg("deg_per_px"), py::kw_only(), py::arg("model") = py::none(),
          py::arg("adaptation_cd_m2") = py::none(), py::arg("pupil_mm") = py::none(),
          py::arg("radius_deg") = py::none(), py::arg("window") = py::none(), py::arg("psf_size") = py::none(),
          py::arg("scene") = py::none(), glare_doc.c_str());
    m.def("read_exr", &read_exr, py::arg("path"),
          "Reads an EXR: (H×W×3 float32 array, metadata dict) with the header's units, degreesPerPixel, "
          "adaptationLuminance (cd/m²) and string attributes, as atonlab writes them.");
    m.def("write_exr", &write_exr, py::arg("path"), py::arg("hdr"), py::kw_only(), py::arg("deg_per_px") = py::none(),
          py::arg("adaptation_cd_m2") = py::none(), py::arg("units") = "cd/m2", py::arg("strings") = py::none(),
          "Writes an H×W×3 (or ×4) array as a 32-bit float EXR with atonlab's header attributes (units, "
          "degreesPerPixel, adaptationLuminance in cd/m², extra strings), whole or not at all.");
    m.def("psf", &psf, py::kw_only(), py::arg("pupil_mm") = py::none(), py::arg("adaptation_cd_m2") = py::none(),
          py::arg("eye_preset") = py::none(), py::arg("clear") = false, py::arg("spd") = "d65", py::arg("size") = 512,
          py::arg("samples") = 30, py::arg("seed") = py::none(), py::arg("time_s") = 0.0, py::arg("scene") = py::none(),
          "The eye's glare PSF alone, as `atonlab psf` computes it on the GPU (docs/glare.md): returns (H×W×3 "
          "float32 RGB PSF, relative, its luminance summing to 1; metadata dict with degreesPerPixel per texel). "
          "pupil_mm: the pupil diameter (default: from adaptation_cd_m2, K2012 eq 3.15, 0.001 cd/m²); eye_preset, "
          "clear (a clear circular pupil: the Airy pattern), spd (a named spectrum), size (N, a power of two), "
          "samples (spectral samples), seed, time_s (s), scene (take [eye] from a scene file). The GIL is released.");
    bind_light(m);
}

}  // namespace atonlab::python
