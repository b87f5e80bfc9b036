// The wave-optics model's keys of [glare], declared and read (eye_keys.h).
#include "eye_keys.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <optional>
#include <string>

#include "atonlab/common/input_error.h"
#include "atonlab/stimuli/eye_model.h"

namespace atonlab::stimuli::wave_optics {
namespace {

// Each key's value as the kernel cache key spells it (glare_setting.h).
template <class T>
std::string text(const T& v) {
    return fmt::format("{}", v);
}
std::string optional_text(const std::optional<double>& v) {
    return v ? text(*v) : std::string("physical");
}

// The declarations, in docs/scene-file.md's order. A preset also sets fields
// no key reads (the eye's scale, the particles' spread and opacity, the lashes'
// reach and tilt, the gratings' jitter, hippus's largest pupil): eye_preset's
// text is those, so a preset that changes them changes the kernel's key.
const GlareSetting kSettings[] = {
    {.key = "spectral_path",
     .type = "string",
     .unit = "—",
     .default_text = "`\"anchored\"`",
     .doc = "how `wave-optics` integrates the spectrum (docs/glare.md \"The spectral path\"): `\"anchored\"` (exact "
            "FFTs at `spectral_anchors` wavelengths, each sample rescaled from its nearest anchors; within 1% of "
            "exact), `\"rescaled\"` (K2012 eq 4.9: one λ0 FFT rescaled to every sample, on the GPU), `\"exact\"` (one "
            "pupil plane and FFT per sample)",
     .example = "\"exact\"",
     .typed_text = [](const GlareSettings& g) { return std::string(spectral_path_name(g.spectral_path)); }},
    {.key = "spectral_anchors",
     .type = "integer",
     .unit = "—",
     .default_text = "6",
     .doc = "`anchored`: anchor wavelengths, 1 … 128, placed at quantiles of the SPD's light",
     .example = "4",
     .typed_text = [](const GlareSettings& g) { return text(g.spectral_anchors); }},
    {.key = "seed",
     .type = "integer",
     .unit = "—",
     .default_text = "1",
     .doc = "the eye's obstacles; same seed → bit-identical PSF on a machine",
     .example = "7",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.seed); }},
    {.key = "eye_preset",
     .type = "string",
     .unit = "—",
     .default_text = "`\"focused\"`",
     .doc = "the eye the other keys start from: `\"focused\"` (two angular scales, in focus; docs/glare.md) or "
            "`\"k2012\"` (the thesis's single scale and Fresnel term at d = 5000 mm, i.e. 0.2 D, drawn with "
            "`spectral_path = \"rescaled\"` unless that key is given); read before every other eye key",
     .example = "\"k2012\"",
     .typed_text =
         [](const GlareSettings& g) {
             const EyeModel& e = g.eye;
             std::string t = fmt::format("{}|{}|{}|{}|", static_cast<int>(e.scale), e.hippus.max_pupil_mm,
                                         e.gratings.angle_jitter, e.eyelashes.reach_mm);
             t += fmt::format("{}|", e.eyelashes.max_tilt_deg);
             for (const Particles* p : {&e.lens_particles, &e.vitreous_particles})
                 t += fmt::format("{}|{}|{}|", p->diameter_spread, p->opacity, p->spread_radius_mm);
             return t;
         }},
    {.key = "clear_pupil",
     .type = "bool",
     .unit = "—",
     .default_text = "false",
     .doc = "a clear circular pupil: every obstacle and hippus off, in focus, physical scale (tests, studies)",
     .example = "true",
     // What it sets is the other keys' fields; its own share is whether they are all clear.
     .typed_text =
         [](const GlareSettings& g) {
             const EyeModel& e = g.eye;
             return text(!e.gratings.enabled && !e.lens_particles.enabled && !e.vitreous_particles.enabled &&
                         !e.eyelashes.enabled && !e.eyelid.enabled && !e.hippus.enabled);
         }},
    {.key = "halo_radius_deg",
     .type = "number",
     .unit = "°",
     .default_text = "4",
     .doc = "the scatter's angular scale (Simpson 1953): the halo's brightest ring at λ0 = 575 nm (the gratings at "
            "the pupil's edge) lands here; `k2012`: the whole PSF is scaled so the gratings' outer halo edge lands "
            "here; 0 = physical λ/W for everything",
     .example = "3",
     .typed_text = [](const GlareSettings& g) { return optional_text(g.eye.halo_radius_deg); }},
    {.key = "plane_width_mm",
     .type = "number",
     .unit = "mm",
     .default_text = "18",
     .doc = "side W of the pupil plane; ≥ 2 × the pupil keeps |F|² unaliased",
     .example = "20",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.plane_width_mm); }},
    {.key = "defocus_diopters",
     .type = "number",
     .unit = "D (1/m)",
     .default_text = "0",
     .doc = "defocus ΔD, either sign: pupil phase exp(iπ ΔD r²/λ) (K2012 eq 4.6's E with d = 1/ΔD); blur disc "
            "radius p·ΔD/2 rad; at most λ0·N/(p·W) (4.09 D for 4 mm at N = 512, 2.04 D for 8 mm), checked at load "
            "with the scene's pupil (`pupil_mm`, or eq 3.15 from a fixed adaptation, or 7.9 mm when it is dynamic), "
            "else an error at this key's line saying why. The old `fresnel_distance_mm` is refused with a message "
            "naming this key (d mm = 1000/d D)",
     .example = "0.5",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.defocus_diopters); }},
    {.key = "supersampling",
     .type = "integer",
     .unit = "—",
     .default_text = "4",
     .doc = "samples per texel per axis when drawing the pupil plane",
     .example = "2",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.supersampling); }},
    {.key = "hippus",
     .type = "bool",
     .unit = "—",
     .default_text = "false",
     .doc = "pupillary hippus, eq 4.7 (seeded smooth noise, driven by the render time)",
     .example = "true",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.hippus.enabled); }},
    {.key = "hippus_amplitude",
     .type = "number",
     .unit = "—",
     .default_text = "0.1",
     .doc = "hippus: the noise term's scale",
     .example = "0.2",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.hippus.amplitude); }},
    {.key = "gratings",
     .type = "bool",
     .unit = "—",
     .default_text = "true",
     .doc = "radial lens gratings → lenticular halo",
     .example = "false",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.gratings.enabled); }},
    {.key = "grating_count",
     .type = "integer",
     .unit = "—",
     .default_text = "120",
     .doc = "gratings: the number of radial lines",
     .example = "90",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.gratings.count); }},
    {.key = "grating_inner_radius_mm",
     .type = "number",
     .unit = "mm",
     .default_text = "1.6",
     .doc = "gratings: where the lines start",
     .example = "1.2",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.gratings.inner_radius_mm); }},
    {.key = "grating_width_um",
     .type = "number",
     .unit = "µm",
     .default_text = "12",
     .doc = "gratings: the line width",
     .example = "15",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.gratings.width_um); }},
    {.key = "grating_opacity",
     .type = "number",
     .unit = "—",
     .default_text = "0.35",
     .doc = "gratings: 1 = opaque",
     .example = "0.5",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.gratings.opacity); }},
    {.key = "lens_particles",
     .type = "bool",
     .unit = "—",
     .default_text = "true",
     .doc = "small opaque discs in the pupil → ciliary corona",
     .example = "false",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.lens_particles.enabled); }},
    {.key = "lens_particle_count",
     .type = "integer",
     .unit = "—",
     .default_text = "600",
     .doc = "lens particles: how many",
     .example = "300",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.lens_particles.count); }},
    {.key = "lens_particle_diameter_um",
     .type = "number",
     .unit = "µm",
     .default_text = "30",
     .doc = "lens particles: the mean diameter",
     .example = "40",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.lens_particles.diameter_um); }},
    {.key = "vitreous_particles",
     .type = "bool",
     .unit = "—",
     .default_text = "true",
     .doc = "large, partly transparent discs",
     .example = "false",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.vitreous_particles.enabled); }},
    {.key = "vitreous_particle_count",
     .type = "integer",
     .unit = "—",
     .default_text = "40",
     .doc = "vitreous particles: how many",
     .example = "20",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.vitreous_particles.count); }},
    {.key = "vitreous_particle_diameter_um",
     .type = "number",
     .unit = "µm",
     .default_text = "150",
     .doc = "vitreous particles: the mean diameter",
     .example = "120",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.vitreous_particles.diameter_um); }},
    {.key = "eyelashes",
     .type = "bool",
     .unit = "—",
     .default_text = "false",
     .doc = "near-vertical lines from the top (Kakimoto) → long streaks",
     .example = "true",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.eyelashes.enabled); }},
    {.key = "eyelash_count",
     .type = "integer",
     .unit = "—",
     .default_text = "12",
     .doc = "eyelashes: how many",
     .example = "8",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.eyelashes.count); }},
    {.key = "eyelash_width_um",
     .type = "number",
     .unit = "µm",
     .default_text = "80",
     .doc = "eyelashes: the width of each",
     .example = "60",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.eyelashes.width_um); }},
    {.key = "eyelid",
     .type = "bool",
     .unit = "—",
     .default_text = "false",
     .doc = "the eyelid: everything above `eyelid_edge_mm` is opaque",
     .example = "true",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.eyelid.enabled); }},
    {.key = "eyelid_edge_mm",
     .type = "number",
     .unit = "mm",
     .default_text = "2.5",
     .doc = "eyelid: the edge's height above the pupil's centre",
     .example = "2",
     .typed_text = [](const GlareSettings& g) { return text(g.eye.eyelid.edge_mm); }},
};

