// atonlab: one binary, subcommands (docs/architecture.md "The libraries").
// Bad input: one sentence on stderr naming file, line and key; exit status 2.
// No usable GL: one sentence saying why; exit status 3.
// `atonlab run`: the study file failed (StoreError): exit status 4 (run_command.cpp); on screen,
// the display's timing refused: 5; the observer ended the session (quit key, confirmed): 6.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "atonlab/common/read_file.h"
#include "atonlab/runner/analyze_command.h"
#include "atonlab/runner/check_command.h"
#include "atonlab/runner/image_commands.h"
#include "atonlab/runner/light_command.h"
#include "atonlab/runner/psf_command.h"
#include "atonlab/runner/run_command.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/gl/context.h"
#include "bench_command.h"
#include "calibrate/calibrate_command.h"
#include "render_command.h"
#include "simulate_command.h"
#include "view_command.h"

int main(int argc, char** argv) {
    CLI::App app{"atonlab: a psychophysics harness for Aids-to-Navigation lights", "atonlab"};
    app.set_version_flag("--version", "atonlab " ATONLAB_VERSION);
    app.require_subcommand(1);
    atonlab::runner::RenderOptions render;
    atonlab::runner::add_render_command(app, render);
    atonlab::runner::PsfOptions psf;
    atonlab::runner::add_psf_command(app, psf);
    atonlab::runner::RunOptions run;
    atonlab::runner::add_run_command(app, run);
    atonlab::runner::SimulateOptions simulate;
    atonlab::runner::add_simulate_command(app, simulate);
    atonlab::runner::CheckOptions check;
    atonlab::runner::add_check_command(app, check);
    atonlab::runner::AnalyzeOptions analyze;
    atonlab::runner::add_analyze_command(app, analyze);
    atonlab::runner::CalibrateOptions calibrate;
    atonlab::runner::add_calibrate_command(app, calibrate);
    atonlab::runner::ViewOptions view;
    atonlab::runner::add_view_command(app, view);
    atonlab::runner::BenchCommandOptions bench;
    atonlab::runner::add_bench_command(app, bench);
    atonlab::runner::LightOptions light;
    atonlab::runner::add_light_command(app, light);
    atonlab::runner::TonemapOptions tonemap;
    atonlab::runner::add_tonemap_command(app, tonemap);
    atonlab::runner::GlareImageOptions glare;
    atonlab::runner::add_glare_command(app, glare);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help exits 0; a bad option or value (CLI11's own codes, 105 for a
        // value out of range) is bad input like any other: exit status 2.
        return app.exit(e) == 0 ? 0 : 2;
    }
    try {
        if (app.got_subcommand("render")) return atonlab::runner::run_render(render);
        if (app.got_subcommand("psf")) return atonlab::runner::run_psf(psf);
        if (app.got_subcommand("run")) return atonlab::runner::run_run(run);
        if (app.got_subcommand("simulate")) return atonlab::runner::run_simulate(simulate);
        if (app.got_subcommand("check")) return atonlab::runner::run_check(check);
        if (app.got_subcommand("analyze")) return atonlab::runner::run_analyze(analyze);
        if (app.got_subcommand("calibrate")) return atonlab::runner::run_calibrate(calibrate);
        if (app.got_subcommand("view")) return atonlab::runner::run_view(view);
        if (app.got_subcommand("bench")) return atonlab::runner::run_bench(bench);
        if (app.got_subcommand("light")) return atonlab::runner::run_light(light);
        if (app.got_subcommand("tonemap")) return atonlab::runner::run_tonemap(tonemap);
        if (app.got_subcommand("glare")) return atonlab::runner::run_glare(glare);
    } catch (const atonlab::InputError& e) {
        std::fprintf(stderr, "atonlab: %s\n", e.what());
        return 2;
    } catch (const atonlab::gl::ContextUnavailable& e) {
        std::fprintf(stderr, "atonlab: %s\n", e.what());
        return 3;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "atonlab: internal error: %s\n", e.what());
        return 70;
    }
    return 0;
}
