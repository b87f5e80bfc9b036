#pragma once
// A measuring instrument that `atonlab calibrate measure|check --instrument`
// asks for a reading of the patch on the screen (docs/calibration.md,
// "Measuring with an instrument"): ArgyllCMS spotread driving a real
// colorimeter or spectroradiometer, or a virtual instrument that reads the
// framebuffer back and applies a display law you give it (tests and demos).
#include <glm/vec3.hpp>
#include <memory>
#include <stdexcept>
#include <string>

namespace CLI {
class App;
}

namespace atonlab::runner {

class PatchScreen;

/// The instrument cannot measure: none found, it needs calibrating and no one
/// can do it, it reported an error, or it did not answer in time. what() is
/// one sentence saying what happened and what to do; nothing is stored.
/// `atonlab calibrate` exits with status 5.
class InstrumentError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// One reading of the patch on the screen.
struct InstrumentReading {
    glm::dvec3 xyz_cd_m2{0.0};  ///< CIE 1931 X, Y, Z, absolute; Y is the luminance in cd/m²
    std::string transcript;     ///< what the instrument said for this reading, raw
};

class Instrument {
public:
    virtual ~Instrument() = default;
    /// "spotread (ArgyllCMS), emissive" or "virtual GOG display ...".
    virtual std::string description() const = 0;
    /// Reads the patch that `screen` shows now (already settled). Throws InstrumentError.
    virtual InstrumentReading read(PatchScreen& screen) = 0;
    /// The relative standard deviation of one reading the instrument states
    /// (its repeatability), 0 when unknown; a floor under the uncertainty the
    /// repeat readings show.
    virtual double repeatability() const { return 0.0; }
};

/// The options of `--instrument` (docs/calibration.md).
struct InstrumentOptions {
    std::string kind;             ///< "" (readings typed or from --readings), "spotread" or "virtual"
    std::string instrument_args;  ///< spotread: extra arguments, split at spaces ("-c 2 -y l")
    double settle_s = 1.0;        ///< wait after a patch is shown before it is read, s
    double timeout_s = 60.0;      ///< longest wait for one reading (or for spotread to start), s
    int repeats = 2;              ///< readings per patch, averaged
    /// Repeat readings agree when max − min <= this % of their mean + kRepeatFloorCdM2.
    double repeat_tolerance_percent = 2.0;
    int attempts = 3;  ///< times a patch is measured before disagreeing repeats end the run
    // The virtual instrument's display: L(V) = black + (peak − black) V^gamma per
    // channel, split by sRGB primaries (docs/calibration.md).
    double virtual_peak_cd_m2 = 120.0;
    double virtual_black_cd_m2 = 0.2;
    double virtual_gamma = 2.4;
    std::string virtual_lut;     ///< a level,channel,cd_m2 CSV instead of the GOG law
    double virtual_noise = 0.0;  ///< relative standard deviation of each reading (0.01 = 1 %)
    unsigned virtual_seed = 1;

    /// Absolute part of the repeat tolerance: near black a colorimeter's
    /// readings scatter by about 0.005 cd/m² (ArgyllCMS i1d3 at 0.1 cd/m²),
    /// more than 2 % of them.
    static constexpr double kRepeatFloorCdM2 = 0.01;
};

/// Adds --instrument, --instrument-args, --settle-s, --instrument-timeout-s,
/// --repeats, --repeat-tolerance-percent and the --virtual-* options.
void add_instrument_options(CLI::App* command, InstrumentOptions& options);

/// Throws InputError naming the option for a value out of range.
void validate_instrument_options(const InstrumentOptions& options);

/// The instrument `options.kind` names (not ""), started: spotread is running
/// and calibrated, ready for the first reading. Throws InstrumentError.
std::unique_ptr<Instrument> open_instrument(const InstrumentOptions& options);

}  // namespace atonlab::runner
