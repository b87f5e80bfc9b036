#pragma once
// ArgyllCMS spotread as the instrument (docs/calibration.md, "spotread"): one
// spotread process for the whole run, in emissive mode (-e: absolute XYZ,
// Y in cd/m²), driven through a pseudo-terminal, calibrated once at start.
#include <memory>

#include "instrument.h"

namespace atonlab::runner {

/// Starts `spotread -e -x ARGS` (found on PATH) and waits until it is ready to
/// take a reading, relaying a calibration request to the operator when stdin
/// is a terminal. Throws InstrumentError (spotread missing, no instrument,
/// calibration needed with no one to do it, an error, a timeout).
std::unique_ptr<Instrument> open_spotread(const InstrumentOptions& options);

}  // namespace atonlab::runner
