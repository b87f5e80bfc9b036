#include "calibration_record.h"

#include <fmt/format.h>

#include <cmath>

#include "atonlab/common/input_error.h"
#include "atonlab/display/fit_json.h"

namespace atonlab::runner {

bool is_measured(const store::Calibration& c) {
    if (display::fit_json_model(c.fit_json).value_or("") != "gog") return false;
    try {
        const display::DisplayModel m = display::display_model_from_fit_json(c.fit_json, c.display_name);
        for (const display::ChannelEncoding& ch : m.channels)
            if (!ch.follows("gog")) return false;
        return true;
    } catch (const InputError&) {
        return false;
    }
}

display::DisplayModel display_model_of(const store::Calibration& c) {
    const std::string what = fmt::format("calibration {} of display \"{}\"", c.id.value, c.display_name);
    auto fail = [&](const std::string& why) -> display::DisplayModel {
        throw InputError(SourceLocation{"", 0, 0, "fit_json"}, fmt::format("{} {}", what, why));
    };
    const auto not_measured = [&] { fail("is not a measured calibration (its fit_json has no GOG display model)"); };
    if (display::fit_json_model(c.fit_json).value_or("") != "gog") not_measured();
    display::DisplayModel model;
    try {
        model = display::display_model_from_fit_json(c.fit_json, c.display_name);
    } catch (const InputError& e) {
        fail(e.message());
    }
    if (!is_measured(c)) not_measured();
    try {
        model.validate(SourceLocation{"", 0, 0, "display"});
    } catch (const InputError& e) {
        fail(fmt::format("holds an unusable display model: {}", e.message()));
    }
    return model;
}

std::optional<store::Calibration> latest_measured_calibration(const store::Store& store, std::string_view display) {
    for (store::Calibration& c : store.calibrations(display))
        if (is_measured(c)) return std::move(c);
    return std::nullopt;
}

std::vector<store::CalibrationReading> readings_from_measurements(const std::vector<display::Measurement>& ms) {
    std::vector<store::CalibrationReading> out;
    for (const display::Measurement& m : ms) {
        store::CalibrationReading r;
        const bool black = m.channel != display::Channel::other && m.level == 0.0;
        r.patch = black ? "black"
                        : (m.channel == display::Channel::grey && m.level == 1.0
                               ? "white"
                               : fmt::format("{}-{:.4g}", display::channel_name(m.channel), m.level));
        r.channel = display::channel_name(m.channel);
        r.level = m.level;
        r.drive_r = m.rgb.r;
        r.drive_g = m.rgb.g;
        r.drive_b = m.rgb.b;
        r.luminance_cd_m2 = m.luminance_cd_m2;
        if (m.xyz_cd_m2) {
            r.xyz_x_cd_m2 = m.xyz_cd_m2->x;
            r.xyz_z_cd_m2 = m.xyz_cd_m2->z;
        }
        if (m.line > 0) r.source_line = m.line;
        out.push_back(std::move(r));
    }
    return out;
}

void print_fit_summary(std::FILE* out, const display::CalibrationReport& report, const display::DisplayModel& model,
                       const display::DisplayGeometry& geometry) {
    std::fprintf(out, "  %-6s %8s %8s %12s %12s %11s %4s\n", "ramp", "GOG γ", "eff. γ", "black cd/m²", "peak cd/m²",
                 "RMSE log10", "n");
    for (const display::RampReport& r : report.ramps)
        std::fprintf(out, "  %-6s %7.3f %8.3f %12.4g %12.4g %11.4f %4d\n", display::channel_name(r.channel),
                     r.fit.gamma, r.effective_gamma, r.black_cd_m2, r.white_cd_m2, r.fit.rmse_log10, r.fit.n);
    std::fprintf(out, "  measured black %.4g cd/m², white %.4g cd/m², contrast %s\n", report.black_cd_m2,
                 report.white_cd_m2,
                 std::isfinite(report.contrast_ratio) ? fmt::format("{:.0f}:1", report.contrast_ratio).c_str()
                                                      : "infinite (black reads 0)");
    std::fprintf(out, "  display model (GOG, %s): peak %.4g cd/m², black %.4g cd/m²\n",
                 report.ramp(display::Channel::red) && report.ramp(display::Channel::green) &&
                         report.ramp(display::Channel::blue)
                     ? "from the red, green and blue ramps"
                     : "from the grey ramp, split by Rec.709 weight",
                 model.peak_cd_m2, model.black_cd_m2);
    for (const std::string& n : report.notes) std::fprintf(out, "  note: %s\n", n.c_str());
    std::fprintf(out, "  geometry: %s\n", geometry.describe().c_str());
}

}  // namespace atonlab::runner
