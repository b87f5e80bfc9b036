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

/// `atonlab run` (docs/running.md). Exit status: 0 completed, 2 bad input, 3 no
/// GL, 4 the study file failed (StoreError), 128 + N stopped by signal N.
struct RunOptions {
    std::string protocol;
    std::string db;
    bool model_observer = false;
    std::string observer;  ///< the observer code (--observer)
    std::string script;    ///< scripted answers (--script)
    bool headless = false;
    std::optional<std::int64_t> resume;
    bool resume_last = false;
    std::optional<std::uint64_t> seed;
    std::optional<std::uint64_t> observer_seed;
    bool quiet = false;
    int progress_every = 0;         ///< 0: 25 when stdout is not a terminal (a terminal gets one updating line)
    bool true_pse = true;           ///< model observer: compute the true PSE / threshold for the summary
    std::int64_t db_max_bytes = 0;  ///< > 0: the study file may not grow past this (StoreOptions::max_size_bytes)
};

void add_run_command(CLI::App& app, RunOptions& options);
int run_run(const RunOptions& options);

}  // namespace atonlab::runner
