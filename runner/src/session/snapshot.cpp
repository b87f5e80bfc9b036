// Condition snapshots (snapshot.h).
#include "session/snapshot.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <system_error>

#include "atonlab/common/read_file.h"
#include "atonlab/display/gamut.h"
#include "atonlab/runner/session/scene_queries.h"
#include "atonlab/runner/session/session_inputs.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;
using nlohmann::json;

namespace {

json optional_number(const std::optional<double>& v) {
    return v ? json(*v) : json(nullptr);
}

/// A JSON number, or null for none (std::nullopt); anything else is an error (nullopt_t never is).
std::optional<double> number_or_null(const json& j, const char* key) {
    const json& v = j.at(key);
    if (v.is_null()) return std::nullopt;
    return v.get<double>();
}

json frame_json(const SnapshotToneMap& f) {
    const display::ToneMapSettings& t = f.tonemap;
    return json{
        {"operator", display::tone_operator_name(t.tone_operator)},
        {"white_relative", t.white_relative},
        {"reinhard_key", t.reinhard_key},
        // Infinity (Reinhard's eq 3) is not a JSON number: null.
        {"reinhard_white_relative",
         std::isinf(t.reinhard_white_relative) ? json(nullptr) : json(t.reinhard_white_relative)},
        {"kakimoto_g", t.kakimoto_g},
        {"kakimoto_k", t.kakimoto_k},
        {"white_cd_m2", optional_number(t.white_cd_m2)},
        {"display_peak_cd_m2", t.display_peak_cd_m2},
        {"display_adaptation_cd_m2", optional_number(t.display_adaptation_cd_m2)},
        {"blueshift", t.blueshift},
        {"blueshift_luminance", display::blueshift_luminance_name(t.blueshift_luminance)},
        {"blueshift_xy", {t.blueshift_xy.x, t.blueshift_xy.y}},
        {"hue_preservation", display::hue_preservation_name(t.hue_preservation)},
        {"mesopic", display::mesopic_model_name(t.mesopic)},
        {"out_of_gamut", display::out_of_gamut_name(t.out_of_gamut)},
        {"adaptation", f.dynamic ? "dynamic" : "fixed"},
        {"adaptation_cd_m2", f.adaptation_cd_m2},
        {"epsilon_cd_m2", f.epsilon_cd_m2},
        {"ldr_glare", f.ldr_glare},
    };
}

template <typename T, typename From>
T named(const json& j, const char* key, From from_name) {
    const auto v = from_name(j.at(key).template get<std::string>());
    if (!v) throw std::invalid_argument(key);
    return *v;
}

SnapshotToneMap frame_from_json(const json& j) {
    SnapshotToneMap f;
    display::ToneMapSettings& t = f.tonemap;
    t.tone_operator = named<display::ToneOperator>(j, "operator", display::tone_operator_from_name);
    t.white_relative = j.at("white_relative").get<double>();
    t.reinhard_key = j.at("reinhard_key").get<double>();
    t.reinhard_white_relative =
        number_or_null(j, "reinhard_white_relative").value_or(std::numeric_limits<double>::infinity());
    t.kakimoto_g = j.at("kakimoto_g").get<double>();
    t.kakimoto_k = j.at("kakimoto_k").get<double>();
    t.white_cd_m2 = number_or_null(j, "white_cd_m2");
    t.display_peak_cd_m2 = j.at("display_peak_cd_m2").get<double>();
    t.display_adaptation_cd_m2 = number_or_null(j, "display_adaptation_cd_m2");
    t.blueshift = j.at("blueshift").get<bool>();
    t.blueshift_luminance =
        named<display::BlueshiftLuminance>(j, "blueshift_luminance", display::blueshift_luminance_from_name);
    const json& xy = j.at("blueshift_xy");
    t.blueshift_xy = {xy.at(0).get<double>(), xy.at(1).get<double>()};
    t.hue_preservation = named<display::HuePreservation>(j, "hue_preservation", display::hue_preservation_from_name);
    t.mesopic = named<display::MesopicModel>(j, "mesopic", display::mesopic_model_from_name);
    t.out_of_gamut = named<display::OutOfGamut>(j, "out_of_gamut", display::out_of_gamut_from_name);
    const std::string mode = j.at("adaptation").get<std::string>();
    if (mode != "fixed" && mode != "dynamic") throw std::invalid_argument("adaptation");
    f.dynamic = mode == "dynamic";
    f.adaptation_cd_m2 = j.at("adaptation_cd_m2").get<double>();
    f.epsilon_cd_m2 = j.at("epsilon_cd_m2").get<double>();
    f.ldr_glare = j.at("ldr_glare").get<bool>();
    display::validate_tonemap_settings(t);
    if (!(f.adaptation_cd_m2 > 0.0) || !std::isfinite(f.adaptation_cd_m2) || !(f.epsilon_cd_m2 > 0.0) ||
        !std::isfinite(f.epsilon_cd_m2))
        throw std::invalid_argument("adaptation_cd_m2");
    return f;
}

}  // namespace

