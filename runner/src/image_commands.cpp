// `atonlab tonemap IN.exr -o OUT.png [...]` and `atonlab glare IN.exr -o OUT.exr [...]`:
// the pipeline's tone mappers, display encoding and glare models applied to a
// scene-referred EXR that atonlab did not render (docs/tone-mapping.md "HDR
// images in and out"). Both run on the CPU in double precision (tonemap_pixel,
// encode_pixel and the glare kernels are the pipeline's CPU references), so
// they need no GL and take images of any size.
#include "atonlab/runner/image_commands.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <utility>
#include <vector>

#include "atonlab/display/display_encodings.h"
#include "atonlab/display/display_model.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/eye_model.h"
#include "atonlab/stimuli/glare_kernel.h"
#include "atonlab/stimuli/glare_models/glare_setting.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/image_glare.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/output_settings.h"
#include "atonlab/stimuli/scene_file.h"
#include "atonlab/stimuli/tonemap.h"

namespace atonlab::runner {

namespace {

SourceLocation option(const char* name) {
    return SourceLocation::command_line(name);
}

bool on_off(const std::optional<std::string>& v, const char* name, bool fallback) {
    if (!v) return fallback;
    if (*v == "on") return true;
    if (*v == "off") return false;
    throw InputError(option(name), fmt::format("must be on or off, not '{}'", *v));
}

double positive(const std::optional<double>& v, const char* name, const char* what) {
    if (!(*v > 0 && std::isfinite(*v)))
        throw InputError(option(name), fmt::format("{} must be a positive number", what));
    return *v;
}

// The input as cd/m²: the EXR's `units` attribute must say cd/m2 (scale 1), or
// --scale says how many cd/m² one pixel unit is. Returns a note for stdout.
std::string to_cd_m2(stimuli::ExrImage& in, const std::string& path, const std::optional<double>& scale) {
    double s = 1.0;
    std::string note;
    if (scale) {
        s = positive(scale, "--scale", "the scale (cd/m² per pixel unit)");
        note = fmt::format("units {} x {} = cd/m2 (--scale)", in.meta.units.empty() ? "(none)" : in.meta.units, s);
    } else if (in.meta.units == "cd/m2") {
        note = "units cd/m2";
    } else if (in.meta.units.empty()) {
        note = "no units attribute: pixel values taken as cd/m2 (give --scale otherwise)";
    } else {
        throw InputError(option("--scale"),
                         fmt::format("{} says its pixels are in '{}', not cd/m2: give --scale (cd/m² per pixel unit)",
                                     path, in.meta.units));
    }
    if (s != 1.0)
        for (std::size_t i = 0; i < in.image.rgba.size(); ++i)
            if (i % 4 != 3) in.image.rgba[i] = static_cast<float>(in.image.rgba[i] * s);
    return note;
}

double luminance_of(const float* p) {
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

}  // namespace

// ---------------------------------------------------------------------------
// tonemap

void add_tonemap_command(CLI::App& app, TonemapOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "tonemap", "Tone-map and display-encode a scene-referred EXR (cd/m²) to a PNG, as the pipeline does");
    cmd->add_option("input", o.input, "Scene-referred EXR: linear Rec.709, cd/m² (or see --scale)")->required();
    cmd->add_option("-o,--output", o.png, "Output PNG: the 8-bit code values the display is sent")->required();
    cmd->add_option("--scene", o.scene,
                    "Take [display] and [tonemap] (and a fixed adaptation) from this scene file; options override");
    cmd->add_option("--scale", o.scale, "cd/m² per pixel unit (default 1 when the EXR says units = cd/m2)");
    cmd->add_option("--adaptation-cd-m2", o.adaptation_cd_m2,
                    "Adaptation luminance L_wa (cd/m²; default: the image's log-average, K2012 eq 4.15)");
    cmd->add_option("--epsilon-cd-m2", o.epsilon_cd_m2, "ε of the log-average (cd/m²; default 1e-6)");
    cmd->add_option("--operator", o.tone_operator,
                    "Tone curve: empirical (default), perceptual, reinhard, kakimoto, linear, clamp");
    cmd->add_option("--encoding", o.encoding,
                    fmt::format("The display's encoding: {} (default {})", display::display_encoding_choices(""),
                                display::display_encoding_srgb().name));
    cmd->add_option("--display", o.deprecated_display, "Deprecated: --encoding")->group("");  // hidden from --help
    cmd->add_option("--peak-cd-m2", o.peak_cd_m2, "The display's peak white (cd/m²; default 100)");
    cmd->add_option("--black-cd-m2", o.black_cd_m2, "The display's black (cd/m²; default 0.1)");
    cmd->add_option("--dither", o.dither, "on (default: the pipeline's spatio-temporal dither) or off (round)");
    cmd->add_option("--blueshift", o.blueshift, "Scotopic blueshift (K2012 eq 4.27-4.29): on (default) or off");
    cmd->add_option("--hue-preservation", o.hue_preservation, "none, xyY (default) or rgb");
    cmd->add_option("--out-of-gamut", o.out_of_gamut,
                    fmt::format("What a colour the display cannot show gives up (display.out_of_gamut): {}; "
                                "clip-channels is pfstools' (default: the scene's, else keep-luminance)",
                                fmt::join(display::out_of_gamut_names(), ", ")));
    cmd->add_option("--key", o.key, "reinhard: the key a (default 0.18)");
    cmd->add_option(
        "--reinhard-white", o.reinhard_white,
        "reinhard: L_white in scaled luminance, or 'max' (the image's brightest pixel, as pfstmo_reinhard02); "
        "default infinity");
    cmd->add_option("--white-cd-m2", o.white_cd_m2, "linear and clamp: the luminance (cd/m²) shown as display white");
}

ToneMapped tonemap_image(const TonemapOptions& o, const std::function<stimuli::ExrImage()>& read_input) {
    // Settings first (every check before reading pixels or writing).
    stimuli::OutputSettings out;
    std::optional<double> scene_adaptation;
    if (!o.scene.empty()) {
        const stimuli::Scene scene = stimuli::load_scene(o.scene, {});
        out = scene.output;
        if (out.adaptation.mode == stimuli::AdaptationMode::fixed) scene_adaptation = scene.adaptation_cd_m2;
    }
    display::ToneMapSettings& tm = out.tonemap;
    if (o.tone_operator) {
        const auto op = display::tone_operator_from_name(*o.tone_operator);
        if (!op)
            throw InputError(option("--operator"),
                             fmt::format("unknown operator '{}'; one of empirical, perceptual, reinhard, kakimoto, "
                                         "linear, clamp",
                                         *o.tone_operator));
        tm.tone_operator = *op;
    }
    if (o.deprecated_display) {
        if (o.encoding) throw InputError(option("--display"), "give --encoding alone: --display is its old name");
        note_deprecated(option("--display"), "--display", "--encoding");
    }
    const std::optional<std::string>& named = o.encoding ? o.encoding : o.deprecated_display;
    if (named || o.peak_cd_m2 || o.black_cd_m2) {
        const double peak = o.peak_cd_m2 ? positive(o.peak_cd_m2, "--peak-cd-m2", "the peak") : out.display.peak_cd_m2;
        const double black = o.black_cd_m2 ? *o.black_cd_m2 : out.display.black_cd_m2;
        if (!(black >= 0 && black < peak))
            throw InputError(option("--black-cd-m2"), "the black must be at least 0 and below the peak (cd/m²)");
        // The scene's law when a name alone makes it (display_encodings.h), else sRGB.
        const display::DisplayEncoding* own = display::display_encoding_of(out.display);
        const std::string encoding = named.value_or(std::string(
            own != nullptr && own->from_peak_black != nullptr ? own->name : display::display_encoding_srgb().name));
        if (auto d = display::display_from_encoding(encoding, peak, black))
            out.display = std::move(*d);
        else
            throw InputError(option(o.encoding ? "--encoding" : "--display"),
                             fmt::format("must be {}, not '{}'", display::display_encoding_choices(""), encoding));
        tm.display_peak_cd_m2 = peak;
    }
    out.encode.dither = on_off(o.dither, "--dither", out.encode.dither == display::Dither::spatiotemporal)
                            ? display::Dither::spatiotemporal
                            : display::Dither::none;
    out.encode.bits = 8;  // the PNG holds 8-bit codes
    tm.blueshift = on_off(o.blueshift, "--blueshift", tm.blueshift);
    if (o.hue_preservation) {
        const auto h = display::hue_preservation_from_name(*o.hue_preservation);
        if (!h)
            throw InputError(option("--hue-preservation"),
                             fmt::format("must be none, xyY or rgb, not '{}'", *o.hue_preservation));
        tm.hue_preservation = *h;
    }
    if (o.out_of_gamut) {
        const auto g = display::out_of_gamut_from_name(*o.out_of_gamut);
        if (!g)
            throw InputError(
                option("--out-of-gamut"),
                fmt::format("must be {}, not '{}'", fmt::join(display::out_of_gamut_names(), ", "), *o.out_of_gamut));
        out.encode.out_of_gamut = *g;
    }
    tm.out_of_gamut = out.encode.out_of_gamut;  // one choice for both (ToneMapSettings::out_of_gamut)
    if (o.key) tm.reinhard_key = positive(o.key, "--key", "the key");
    bool white_is_max = false;
    if (o.reinhard_white) {
        if (*o.reinhard_white == "max") {
            white_is_max = true;
        } else {
            double v = 0;
            try {
                std::size_t used = 0;
                v = std::stod(*o.reinhard_white, &used);
                if (used != o.reinhard_white->size()) v = -1;
            } catch (const std::exception&) {
                v = -1;
            }
            if (!(v > 0)) throw InputError(option("--reinhard-white"), "must be a positive number or 'max'");
            tm.reinhard_white_relative = v;
        }
    }
    if (o.white_cd_m2) tm.white_cd_m2 = positive(o.white_cd_m2, "--white-cd-m2", "the white luminance");
    if (o.adaptation_cd_m2) positive(o.adaptation_cd_m2, "--adaptation-cd-m2", "the adaptation luminance");
    const double epsilon =
        o.epsilon_cd_m2 ? positive(o.epsilon_cd_m2, "--epsilon-cd-m2", "ε") : out.adaptation.epsilon_cd_m2;
    stimuli::validate_output_settings(out);

    stimuli::ExrImage in = read_input();
    ToneMapped result;
    result.units = to_cd_m2(in, o.input, o.scale);
    const stimuli::ImageRGBA32F& hdr = in.image;
    result.width = hdr.width;
    result.height = hdr.height;
    const double log_average = stimuli::log_average_luminance(hdr, epsilon);  // K2012 eq 4.15
    const double adaptation = o.adaptation_cd_m2 ? *o.adaptation_cd_m2 : scene_adaptation.value_or(log_average);
    if (white_is_max) {
        double max_l = 0;
        for (int y = 0; y < hdr.height; ++y)
            for (int x = 0; x < hdr.width; ++x) max_l = std::max(max_l, luminance_of(hdr.pixel(x, y)));
        // Reinhard et al. 2002 eq 4's L_white as the scaled luminance (eq 2) of the brightest pixel.
        tm.reinhard_white_relative = max_l > 0 ? tm.reinhard_key * max_l / adaptation : 1.0;
    }
    display::validate_tonemap_settings(tm);

    std::vector<std::uint8_t>& codes = result.codes;
    codes.resize(static_cast<std::size_t>(hdr.width) * hdr.height * 3);
    std::size_t clipped = 0;
    for (int y = 0; y < hdr.height; ++y)
        for (int x = 0; x < hdr.width; ++x) {
            const float* p = hdr.pixel(x, y);
            const glm::dvec3 rel = display::tonemap_pixel({p[0], p[1], p[2]}, adaptation, tm);
            if (rel.r > 1 || rel.g > 1 || rel.b > 1) ++clipped;
            // The dither pattern's rows count from the bottom, as on the GPU (frame 0).
            const glm::ivec3 c = display::encode_pixel(out.display, rel, {x, hdr.height - 1 - y}, 0, out.encode);
            std::uint8_t* q = &codes[(static_cast<std::size_t>(y) * hdr.width + x) * 3];
            for (int k = 0; k < 3; ++k) q[k] = static_cast<std::uint8_t>(c[k]);
        }
    result.log_average_cd_m2 = log_average;
    result.adaptation_cd_m2 = adaptation;
    result.clipped = clipped;
    // What was applied, as `atonlab tonemap` prints it (two lines).
    result.settings =
        fmt::format("  adaptation_cd_m2={:.6g} ({}) operator={}{} hue_preservation={} blueshift={}\n", adaptation,
                    o.adaptation_cd_m2 ? "given"
                    : scene_adaptation ? "the scene's fixed level"
                                       : "log-average, K2012 eq 4.15",
                    display::tone_operator_name(tm.tone_operator),
                    tm.tone_operator == display::ToneOperator::reinhard
                        ? fmt::format(" key={} white_relative={:.6g}", tm.reinhard_key, tm.reinhard_white_relative)
                        : std::string(),
                    display::hue_preservation_name(tm.hue_preservation), tm.blueshift ? "on" : "off");
    result.settings += fmt::format(
        "  display={} peak_cd_m2={:g} black_cd_m2={:g} bits=8 dither={} out_of_gamut={}; {} pixels above display "
        "white (clipped)\n",
        out.display.name, out.display.peak_cd_m2, out.display.black_cd_m2,
        out.encode.dither == display::Dither::none ? "off" : "on", display::out_of_gamut_name(out.encode.out_of_gamut),
        clipped);
    return result;
}

int run_tonemap(const TonemapOptions& o) {
    const ToneMapped t = tonemap_image(o, [&o] { return stimuli::read_exr(o.input); });
    std::vector<float> codes(t.codes.size());
    for (std::size_t i = 0; i < codes.size(); ++i) codes[i] = static_cast<float>(t.codes[i] / 255.0);
    stimuli::write_png_rgb8(o.png, t.width, t.height, codes);
    std::printf("%s: %dx%d, %s, log-average %.6g cd/m2 -> %s\n", o.input.c_str(), t.width, t.height, t.units.c_str(),
                t.log_average_cd_m2, o.png.c_str());
    std::fputs(t.settings.c_str(), stdout);
    return 0;
}

// ---------------------------------------------------------------------------
// glare

namespace {

// The models `atonlab glare` takes (those with a CPU kernel), as "a, b or c".
std::string image_models(std::string_view quote) {
    return stimuli::glare_model_choices(quote, [](const stimuli::GlareModelType& m) { return m.on_images(); });
}

}  // namespace

void add_glare_command(CLI::App& app, GlareImageOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "glare",
        "Add the eye's glare to a scene-referred EXR: convolve it with a glare model's PSF (energy-conserving)");
    cmd->add_option("input", o.input, "Scene-referred EXR (linear; cd/m² or any linear unit)")->required();
    cmd->add_option("-o,--output", o.output, "Output EXR (32-bit float, the input's header attributes kept)")
        ->required();
    cmd->add_option("--scene", o.scene, "Take [glare] (and the adaptation) from this scene file; options override");
    // The models' names from their registry (glare_models/glare_model_list.h).
    const auto name = [](stimuli::GlareModel m) { return std::string(stimuli::glare_model_name(m)); };
    cmd->add_option("--model", o.model,
                    fmt::format("{} (default {})", image_models(""), name(kDefaultImageGlareModel)));
    cmd->add_option("--deg-per-px", o.degrees_per_pixel,
                    "Degrees of visual angle per pixel (default: the EXR's degreesPerPixel attribute)");
    cmd->add_option("--adaptation-cd-m2", o.adaptation_cd_m2,
                    "Adaptation luminance (cd/m²): the pupil (K2012 eq 3.15) and Spencer's vision class (default: "
                    "the EXR's adaptationLuminance attribute, else the image's log-average)");
    cmd->add_option("--pupil-mm", o.pupil_mm,
                    name(stimuli::GlareModel::wave_optics) + ": the pupil diameter (mm) instead of the adaptation's");
    cmd->add_option(
        "--radius-deg", o.radius_deg,
        fmt::format("The kernel's radius (degrees; default per model, {} {})", name(stimuli::GlareModel::cie),
                    stimuli::glare_model_type(stimuli::GlareModel::cie).default_radius_deg({}, 0.0)));
    cmd->add_option("--window", o.window, "The kernel's radial window: silverman (default), epanechnikov or none");
    cmd->add_option("--psf-size", o.psf_size,
                    name(stimuli::GlareModel::wave_optics) + ": the PSF size N (a power of two; default 512)");
    // Each model's own settings, as the model declares them (glare_models/glare_setting.h):
    // --bloom-sigma-deg for bloom_sigma_deg, read and checked as the scene file's key.
    for (const stimuli::GlareModelType* m : stimuli::glare_models()) {
        if (!m->on_images()) continue;
        for (const stimuli::GlareSetting& s : m->settings()) {
            const std::string key(s.key);
            cmd->add_option_function<std::string>(
                   stimuli::glare_setting_option(key),
                   [&o, key](const std::string& text) {
                       // The one reading of an option's text as a value (toml_value.h): TOML, else a string.
                       auto v = TomlValue::parse(text);
                       if (!v) v = TomlValue::string(text);
                       if (!v)
                           throw InputError(option(stimuli::glare_setting_option(key).c_str()),
                                            fmt::format("'{}' is not a value", text));
                       o.settings.insert_or_assign(key, *v);
                   },
                   fmt::format("{}: {} ({}; default {}, e.g. {})", m->name(), s.doc, s.unit, s.default_text, s.example))
                ->type_name(std::string(s.type));
        }
    }
}

