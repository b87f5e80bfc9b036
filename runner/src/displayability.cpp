// Displayability of a protocol's stimuli on its display (displayability.h;
// docs/running.md, "Displayability").
#include "displayability.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "atonlab/protocols/observer.h"
#include "atonlab/store/json.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;

namespace {

/// Every judged light of the condition's stimulus at `level` (the test first
/// in 2AFC: the order does not change what each light looks like).
LevelEnd render_end(StimulusRenderer& renderer, const p::Protocol& protocol, const p::Condition& c, double level,
                    double window_radius_deg) {
    p::Proposal proposal;
    proposal.level = level;
    if (c.task == p::Task::TwoAfc) proposal.test_on_left = true;
    const p::Stimulus stim = p::make_stimulus(protocol, c, proposal);
    LevelEnd end;
    end.level = level;
    std::vector<std::shared_ptr<const FrameViews>> frames(stim.frames.size());
    std::vector<std::size_t> seen(stim.frames.size(), 0);
    for (std::size_t f = 0; f < stim.frames.size(); ++f) {
        std::vector<std::string> lights;
        for (const p::StimulusView& v : stim.views)
            if (v.frame == f) lights.push_back(v.light);
        frames[f] = renderer.views(stim.frames[f], lights);
    }
    for (const p::StimulusView& v : stim.views) {
        const LightWindow& w = frames[v.frame]->windows[seen[v.frame]++];
        end.white_code = w.white_code;
        ShownLight s;
        s.role = v.role;
        s.light = v.light;
        s.peak_code = w.peak_code;
        s.background_code = w.background_code;
        s.rise_codes = w.rise_codes;
        s.clipped = w.clipped;
        s.light_lux = p::window_light_lux(w.image, w.light_px, window_radius_deg);
        end.lights.push_back(std::move(s));
    }
    return end;
}

const ShownLight* find_role(const LevelEnd& end, p::Role role) {
    for (const ShownLight& s : end.lights)
        if (s.role == role) return &s;
    return nullptr;
}

std::string role_text(const ShownLight& s) {
    return fmt::format("{} light \"{}\"", p::to_string(s.role), s.light);
}

/// R1-R3 of displayability.h for one condition.
std::vector<std::string> problems_of(const p::Condition& c, const LevelEnd& low, const LevelEnd& high, int white) {
    std::vector<std::string> out;
    const bool matching = c.task != p::Task::YesNo;
    const std::string top = fmt::format("{:.4g}", high.level);
    // R1: each judged light, at the top of the range, where it is brightest.
    for (const ShownLight& s : high.lights) {
        if (s.rise_codes >= kMinRiseCodes) continue;
        const bool level_light = s.role == c.level_on;
        out.push_back(fmt::format(
            "the {} rises {} code value{} above the background (code {}) at the top of the level range ({}), "
            "fewer than {}: it cannot be seen; {}",
            role_text(s), s.rise_codes, s.rise_codes == 1 ? "" : "s", s.background_code, top, kMinRiseCodes,
            level_light ? "raise max_level (or the intensity the level scales)"
                        : "raise its intensity_cd (give it headroom: docs/protocol-file.md, \"Displayability\")"));
    }
    const ShownLight* lo = find_role(low, c.level_on);
    const ShownLight* hi = find_role(high, c.level_on);
    if (!lo || !hi) return out;
    // R2: the level changes nothing on the screen.
    if (!(hi->light_lux > lo->light_lux) && hi->rise_codes >= kMinRiseCodes)
        out.push_back(fmt::format(
            "the {} shows the same at both ends of the level range ({:.4g} and {}){}: the level changes nothing on "
            "this display; lower the range (min_level, max_level) below where it clips",
            role_text(*hi), low.level, top, hi->clipped ? fmt::format(", clipped at the display's white (code {})", white)
                                                       : std::string()));
    // R3: clipped, and still less light than the other stimulus.
    if (matching && hi->clipped) {
        const p::Role other_role = c.level_on == p::Role::Test ? p::Role::Reference : p::Role::Test;
        // 1% below: two lights clipped alike are equal, not one dimmer (the sums differ in the last digits).
        if (const ShownLight* other = find_role(high, other_role); other && hi->light_lux < 0.99 * other->light_lux)
            out.push_back(fmt::format(
                "at the top of the level range ({}) the {} is clipped at the display's white (code {}) and still "
                "puts less light into the eye ({:.3g} lx) than the {} ({:.3g} lx): no level can make it the brighter; "
                "lower the {}'s intensity, or show the lights on larger pixels (a smaller display.width_px, or a "
                "longer viewing distance in pixels per degree) or an HDR display",
                top, role_text(*hi), white, hi->light_lux, role_text(*other), other->light_lux,
                p::to_string(other_role)));
    }
    return out;
}

std::string light_cell(const ShownLight& s, int white) {
    return fmt::format("{} {:>4} (bg {:>3}, +{:<3}{}) {:.2e} lx", p::to_string(s.role), s.peak_code, s.background_code,
                       s.rise_codes, s.peak_code >= white && s.clipped ? " WHITE" : "", s.light_lux);
}

}  // namespace

