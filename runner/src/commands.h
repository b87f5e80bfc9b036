#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace atonlab::runner {

struct RenderOptions {
    std::string scene;
    std::string exr;
    std::string png;
    double time_s = 0.0;
    std::vector<std::string> overrides;
    bool half = false;
    std::optional<double> white_cd_m2;
};

void add_render_command(CLI::App& app, RenderOptions& options);
int run_render(const RenderOptions& options);

struct PsfOptions {
    std::optional<double> pupil_mm;
    std::optional<double> adaptation_cd_m2;
    std::string scene;
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

}  // namespace atonlab::runner
