#pragma once
// `atonlab simulate PROTOCOL… --sessions N --out DIR` (docs/simulate.md):
// plan a study by running it N times with simulated observers, one study file
// per session, resumable.
#include "simulate/simulate_options.h"

namespace CLI {
class App;
}

namespace atonlab::runner {

void add_simulate_command(CLI::App& app, SimulateOptions& options);
/// Exit status as SimulateOptions says.
int run_simulate(const SimulateOptions& options);

}  // namespace atonlab::runner
