// `atonlab light (--intensity-cd I | --range-nmi D) [--colour C] [--visibility-nmi V |
// --transmissivity T] [--period night|day] [--background B] [--at-nmi X]...`
// Allard's law (K2012 eq 2.1; IALA E200-2) for one light: the range from the
// intensity or the intensity from the range, the IALA nominal range and its
// band, and the illuminance at given distances. docs/light.md.
#include "atonlab/runner/light_command.h"

#include <CLI/CLI.hpp>
#include <array>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "atonlab/stimuli/atmosphere.h"
#include "atonlab/stimuli/error.h"

namespace atonlab::runner {

void add_light_command(CLI::App& app, LightOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "light",
        "Allard's law for one light: range from intensity or intensity from range, and the IALA nominal range");
    cmd->add_option("--intensity-cd", o.intensity_cd, "The light's luminous intensity (cd): print its range");
    cmd->add_option("--range-nmi", o.range_nmi, "The range wanted (nmi): print the intensity it needs");
    cmd->add_option("--colour", o.colour, "white, red, green, yellow or blue (printed; Allard's law is photometric)");
    auto* vis = cmd->add_option("--visibility-nmi", o.visibility_nmi,
                                "Meteorological visibility V (nmi; default 10, IALA's nominal conditions)");
    auto* trans = cmd->add_option("--transmissivity", o.transmissivity_per_nmi,
                                  "Atmospheric transmissivity T per nmi instead of V (T = 0.05^(1/V); 0 < T < 1)");
    vis->excludes(trans);
    cmd->add_option("--period", o.period, "night (threshold 2e-7 lx, the default) or day (1e-3 lx)");
    cmd->add_option("--background", o.background,
                    "Background lighting: none (default), minor or substantial (threshold x 1, 10, 100)");
    cmd->add_option("--at-nmi", o.distances_nmi, "Also print the illuminance at this distance (nmi; repeatable)");
}

namespace {

bool positive_finite(double v) {
    return v > 0 && std::isfinite(v);
}

}  // namespace

LightAnswer light_answer(const LightOptions& o) {
    // Every check before any output.
    if (o.intensity_cd.has_value() == o.range_nmi.has_value())
        throw InputError(SourceLocation::command_line("--intensity-cd"),
                         "give exactly one of --intensity-cd and --range-nmi");
    if (o.intensity_cd && !positive_finite(*o.intensity_cd))
        throw InputError(SourceLocation::command_line("--intensity-cd"), "the intensity must be a positive number of cd");
    if (o.range_nmi && !positive_finite(*o.range_nmi))
        throw InputError(SourceLocation::command_line("--range-nmi"), "the range must be a positive number of nmi");
    constexpr std::array<std::string_view, 5> colours{"white", "red", "green", "yellow", "blue"};
    bool known_colour = false;
    for (const auto c : colours) known_colour = known_colour || o.colour == c;
    if (!known_colour)
        throw InputError(SourceLocation::command_line("--colour"),
                         "the colour must be white, red, green, yellow or blue, not '" + o.colour + "'");
    double visibility_nmi = 10.0;
    if (o.visibility_nmi) {
        if (!positive_finite(*o.visibility_nmi))
            throw InputError(SourceLocation::command_line("--visibility-nmi"),
                             "the visibility must be a positive number of nmi");
        visibility_nmi = *o.visibility_nmi;
    }
    if (o.transmissivity_per_nmi) {
        if (!(*o.transmissivity_per_nmi > 0 && *o.transmissivity_per_nmi < 1))
            throw InputError(SourceLocation::command_line("--transmissivity"),
                             "the transmissivity per nmi must lie between 0 and 1 (exclusive)");
        visibility_nmi = stimuli::visibility_nmi_from_transmissivity(*o.transmissivity_per_nmi);
    }
    double threshold_lux = 0;
    if (o.period == "night")
        threshold_lux = stimuli::allard_threshold_night_lux;
    else if (o.period == "day")
        threshold_lux = stimuli::allard_threshold_day_lux;
    else
        throw InputError(SourceLocation::command_line("--period"),
                         "the period must be night or day, not '" + o.period + "'");
    double background_factor = 0;
    if (o.background == "none")
        background_factor = 1;
    else if (o.background == "minor")
        background_factor = 10;
    else if (o.background == "substantial")
        background_factor = 100;
    else
        throw InputError(SourceLocation::command_line("--background"),
                         "the background must be none, minor or substantial, not '" + o.background + "'");
    for (const double d : o.distances_nmi)
        if (!positive_finite(d))
            throw InputError(SourceLocation::command_line("--at-nmi"), "each distance must be a positive number of nmi");

    // K2012 eq 2.1 one way or the other.
    const double intensity_cd =
        o.intensity_cd ? *o.intensity_cd
                       : stimuli::allard_intensity_cd(*o.range_nmi, threshold_lux, visibility_nmi, background_factor);
    const double range_nmi =
        o.range_nmi ? *o.range_nmi
                    : stimuli::allard_range_nmi(intensity_cd, threshold_lux, visibility_nmi, background_factor);
    LightAnswer a;
    a.intensity_cd = intensity_cd;
    a.range_nmi = range_nmi;
    a.threshold_lux = threshold_lux;
    a.background_factor = background_factor;
    a.visibility_nmi = visibility_nmi;
    return a;
}

int run_light(const LightOptions& o) {
    const LightAnswer a = light_answer(o);
    const double intensity_cd = a.intensity_cd, range_nmi = a.range_nmi, visibility_nmi = a.visibility_nmi;
    const double threshold_lux = a.threshold_lux, background_factor = a.background_factor;
    const double threshold_eff_lux = threshold_lux * background_factor;
    constexpr double km_per_nmi = stimuli::metres_per_nautical_mile / 1000.0;

    std::printf("light: %s, %s, background lighting %s\n", o.colour.c_str(), o.period.c_str(), o.background.c_str());
    std::printf("  threshold illuminance E_t: %.6g lx (%.6g lx x %g)\n", threshold_eff_lux, threshold_lux,
                background_factor);
    std::printf("  visibility V: %.6g nmi (transmissivity T = 0.05^(1/V) = %.6f per nmi)\n", visibility_nmi,
                stimuli::allard_transmissivity_per_nmi(visibility_nmi));
    std::printf("  intensity I: %.6g cd%s\n", intensity_cd,
                o.intensity_cd ? " (given)" : " (Allard's law, K2012 eq 2.1)");
    std::printf("  range d: %.6g nmi = %.6g km%s\n", range_nmi, range_nmi * km_per_nmi,
                o.range_nmi ? " (given)" : " (Allard's law, K2012 eq 2.1)");
    // The charted figure: IALA E200-2's nominal conditions whatever was asked above.
    const int nominal = stimuli::nominal_range_nmi(intensity_cd);
    const stimuli::IntensityBand band = stimuli::nominal_range_band_cd(nominal);
    std::printf("  nominal range: %d nmi (IALA E200-2 band %.6g .. %.6g cd; night, V = 10 nmi, no background)\n",
                nominal, band.lower_cd, band.upper_cd);
    for (const double d : o.distances_nmi) {
        const double e_lux = stimuli::allard_illuminance_lux(intensity_cd, d, visibility_nmi);
        std::printf("  illuminance at %.6g nmi (%.6g km): %.6g lx = %.4g x E_t\n", d, d * km_per_nmi, e_lux,
                    e_lux / threshold_eff_lux);
    }
    return 0;
}

}  // namespace atonlab::runner
