// The scene file's single tables: [display], [camera], [environment], [eye], [glare], [tonemap] (scene_reader.h).
#include "atonlab/display/display_encodings.h"
#include "scene_reader.h"

namespace atonlab::stimuli::scene_reader {

// ---------------------------------------------------------------------------
// Sections.

DisplayGeometry read_display(const Document& doc, const Section& root) {
    const toml::table* t = sub_table(root, "display", "[display]");
    if (t == nullptr)
        doc.fail(
            nullptr, "display",
            "the scene has no [display] table; it is required (width_px, height_px, width_m, viewing_distance_m).");
    Section s(doc, *t, "display", "the [display] table");
    s.allow(kDisplayKeys);
    DisplayGeometry d;
    // What every GL 4.5 context can allocate (common/input_limits.h).
    constexpr int max_px = limits::kMaxDisplaySidePx;
    auto w = s.integer("width_px", 1, max_px);
    if (!w) s.missing("width_px", "the display's width in pixels");
    auto h = s.integer("height_px", 1, max_px);
    if (!h) s.missing("height_px", "the display's height in pixels");
    d.width_px = *w;
    d.height_px = *h;
    if (static_cast<long long>(*w) * *h > limits::kMaxDisplayPixels)
        s.fail(s.get("height_px"), "height_px",
               fmt::format("a display of {}×{} px has {} pixels, more than the {} (8192×8192) the renderer's "
                           "full-frame targets are sized for.",
                           *w, *h, static_cast<long long>(*w) * *h, limits::kMaxDisplayPixels));
    d.width_m = s.required_number("width_m", "the picture's visible width in metres");
    s.greater_than("width_m", d.width_m, 0.0);
    d.viewing_distance_m = s.required_number("viewing_distance_m", "eye to screen distance in metres");
    s.greater_than("viewing_distance_m", d.viewing_distance_m, 0.0);
    return d;
}

Camera read_camera(const Document& doc, const Section& root) {
    Camera c;
    const toml::table* t = sub_table(root, "camera", "[camera]");
    if (t == nullptr) return c;
    Section s(doc, *t, "camera", "the [camera] table");
    s.allow(kCameraKeys);
    if (auto p = vec3(s, "position_m")) c.position_m = *p;
    c.yaw_deg = s.number_or("yaw_deg", 0.0);
    c.pitch_deg = s.number_or("pitch_deg", 0.0);
    c.roll_deg = s.number_or("roll_deg", 0.0);
    if (auto fov = s.number("fov_deg")) {
        if (!(*fov > 0.0 && *fov < 180.0))
            s.fail(s.get("fov_deg"), "fov_deg",
                   fmt::format("fov_deg must be greater than 0 and less than 180, got {}.", number_text(*fov)));
        c.fov_y_deg = *fov;
    }
    return c;
}

Environment read_environment(const Document& doc, const Section& root) {
    Environment e;
    const toml::table* t = sub_table(root, "environment", "[environment]");
    if (t == nullptr) return e;
    Section s(doc, *t, "environment", "the [environment] table");
    s.allow(kEnvironmentKeys);
    if (auto bg = s.string("background")) {
        if (*bg == "uniform")
            e.background = Background::uniform;
        else if (*bg == "sky-sea")
            e.background = Background::sky_sea;
        else
            s.fail(s.get("background"), "background",
                   fmt::format("unknown background \"{}\"; it must be \"uniform\" or \"sky-sea\".", text::echo(*bg)));
    }
    e.luminance_cd_m2 = s.number_or("luminance_cd_m2", e.luminance_cd_m2);
    s.at_least("luminance_cd_m2", e.luminance_cd_m2, 0.0);
    const auto visibility = s.number("visibility_nmi");
    const auto extinction = s.number("extinction_per_km");
    if (visibility && extinction)
        s.fail(s.get("extinction_per_km"), "extinction_per_km",
               "give either visibility_nmi or extinction_per_km, not both.");
    if (visibility) {
        s.greater_than("visibility_nmi", *visibility, 0.0);
        e.extinction_per_m = extinction_per_m_from_visibility_m(*visibility * metres_per_nautical_mile);
    }
    if (extinction) {
        s.at_least("extinction_per_km", *extinction, 0.0);
        e.extinction_per_m = *extinction / 1000.0;
    }
    e.sea_reflectance_f0 = s.number_or("sea_reflectance", e.sea_reflectance_f0);
    s.within("sea_reflectance", e.sea_reflectance_f0, 0.0, 1.0);
    if (auto spd = s.string("spd")) {
        const auto spectrum = named_spectrum(*spd);
        if (!spectrum)
            s.fail(s.get("spd"), "spd",
                   fmt::format("unknown spectrum \"{}\" for the sky; named spectra are {}.", text::echo(*spd),
                               join(spectrum_names(), "\"")));
        e.spd = *spd;
        // D65 is the display's white: drawn (1, 1, 1) exactly, as before the key (byte-identical frames).
        if (*spd != "d65") e.rgb_per_cd_m2 = normalised_rgb_from_spectrum(*spectrum);
    }
    return e;
}

namespace {

// A table's own keys and the settings the models declare in it (glare_setting.h).
std::vector<std::string_view> with_models_keys(KeyList own, GlareTable table) {
    std::vector<std::string_view> all(own.begin(), own.end());
    for (const GlareModelType* m : glare_models())
        for (const GlareSetting& s : m->settings())
            if (s.table == table) all.push_back(s.key);
    return all;
}

}  // namespace

KeyList eye_keys() {
    static const std::vector<std::string_view> keys = with_models_keys(kEyeOwnKeys, GlareTable::eye);
    return keys;
}

KeyList glare_keys() {
    static const std::vector<std::string_view> keys = with_models_keys(kSharedGlareKeys, GlareTable::glare);
    return keys;
}

/// The glare key of [eye] or of a [[light]]: one of the models' names.
std::optional<GlareModel> read_glare_model(const Section& s) {
    const auto g = s.string("glare");
    if (!g) return std::nullopt;
    auto model = glare_model_from_name(*g);
    if (!model)
        s.fail(s.get("glare"), "glare",
               fmt::format("unknown glare model \"{}\"; it must be {}.", text::echo(*g), glare_model_choices()));
    return model;
}

/// Returns Scene::adaptation_cd_m2; sets the glare model and pupil.
double read_eye(const Document& doc, const Section& root, const Environment& environment, GlareSettings& glare,
                AdaptationSettings& adapt) {
    const double fallback = environment.luminance_cd_m2 > 0.0 ? environment.luminance_cd_m2 : 0.001;
    const toml::table* t = sub_table(root, "eye", "[eye]");
    if (t == nullptr) return fallback;
    Section s(doc, *t, "eye", "the [eye] table");
    s.allow(eye_keys());
    if (auto a = s.string("adaptation")) {
        if (*a == "dynamic")
            adapt.mode = AdaptationMode::dynamic;
        else if (*a != "fixed")
            s.fail(s.get("adaptation"), "adaptation",
                   fmt::format("unknown adaptation \"{}\"; it must be \"fixed\" or \"dynamic\".", *a));
    }
    adapt.stride = s.integer("adaptation_stride", 1, 64).value_or(adapt.stride);
    const double adaptation = s.number_or("adaptation_cd_m2", fallback);
    s.greater_than("adaptation_cd_m2", adaptation, 0.0);
    if (auto model = read_glare_model(s)) glare.model = *model;
    if (auto p = s.number("pupil_mm")) {
        s.greater_than("pupil_mm", *p, 0.0);
        s.within("pupil_mm", *p, 0.5, 12.0);
        glare.pupil_mm = *p;
    }
    // The glare models' keys of [eye] (the `cie` observer's age and pigmentation).
    for (const GlareModelType* m : glare_models()) m->read_eye_keys(s, glare);
    return adaptation;
}

/// The [glare] table: the glare stage's settings and the eye model (docs/scene-file.md).
/// pupil_mm: the pupil the scene's frames will use (fixed adaptation), or the
/// darkest eq 3.15 gives (dynamic), for the checks that depend on it.
void read_glare(const Document& doc, const Section& root, GlareSettings& g, double pupil_mm) {
    const toml::table* t = sub_table(root, "glare", "[glare]");
    if (t == nullptr) return;
    Section s(doc, *t, "glare", "the [glare] table");
    // The key the two-scale eye replaced (docs/glare.md): its distance was a
    // defocus of 1/d diopters, now said as such.
    if (s.has("fresnel_distance_mm"))
        s.fail(s.get("fresnel_distance_mm"), "fresnel_distance_mm",
               "fresnel_distance_mm is no longer read: the eye's defocus is now 'defocus_diopters' (0 = in focus, "
               "the default; a distance d in mm is 1000/d diopters), and eye_preset = \"k2012\" draws the thesis's "
               "single-scale eye with its Fresnel term (d = 5000 mm).");
    s.allow(glare_keys());
    g.psf_size = s.integer("psf_size", 16, 2048).value_or(g.psf_size);
    if (!is_power_of_two(g.psf_size))
        s.fail(s.get("psf_size"), "psf_size",
               fmt::format("psf_size must be a power of two (the FFT needs one), got {}.", g.psf_size));
    g.spectral_samples = s.integer("spectral_samples", 1, 128).value_or(g.spectral_samples);
    if (auto w = s.string("window")) {
        try {
            g.window = glare_window_from_name(*w);
        } catch (const InputError& err) {
            s.fail(s.get("window"), "window", err.message());
        }
    }
    if (auto r = s.number("radius_deg")) {
        s.greater_than("radius_deg", *r, 0.0);
        s.within("radius_deg", *r, 0.0, 45.0);
        g.radius_deg = *r;
    }
    g.area_layers = s.integer("area_layers", 2, 256).value_or(g.area_layers);
    if (auto p = s.string("placement")) {
        if (auto v = placement_from_name(*p))
            g.placement = *v;
        else
            s.fail(
                s.get("placement"), "placement",
                fmt::format("unknown placement \"{}\"; it must be \"automatic\", \"gpu\" or \"cpu\".", text::echo(*p)));
    }
    // Each model's own keys (glare_models/): every model's, whichever the scene uses, since a light may pick its own.
    for (const GlareModelType* m : glare_models()) m->read_glare_keys(doc, s, g, pupil_mm);
}

/// The display model ([display] photometric keys) and [tonemap] (docs/scene-file.md).
void read_output(const Document& doc, const Section& root, OutputSettings& out) {
    if (const toml::table* t = sub_table(root, "display", "[display]")) {
        Section s(doc, *t, "display", "the [display] table");
        const double peak = s.number_or("peak_cd_m2", out.display.peak_cd_m2);
        s.greater_than("peak_cd_m2", peak, 0.0);
        const double black = s.number_or("black_cd_m2", out.display.black_cd_m2);
        s.at_least("black_cd_m2", black, 0.0);
        if (!(black < peak))
            s.fail(s.has("black_cd_m2") ? s.get("black_cd_m2") : s.get("peak_cd_m2"), "black_cd_m2",
                   fmt::format("the display's black ({} cd/m²) must be below its peak ({} cd/m²).", number_text(black),
                               number_text(peak)));
        // The laws a name alone makes (display_encodings.h); sRGB unless the file says otherwise.
        // `transfer` is the key's old name: still read, with a note.
        if (s.has("transfer") && s.has("encoding"))
            s.fail(s.get("transfer"), "transfer", "give encoding alone: transfer is its old name.");
        const char* const key = s.has("transfer") ? "transfer" : "encoding";
        if (s.has("transfer"))
            note_deprecated(doc.where(s.get("transfer"), "display.transfer"), "[display] transfer", "encoding");
        const std::string encoding = s.string(key).value_or(std::string(display_encoding_srgb().name));
        if (auto d = display_from_encoding(encoding, peak, black))
            out.display = std::move(*d);
        else
            s.fail(s.get(key), key,
                   fmt::format("unknown encoding \"{}\"; it must be {} (or give a calibration file).", encoding,
                               display_encoding_choices("\"")));
        if (auto cal = s.string("calibration")) {
            std::filesystem::path p(*cal);
            if (p.is_relative() && !doc.file().empty()) p = std::filesystem::path(doc.file()).parent_path() / p;
            try {
                out.display = display_from_calibration(fit_calibration(read_calibration_file(p)), p.stem().string());
            } catch (const InputError& e) {
                s.fail(s.get("calibration"), "calibration",
                       fmt::format("the calibration file is unusable: {}", e.what()));
            }
        }
        out.encode.bits = s.integer("bits", 1, 16).value_or(out.encode.bits);
        if (auto d = s.boolean("dither")) out.encode.dither = *d ? Dither::spatiotemporal : Dither::none;
        if (auto seed = s.integer("dither_seed", 0, std::numeric_limits<int>::max()))
            out.encode.seed = static_cast<std::uint32_t>(*seed);
        if (auto g = s.string("out_of_gamut")) {
            auto v = out_of_gamut_from_name(*g);
            if (!v)
                s.fail(s.get("out_of_gamut"), "out_of_gamut",
                       fmt::format("unknown out_of_gamut \"{}\"; it must be one of {}.", text::echo(*g),
                                   join(out_of_gamut_names(), "\"")));
            out.encode.out_of_gamut = *v;
        }
    }
    ToneMapSettings& tm = out.tonemap;
    tm.display_peak_cd_m2 = out.display.peak_cd_m2;
    tm.out_of_gamut = out.encode.out_of_gamut;  // one key for both (ToneMapSettings::out_of_gamut)
    const toml::table* t = sub_table(root, "tonemap", "[tonemap]");
    if (t == nullptr) return;
    Section s(doc, *t, "tonemap", "the [tonemap] table");
    s.allow(kTonemapKeys);
    if (auto op = s.string("operator")) {
        auto v = tone_operator_from_name(*op);
        if (!v)
            s.fail(s.get("operator"), "operator",
                   fmt::format("unknown tone-mapping operator \"{}\"; it must be one of {}.", text::echo(*op),
                               join(tone_operator_names(), "\"")));
        tm.tone_operator = *v;
    }
    tm.white_relative = s.number_or("white_relative", tm.white_relative);
    tm.reinhard_key = s.number_or("reinhard_key", tm.reinhard_key);
    tm.reinhard_white_relative = s.number_or("reinhard_white_relative", tm.reinhard_white_relative);
    tm.kakimoto_g = s.number_or("kakimoto_g", tm.kakimoto_g);
    tm.kakimoto_k = s.number_or("kakimoto_k", tm.kakimoto_k);
    if (auto w = s.number("white_cd_m2")) tm.white_cd_m2 = *w;
    if (auto a = s.number("display_adaptation_cd_m2")) tm.display_adaptation_cd_m2 = *a;
    tm.blueshift = s.boolean("blueshift").value_or(tm.blueshift);
    if (auto b = s.string("blueshift_luminance")) {
        auto v = blueshift_luminance_from_name(*b);
        if (!v)
            s.fail(s.get("blueshift_luminance"), "blueshift_luminance",
                   fmt::format("unknown blueshift luminance \"{}\"; it must be \"pixel\" (the rod sensitivity of each "
                               "pixel's own luminance) or \"adaptation\" (of the adaptation luminance).",
                               *b));
        tm.blueshift_luminance = *v;
    }
    if (auto xy = s.numbers("blueshift_xy", 2)) tm.blueshift_xy = {(*xy)[0], (*xy)[1]};
    if (auto h = s.string("hue_preservation")) {
        auto v = hue_preservation_from_name(*h);
        if (!v)
            s.fail(s.get("hue_preservation"), "hue_preservation",
                   fmt::format("unknown hue preservation \"{}\"; it must be one of {}.", text::echo(*h),
                               join(hue_preservation_names(), "\"")));
        tm.hue_preservation = *v;
    }
    if (auto m = s.string("mesopic")) {
        auto v = mesopic_model_from_name(*m);
        if (!v)
            s.fail(s.get("mesopic"), "mesopic",
                   fmt::format("unknown mesopic model \"{}\"; it must be \"k2012\" (each operator's own rods) or "
                               "\"cie191\" (CIE 191:2010's mesopic luminance).",
                               text::echo(*m)));
        tm.mesopic = *v;
    }
    out.ldr_glare = s.boolean("ldr_glare").value_or(out.ldr_glare);
    try {
        validate_tonemap_settings(tm);
    } catch (const InputError& e) {
        // The validator names "tonemap.KEY"; point at that key's line.
        std::string key = e.where() ? e.where()->key : std::string();
        if (key.starts_with("tonemap.")) key.erase(0, 8);
        s.fail(s.has(key) ? s.get(key) : &s.table(), key.empty() ? "operator" : key, e.message());
    }
}

}  // namespace atonlab::stimuli::scene_reader
