// The wave-optics model's keys of [glare] (eye_keys.h).
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
