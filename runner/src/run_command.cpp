// `atonlab run PROTOCOL.toml --db STUDY.db (--model-observer | --script FILE [--observer ID]) --headless
//      [--resume SESSION_ID | --resume-last] [--seed N] [--observer-seed N] [--quiet]`
// A protocol's session, headless, each trial committed to the study file before
// the next is shown (docs/running.md). The engine is run_session.cpp; this file
// is the command line and the exit status of a study-file failure (4).
#include <CLI/CLI.hpp>
#include <cstdio>

#include "atonlab/protocols/protocol.h"
#include "atonlab/store/error.h"
#include "commands.h"
#include "run_session.h"

namespace atonlab::runner {

void add_run_command(CLI::App& app, RunOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "run",
        "Run a protocol's session headless with a model or scripted observer, logging every trial to a study file");
    cmd->add_option("protocol", o.protocol, "Protocol file (TOML; see docs/protocol-file.md)")->required();
    cmd->add_option("--db", o.db, "Study file (SQLite; created if absent; see docs/store.md)")->required();
    auto* model =
        cmd->add_flag("--model-observer", o.model_observer, "Answer with the model observer (observer code \"model\")");
    auto* script = cmd->add_option("--script", o.script,
                                   "Answer from a file, one answer per line (docs/protocol-file.md, Observers)");
    auto* observer = cmd->add_option("--observer", o.observer,
                                     "Observer code (1-32 of A-Z a-z 0-9 _ -); with --script (default \"script\")");
    model->excludes(script);
    model->excludes(observer);
    cmd->add_flag("--headless", o.headless, "Render off-screen; no window (required in this build)");
    auto* resume = cmd->add_option("--resume", o.resume, "Continue this session (its id in the study file)");
    auto* last = cmd->add_flag("--resume-last", o.resume_last,
                               "Continue the latest unfinished session of this protocol and observer");
    resume->excludes(last);
    cmd->add_option("--seed", o.seed, "The session's random seed (default: the protocol's)");
    cmd->add_option("--observer-seed", o.observer_seed,
                    "The model observer's seed (default: derived from the session's seed)");
    cmd->add_flag("--quiet", o.quiet, "Print nothing but errors");
    cmd->add_option("--progress-every", o.progress_every,
                    "Without a terminal: a progress line every N trials (default 25)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--db-max-bytes", o.db_max_bytes,
                    "Let the study file grow to at most this many bytes; beyond, the run stops as on a full disk "
                    "(default 0: no limit)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_flag_callback(
        "--no-true-pse", [&o] { o.true_pse = false; },
        "Model observer: skip computing its true PSE / threshold for the summary");
}

int run_run(const RunOptions& o) {
    try {
        return run_session(o);
    } catch (const store::StoreError& e) {
        // The study file failed (newer schema, write-protected, disk full, I/O
        // error, ...): what is stored stays as it was; one sentence, status 4.
        std::fprintf(stderr, "atonlab: %s\n", e.what());
        return 4;
    } catch (const protocols::ProtocolError& e) {
        // A protocol or script error the engine did not already turn into an InputError.
        std::fprintf(stderr, "atonlab: %s\n", e.what());
        return 2;
    }
}

}  // namespace atonlab::runner
