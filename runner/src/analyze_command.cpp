// `atonlab analyze STUDY.db... [--csv FILE]... --out DIR [--bootstrap N] [--seed N] [--family F] [--quiet]`
// `atonlab analyze SIMULATION_DIR --out DIR [--intervals profile|bootstrap] [--effect D] [--effect-between A,B]`
// (a folder `atonlab simulate` wrote: analyze_simulation.cpp)
// Offline analysis of response logs (docs/analysis.md): reads study files
// read-only (and/or CSVs of trials), fits and summarises every condition
// (analysis/), draws the figures with gnuplot and writes report.html,
// summary.json, fits.csv, trials.csv and figures/ into DIR.
//
// The one part that needs the stimuli library lives in runner/, not in
// analysis/: the stored stimulus snapshots (scene-referred EXR, cd/m²) are made
// into PNGs for the report by snapshot_picture.cpp.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <set>
#include <thread>

#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/display_losses.h"
#include "atonlab/analysis/plots.h"
#include "atonlab/analysis/report.h"
#include "atonlab/analysis/simulation.h"
#include "atonlab/analysis/study_analysis.h"
#include "atonlab/runner/analyze_command.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/store/error.h"
#include "atonlab/store/store.h"
#include "snapshot_picture.h"

namespace atonlab::runner {

namespace an = atonlab::analysis;
namespace fs = std::filesystem;

void add_analyze_command(CLI::App& app, AnalyzeOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "analyze", "Analyse study files (or CSVs of trials): fits, report.html, summary.json, CSVs and figures");
    cmd->add_option("studies", o.studies,
                    "Study files (SQLite; opened read-only; see docs/store.md), or one simulation folder (atonlab "
                    "simulate's --out)");
    cmd->add_option("--csv", o.csv, "A long-format CSV of trials (docs/analysis.md); may be given several times");
    cmd->add_option("--out", o.out, "Output folder (created if absent)")->required();
    cmd->add_option("--bootstrap", o.bootstrap, "Parametric bootstrap resamples per fit (0: no intervals)")
        ->check(CLI::Range(0, 1000000));
    cmd->add_option("--seed", o.seed, "Seed of the bootstrap's random streams");
    cmd->add_option("--family", o.family, "Psychometric function: normal, logistic, weibull, gumbel")
        ->check(CLI::IsMember({"normal", "logistic", "weibull", "gumbel"}));
    cmd->add_option("--last-reversals", o.last_reversals, "Staircases: average the last N reversals")
        ->check(CLI::Range(1, 1000));
    cmd->add_option("--threads", o.threads,
                    "Bootstrap threads (default: the machine's cores; results do not depend on it)")
        ->check(CLI::Range(1, 256));
    cmd->add_option("--gnuplot", o.gnuplot, "The gnuplot program that draws the figures");
    cmd->add_flag("--quiet", o.quiet, "Print nothing but errors");
    cmd->add_flag("--salvage", o.salvage,
                  "Read what SQLite can still read of a damaged study file instead of refusing it; the report and "
                  "summary.json say first which file was damaged and how many rows were read");
    cmd->add_option("--intervals", o.intervals,
                    "A simulation folder: each session's interval, profile (likelihood, no resampling; the default) "
                    "or bootstrap (parametric, --bootstrap N resamples, percentile)")
        ->check(CLI::IsMember({"profile", "bootstrap"}));
    cmd->add_option("--effect", o.effect,
                    "A simulation folder: the effect (log10 units) whose power to be detected at alpha = 0.05 is "
                    "reported");
    cmd->add_option("--effect-between", o.effect_between,
                    "A simulation folder: the two conditions A,B the effect lies between (A - B); default: each "
                    "glare condition's enhancement");
}

namespace {

/// One updating line on a terminal, a line per finished group otherwise.
class BootstrapProgress {
public:
    explicit BootstrapProgress(bool quiet) : quiet_(quiet), tty_(isatty(2) != 0) {}
    ~BootstrapProgress() { end(); }
    BootstrapProgress(const BootstrapProgress&) = delete;
    BootstrapProgress& operator=(const BootstrapProgress&) = delete;

