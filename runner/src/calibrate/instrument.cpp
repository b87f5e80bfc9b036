#include "instrument.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cmath>

#include "atonlab/stimuli/error.h"
#include "spotread_instrument.h"
#include "virtual_instrument.h"

namespace atonlab::runner {

void add_instrument_options(CLI::App* cmd, InstrumentOptions& o) {
    cmd->add_option("--instrument", o.kind,
                    "Read each patch with an instrument instead of typed readings: spotread (ArgyllCMS, any meter it "
                    "drives) or virtual (a display law, for tests and demos)")
        ->check(CLI::IsMember({"spotread", "virtual"}));
    cmd->add_option("--instrument-args", o.instrument_args,
                    "Extra spotread arguments, e.g. \"-c 2 -y l\" (atonlab always gives -e -x)");
    cmd->add_option("--settle-s", o.settle_s, "Wait after showing a patch before reading it, s (default 1)");
    cmd->add_option("--instrument-timeout-s", o.timeout_s, "Longest wait for one reading, s (default 60)");
    cmd->add_option("--repeats", o.repeats, "Readings per patch, averaged (default 2)");
    cmd->add_option("--repeat-tolerance-percent", o.repeat_tolerance_percent,
                    "Repeat readings agree within this % of their mean + 0.01 cd/m², else the patch is measured again "
                    "(default 2)");
    cmd->add_option("--virtual-peak-cd-m2", o.virtual_peak_cd_m2, "Virtual display: white, cd/m² (default 120)");
    cmd->add_option("--virtual-black-cd-m2", o.virtual_black_cd_m2, "Virtual display: black, cd/m² (default 0.2)");
    cmd->add_option("--virtual-gamma", o.virtual_gamma, "Virtual display: gamma of each channel (default 2.4)");
    cmd->add_option("--virtual-lut", o.virtual_lut,
                    "Virtual display: the grey law from a level,channel,cd_m2 CSV instead of peak, black and gamma");
    cmd->add_option("--virtual-noise", o.virtual_noise,
                    "Virtual instrument: relative standard deviation of each reading, e.g. 0.01 (default 0)");
    cmd->add_option("--virtual-seed", o.virtual_seed, "Virtual instrument: noise seed (default 1)");
}

void validate_instrument_options(const InstrumentOptions& o) {
    auto bad = [](const char* option, const std::string& why) {
        return InputError(SourceLocation::command_line(option), why);
    };
    auto positive = [&](double v, const char* option, const char* what) {
        if (!(std::isfinite(v) && v > 0.0)) throw bad(option, fmt::format("{} must be > 0, not {}.", what, v));
    };
    if (!(std::isfinite(o.settle_s) && o.settle_s >= 0.0))
        throw bad("--settle-s", fmt::format("the settle time must be >= 0 s, not {}.", o.settle_s));
    positive(o.timeout_s, "--instrument-timeout-s", "the timeout");
    if (o.repeats < 1 || o.repeats > 100)
        throw bad("--repeats", fmt::format("1 to 100 readings a patch, not {}.", o.repeats));
    positive(o.repeat_tolerance_percent, "--repeat-tolerance-percent", "the tolerance");
    if (o.kind != "virtual") return;
    if (o.virtual_lut.empty()) {
        positive(o.virtual_peak_cd_m2, "--virtual-peak-cd-m2", "the peak");
        positive(o.virtual_gamma, "--virtual-gamma", "gamma");
        if (!(std::isfinite(o.virtual_black_cd_m2) && o.virtual_black_cd_m2 >= 0.0 &&
              o.virtual_black_cd_m2 < o.virtual_peak_cd_m2))
            throw bad("--virtual-black-cd-m2", fmt::format("black must be >= 0 and below the peak ({} cd/m²), not {}.",
                                                           o.virtual_peak_cd_m2, o.virtual_black_cd_m2));
    }
    if (!(std::isfinite(o.virtual_noise) && o.virtual_noise >= 0.0 && o.virtual_noise < 0.5))
        throw bad("--virtual-noise", fmt::format("the noise is a fraction in [0, 0.5), not {}.", o.virtual_noise));
}

std::unique_ptr<Instrument> open_instrument(const InstrumentOptions& o) {
    if (o.kind == "spotread") return open_spotread(o);
    return open_virtual_instrument(o);
}

}  // namespace atonlab::runner
