#include "atonlab/display/fit_json.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "atonlab/common/input_error.h"
#include "atonlab/display/display_encodings.h"

namespace atonlab::display {
namespace {

using Json = nlohmann::ordered_json;  // keys in the order written (docs/calibration.md)

const char* const kChannelNames[3] = {"red", "green", "blue"};

Json gog_json(const GogParams& p) {
    return Json{{"a", p.a}, {"b", p.b}, {"k", p.k}, {"gamma", p.gamma}};
}

/// The whole screen's peak and black, as both kinds of fit_json hold them.
void put_display(Json& out, const DisplayModel& model) {
    out["peak_cd_m2"] = model.peak_cd_m2;
    out["black_cd_m2"] = model.black_cd_m2;
}

Json channels_json(const DisplayModel& model) {
    Json channels = Json::array();
    for (int c = 0; c < 3; ++c) {
        const ChannelEncoding& ch = model.channels[static_cast<std::size_t>(c)];
        // The laws made from a black and a white (sRGB, PQ) are defined by them; the fitted ones carry
        // them for the reader's eye.
        const DisplayEncoding& e = *ch.encoding;
        const bool own = e.from_peak_black != nullptr;
        Json j{{"channel", kChannelNames[c]},
               {"encoding", std::string(e.name)},
               {"black_cd_m2", own ? ch.black_cd_m2 : ch.min_cd_m2()},
               {"white_cd_m2", own ? ch.white_cd_m2 : ch.max_cd_m2()}};
        // The encoding's own parameters and knots, as it declares them (display_encodings.h).
        for (std::size_t i = 0; i < e.parameters.size(); ++i) j[std::string(e.parameters[i].key)] = ch.parameter[i];
        if (!e.knots_key.empty()) {
            Json points = Json::array();
            for (const LutPoint& p : ch.lut) points.push_back(Json::array({p.drive, p.cd_m2}));
            j[std::string(e.knots_key)] = std::move(points);
        }
        channels.push_back(std::move(j));
    }
    return channels;
}

/// nlohmann writes NaN and ±inf as null, as JSON has no such numbers.
std::string text(const Json& j) {
    return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

[[noreturn]] void missing(const std::string& what) {
    throw InputError(SourceLocation{"", 0, 0, "fit_json"}, what);
}

double number(const Json& object, const std::string& at, const char* key) {
    const auto it = object.find(key);
    if (it == object.end() || !it->is_number()) missing(fmt::format("has no number {}{}", at, key));
    return it->get<double>();
}

}  // namespace

std::string measured_fit_json(const CalibrationReport& report, const DisplayModel& model,
                              const DisplayGeometry& geometry, std::string_view method) {
    Json ramps = Json::array();
    for (const RampReport& r : report.ramps) {
        Json j{{"channel", channel_name(r.channel)}};
        j.update(gog_json(gog_params(r.fit)));
        j.update(Json{{"effective_gamma", r.effective_gamma},
                      {"black_cd_m2", r.black_cd_m2},
                      {"peak_cd_m2", r.white_cd_m2},
                      {"rmse_log10", r.fit.rmse_log10},
                      {"n", r.fit.n},
                      {"levels", r.levels}});
        ramps.push_back(std::move(j));
    }
    Json display;
    put_display(display, model);
    display["channels"] = channels_json(model);
    Json out{{"model", "gog"},
             {"method", std::string(method)},
             {"black_cd_m2", report.black_cd_m2},
             {"white_cd_m2", report.white_cd_m2},
             {"contrast_ratio", report.contrast_ratio},
             {"pixels_per_degree", geometry.pixels_per_degree()},
             {"n_measurements", report.n_measurements},
             {"n_other", report.n_other},
             {"ramps", std::move(ramps)},
             {"display", std::move(display)},
             {"notes", report.notes}};
    return text(out);
}

std::string nominal_fit_json(const DisplayModel& model, const EncodeSettings& encode) {
    Json out{{"model", "nominal"}};
    put_display(out, model);
    out["bits"] = encode.bits;
    out["dither"] = encode.dither == Dither::spatiotemporal;
    out["channels"] = channels_json(model);
    return text(out);
}

std::optional<std::string> fit_json_model(std::string_view fit_json) {
    const Json j = Json::parse(fit_json, nullptr, false);
    if (!j.is_object()) return std::nullopt;
    const auto it = j.find("model");
    if (it == j.end() || !it->is_string()) return std::nullopt;
    return it->get<std::string>();
}

DisplayModel display_model_from_fit_json(std::string_view fit_json, std::string name) {
    const Json j = Json::parse(fit_json, nullptr, false);
    if (!j.is_object()) missing("is not a JSON object");
    const auto display = j.find("display");
    const bool nested = display != j.end() && display->is_object() && display->contains("channels");
    const Json& root = nested ? *display : j;
    const std::string at = nested ? "display." : "";
    const auto channels = root.find("channels");
    if (channels == root.end() || !channels->is_array() || channels->size() != 3)
        missing(fmt::format("has no three channels {}channels", at));
    DisplayModel model;
    model.name = std::move(name);
    model.peak_cd_m2 = number(root, at, "peak_cd_m2");
    model.black_cd_m2 = number(root, at, "black_cd_m2");
    for (std::size_t c = 0; c < 3; ++c) {
        const Json& cj = (*channels)[c];
        const std::string cat = fmt::format("{}channels[{}].", at, c);
        if (!cj.is_object()) missing(fmt::format("has no object {}", cat));
        // "transfer": the key's name before it was "encoding" (calibrations stored until 2026-12).
        auto named = cj.find("encoding");
        if (named == cj.end()) named = cj.find("transfer");
        const std::string law = named != cj.end() && named->is_string() ? named->get<std::string>() : "";
        const DisplayEncoding* encoding = display_encoding_named(law);
        if (encoding == nullptr)
            missing(fmt::format("has no known encoding {}encoding ({})", cat, display_encoding_choices("", true)));
        ChannelEncoding& ch = model.channels[c];
        ch.encoding = encoding;
        if (encoding->from_peak_black != nullptr) {  // sRGB, PQ: their black and white
            ch.black_cd_m2 = number(cj, cat, "black_cd_m2");
            ch.white_cd_m2 = number(cj, cat, "white_cd_m2");
        }
        // The encoding's own parameters and knots, as it declares them (display_encodings.h).
        for (std::size_t i = 0; i < encoding->parameters.size(); ++i) {
            const EncodingParameter& p = encoding->parameters[i];
            const std::string key(p.key);
            ch.parameter[i] = p.missing != nullptr && !cj.contains(key) ? p.missing(ch, model.peak_cd_m2)
                                                                        : number(cj, cat, key.c_str());
        }
        if (!encoding->knots_key.empty()) {
            const std::string key(encoding->knots_key);
            const auto knots = cj.find(key);
            if (knots == cj.end() || !knots->is_array() || knots->empty())
                missing(fmt::format("has no points {}{}", cat, key));
            for (std::size_t i = 0; i < knots->size(); ++i) {
                const Json& p = (*knots)[i];
                if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number())
                    missing(fmt::format("has no [drive, cd_m2] pair {}{}[{}]", cat, key, i));
                ch.lut.push_back(LutPoint{p[0].get<double>(), p[1].get<double>()});
            }
        }
    }
    return model;
}

bool same_fit_json(std::string_view a, std::string_view b) {
    if (a == b) return true;
    // Unordered objects (nlohmann::json): key order does not count. Each channel's old key renamed.
    auto normal = [](std::string_view text) {
        nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
        if (!j.is_object()) return j;
        for (nlohmann::json* root : {&j, j.contains("display") ? &j["display"] : nullptr}) {
            if (root == nullptr || !root->is_object() || !root->contains("channels")) continue;
            for (nlohmann::json& ch : (*root)["channels"])
                if (ch.is_object() && ch.contains("transfer") && !ch.contains("encoding")) {
                    ch["encoding"] = ch["transfer"];
                    ch.erase("transfer");
                }
        }
        return j;
    };
    const nlohmann::json x = normal(a), y = normal(b);
    return !x.is_discarded() && x == y;
}

}  // namespace atonlab::display
