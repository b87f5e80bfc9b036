#pragma once
// `atonlab tonemap` and `atonlab glare`: HDR images atonlab did not render, in
// and out (docs/tone-mapping.md "HDR images in and out").
#include <optional>
#include <string>

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
    std::optional<std::string> display;  ///< srgb or pq
    std::optional<double> peak_cd_m2;
    std::optional<double> black_cd_m2;
    std::optional<std::string> dither;     ///< on or off
    std::optional<std::string> blueshift;  ///< on or off
    std::optional<std::string> hue_preservation;
    std::optional<double> key;                  ///< reinhard's key
    std::optional<std::string> reinhard_white;  ///< a number or "max"
    std::optional<double> white_cd_m2;          ///< linear, clamp
};

void add_tonemap_command(CLI::App& app, TonemapOptions& options);
int run_tonemap(const TonemapOptions& options);

struct GlareImageOptions {
    std::string input;   ///< scene-referred EXR
    std::string output;  ///< EXR with the glare added
    std::string scene;   ///< take [glare] (and the adaptation) from here
    std::optional<std::string> model;
    std::optional<double> degrees_per_pixel;
    std::optional<double> adaptation_cd_m2;
    std::optional<double> pupil_mm;
    std::optional<double> radius_deg;
    std::optional<double> bloom_sigma_deg;
    std::optional<std::string> window;
    std::optional<int> psf_size;
};

void add_glare_command(CLI::App& app, GlareImageOptions& options);
int run_glare(const GlareImageOptions& options);

}  // namespace atonlab::runner
