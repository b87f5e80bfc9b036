#pragma once
// A display calibration's fit_json (docs/calibration.md "fit_json"): the one
// place it is written and read. Measured and imported calibrations keep their
// GOG fits and, under "display", the DisplayModel sessions encode for; the
// nominal row `atonlab run` records for an uncalibrated display keeps the scene's
// DisplayModel at the top level. Both write the display model the same way:
// peak_cd_m2, black_cd_m2 and per channel its encoding, black and white (cd/m²)
// and the encoding's parameters and knots as it declares them (GOG a, b, k, gamma; PQ
// pq_weight; LUT lut). A channel's "transfer" (the key's old name) is read as "encoding".
#include <optional>
#include <string>
#include <string_view>

#include "atonlab/display/calibration.h"
#include "atonlab/display/display_model.h"
#include "atonlab/display/geometry.h"

namespace atonlab::display {

/// fit_json of a measured or imported calibration: model "gog", `method`
/// ("measured" or "imported"), measured black, white and contrast, pixels per
/// degree of `geometry`, the per-ramp fits, and under "display" the model.
/// Numbers are the shortest decimals that read back as the same double;
/// non-finite numbers (a contrast ratio over a black that reads 0) are null.
std::string measured_fit_json(const CalibrationReport& report, const DisplayModel& model,
                              const DisplayGeometry& geometry, std::string_view method);

/// fit_json of the nominal display model a session records: model "nominal",
/// the model, and the encoder's bits and dither.
std::string nominal_fit_json(const DisplayModel& model, const EncodeSettings& encode);

/// The "model" word of fit_json ("gog", "nominal"); nullopt when the text is
/// not a JSON object with a string "model".
std::optional<std::string> fit_json_model(std::string_view fit_json);

/// The display model in fit_json (under "display" when that object has
/// channels, else at the top level), named `name`, not validated. Throws
/// InputError (key "fit_json") whose message names what is missing, e.g. "has
/// no number display.channels[1].gamma", or an unknown encoding.
DisplayModel display_model_from_fit_json(std::string_view fit_json, std::string name);

/// Whether two fit JSON texts hold the same values, whatever their key order and whether a
/// channel names its encoding "encoding" or by the key's old name "transfer" (a nominal row
/// written before the rename is the same display as one written now).
bool same_fit_json(std::string_view a, std::string_view b);

}  // namespace atonlab::display