std::string joined(const std::vector<std::string>& names) {
    std::string s;
    for (const auto& n : names) s += fmt::format("{}'{}'", s.empty() ? "" : ", ", n);
    return s;
}

void read_eye(const toml_reader::Section& s, EyeModel& e) {
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
}

}  // namespace

std::span<const GlareSetting> settings() {
    return kSettings;
}

void read_keys(const toml_reader::Section& s, GlareSettings& g, double pupil_mm) {
    EyeModel& e = g.eye;
    if (auto preset = s.string("eye_preset")) {
        const std::optional<EyeModel> named = eye_preset(*preset);
        if (!named)
            s.fail(s.get("eye_preset"), "eye_preset",
                   fmt::format("unknown eye preset \"{}\"; presets are {}.", *preset, joined(eye_preset_names())));
        e = *named;
        // The thesis's look includes its spectral method: one FFT at λ0 and
        // eq 4.9 lookups (docs/glare.md). Summed exactly over wavelengths, its
        // defocus rings fill the dark centre it drew, so the preset draws with
        // the rescaled path unless spectral_path says otherwise.
        if (e.scale == EyeScale::k2012_single) g.spectral_path = SpectralPath::rescaled;
    }
    if (s.boolean("clear_pupil").value_or(false)) e = EyeModel::clear_pupil(e.pupil_diameter_mm);
    if (auto p = s.string("spectral_path")) {
        const auto path = spectral_path_from_name(*p);
        if (!path)
            s.fail(
                s.get("spectral_path"), "spectral_path",
                fmt::format("unknown spectral path \"{}\"; it must be \"anchored\", \"rescaled\" or \"exact\".", *p));
        g.spectral_path = *path;
    }
    g.spectral_anchors = s.integer("spectral_anchors", 1, 128).value_or(g.spectral_anchors);
    read_eye(s, e);
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

}  // namespace atonlab::stimuli::wave_optics
