#pragma once
// `atonlab run` (docs/running.md): the command line around the session engine
// (run_session.h), its options in session/run_options.h.

#include "atonlab/runner/session/run_options.h"

namespace CLI {
class App;
}

namespace atonlab::runner {

void add_run_command(CLI::App& app, RunOptions& options);
int run_run(const RunOptions& options);

}  // namespace atonlab::runner