ImageGlared glare_image(const GlareImageOptions& o, const std::function<stimuli::ExrImage()>& read_input) {
    stimuli::GlareSettings gs;
    gs.model = kDefaultImageGlareModel;
    std::optional<double> scene_adaptation;
    if (!o.scene.empty()) {
        const stimuli::Scene scene = stimuli::load_scene(o.scene, {});
        gs = scene.glare;
        scene_adaptation = scene.adaptation_cd_m2;
    }
    if (o.model) {
        const auto m = stimuli::glare_model_from_name(*o.model);
        if (!m)
            throw InputError(option("--model"),
                             fmt::format("unknown glare model '{}'; one of {}", *o.model, image_models("")));
        gs.model = *m;
    }
    if (!stimuli::glare_model_type(gs.model).on_images())
        throw InputError(option("--model"), fmt::format("an image's glare can be {}, not {}", image_models(""),
                                                        stimuli::glare_model_name(gs.model)));
    if (o.pupil_mm) gs.pupil_mm = positive(o.pupil_mm, "--pupil-mm", "the pupil diameter");
    if (o.radius_deg) gs.radius_deg = positive(o.radius_deg, "--radius-deg", "the radius");
    if (o.window) {
        try {
            gs.window = stimuli::glare_window_from_name(*o.window);
        } catch (const InputError& e) {
            throw InputError(option("--window"), e.message());
        }
    }
    if (o.psf_size) gs.psf_size = *o.psf_size;
    if (o.adaptation_cd_m2) positive(o.adaptation_cd_m2, "--adaptation-cd-m2", "the adaptation luminance");
    if (o.degrees_per_pixel) positive(o.degrees_per_pixel, "--deg-per-px", "the degrees per pixel");

    stimuli::ExrImage in = read_input();
    const double dpp = o.degrees_per_pixel.value_or(in.meta.degrees_per_pixel);
    if (!(dpp > 0))
        throw InputError(option("--deg-per-px"),
                         fmt::format("{} has no degreesPerPixel attribute: give --deg-per-px", o.input));
    const double adaptation = o.adaptation_cd_m2 ? *o.adaptation_cd_m2
                              : scene_adaptation
                                  ? *scene_adaptation
                                  : in.meta.adaptation_cd_m2.value_or(stimuli::log_average_luminance(in.image));

    stimuli::GlareKernel kernel;
    try {
        stimuli::apply_glare_settings(o.settings, gs,
                                      gs.pupil_mm.value_or(stimuli::pupil_diameter_mm_from_adaptation(adaptation)));
        kernel = stimuli::image_glare_kernel(gs, adaptation, dpp);
    } catch (const InputError& e) {
        // The library names the scene key; on the command line it is an option.
        const std::string key = e.where() ? e.where()->key : std::string();
        // A model's own setting: its option (glare_setting_option).
        if (o.settings.contains(key)) throw InputError(option(stimuli::glare_setting_option(key).c_str()), e.message());
        const char* name = key == "radius_deg"                                        ? "--radius-deg"
                           : key == "size" || key == "psf_size"                       ? "--psf-size"
                           : key == "pixels_per_degree" || key == "degrees_per_pixel" ? "--deg-per-px"
                           : !o.scene.empty()                                         ? o.scene.c_str()
                                                                                      : "--model";
        throw InputError(option(name), e.message());
    }
    stimuli::ImageGlareResult r = stimuli::convolve_image_glare(in.image, kernel);

    constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
    const double omega_sr = (dpp * kDegToRad) * (dpp * kDegToRad);
    stimuli::ExrMetadata meta = in.meta;
    meta.degrees_per_pixel = dpp;
    meta.adaptation_cd_m2 = adaptation;
    const std::string line = fmt::format(
        "model={} adaptation_cd_m2={:.6g} pupil_mm={:.3f} kernel_px={} radius_deg={:.4g} window={} "
        "window_cut_rgb=[{:.6f}, {:.6f}, {:.6f}] edge_cut_rgb=[{:.6f}, {:.6f}, {:.6f}]",
        stimuli::glare_model_name(gs.model), adaptation,
        gs.pupil_mm.value_or(stimuli::pupil_diameter_mm_from_adaptation(adaptation)), kernel.size,
        kernel.radius_px / kernel.pixels_per_degree, stimuli::glare_window_name(gs.window), kernel.window_cut.r,
        kernel.window_cut.g, kernel.window_cut.b, r.edge_cut.r, r.edge_cut.g, r.edge_cut.b);
    meta.strings["image_glare"] = line;
    ImageGlared out;
    out.sums = fmt::format(
        "  sum L*Omega (cd/m2 sr x pixel Omega {:.6g} sr): in [{:.6g}, {:.6g}, {:.6g}], out [{:.6g}, {:.6g}, {:.6g}]\n",
        omega_sr, r.input_sum.r * omega_sr, r.input_sum.g * omega_sr, r.input_sum.b * omega_sr,
        r.output_sum.r * omega_sr, r.output_sum.g * omega_sr, r.output_sum.b * omega_sr);
    out.image = stimuli::ExrImage{std::move(r.image), std::move(meta)};
    out.line = line;
    return out;
}

int run_glare(const GlareImageOptions& o) {
    const ImageGlared g = glare_image(o, [&o] { return stimuli::read_exr(o.input); });
    stimuli::write_exr(o.output, g.image.image, g.image.meta, stimuli::ExrPixelType::float32);
    std::printf("%s: %dx%d, %.6g deg/px%s -> %s\n", o.input.c_str(), g.image.image.width, g.image.image.height,
                g.image.meta.degrees_per_pixel, o.degrees_per_pixel ? " (given)" : " (degreesPerPixel attribute)",
                o.output.c_str());
    std::printf("  %s\n", g.line.c_str());
    std::fputs(g.sums.c_str(), stdout);
    return 0;
}

}  // namespace atonlab::runner
