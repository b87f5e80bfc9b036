#pragma once
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

/// `atonlab run` (docs/running.md). Exit status: 0 completed, 2 bad input, 3 no
/// GL, 4 the study file failed (StoreError), 5 the display's timing was refused,
/// 6 the observer ended the session (quit key, confirmed), 128 + N stopped by signal N.
struct RunOptions {
    std::string protocol;
    std::string db;
    std::string profiles;      ///< --profiles: the display-profile file (default: profile_location.h)
    bool no_profiles = false;  ///< --no-profiles: the study file's calibrations only
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
    bool allow_undisplayable = false;  ///< run a protocol the displayability check refuses (recorded with the session)
    /// Headless: a GL 4.5 context is already current (the Python module's one
    /// context) and is used instead of a new one.
    bool gl_context_current = false;
    /// Called after each trial is committed with the session's stored trials
    /// and the schedule's bound (the Python module's progress callback and its
    /// Ctrl-C check); it may call request_stop() (session/stop_signals.h).
    std::function<void(std::size_t stored, std::optional<std::size_t> bound)> after_trial;

    // On screen (without --headless; docs/running.md "On screen").
    int monitor = 0;                          ///< GLFW's monitor index; 0 is the primary
    std::optional<double> software_vsync_hz;  ///< pace flips by a timer (a display without vblank, e.g. Xvfb)
    bool skip_sync_test = false;              ///< start even when the refresh measurement fails
    double sync_sd_max_ms = 1.0;              ///< the flip intervals' SD must be below this, ms
    double refresh_tolerance = 0.02;          ///< measured vs nominal refresh rate, relative
    std::string font;                         ///< TrueType font (default DejaVu Sans)
    bool trace = false;                       ///< print what each screen waits for (tests drive keys from it)

    // Test-only (docs/running.md "Testing").
    int inject_stall_frames = 0;                        ///< stall this many refreshes after a stimulus onset ...
    std::optional<std::int64_t> inject_stall_at_trial;  ///< ... of this trial (the store's trial_index)
    std::optional<std::int64_t> capture_trial;          ///< capture each frame of this trial as shown ...
    std::string capture_dir;                            ///< ... into this folder
    std::string capture_screen_file;                    ///< ... copying this file (Xvfb -fbdir's screen) instead of
                                                        ///< reading the GL back buffer
};

void add_run_command(CLI::App& app, RunOptions& options);
int run_run(const RunOptions& options);

/// `atonlab check` (docs/running.md, "Displayability"): what a display shows of
/// a protocol's stimuli. Exit status: 0 displayable, 2 not (or bad input), 3 no
/// GL, 4 the study file (--db) could not be read.
struct CheckOptions {
    std::string protocol;
    std::vector<std::string> sets;  ///< --set display.KEY=VALUE
    std::string db;                 ///< --db: the study file whose calibration encodes the frames
};

void add_check_command(CLI::App& app, CheckOptions& options);
int run_check(const CheckOptions& options);

/// `atonlab analyze` (docs/analysis.md). Exit status: 0 done, 2 bad input, 4 a
/// study file could not be read, 5 the report was written without some figures.
struct AnalyzeOptions {
    std::vector<std::string> studies;  ///< study files, opened read-only
    std::vector<std::string> csv;      ///< long-format CSVs of trials (--csv)
    std::string out;                   ///< output folder
    std::optional<int> bootstrap;      ///< resamples per fit (default 999)
    std::optional<std::uint64_t> seed;
    std::string family;                ///< normal, logistic, weibull, gumbel (default normal)
    int last_reversals = 6;
    std::optional<int> threads;
    std::string gnuplot = "gnuplot";
    bool quiet = false;
    bool salvage = false;  ///< read what is left of a damaged study file instead of refusing it
};

void add_analyze_command(CLI::App& app, AnalyzeOptions& options);
int run_analyze(const AnalyzeOptions& options);

/// `atonlab bench` (docs/bench.md).
struct BenchCommandOptions {
    bool quick = false;
    std::string out_dir;
    std::vector<std::string> only;
    std::string device_label;
    bool no_plots = false;
    bool quiet = false;
};

void add_bench_command(CLI::App& app, BenchCommandOptions& options);
int run_bench(const BenchCommandOptions& options);

}  // namespace atonlab::runner
