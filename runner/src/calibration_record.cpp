#include "calibration_record.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

#include "atonlab/stimuli/error.h"
#include "atonlab/store/json.h"

namespace atonlab::runner {
namespace {

const char* const kChannelNames[3] = {"red", "green", "blue"};

using Json = nlohmann::ordered_json;

/// The GOG parameters as members of `j` (a ramp or a channel).
void add_gog(Json& j, const stimuli::GogParams& p) {
    j["a"] = p.a;
    j["b"] = p.b;
    j["k"] = p.k;
    j["gamma"] = p.gamma;
}

}  // namespace

double DisplayGeometry::pixels_per_degree() const {
    const double pitch_m = width_m / width_px;
    const double pixel_deg = 2.0 * std::atan(pitch_m / (2.0 * viewing_distance_m)) * 180.0 / std::numbers::pi;
    return 1.0 / pixel_deg;
}

std::string DisplayGeometry::describe() const {
    return fmt::format("{} x {} px, {:.4g} x {:.4g} m at {:.4g} m: {:.1f} px/deg at the centre", width_px, height_px,
                       width_m, height_m, viewing_distance_m, pixels_per_degree());
}

std::string measured_fit_json(const stimuli::CalibrationReport& report, const stimuli::DisplayModel& model,
                              const DisplayGeometry& geometry, std::string_view method) {
    Json ramps = Json::array();
    for (const stimuli::RampReport& r : report.ramps) {
        Json ramp{{"channel", stimuli::channel_name(r.channel)}};
        add_gog(ramp, stimuli::gog_params(r.fit));
        ramp["effective_gamma"] = r.effective_gamma;
        ramp["black_cd_m2"] = r.black_cd_m2;
        ramp["peak_cd_m2"] = r.white_cd_m2;
        ramp["rmse_log10"] = r.fit.rmse_log10;
        ramp["n"] = r.fit.n;
        ramp["levels"] = r.levels;
        ramps.push_back(std::move(ramp));
    }
    Json channels = Json::array();
    for (int c = 0; c < 3; ++c) {
        Json channel{{"channel", kChannelNames[c]}, {"transfer", "gog"}};
        add_gog(channel, model.channels[static_cast<std::size_t>(c)].gog);
        channels.push_back(std::move(channel));
    }
    const Json j{
        {"model", "gog"},
        {"method", method},
        {"black_cd_m2", report.black_cd_m2},
        {"white_cd_m2", report.white_cd_m2},
        {"contrast_ratio", report.contrast_ratio},
        {"pixels_per_degree", geometry.pixels_per_degree()},
        {"n_measurements", report.n_measurements},
        {"n_other", report.n_other},
        {"ramps", std::move(ramps)},
        {"display",
         {{"peak_cd_m2", model.peak_cd_m2}, {"black_cd_m2", model.black_cd_m2}, {"channels", std::move(channels)}}},
        {"notes", report.notes}};
    return store::dump_json(j);
}

bool is_measured(const store::Calibration& c) {
    try {
        const nlohmann::json j = store::parse_json(c.fit_json);
        return store::string_at(j, "/model") == "gog" && store::array_at(j, "/display/channels").size() == 3;
    } catch (const store::StoreError&) {
        return false;
    }
}

stimuli::DisplayModel display_model_of(const store::Calibration& c) {
    const std::string what = fmt::format("calibration {} of display \"{}\"", c.id.value, c.display_name);
    auto fail = [&](const std::string& why) -> stimuli::DisplayModel {
        throw InputError(SourceLocation{"", 0, 0, "fit_json"}, fmt::format("{} {}", what, why));
    };
    if (!is_measured(c)) return fail("is not a measured calibration (its fit_json has no GOG display model)");
    const nlohmann::json j = store::parse_json(c.fit_json, "fit_json of " + what);
    std::array<stimuli::GogParams, 3> params{};
    for (int ch = 0; ch < 3; ++ch) {
        auto value = [&](const char* name) {
            const auto v = store::number_at(j, fmt::format("/display/channels/{}/{}", ch, name));
            if (!v) fail(fmt::format("has no number display.channels[{}].{}", ch, name));
            return *v;
        };
        params[static_cast<std::size_t>(ch)] = stimuli::GogParams{value("a"), value("b"), value("k"), value("gamma")};
    }
    stimuli::DisplayModel model = stimuli::DisplayModel::gog(params, c.display_name);
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

std::vector<store::CalibrationReading> readings_from_measurements(const std::vector<stimuli::Measurement>& ms) {
    std::vector<store::CalibrationReading> out;
    for (const stimuli::Measurement& m : ms) {
        store::CalibrationReading r;
        const bool black = m.channel != stimuli::Channel::other && m.level == 0.0;
        r.patch = black ? "black"
                        : (m.channel == stimuli::Channel::grey && m.level == 1.0
                               ? "white"
                               : fmt::format("{}-{:.4g}", stimuli::channel_name(m.channel), m.level));
        r.channel = stimuli::channel_name(m.channel);
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

void print_fit_summary(std::FILE* out, const stimuli::CalibrationReport& report, const stimuli::DisplayModel& model,
                       const DisplayGeometry& geometry) {
    std::fprintf(out, "  %-6s %8s %8s %12s %12s %11s %4s\n", "ramp", "GOG γ", "eff. γ", "black cd/m²", "peak cd/m²",
                 "RMSE log10", "n");
    for (const stimuli::RampReport& r : report.ramps)
        std::fprintf(out, "  %-6s %7.3f %8.3f %12.4g %12.4g %11.4f %4d\n", stimuli::channel_name(r.channel),
                     r.fit.gamma, r.effective_gamma, r.black_cd_m2, r.white_cd_m2, r.fit.rmse_log10, r.fit.n);
    std::fprintf(out, "  measured black %.4g cd/m², white %.4g cd/m², contrast %s\n", report.black_cd_m2,
                 report.white_cd_m2,
                 std::isfinite(report.contrast_ratio) ? fmt::format("{:.0f}:1", report.contrast_ratio).c_str()
                                                      : "infinite (black reads 0)");
    std::fprintf(out, "  display model (GOG, %s): peak %.4g cd/m², black %.4g cd/m²\n",
                 report.ramp(stimuli::Channel::red) && report.ramp(stimuli::Channel::green) &&
                         report.ramp(stimuli::Channel::blue)
                     ? "from the red, green and blue ramps"
                     : "from the grey ramp, split by Rec.709 weight",
                 model.peak_cd_m2, model.black_cd_m2);
    for (const std::string& n : report.notes) std::fprintf(out, "  note: %s\n", n.c_str());
    std::fprintf(out, "  geometry: %s\n", geometry.describe().c_str());
}

}  // namespace atonlab::runner
