#pragma once
// The wave-optics model's keys of [glare]: its spectral path and the eye model
// (eye_model.h; docs/scene-file.md "[glare]").
#include <string_view>

#include "atonlab/common/toml_reader.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli::wave_optics {

inline constexpr std::string_view kKeys[] = {"eye_preset",
                                             "spectral_path",
                                             "spectral_anchors",
                                             "seed",
                                             "halo_radius_deg",
                                             "plane_width_mm",
                                             "defocus_diopters",
                                             "supersampling",
                                             "clear_pupil",
                                             "hippus",
                                             "hippus_amplitude",
                                             "gratings",
                                             "grating_count",
                                             "grating_inner_radius_mm",
                                             "grating_width_um",
                                             "grating_opacity",
                                             "lens_particles",
                                             "lens_particle_count",
                                             "lens_particle_diameter_um",
                                             "vitreous_particles",
                                             "vitreous_particle_count",
                                             "vitreous_particle_diameter_um",
                                             "eyelashes",
                                             "eyelash_count",
                                             "eyelash_width_um",
                                             "eyelid",
                                             "eyelid_edge_mm"};

/// Reads them into g (g.psf_size already read) and checks the eye model with
/// the scene's pupil (pupil_mm), failing at the key's line.
void read_keys(const toml_reader::Section& s, GlareSettings& g, double pupil_mm);

}  // namespace atonlab::stimuli::wave_optics
