#pragma once
// `atonlab light` (docs/light.md): Allard's law for one light, the calculation
// a lighthouse engineer does.
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace atonlab::runner {

struct LightOptions {
    std::optional<double> intensity_cd;            ///< the light's intensity, or ...
    std::optional<double> range_nmi;               ///< ... its range at the threshold
    std::string colour = "white";                  ///< white, red, green, yellow, blue (a label: see docs/light.md)
    std::optional<double> visibility_nmi;          ///< meteorological visibility V (default 10 nmi) ...
    std::optional<double> transmissivity_per_nmi;  ///< ... or the transmissivity T per nmi
    std::string period = "night";                  ///< night: E_t = 2e-7 lx; day: 1e-3 lx
    std::string background = "none";               ///< none, minor, substantial: E_t x 1, 10, 100
    std::vector<double> distances_nmi;             ///< print the illuminance at these distances
};

void add_light_command(CLI::App& app, LightOptions& options);
int run_light(const LightOptions& options);

/// Allard's law's answer (K2012 eq 2.1) for the options, checked as `atonlab light` checks them.
struct LightAnswer {
    double intensity_cd = 0.0;       ///< given, or from the range
    double range_nmi = 0.0;          ///< given, or from the intensity
    double threshold_lux = 0.0;      ///< E_t of the period (lx), before the background factor
    double background_factor = 1.0;  ///< 1, 10 or 100
    double visibility_nmi = 10.0;    ///< V (nmi)
};
/// Throws InputError naming the option, as the command does.
LightAnswer light_answer(const LightOptions& options);

}  // namespace atonlab::runner