    void operator()(const std::string& group, int done, int total) {
        if (quiet_) return;
        const auto now = std::chrono::steady_clock::now();
        if (tty_) {
            if (done != total && group == group_ && now - last_ < std::chrono::milliseconds(100)) return;
            std::fprintf(stderr, "\r\033[Kbootstrap: %s %d/%d", group.c_str(), done, total);
            std::fflush(stderr);
            open_ = true;
        } else if (done == total) {
            std::fprintf(stderr, "bootstrap: %s: %d resamples\n", group.c_str(), total);
        }
        group_ = group;
        last_ = now;
    }
    void end() {
        if (open_) std::fprintf(stderr, "\r\033[K");
        open_ = false;
    }

private:
    bool quiet_;
    bool tty_;
    bool open_ = false;
    std::string group_;
    std::chrono::steady_clock::time_point last_{};
};

/// Snapshot PNGs for every condition that has one (the first session's).
std::vector<an::SnapshotImage> make_snapshots(const an::Dataset& data, const an::StudyResults& results,
                                              const fs::path& out_dir, std::vector<std::string>& problems) {
    std::vector<an::SnapshotImage> out;
    std::set<std::string> done;
    std::map<std::string, std::unique_ptr<store::Store>> open;
    const std::map<std::string, std::string> slugs = an::condition_slugs(results);  // one file per condition
    for (const an::SnapshotRef& ref : data.snapshots) {
        if (done.count(ref.condition)) continue;
        const an::ConditionInfo* c = results.condition(ref.condition);
        if (!c) continue;
        try {
            const std::string& file = ref.read_from.empty() ? ref.source : ref.read_from;
            auto& db = open[file];
            if (!db) {
                // read_study has checked the file (or salvaged it): not a second integrity check.
                store::StoreOptions options;
                options.verify = false;
                db = std::make_unique<store::Store>(store::Store::open_read_only(file, options));
            }
            const auto snap = db->get_snapshot(store::SessionId{ref.session_id}, ref.condition);
            if (!snap) continue;
            done.insert(ref.condition);
            fs::create_directories(out_dir / "figures");
            const fs::path rel = fs::path("figures") / ("snapshot-" + slugs.at(ref.condition) + ".png");
            std::string caption;
            const std::string why = snapshot_png(*snap, *c, out_dir / rel, caption);
            if (!why.empty()) {
                problems.push_back(fmt::format("the snapshot of condition \"{}\" (session {}) could not be shown: {}",
                                               ref.condition, ref.session, why));
                continue;
            }
            out.push_back({ref.condition, ref.session, rel, caption});
        } catch (const store::StoreError& e) {
            problems.push_back(
                fmt::format("the snapshot of condition \"{}\" could not be read: {}", ref.condition, e.what()));
        }
    }
    return out;
}

std::string command_line_text(const AnalyzeOptions& o) {
    std::string s = "atonlab analyze";
    for (const std::string& f : o.studies) s += " " + f;
    for (const std::string& f : o.csv) s += " --csv " + f;
    s += " --out " + o.out;
    if (o.bootstrap) s += fmt::format(" --bootstrap {}", *o.bootstrap);
    if (o.seed) s += fmt::format(" --seed {}", *o.seed);
    if (!o.family.empty()) s += " --family " + o.family;
    if (o.salvage) s += " --salvage";
    return s;
}

/// A study-file error that is the command line's fault (exit status 2: no such
/// file, an argument out of range) rather than the file's (4: not a study
/// file, a newer schema, damaged — refused as `run` and `calibrate` refuse it).
bool is_bad_input(store::StoreErrc k) {
    using store::StoreErrc;
    return k == StoreErrc::cannot_open || k == StoreErrc::not_found || k == StoreErrc::invalid_argument;
}

}  // namespace

bool make_output_folder(const std::string& out) {
    std::error_code ec;
    fs::create_directories(out, ec);
    if (ec || !fs::is_directory(out)) {
        std::fprintf(stderr, "atonlab: %s: the output folder cannot be created (%s).\n", out.c_str(),
                     ec ? ec.message().c_str() : "a file of that name exists");
        return false;
    }
    return true;
}