std::string snapshot_tonemap_json(const std::vector<SnapshotToneMap>& frames) {
    json out = json::array();
    for (const SnapshotToneMap& f : frames) out.push_back(frame_json(f));
    return out.dump();
}

std::optional<std::vector<SnapshotToneMap>> read_snapshot_tonemap(const std::string& text) {
    try {
        const json j = json::parse(text);
        if (!j.is_array() || j.empty()) return std::nullopt;
        std::vector<SnapshotToneMap> out;
        for (const json& f : j) out.push_back(frame_from_json(f));
        return out;
    } catch (const std::exception&) {  // not JSON, a key missing or of the wrong type, an invalid setting
        return std::nullopt;
    }
}

std::vector<std::byte> snapshot_exr(StimulusRenderer& renderer, const p::Protocol& protocol, const p::Condition& c,
                                    const p::ScheduledTrial& t, std::int64_t session) {
    s::ImageRGBA32F stacked;
    double dpp = 0.0;
    std::string frames_note, lights_note;
    std::vector<SnapshotToneMap> shown;
    for (std::size_t f = 0; f < t.stimulus.frames.size(); ++f) {
        std::vector<glm::dvec2> light_px;
        const s::ImageRGBA32F img = renderer.hdr(t.stimulus.frames[f], judged_lights(t.stimulus, f), dpp, &light_px);
        if (f == 0) {
            stacked.width = img.width;
        } else if (img.width != stacked.width) {
            break;  // frames of different sizes (a condition overriding the display) are not stacked
        }
        frames_note +=
            fmt::format("{}rows {}-{}: frame {} ({})", f ? "; " : "", stacked.height, stacked.height + img.height - 1,
                        f, t.stimulus.frames[f].role ? p::to_string(*t.stimulus.frames[f].role) : "both");
        // Where each judged light of the frame is in the stacked image, so that
        // the report crops around every one of them (docs/analysis.md, "Stimulus
        // pictures"): "frame F ROLE at X,Y (LIGHT)", in view order.
        std::size_t k = 0;
        for (const p::StimulusView& v : t.stimulus.views) {
            if (v.frame != f || k >= light_px.size()) continue;
            const glm::dvec2 at = light_px[k++];
            lights_note += fmt::format("{}frame {} {} at {:.1f},{:.1f} ({})", lights_note.empty() ? "" : "; ", f,
                                       p::to_string(v.role), at.x, at.y + stacked.height, v.light);
        }
        {
            // The settings the display pass used for this frame (Pipeline::render, DisplayPipeline).
            const auto sc = renderer.scene(t.stimulus.frames[f].overrides);
            SnapshotToneMap m;
            m.tonemap = sc->output.tonemap;
            m.tonemap.out_of_gamut = sc->output.encode.out_of_gamut;
            m.dynamic = sc->output.adaptation.mode == s::AdaptationMode::dynamic;
            m.adaptation_cd_m2 = sc->adaptation_cd_m2;
            m.epsilon_cd_m2 = sc->output.adaptation.epsilon_cd_m2;
            m.ldr_glare = sc->output.ldr_glare;
            shown.push_back(m);
        }
        stacked.height += img.height;
        stacked.rgba.insert(stacked.rgba.end(), img.rgba.begin(), img.rgba.end());
    }
    s::ExrMetadata meta;
    meta.units = "cd/m2";
    meta.degrees_per_pixel = dpp;
    meta.strings["software"] = "atonlab " ATONLAB_VERSION;
    meta.strings["protocol"] = protocol.file;
    meta.strings["condition"] = c.name;
    meta.strings["frames"] = frames_note;
    if (!lights_note.empty()) meta.strings["lights"] = lights_note;
    meta.strings["tonemap"] = snapshot_tonemap_json(shown);
    meta.strings["level"] = fmt::format("{} ({} = {})", t.stimulus.level, c.level_key, t.stimulus.scene_value);
    const std::filesystem::path tmp =
        std::filesystem::temp_directory_path() / fmt::format("atonlab-snapshot-{}-{}.exr", getpid(), session);
    // A: the scotopic channel, so that the report's rod signal is each light's own (docs/analysis.md).
    s::write_exr(tmp, stacked, meta, s::ExrPixelType::float32, /*write_alpha=*/true);
    std::string bytes;
    try {
        bytes = files::read_text(tmp, "snapshot", std::numeric_limits<std::uintmax_t>::max());  // written just now
    } catch (...) {
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw;
    }
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    std::vector<std::byte> out(bytes.size());
    std::transform(bytes.begin(), bytes.end(), out.begin(), [](char ch) { return static_cast<std::byte>(ch); });
    return out;
}

}  // namespace atonlab::runner
