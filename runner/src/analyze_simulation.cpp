// `atonlab analyze DIR` for a simulation folder (docs/analysis.md "The
// simulation report"): every session file read and estimated on all cores
// (analysis/simulation.h), the report written into --out
// (analysis/simulation_report.h). Exit status: 0 done (files left out are
// listed, on stderr and in the report), 2 bad input, 4 no session file could
// be used (the report still lists why), 5 the report lacks a figure.
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "atonlab/analysis/simulation.h"
#include "atonlab/analysis/simulation_report.h"
#include "atonlab/common/input_error.h"
#include "atonlab/runner/analyze_command.h"

namespace atonlab::runner {

namespace an = atonlab::analysis;
namespace fs = std::filesystem;

namespace {

std::string command_line_text(const AnalyzeOptions& o) {
    std::string s = "atonlab analyze " + o.studies.front() + " --out " + o.out;
    if (!o.intervals.empty()) s += " --intervals " + o.intervals;
    if (o.bootstrap) s += fmt::format(" --bootstrap {}", *o.bootstrap);
    if (o.seed) s += fmt::format(" --seed {}", *o.seed);
    if (!o.family.empty()) s += " --family " + o.family;
    if (o.effect) s += fmt::format(" --effect {}", *o.effect);
    if (!o.effect_between.empty()) s += " --effect-between " + o.effect_between;
    return s;
}

an::SimulationOptions simulation_options(const AnalyzeOptions& o) {
    an::SimulationOptions so;
    so.intervals = o.intervals == "bootstrap" ? an::IntervalMethod::Bootstrap : an::IntervalMethod::Profile;
    if (o.bootstrap) {
        if (so.intervals != an::IntervalMethod::Bootstrap)
            throw InputError(SourceLocation::command_line("--bootstrap"),
                             "a simulation folder's intervals are resampled only with --intervals bootstrap");
        so.bootstrap = *o.bootstrap;
    }
    if (o.seed) so.seed = *o.seed;
    if (!o.family.empty()) so.family = *an::parse_family(o.family);
    so.last_reversals = o.last_reversals;
    so.n_threads = o.threads ? *o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    if (o.effect) {
        if (!std::isfinite(*o.effect))
            throw InputError(SourceLocation::command_line("--effect"), "the effect must be a finite number");
        so.effect_log10 = *o.effect;
    }
    if (!o.effect_between.empty()) {
        const auto comma = o.effect_between.find(',');
        if (comma == std::string::npos || comma == 0 || comma + 1 == o.effect_between.size() ||
            o.effect_between.find(',', comma + 1) != std::string::npos)
            throw InputError(SourceLocation::command_line("--effect-between"),
                             fmt::format("\"{}\" is not two condition names A,B", o.effect_between));
        if (!o.effect)
            throw InputError(SourceLocation::command_line("--effect-between"), "it needs --effect D, the effect");
        so.effect_between = std::pair{o.effect_between.substr(0, comma), o.effect_between.substr(comma + 1)};
    }
    return so;
}

}  // namespace

int run_analyze_simulation(const AnalyzeOptions& o) {
    const auto started = std::chrono::steady_clock::now();
    an::SimulationOptions so = simulation_options(o);
    const fs::path dir = o.studies.front();
    const bool tty = isatty(2) != 0 && !o.quiet;
    auto last = std::chrono::steady_clock::now();
    so.progress = [&](std::size_t done, std::size_t total) {
        const auto now = std::chrono::steady_clock::now();
        if (!tty || (done != total && now - last < std::chrono::milliseconds(200))) return;
        last = now;
        const double s = std::chrono::duration<double>(now - started).count();
        std::fprintf(stderr, "\r\033[Kread %zu/%zu files (%.0f/s)", done, total,
                     s > 0.0 ? static_cast<double>(done) / s : 0.0);
        std::fflush(stderr);
    };
    const an::SimulationResults results = an::analyze_simulation(dir, so);
    if (tty) std::fprintf(stderr, "\r\033[K");

    const fs::path out_dir = o.out;
    if (!make_output_folder(o.out)) return 2;
    an::PlotOptions po;
    po.gnuplot = o.gnuplot;
    const an::PlotResult plots = an::make_simulation_figures(out_dir, results, po);
    an::SimulationReportContext ctx;
    ctx.results = &results;
    ctx.plots = &plots;
    ctx.software_version = ATONLAB_VERSION;
    ctx.command_line = command_line_text(o);
    ctx.total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    an::write_simulation_report(out_dir, ctx);

    constexpr std::size_t kListed = 20;
    for (std::size_t i = 0; i < std::min(kListed, results.skipped.size()); ++i)
        std::fprintf(stderr, "atonlab: warning: left out %s: %s\n", results.skipped[i].file.c_str(),
                     results.skipped[i].reason.c_str());
    if (results.skipped.size() > kListed)
        std::fprintf(stderr, "atonlab: warning: and %zu more files left out (listed in summary.json)\n",
                     results.skipped.size() - kListed);
    for (const std::string& p : plots.problems) std::fprintf(stderr, "atonlab: warning: %s\n", p.c_str());
    if (!o.quiet) {
        std::printf("read %zu session(s) of %zu file(s) in %.1f s (%zu left out), %zu design(s)\n",
                    results.sessions.size(), results.files_found, results.read_s, results.skipped.size(),
                    results.manifest.designs.size());
        if (results.bootstrap_fits > 0)
            std::printf("bootstrap: %lld refits, %.0f fits/s on %d thread(s)\n",
                        static_cast<long long>(results.bootstrap_fits),
                        static_cast<double>(results.bootstrap_fits) / std::max(results.read_s, 1e-9), so.n_threads);
        for (const an::ConditionSummary& c : results.conditions) {
            std::printf("  %-16s %-20s bias %s  SD %s  coverage %s (%d/%d)\n", c.design.c_str(), c.condition.c_str(),
                        c.bias ? fmt::format("{:+.4f}", *c.bias).c_str() : "-",
                        c.sd ? fmt::format("{:.4f}", *c.sd).c_str() : "-",
                        c.coverage ? fmt::format("{:.1f}%", 100.0 * *c.coverage).c_str() : "-", c.n_covered,
                        c.n_intervals);
        }
        for (const an::PowerSummary& p : results.power)
            std::printf("  power %-10s %s: %s (%d sessions)\n", p.design.c_str(),
                        (p.condition_b.empty() ? p.condition_a : p.what).c_str(),
                        p.power ? fmt::format("{:.1f}%", 100.0 * *p.power).c_str() : "-", p.n_sessions);
        std::printf("report: %s\n", (out_dir / "report.html").string().c_str());
    }
    if (results.sessions.empty()) {
        std::fprintf(stderr, "atonlab: %s: no session file could be used (%zu file(s) found; reasons in the report)\n",
                     dir.string().c_str(), results.files_found);
        return 4;
    }
    return plots.problems.empty() ? 0 : 5;
}

}  // namespace atonlab::runner
