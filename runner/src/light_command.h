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

}  // namespace atonlab::runner
