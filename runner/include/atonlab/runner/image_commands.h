#pragma once
// `atonlab tonemap` and `atonlab glare`: HDR images atonlab did not render, in
// and out (docs/tone-mapping.md "HDR images in and out").
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/common/toml_value.h"
#include "atonlab/stimuli/glare_models/glare_model_list.h"
#include "atonlab/stimuli/image_io.h"

namespace CLI {
class App;
}

namespace atonlab::runner {

struct TonemapOptions {
    std::string input;                       ///< scene-referred EXR
    std::string png;                         ///< output PNG (8-bit display codes)
    std::string scene;                       ///< take [display] and [tonemap] (and a fixed adaptation) from here
    std::optional<double> scale;             ///< cd/m² per pixel unit (default 1 for a cd/m2 EXR)
    std::optional<double> adaptation_cd_m2;  ///< default: the log-average (K2012 eq 4.15)
    std::optional<double> epsilon_cd_m2;     ///< ε of eq 4.15
    std::optional<std::string> tone_operator;
    std::optional<std::string> encoding;  ///< the display's encoding: srgb or pq (display_encodings.h)
    /// `--display`, the old name of `--encoding`: still taken, with a note.
    std::optional<std::string> deprecated_display;
    std::optional<double> peak_cd_m2;
    std::optional<double> black_cd_m2;
    std::optional<std::string> dither;     ///< on or off
    std::optional<std::string> blueshift;  ///< on or off
    std::optional<std::string> hue_preservation;
    std::optional<std::string> out_of_gamut;    ///< display.out_of_gamut (gamut.h)
    std::optional<double> key;                  ///< reinhard's key
    std::optional<std::string> reinhard_white;  ///< a number or "max"
    std::optional<double> white_cd_m2;          ///< linear, clamp
};

void add_tonemap_command(CLI::App& app, TonemapOptions& options);
int run_tonemap(const TonemapOptions& options);

/// What tonemap_image() made: the display's 8-bit codes and what was applied.
struct ToneMapped {
    int width = 0, height = 0;
    std::vector<std::uint8_t> codes;  ///< RGB, row 0 at the top, width * height * 3
    std::string units;                ///< how the input was taken as cd/m²
    double log_average_cd_m2 = 0.0;   ///< K2012 eq 4.15
    double adaptation_cd_m2 = 0.0;    ///< the L_wa used
    std::size_t clipped = 0;          ///< pixels above display white
    std::string settings;             ///< the two lines `atonlab tonemap` prints after its first
};

/// `atonlab tonemap`'s work without its files (the Python module's
/// atonlab.tonemap): the options checked first, then read_input() called for
/// the scene-referred image (o.input names it in messages), tone-mapped and
/// encoded on the CPU. Throws InputError as the command does.
ToneMapped tonemap_image(const TonemapOptions& options, const std::function<stimuli::ExrImage()>& read_input);

/// `atonlab glare`'s (and atonlab.glare()'s) model when none is given: Spencer et al. 1995's PSF,
/// which needs no scene (docs/glare.md).
inline constexpr stimuli::GlareModel kDefaultImageGlareModel = stimuli::GlareModel::spencer;

struct GlareImageOptions {
    std::string input;   ///< scene-referred EXR
    std::string output;  ///< EXR with the glare added
    std::string scene;   ///< take [glare] (and the adaptation) from here
    std::optional<std::string> model;
    std::optional<double> degrees_per_pixel;
    std::optional<double> adaptation_cd_m2;
    std::optional<double> pupil_mm;
    std::optional<double> radius_deg;
    /// The models' own settings by key (--bloom-sigma-deg for bloom_sigma_deg;
    /// each model declares them, glare_models/glare_setting.h).
    std::map<std::string, TomlValue, std::less<>> settings;
    std::optional<std::string> window;
    std::optional<int> psf_size;
};

void add_glare_command(CLI::App& app, GlareImageOptions& options);
int run_glare(const GlareImageOptions& options);

/// What glare_image() made: the image with the glare and the EXR attributes
/// `atonlab glare` writes, and its report lines.
struct ImageGlared {
    stimuli::ExrImage image;
    std::string line;  ///< model, pupil, kernel and cuts (the image_glare attribute)
    std::string sums;  ///< the energy line `atonlab glare` prints
};

/// `atonlab glare`'s work without its files (the Python module's
/// atonlab.glare): the options checked first, then read_input() called for
/// the image. Throws InputError as the command does.
ImageGlared glare_image(const GlareImageOptions& options, const std::function<stimuli::ExrImage()>& read_input);

}  // namespace atonlab::runner