int run_analyze(const AnalyzeOptions& o) {
    if (o.studies.size() == 1 && fs::is_directory(o.studies.front())) {
        if (!an::is_simulation_folder(o.studies.front()))
            throw InputError(fmt::format("{} is a folder without simulation.json: atonlab analyze reads study files, "
                                         "CSVs of trials, or one simulation folder (docs/analysis.md).",
                                         o.studies.front()));
        if (!o.csv.empty() || o.salvage)
            throw InputError(SourceLocation::command_line(o.salvage ? "--salvage" : "--csv"),
                             "a simulation folder is analysed alone, without --csv or --salvage");
        return run_analyze_simulation(o);
    }
    for (const auto& [given, option] : {std::pair{!o.intervals.empty(), "--intervals"},
                                        std::pair{o.effect.has_value(), "--effect"},
                                        std::pair{!o.effect_between.empty(), "--effect-between"}})
        if (given)
            throw InputError(SourceLocation::command_line(option),
                             "this option is for a simulation folder (atonlab analyze DIR), not for study files");
    if (o.studies.empty() && o.csv.empty())
        throw InputError("atonlab analyze needs at least one study file or --csv FILE to read.");
    an::AnalysisOptions ao;
    if (o.bootstrap) ao.bootstrap = *o.bootstrap;
    if (o.seed) ao.seed = *o.seed;
    if (!o.family.empty()) ao.family = *an::parse_family(o.family);
    ao.last_reversals = o.last_reversals;
    ao.n_threads = o.threads ? *o.threads : std::max(1u, std::min(8u, std::thread::hardware_concurrency()));

    // --- read every input: nothing is written before all of them are read.
    an::Dataset data;
    try {
        for (const std::string& f : o.studies) an::merge(data, an::read_study(f, o.salvage));
        for (const std::string& f : o.csv) an::merge(data, an::read_trials_csv(f));
    } catch (const store::StoreError& e) {
        std::fprintf(stderr, "atonlab: %s\n", e.what());
        return is_bad_input(e.kind()) ? 2 : 4;
    } catch (const InputError& e) {
        std::fprintf(stderr, "atonlab: %s\n", e.what());
        return 2;
    }
    if (data.trials.empty() && data.sessions.empty()) {
        std::fprintf(stderr, "atonlab: the input holds no sessions and no trials: nothing to analyse.\n");
        return 2;
    }

    const fs::path out_dir = o.out;
    if (!make_output_folder(o.out)) return 2;

    for (const an::DamagedInput& x : data.damaged) {
        std::fprintf(stderr,
                     "atonlab: warning: %s is damaged; salvaged %zu session(s) and %zu trial(s), %lld trial row(s) "
                     "unreadable\n",
                     x.file.c_str(), x.sessions_read, x.trials_read, static_cast<long long>(x.trials_unreadable));
        // Each row left out, named (all of them are in summary.json and report.html).
        constexpr std::size_t kListed = 20;
        for (std::size_t i = 0; i < std::min(x.skipped_rows.size(), kListed); ++i)
            std::fprintf(stderr, "atonlab: warning: %s: left out %s\n", x.file.c_str(), x.skipped_rows[i].c_str());
        if (x.skipped_rows.size() > kListed)
            std::fprintf(stderr, "atonlab: warning: %s: and %zu more rows left out (listed in summary.json)\n",
                         x.file.c_str(), x.skipped_rows.size() - kListed);
    }

    const auto started = std::chrono::steady_clock::now();
    BootstrapProgress progress(o.quiet);
    ao.progress = [&progress](const std::string& g, int done, int total) { progress(g, done, total); };
    const an::StudyResults results = an::analyze_study(data, ao);
    progress.end();
    const double analysis_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

    an::PlotOptions po;
    po.gnuplot = o.gnuplot;
    const an::PlotResult plots = an::make_figures(out_dir, data, results, po);
    an::ReportContext ctx;
    ctx.data = &data;
    ctx.results = &results;
    ctx.plots = &plots;
    ctx.snapshots = make_snapshots(data, results, out_dir, ctx.problems);
    ctx.software_version = ATONLAB_VERSION;
    ctx.command_line = command_line_text(o);
    an::write_report(out_dir, ctx);
    const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

    if (!o.quiet) {
        std::printf(
            "analysed %zu trials of %zu observer(s) in %zu session(s): %zu conditions (%.1f s fits and "
            "bootstrap, %.1f s in all)\n",
            data.trials.size(), results.observers.size(), data.sessions.size(), results.conditions.size(), analysis_s,
            total_s);
        for (const an::ConditionInfo& c : results.conditions) {
            const an::GroupResult* g = results.main_group(c.condition);
            if (!g) continue;
            const an::HeadlineEstimate& h = g->headline;
            std::string line = fmt::format("  {:<24} ", c.condition);
            if (h.value) {
                line += fmt::format("{:.3f}", *h.value);
                if (h.ci) line += fmt::format(" [{:.3f}, {:.3f}]", h.ci->lower, h.ci->upper);
                line += fmt::format(" {} ({})", c.level_unit(), h.method);
            } else {
                line += "no estimate";
            }
            if (!h.reliable && !h.reason.empty()) line += "; unreliable: " + h.reason;
            std::printf("%s\n", line.c_str());
        }
        for (const an::SessionInfo& s : data.sessions) {
            if (s.displayable == false)
                std::printf(
                    "  session %s ran with --allow-undisplayable: %s could not produce a match on its display\n",
                    s.key.c_str(), fmt::format("{}", fmt::join(s.undisplayable, ", ")).c_str());
            for (const std::string& loss : an::display_loss_sentences(s))
                std::printf("  session %s: %s\n", s.key.c_str(), loss.c_str());
            if (s.presentation_margin)
                std::printf("  session %s: presentation margin %.0f %% of a refresh\n", s.key.c_str(),
                            *s.presentation_margin * 100.0);
            if (s.stops > 0)
                std::printf("  session %s was stopped by the runner %d time(s) (status %s); last: %s\n", s.key.c_str(),
                            s.stops, s.status.c_str(), s.stop_text.c_str());
        }
        const std::size_t notes = results.warnings.size() + plots.problems.size() + ctx.problems.size();
        if (notes) std::printf("%zu note(s) and warning(s): see the report\n", notes);
        std::printf("report: %s\n", (out_dir / "report.html").string().c_str());
    }
    for (const std::string& p : plots.problems) std::fprintf(stderr, "atonlab: warning: %s\n", p.c_str());
    // The report is complete but a figure is missing: a distinct status, so a
    // script notices (docs/analysis.md "Exit status").
    return plots.problems.empty() ? 0 : 5;
}

}  // namespace atonlab::runner
