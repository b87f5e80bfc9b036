// The scene file's single tables: [display], [camera], [environment], [eye], [glare], [tonemap] (scene_reader.h).
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
    return e;
}

/// The glare key of [eye] or of a [[light]]: one of the models' names.
std::optional<GlareModel> read_glare_model(const Section& s) {
    const auto g = s.string("glare");
    if (!g) return std::nullopt;
    auto model = glare_model_from_name(*g);
    if (!model)
        s.fail(s.get("glare"), "glare",
               fmt::format("unknown glare model \"{}\"; it must be \"none\", \"wave-optics\", \"gaussian-bloom\", "
                           "\"spencer\", \"aperture\" or \"cie\".",
                           text::echo(*g)));
    return model;
}

/// Returns Scene::adaptation_cd_m2; sets the glare model and pupil.
double read_eye(const Document& doc, const Section& root, const Environment& environment, GlareSettings& glare,
                AdaptationSettings& adapt) {
    const double fallback = environment.luminance_cd_m2 > 0.0 ? environment.luminance_cd_m2 : 0.001;
    const toml::table* t = sub_table(root, "eye", "[eye]");
    if (t == nullptr) return fallback;
    Section s(doc, *t, "eye", "the [eye] table");
    s.allow(kEyeKeys);
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
    // The CIE observer (age, pigmentation) of the `cie` model (cie_glare.h).
    if (auto a = s.number("cie_age_years")) {
        s.within("cie_age_years", *a, 0.0, 100.0);
        glare.cie.age_years = *a;
    }
    if (auto p = s.number("cie_pigmentation")) {
        s.within("cie_pigmentation", *p, 0.0, 1.2);
        glare.cie.pigmentation = *p;
    }
    try {
        (void)cie_glare_spread(glare.cie);
    } catch (const InputError& err) {
        // Only a combination of the two can fail here: name the one the file gives (the age first).
        const std::string key = s.get("cie_age_years") ? "cie_age_years" : "cie_pigmentation";
        s.fail(s.get(key), key, err.message());
    }
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
    s.allow(kGlareKeys);
    EyeModel& e = g.eye;
    if (auto preset = s.string("eye_preset")) {
        const std::optional<EyeModel> named = eye_preset(*preset);
        if (!named)
            s.fail(s.get("eye_preset"), "eye_preset",
                   fmt::format("unknown eye preset \"{}\"; presets are {}.", *preset, join(eye_preset_names())));
        e = *named;
        // The thesis's look includes its spectral method: one FFT at λ0 and
        // eq 4.9 lookups (docs/glare.md). Summed exactly over wavelengths, its
        // defocus rings fill the dark centre it drew, so the preset draws with
        // the rescaled path unless spectral_path says otherwise.
        if (e.scale == EyeScale::k2012_single) g.spectral_path = SpectralPath::rescaled;
    }
    if (s.boolean("clear_pupil").value_or(false)) e = EyeModel::clear_pupil(e.pupil_diameter_mm);
    g.psf_size = s.integer("psf_size", 16, 2048).value_or(g.psf_size);
    if (!is_power_of_two(g.psf_size))
        s.fail(s.get("psf_size"), "psf_size",
               fmt::format("psf_size must be a power of two (the FFT needs one), got {}.", g.psf_size));
    g.spectral_samples = s.integer("spectral_samples", 1, 128).value_or(g.spectral_samples);
    if (auto p = s.string("spectral_path")) {
        const auto path = spectral_path_from_name(*p);
        if (!path)
            s.fail(s.get("spectral_path"), "spectral_path",
                   fmt::format("unknown spectral path \"{}\"; it must be \"anchored\", \"rescaled\" or \"exact\".",
                               *p));
        g.spectral_path = *path;
    }
    g.spectral_anchors = s.integer("spectral_anchors", 1, 128).value_or(g.spectral_anchors);
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
    g.bloom_sigma_deg = s.number_or("bloom_sigma_deg", g.bloom_sigma_deg);
    s.greater_than("bloom_sigma_deg", g.bloom_sigma_deg, 0.0);
    if (auto v = s.string("spencer_vision")) {
        if (*v == "photopic") g.spencer_vision = SpencerVision::photopic;
        else if (*v == "mesopic") g.spencer_vision = SpencerVision::mesopic;
        else if (*v == "scotopic") g.spencer_vision = SpencerVision::scotopic;
        else if (*v != "auto")
            s.fail(s.get("spencer_vision"), "spencer_vision",
                   fmt::format("unknown vision \"{}\"; it must be \"photopic\", \"mesopic\", \"scotopic\" or \"auto\".",
                               *v));
    }
    if (auto img = s.string("aperture_image")) {
        // Relative to the scene file, like every path in it.
        std::filesystem::path p(*img);
        if (p.is_relative() && !doc.file().empty()) p = std::filesystem::path(doc.file()).parent_path() / p;
        if (!std::filesystem::is_regular_file(p))
            s.fail(s.get("aperture_image"), "aperture_image",
                   fmt::format("the aperture image {} does not exist or is not a file.", p.string()));
        g.aperture_image = p.string();
    }
    g.aperture_width_mm = s.number_or("aperture_width_mm", g.aperture_width_mm);
    s.greater_than("aperture_width_mm", g.aperture_width_mm, 0.0);
    g.aperture_with_pupil = s.boolean("aperture_with_pupil").value_or(g.aperture_with_pupil);

    if (auto seed = s.integer("seed", 0, std::numeric_limits<int>::max())) e.seed = static_cast<std::uint64_t>(*seed);
    if (auto h = s.number("halo_radius_deg")) {
        s.at_least("halo_radius_deg", *h, 0.0);
        e.halo_radius_deg = *h > 0 ? std::optional<double>(*h) : std::nullopt;  // 0: physical scale
    }
    e.plane_width_mm = s.number_or("plane_width_mm", e.plane_width_mm);
    e.defocus_diopters = s.number_or("defocus_diopters", e.defocus_diopters);
    e.supersampling = s.integer("supersampling", 1, 16).value_or(e.supersampling);
    e.hippus.enabled = s.boolean("hippus").value_or(e.hippus.enabled);
    e.hippus.amplitude = s.number_or("hippus_amplitude", e.hippus.amplitude);
    e.gratings.enabled = s.boolean("gratings").value_or(e.gratings.enabled);
    e.gratings.count = s.integer("grating_count", 0, 100000).value_or(e.gratings.count);
    e.gratings.inner_radius_mm = s.number_or("grating_inner_radius_mm", e.gratings.inner_radius_mm);
    e.gratings.width_um = s.number_or("grating_width_um", e.gratings.width_um);
    e.gratings.opacity = s.number_or("grating_opacity", e.gratings.opacity);
    e.lens_particles.enabled = s.boolean("lens_particles").value_or(e.lens_particles.enabled);
    e.lens_particles.count = s.integer("lens_particle_count", 0, 1000000).value_or(e.lens_particles.count);
    e.lens_particles.diameter_um = s.number_or("lens_particle_diameter_um", e.lens_particles.diameter_um);
    e.vitreous_particles.enabled = s.boolean("vitreous_particles").value_or(e.vitreous_particles.enabled);
    e.vitreous_particles.count = s.integer("vitreous_particle_count", 0, 1000000).value_or(e.vitreous_particles.count);
    e.vitreous_particles.diameter_um = s.number_or("vitreous_particle_diameter_um", e.vitreous_particles.diameter_um);
    e.eyelashes.enabled = s.boolean("eyelashes").value_or(e.eyelashes.enabled);
    e.eyelashes.count = s.integer("eyelash_count", 0, 10000).value_or(e.eyelashes.count);
    e.eyelashes.width_um = s.number_or("eyelash_width_um", e.eyelashes.width_um);
    e.eyelid.enabled = s.boolean("eyelid").value_or(e.eyelid.enabled);
    e.eyelid.edge_mm = s.number_or("eyelid_edge_mm", e.eyelid.edge_mm);
    // The eye model's own checks (the pupil itself is checked per frame, where
    // hippus has moved it): with the scene's pupil within half the plane, so
    // that a defocus the frames' grid cannot sample is refused here, at its line.
    try {
        EyeModel probe = e;
        probe.pupil_diameter_mm = std::min(pupil_mm, 0.5 * probe.plane_width_mm);
        probe.hippus.enabled = false;
        probe.validate(g.psf_size);
    } catch (const InputError& err) {
        const std::string key = err.where() ? err.where()->key : std::string();
        // Keys spelt the same in the file and the model are refused at their own line.
        if (!key.empty() && s.has(key)) s.fail(s.get(key), key, err.message());
        s.fail_table(fmt::format("the eye model is invalid ({}): {}", key, err.message()));
    }
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
        const std::string transfer = s.string("transfer").value_or("srgb");
        if (transfer == "srgb")
            out.display = DisplayModel::srgb(peak, black);
        else if (transfer == "pq")
            out.display = DisplayModel::pq(peak, black);
        else
            s.fail(s.get("transfer"), "transfer",
                   fmt::format("unknown transfer \"{}\"; it must be \"srgb\" or \"pq\" (or give a calibration file).",
                               transfer));
        if (auto cal = s.string("calibration")) {
            std::filesystem::path p(*cal);
            if (p.is_relative() && !doc.file().empty()) p = std::filesystem::path(doc.file()).parent_path() / p;
            try {
                out.display = display_from_calibration(fit_calibration(read_calibration_file(p)), p.stem().string());
            } catch (const InputError& e) {
                s.fail(s.get("calibration"), "calibration", fmt::format("the calibration file is unusable: {}", e.what()));
            }
        }
        out.encode.bits = s.integer("bits", 1, 16).value_or(out.encode.bits);
        if (auto d = s.boolean("dither")) out.encode.dither = *d ? Dither::spatiotemporal : Dither::none;
        if (auto seed = s.integer("dither_seed", 0, std::numeric_limits<int>::max()))
            out.encode.seed = static_cast<std::uint32_t>(*seed);
    }
    ToneMapSettings& tm = out.tonemap;
    tm.display_peak_cd_m2 = out.display.peak_cd_m2;
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
