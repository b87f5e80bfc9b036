// atonlab: one binary, subcommands (DESIGN.md "Command line").
// Bad input: one sentence on stderr naming file, line and key; exit status 2.
// No usable GL: one sentence saying why; exit status 3.
// `atonlab run`: the study file failed (StoreError): exit status 4 (run_command.cpp).
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/gl/context.h"
#include "commands.h"

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
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }
    try {
        if (app.got_subcommand("render")) return atonlab::runner::run_render(render);
        if (app.got_subcommand("psf")) return atonlab::runner::run_psf(psf);
        if (app.got_subcommand("run")) return atonlab::runner::run_run(run);
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
