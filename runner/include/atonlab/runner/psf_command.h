#pragma once
// `atonlab psf` (docs/glare.md): the eye's point-spread functions to EXR.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "atonlab/stimuli/image_io.h"

namespace CLI {
class App;
}

namespace atonlab::runner {

struct PsfOptions {
    std::optional<double> pupil_mm;
    std::optional<double> adaptation_cd_m2;
    std::string scene;
    std::optional<std::string> eye_preset;
    bool clear = false;
    std::string spd = "d65";
    int size = 512;
    int samples = 30;
    std::optional<std::uint64_t> seed;
    double time_s = 0.0;
    double pixels_per_degree = 50.4;
    double area_radius_px = 0.0;
    int area_layers = 16;
    std::string exr;
};

void add_psf_command(CLI::App& app, PsfOptions& options);
int run_psf(const PsfOptions& options);

/// What `atonlab psf` writes, computed (the Python module's atonlab.psf): the
/// RGB PSF first, then the monochromatic one, then any area layers.
struct PsfImages {
    std::vector<std::pair<std::filesystem::path, stimuli::ImageRGBA32F>> files;  ///< named after options.exr
    std::vector<stimuli::ExrMetadata> metas;                                    ///< one per file
    std::string summary;  ///< the line `atonlab psf` prints
};
/// The options checked, then make_context() called (a GL 4.5 context must be
/// current after it), then the PSFs computed. Throws InputError as the command does.
PsfImages psf_images(const PsfOptions& options, const std::function<void()>& make_context);

}  // namespace atonlab::runner
