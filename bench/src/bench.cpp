#include "atonlab/bench/bench.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <stdexcept>

#include "atonlab/stimuli/error.h"
#include "bench_common.h"

namespace atonlab::bench {

namespace {

struct Entry {
    const char* name;
    void (*run)(Bench&);
};

// In run order: the cheap CPU/GPU kernels first, the frames last.
const Entry kBenches[] = {
    {"psf_size", bench_psf_size},
    {"spectral_samples", bench_spectral_samples},
    {"cie_veil", bench_cie_veil},
    {"cie_veil_methods", bench_cie_veil_methods},
    {"psf_rebuild", bench_psf_rebuild},
    {"fft", bench_fft},
    {"pupil_tolerance", bench_pupil_tolerance},
    {"moving_pupil", bench_moving_pupil},
    {"area_layers", bench_area_layers},
    {"hdr_format", bench_hdr_format},
    {"adaptation_stride", bench_adaptation_stride},
    {"tonemap", bench_tonemap},
    {"tonemap_pfstools", bench_tonemap_pfstools},
    {"display_skips", bench_display_skips},
    {"lights", bench_lights},
    {"simulator_frames", bench_simulator_frames},
    {"eye_validation", bench_eye_validation},
};

}  // namespace

std::vector<std::string> bench_names() {
    std::vector<std::string> names;
    for (const Entry& e : kBenches) names.emplace_back(e.name);
    return names;
}

BenchSummary run_bench(const BenchOptions& options, const gl::ContextInfo& context) {
    namespace fs = std::filesystem;
    const std::vector<std::string> names = bench_names();
    for (const std::string& n : options.only)
        if (std::find(names.begin(), names.end(), n) == names.end())
            throw InputError(SourceLocation{"", 0, 0, "--only"},
                             fmt::format("there is no bench \"{}\"; the benches are {}.", n, fmt::join(names, ", ")));
    if (options.out_dir.empty())
        throw InputError(SourceLocation{"", 0, 0, "--out"}, "the bench needs an output directory (--out DIR).");
    std::error_code ec;
    fs::create_directories(options.out_dir, ec);
    if (ec || !fs::is_directory(options.out_dir))
        throw InputError(SourceLocation{options.out_dir, 0, 0, "--out"},
                         fmt::format("cannot create the output directory {}: {}.", options.out_dir, ec.message()));

    set_gpu_timer_trusted(!context.software);
    // Described before the run: the date and the load average are the start's.
    const Machine m = describe_machine(options.device_label, context.vendor, context.renderer, context.version,
                                       context.platform, context.software, options.quick);
    Bench b{options, {}, {}, {}, {}};
    const auto started = std::chrono::steady_clock::now();
    for (const Entry& e : kBenches) {
        if (!options.only.empty() && std::find(options.only.begin(), options.only.end(), e.name) == options.only.end())
            continue;
        const auto t0 = std::chrono::steady_clock::now();
        if (options.verbose) std::printf("bench %s%s\n", e.name, options.quick ? " (quick)" : "");
        e.run(b);
        if (options.verbose)
            std::printf("  (%.1f s)\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    mark_pareto(b.rows);

    BenchSummary summary;
    auto path = [&](const char* f) {
        summary.files.push_back((fs::path(options.out_dir) / f).string());
        return summary.files.back();
    };
    write_csv(path("bench.csv"), b.rows);
    if (!b.points.empty()) write_scaling_csv(path("scaling.csv"), b.points);
    write_machine(path("machine.txt"), m);
    if (context.software)
        b.scaling_notes.push_back("A software rasteriser: every time is the wall clock between glFinish calls "
                                  "(its GL timer queries do not measure compute dispatches).");
    b.scaling_notes.push_back(fmt::format(
        "The whole bench took {:.0f} s.",
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count()));
    write_markdown(path("bench.md"), m, b.rows, b.points, b.scaling_notes);
    for (const auto& [name, text] : b.documents) write_output(path(name.c_str()), text);
    if (options.plots) {
        summary.plotted = write_plots(options.out_dir, b.rows, b.points);
        if (summary.plotted) {
            path("pareto.png");
            if (!b.points.empty()) path("scaling.png");
        }
    }
    summary.rows = static_cast<int>(b.rows.size());
    for (const Row& r : b.rows)
        if (r.is_default && !std::isnan(r.error) && !r.pareto) summary.off_front.push_back(r.bench + ": " + r.setting);
    return summary;
}

}  // namespace atonlab::bench
