#pragma once
// `atonlab check`: the displayability check of `atonlab run` on its own.
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace atonlab::runner {

/// `atonlab check` (docs/running.md, "Displayability"): what a display shows of
/// a protocol's stimuli. Exit status: 0 displayable, 2 not (or bad input), 3 no
/// GL, 4 the study file (--db) could not be read.
struct CheckOptions {
    std::string protocol;
    std::vector<std::string> sets;  ///< --set display.KEY=VALUE
    std::string db;                 ///< --db: the study file whose calibration encodes the frames
    bool strict = false;            ///< --strict: a warning (a light clipped at white) refuses too
};

void add_check_command(CLI::App& app, CheckOptions& options);
int run_check(const CheckOptions& options);

}  // namespace atonlab::runner