bool Displayability::displayable() const noexcept {
    return std::all_of(conditions.begin(), conditions.end(),
                       [](const ConditionDisplayability& c) { return c.displayable(); });
}

Displayability check_displayability(StimulusRenderer& renderer, const p::Protocol& protocol) {
    const p::ModelObserverParams params{};  // the observer's window: the light each stimulus adds
    Displayability d;
    d.width_px = protocol.display.width_px;
    d.height_px = protocol.display.height_px;
    d.width_m = protocol.display.width_m;
    d.viewing_distance_m = protocol.display.viewing_distance_m;
    // Degrees per pixel at the centre (a flat screen; the same pinhole as the camera's).
    d.deg_per_px = 2.0 * std::atan(0.5 * d.width_m / d.width_px / d.viewing_distance_m) * 180.0 / M_PI;
    for (const p::Block& b : protocol.blocks)
        for (const p::Condition& c : b.conditions) {
            const auto [lo, hi] = c.procedure.level_range();
            ConditionDisplayability cd;
            cd.name = c.name;
            cd.line = c.line;
            cd.low = render_end(renderer, protocol, c, lo, params.window_radius_deg);
            cd.high = render_end(renderer, protocol, c, hi, params.window_radius_deg);
            // The codes' depth (white = 2^bits − 1), as every window of the frames knows it.
            d.bits = static_cast<int>(std::lround(std::log2(static_cast<double>(cd.high.white_code) + 1.0)));
            cd.problems = problems_of(c, cd.low, cd.high, (1 << d.bits) - 1);
            d.conditions.push_back(std::move(cd));
        }
    return d;
}

std::string displayability_table(const Displayability& d) {
    const int white = (1 << d.bits) - 1;
    std::string t = fmt::format(
        "displayability on {}×{} px, {:.3g} m wide at {:.3g} m ({:.4f}°/px), {}-bit codes (white {}): peak code "
        "(background, rise), light into the eye:\n",
        d.width_px, d.height_px, d.width_m, d.viewing_distance_m, d.deg_per_px, d.bits, white);
    for (const ConditionDisplayability& c : d.conditions) {
        for (const LevelEnd* end : {&c.low, &c.high}) {
            std::string row = fmt::format("  {:<24} level {:>8.4g} ", end == &c.low ? c.name : std::string(),
                                          end->level);
            for (const ShownLight& s : end->lights) row += " | " + light_cell(s, white);
            t += row + "\n";
        }
        t += c.displayable() ? "" : fmt::format("  {:<24} NOT DISPLAYABLE\n", "");
    }
    return t;
}

std::string displayability_refusal(const Displayability& d, const std::string& protocol_file) {
    std::string out;
    for (const ConditionDisplayability& c : d.conditions) {
        if (c.displayable()) continue;
        std::string why;
        for (const std::string& problem : c.problems) why += (why.empty() ? "" : "; and ") + problem;
        out += fmt::format("{}{}:{}: condition \"{}\" cannot produce a match on this {}×{} display: {}.",
                           out.empty() ? "" : "\n", protocol_file, c.line, c.name, d.width_px, d.height_px, why);
    }
    return out;
}

std::string displayability_json(const Displayability& d, bool allowed) {
    using Json = nlohmann::ordered_json;
    Json conditions = Json::array();
    for (const ConditionDisplayability& c : d.conditions) {
        Json ends = Json::array();
        for (const LevelEnd* end : {&c.low, &c.high}) {
            Json lights = Json::array();
            for (const ShownLight& s : end->lights)
                lights.push_back(Json{{"role", p::to_string(s.role)},
                                      {"light", s.light},
                                      {"peak_code", s.peak_code},
                                      {"background_code", s.background_code},
                                      {"rise_codes", s.rise_codes},
                                      {"clipped", s.clipped},
                                      {"light_lux", s.light_lux}});
            ends.push_back(Json{{"level", end->level}, {"lights", std::move(lights)}});
        }
        conditions.push_back(Json{
            {"name", c.name}, {"displayable", c.displayable()}, {"problems", c.problems}, {"ends", std::move(ends)}});
    }
    const Json j{{"display",
                  {{"width_px", d.width_px},
                   {"height_px", d.height_px},
                   {"width_m", d.width_m},
                   {"viewing_distance_m", d.viewing_distance_m},
                   {"deg_per_px", d.deg_per_px},
                   {"bits", d.bits},
                   {"white_code", (1 << d.bits) - 1}}},
                 {"min_rise_codes", kMinRiseCodes},
                 {"displayable", d.displayable()},
                 {"allowed_undisplayable", allowed},
                 {"conditions", std::move(conditions)}};
    return store::dump_json(j);
}

}  // namespace atonlab::runner
