// Displayability of a protocol's stimuli on its display (displayability.h;
// docs/running.md, "Displayability").
#include "atonlab/runner/displayability.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "atonlab/display/gamut.h"
#include "atonlab/display/tonemap.h"
#include "atonlab/protocols/observer.h"
#include "atonlab/stimuli/tonemap.h"
#include "atonlab/store/json.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;

namespace {

/// The light a judged light's window loses to the display's white and to
/// display.out_of_gamut (ShownLight::white_loss_share, gamut_loss_share): the
/// tone mapper's CPU reference on the frame's HDR image at the frame's
/// adaptation, each window pixel's target luminance Y (relative to white: the
/// tone curve's L_d) against min(1, Y) (what keep-luminance shows) and against
/// what the choice shows, summed as Σ ΔL · Ω_px over the observer's window.
void gamut_losses(const stimuli::ImageRGBA32F& hdr, const stimuli::Scene& sc, double adaptation_cd_m2,
                  const LightWindow& w, double radius_deg, ShownLight& s) {
    const display::DisplayModel& dm = sc.output.display;
    const glm::dvec3 weights = display::channel_weights(dm);
    double white_cd_m2 = 0.0;
    for (int c = 0; c < 3; ++c) white_cd_m2 += dm.channels[static_cast<std::size_t>(c)].max_cd_m2();
    display::ToneMapSettings no_hue = sc.output.tonemap;
    no_hue.hue_preservation = display::HuePreservation::none;
    no_hue.out_of_gamut = display::OutOfGamut::clip_channels;  // no fit in the tone mapper either
    p::DisplayedImage to_white = w.image, to_choice = w.image;
    to_white.background_cd_m2.clear();
    to_choice.background_cd_m2.clear();
    const int x0 = static_cast<int>(std::lround(w.frame_px.x - w.light_px.x));
    const int y0 = static_cast<int>(std::lround(w.frame_px.y - w.light_px.y));
    for (int j = 0; j < w.image.height; ++j)
        for (int i = 0; i < w.image.width; ++i) {
            const std::size_t k = static_cast<std::size_t>(j) * w.image.width + i;
            to_white.luminance_cd_m2[k] = to_choice.luminance_cd_m2[k] = 0.0f;
            const int x = x0 + i, y = y0 + j;
            if (x < 0 || y < 0 || x >= hdr.width || y >= hdr.height) continue;
            const float* px = hdr.pixel(x, y);
            const glm::dvec3 rgb(px[0], px[1], px[2]);
            const glm::dvec3 rel = display::tonemap_pixel(rgb, px[3], adaptation_cd_m2, sc.output.tonemap);
            // The tone curve's L_d: without hue preservation (eq 4.29) the output's luminance is
            // L_d itself; eq 4.28 (xyY) caps it at 1 before the display sees it.
            const double asked = glm::dot(weights, display::tonemap_pixel(rgb, px[3], adaptation_cd_m2, no_hue));
            const double kept = std::min(1.0, asked);  // keep-luminance (gamut.h)
            const double shown = glm::dot(weights, display::fit_to_gamut(rel, weights, sc.output.encode.out_of_gamut));
            to_white.luminance_cd_m2[k] = static_cast<float>((asked - kept) * white_cd_m2);
            to_choice.luminance_cd_m2[k] = static_cast<float>(std::max(0.0, kept - shown) * white_cd_m2);
        }
    const double white_lux = p::window_illuminance_lux(to_white, w.light_px, radius_deg);
    const double choice_lux = p::window_illuminance_lux(to_choice, w.light_px, radius_deg);
    const double asked_lux = std::max(0.0, s.added_lux) + white_lux + choice_lux;
    if (asked_lux > 0.0) {
        s.white_loss_share = white_lux / asked_lux;
        s.gamut_loss_share = choice_lux / asked_lux;
    }
}

/// The tone mapper's adaptation for a frame rendered afresh (StimulusRenderer::encode_scene):
/// the eye's level, or with dynamic adaptation the frame's own log-average (K2012 eq 4.15).
double frame_adaptation_cd_m2(const stimuli::Scene& sc, const stimuli::ImageRGBA32F& hdr) {
    if (sc.output.adaptation.mode == stimuli::AdaptationMode::fixed) return sc.adaptation_cd_m2;
    return stimuli::log_average_luminance(hdr, sc.output.adaptation.epsilon_cd_m2);
}

/// Every judged light of the condition's stimulus at `level` (the test first
/// in 2AFC: the order does not change what each light looks like).
LevelEnd render_end(StimulusRenderer& renderer, const p::Protocol& protocol, const p::Condition& c, double level) {
    p::Proposal proposal;
    proposal.level = level;
    if (c.task == p::Task::TwoAfc) proposal.test_on_left = true;
    const p::Stimulus stim = p::make_stimulus(protocol, c, proposal);
    LevelEnd end;
    end.level = level;
    std::vector<std::shared_ptr<const FrameViews>> frames(stim.frames.size());
    std::vector<stimuli::ImageRGBA32F> hdrs(stim.frames.size());
    std::vector<std::size_t> seen(stim.frames.size(), 0);
    for (std::size_t f = 0; f < stim.frames.size(); ++f) {
        std::vector<std::string> lights;
        for (const p::StimulusView& v : stim.views)
            if (v.frame == f) lights.push_back(v.light);
        double deg_per_px = 0.0;
        hdrs[f] = renderer.hdr(stim.frames[f], lights, deg_per_px);  // renders and caches the views
        frames[f] = renderer.views(stim.frames[f], lights);
    }
    for (const p::StimulusView& v : stim.views) {
        const LightWindow& w = frames[v.frame]->windows[seen[v.frame]++];
        end.white_code = w.white_code;
        ShownLight s;
        s.role = v.role;
        s.light = v.light;
        s.peak_code = w.peak_code;
        s.clipped = w.clipped;
        s.background_code = w.background_code;
        s.background_cd_m2 = w.background_cd_m2;
        // What the model observer sums (observer.h window_light_lux), signed:
        // Σ (L − L_off) · Ω over its window.
        s.added_lux = p::increment_illuminance_lux(w.image, w.light_px, renderer.window_radius_deg());
        s.resolution_lux = w.code_step_cd_m2 * w.image.pixel_sr(w.brightest_px.x, w.brightest_px.y);
        const auto sc = renderer.scene(stim.frames[v.frame].overrides);
        end.out_of_gamut = std::string(display::out_of_gamut_name(sc->output.encode.out_of_gamut));
        gamut_losses(hdrs[v.frame], *sc, frame_adaptation_cd_m2(*sc, hdrs[v.frame]), w, renderer.window_radius_deg(),
                     s);
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

/// The level where the level stimulus would add `target` lux, from the two
/// ends (R4): log10 of the light linear in the level on a log10 level scale
/// (a light's intensity is 10^level), the light itself on a linear one.
/// nullopt where the ends do not give it.
std::optional<double> interpolate_level(const p::Condition& c, double lo_level, double lo_lux, double hi_level,
                                        double hi_lux, double target_lux) {
    const bool log_scale = c.level_scale == p::LevelScale::Log10;
    if (log_scale && !(lo_lux > 0 && hi_lux > 0 && target_lux > 0)) return std::nullopt;
    const auto f = [&](double e) { return log_scale ? std::log10(e) : e; };
    if (!(f(hi_lux) != f(lo_lux))) return std::nullopt;
    const double level = lo_level + (hi_level - lo_level) * (f(target_lux) - f(lo_lux)) / (f(hi_lux) - f(lo_lux));
    return std::isfinite(level) ? std::optional<double>(level) : std::nullopt;
}

/// The name of the bound at the low or high end of a condition's range.
std::string bound_name(const p::Condition& c, bool high) {
    return std::string(c.procedure.type().bound_names[high ? 1 : 0]);
}

/// R1 for one light: it adds less than the display's resolution.
std::string invisible(const ShownLight& s, const std::string& where, bool level_light, const std::string& raise) {
    const std::string adds =
        s.added_lux > 0
            ? fmt::format("adds {:.3g} lx, less than one code step at its brightest pixel ({:.3g} lx)", s.added_lux,
                          s.resolution_lux)
            : fmt::format("adds no light ({:.3g} lx; one code step there is {:.3g} lx)", s.added_lux, s.resolution_lux);
    return fmt::format(
        "the {} {} within the observer's window {} over a background of {:.3g} cd/m² (codes {},{},{}): it cannot be "
        "seen; {}",
        role_text(s), adds, where, s.background_cd_m2, s.background_code.r, s.background_code.g, s.background_code.b,
        level_light ? raise : "raise its intensity_cd (give it headroom: docs/protocol-file.md, \"Displayability\")");
}

/// R1-R4 of displayability.h for one condition; sets cd.equal_level.
void judge(const p::Condition& c, ConditionDisplayability& cd, int white) {
    std::vector<std::string>& out = cd.problems;
    const bool matching = c.task != p::Task::YesNo;
    const p::Role other_role = c.level_on == p::Role::Test ? p::Role::Reference : p::Role::Test;
    const ShownLight* lo = find_role(cd.low, c.level_on);
    const ShownLight* hi = find_role(cd.high, c.level_on);
    // Where the level stimulus adds most: the top of the range unless the
    // level dims it (a level key that darkens).
    const bool rising = !(lo && hi && lo->added_lux > hi->added_lux);
    const LevelEnd& bright = rising ? cd.high : cd.low;
    const LevelEnd& dim = rising ? cd.low : cd.high;
    const std::string bright_at = fmt::format("at {} ({:.4g})", bound_name(c, rising), bright.level);
    // R1: every judged light where it adds most (the other stimulus is the same at both ends).
    bool seen = true;
    for (const ShownLight& s : bright.lights) {
        if (s.added_lux > 0 && s.added_lux >= s.resolution_lux) continue;
        seen = false;
        out.push_back(invisible(s, bright_at, s.role == c.level_on,
                                fmt::format("{} {} (or raise the intensity the level scales)",
                                            rising ? "raise" : "lower", bound_name(c, rising))));
    }
    if (!lo || !hi || !seen) return;
    const ShownLight& level_bright = rising ? *hi : *lo;
    const ShownLight& level_dim = rising ? *lo : *hi;
    // R2: the level changes nothing on the screen.
    if (const double change = std::abs(hi->added_lux - lo->added_lux);
        change == 0 || change < level_bright.resolution_lux) {
        out.push_back(fmt::format(
            "the {} adds the same light at both ends of the level range ({:.4g} and {:.4g}: {:.3g} and {:.3g} lx, "
            "less apart than one code step, {:.3g} lx){}: the level changes nothing on this display; lower the range "
            "(min_level, max_level) below where it clips",
            role_text(*hi), cd.low.level, cd.high.level, lo->added_lux, hi->added_lux, level_bright.resolution_lux,
            hi->clipped ? fmt::format(", clipped at the display's white (code {})", white) : std::string()));
        return;
    }
    if (!matching) return;
    const ShownLight* other = find_role(bright, other_role);
    if (!other) return;
    cd.equal_level = interpolate_level(c, cd.low.level, lo->added_lux, cd.high.level, hi->added_lux, other->added_lux);
    const double span = std::abs(cd.high.level - cd.low.level);
    // R3: clipped where brightest, and still less light than the other stimulus.
    // 1% below: two lights clipped alike are equal, not one dimmer (the sums differ in the last digits).
    if (level_bright.clipped && level_bright.added_lux < 0.99 * other->added_lux) {
        out.push_back(fmt::format(
            "{} the {} is clipped at the display's white (code {}) and still adds less light ({:.3g} lx) than the "
            "{} ({:.3g} lx): no level can make it the brighter; lower the {}'s intensity, or show the lights on "
            "larger pixels (a smaller display.width_px, or a longer viewing distance in pixels per degree) or an HDR "
            "display",
            bright_at, role_text(level_bright), white, level_bright.added_lux, role_text(*other), other->added_lux,
            p::to_string(other_role)));
        return;
    }
    // R4: the range straddles the other stimulus. A quarter of the range's
    // width beyond the estimated equal level leaves the procedure room to bracket it.
    const auto move_to = [&](bool high_bound) {
        const double sign = high_bound ? 1.0 : -1.0;
        return cd.equal_level ? fmt::format(
                                    "; {} {} to about {:.3g} (the two would add equal light near level "
                                    "{:.3g}, interpolated between the ends)",
                                    high_bound ? "raise" : "lower", bound_name(c, high_bound),
                                    *cd.equal_level + sign * 0.25 * span, *cd.equal_level)
                              : fmt::format("; {} {}", high_bound ? "raise" : "lower", bound_name(c, high_bound));
    };
    if (level_dim.added_lux >= other->added_lux) {
        out.push_back(fmt::format(
            "the level range does not reach below the {}: at {} ({:.4g}), where it is dimmest, the {} already adds "
            "{:.3g} lx, at least the {}'s {:.3g} lx, so no level in the range makes it the dimmer{}",
            role_text(*other), bound_name(c, !rising), dim.level, role_text(level_dim), level_dim.added_lux,
            p::to_string(other_role), other->added_lux, move_to(!rising)));
    } else if (!level_bright.clipped && level_bright.added_lux <= other->added_lux) {
        out.push_back(fmt::format(
            "the level range does not reach above the {}: {}, where it is brightest, the {} adds only {:.3g} lx, no "
            "more than the {}'s {:.3g} lx, so no level in the range makes it the brighter{}",
            role_text(*other), bright_at, role_text(level_bright), level_bright.added_lux, p::to_string(other_role),
            other->added_lux, move_to(rising)));
    }
}

/// R5 and W1 of displayability.h for one condition (after judge(): W1 uses its equal level).
void judge_losses(const p::Condition& c, ConditionDisplayability& cd, int white, double max_loss) {
    const bool matching = c.task != p::Task::YesNo;
    // Where the match may lie: for the other stimulus every level (it is judged against at
    // each); for the level stimulus the end nearer the estimated equal level (both without one).
    const double mid = 0.5 * (cd.low.level + cd.high.level);
    for (const LevelEnd* end : {&cd.low, &cd.high}) {
        const bool high = end == &cd.high;
        const bool near_match = !cd.equal_level || (high ? *cd.equal_level >= mid : *cd.equal_level <= mid);
        const std::string& choice = end->out_of_gamut;
        const bool keep_luminance = choice == display::out_of_gamut_name(display::OutOfGamut::keep_luminance);
        for (const ShownLight& s : end->lights) {
            const std::string at = fmt::format("at {} ({:.4g})", bound_name(c, high), end->level);
            if (matching && !keep_luminance && s.gamut_loss_share > max_loss)
                cd.problems.push_back(fmt::format(
                    "{} the {} gives up {:.1f} % of its light within the observer's window to display.out_of_gamut = "
                    "\"{}\" (more than display.max_out_of_gamut_loss, {:.3g} %): a brightness match would judge a "
                    "colour that lost its luminance; use keep-luminance for brightness, or lower its intensity",
                    at, role_text(s), 100.0 * s.gamut_loss_share, choice, 100.0 * max_loss));
            // The other stimulus is the same at both ends: said once, at the top.
            const bool where = s.role != c.level_on ? high : near_match;
            if (s.white_loss_share > kWhiteLossWarningShare && where)
                cd.warnings.push_back(fmt::format(
                    "{} the {} is clipped at the display's white (code {}) and shows {:.1f} % less light within the "
                    "observer's window than its intensity asks for: a match near this level may lie; lower the "
                    "intensity, or show the lights on an HDR display or larger pixels",
                    at, role_text(s), white, 100.0 * s.white_loss_share));
        }
    }
}

std::string light_cell(const ShownLight& s, int white) {
    // The shares lost (ShownLight), only where there are any: a light shown whole reads as before.
    const std::string lost =
        (s.white_loss_share >= 0.005 ? fmt::format(" -{:.0f}% at white", 100.0 * s.white_loss_share) : "") +
        (s.gamut_loss_share >= 0.005 ? fmt::format(" -{:.0f}% to gamut", 100.0 * s.gamut_loss_share) : "");
    return fmt::format("{} {:+.2e} lx ({:>7.3g} steps of {:.1e} lx) peak {:>4}{}{} bg {},{},{} {:.2e} cd/m²",
                       p::to_string(s.role), s.added_lux, s.resolution_lux > 0 ? s.added_lux / s.resolution_lux : 0.0,
                       s.resolution_lux, s.peak_code, s.peak_code >= white && s.clipped ? " WHITE" : "", lost,
                       s.background_code.r, s.background_code.g, s.background_code.b, s.background_cd_m2);
}

}  // namespace

bool Displayability::displayable() const noexcept {
    return std::all_of(conditions.begin(), conditions.end(),
                       [](const ConditionDisplayability& c) { return c.displayable(); });
}

Displayability check_displayability(StimulusRenderer& renderer, const p::Protocol& protocol) {
    Displayability d;
    d.width_px = protocol.display.width_px;
    d.height_px = protocol.display.height_px;
    d.width_m = protocol.display.width_m;
    d.viewing_distance_m = protocol.display.viewing_distance_m;
    // Degrees per pixel at the centre (a flat screen; the same pinhole as the camera's).
    d.window_radius_deg = renderer.window_radius_deg();
    d.deg_per_px = 2.0 * std::atan(0.5 * d.width_m / d.width_px / d.viewing_distance_m) * 180.0 / M_PI;
    d.out_of_gamut = std::string(display::out_of_gamut_name(renderer.scene({})->output.encode.out_of_gamut));
    d.max_out_of_gamut_loss = protocol.display.max_out_of_gamut_loss;
    for (const p::Block& b : protocol.blocks)
        for (const p::Condition& c : b.conditions) {
            const auto [lo, hi] = c.procedure.level_range();
            ConditionDisplayability cd;
            cd.name = c.name;
            cd.line = c.line;
            cd.low = render_end(renderer, protocol, c, lo);
            cd.high = render_end(renderer, protocol, c, hi);
            // The codes' depth (white = 2^bits − 1), as every window of the frames knows it.
            d.bits = static_cast<int>(std::lround(std::log2(static_cast<double>(cd.high.white_code) + 1.0)));
            judge(c, cd, (1 << d.bits) - 1);
            judge_losses(c, cd, (1 << d.bits) - 1, d.max_out_of_gamut_loss);
            d.conditions.push_back(std::move(cd));
        }
    return d;
}

std::string displayability_table(const Displayability& d) {
    const int white = (1 << d.bits) - 1;
    std::string t = fmt::format(
        "displayability on {}×{} px, {:.3g} m wide at {:.3g} m ({:.4f}°/px), {}-bit codes (white {}): per judged "
        "light, the light it adds to the eye within the observer's {:.3g}° window (Σ (L − L_off)·Ω, lx, L decoded "
        "through the display model), that in code steps at its brightest pixel (one step's light, lx), its peak "
        "code, and the background there with the judged lights off (codes R,G,B; cd/m²):\n",
        d.width_px, d.height_px, d.width_m, d.viewing_distance_m, d.deg_per_px, d.bits, white, d.window_radius_deg);
    if (d.out_of_gamut != display::out_of_gamut_name(display::OutOfGamut::keep_luminance))
        t += fmt::format("  colours the display cannot show: display.out_of_gamut = \"{}\" (not keep-luminance)\n",
                         d.out_of_gamut);
    for (const ConditionDisplayability& c : d.conditions) {
        for (const LevelEnd* end : {&c.low, &c.high}) {
            std::string row =
                fmt::format("  {:<24} level {:>8.4g} ", end == &c.low ? c.name : std::string(), end->level);
            for (const ShownLight& s : end->lights) row += " | " + light_cell(s, white);
            t += row + "\n";
        }
        if (c.equal_level)
            t += fmt::format("  {:<24} level stimulus equals the other near level {:.3g} (interpolated)\n", "",
                             *c.equal_level);
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

std::string displayability_warnings(const Displayability& d, const std::string& protocol_file) {
    std::string out;
    for (const ConditionDisplayability& c : d.conditions)
        for (const std::string& w : c.warnings)
            out += fmt::format("{}atonlab: warning: {}:{}: condition \"{}\": {}.", out.empty() ? "" : "\n",
                               protocol_file, c.line, c.name, w);
    return out;
}

std::string displayability_json(const Displayability& d, bool allowed, const std::string& presentation_json) {
    using Json = nlohmann::ordered_json;
    Json conditions = Json::array();
    for (const ConditionDisplayability& c : d.conditions) {
        Json ends = Json::array();
        for (const LevelEnd* end : {&c.low, &c.high}) {
            Json lights = Json::array();
            for (const ShownLight& s : end->lights)
                lights.push_back(Json{
                    {"role", p::to_string(s.role)},
                    {"light", s.light},
                    {"added_lux", s.added_lux},
                    {"resolution_lux", s.resolution_lux},
                    {"peak_code", s.peak_code},
                    {"clipped", s.clipped},
                    {"background_code", Json::array({s.background_code.r, s.background_code.g, s.background_code.b})},
                    {"background_cd_m2", s.background_cd_m2},
                    {"white_loss_share", s.white_loss_share},
                    {"gamut_loss_share", s.gamut_loss_share}});
            ends.push_back(
                Json{{"level", end->level}, {"out_of_gamut", end->out_of_gamut}, {"lights", std::move(lights)}});
        }
        conditions.push_back(Json{{"name", c.name},
                                  {"displayable", c.displayable()},
                                  {"problems", c.problems},
                                  {"warnings", c.warnings},
                                  {"equal_level", c.equal_level ? Json(*c.equal_level) : Json(nullptr)},
                                  {"ends", std::move(ends)}});
    }
    const Json j{
        {"display",
         {{"width_px", d.width_px},
          {"height_px", d.height_px},
          {"width_m", d.width_m},
          {"viewing_distance_m", d.viewing_distance_m},
          {"deg_per_px", d.deg_per_px},
          {"bits", d.bits},
          {"white_code", (1 << d.bits) - 1},
          {"out_of_gamut", d.out_of_gamut}}},
        {"window_radius_deg", d.window_radius_deg},
        // The limits the shares below were judged by (W1, R5): absent in older records.
        {"thresholds",
         {{"white_loss_warning_share", kWhiteLossWarningShare}, {"max_out_of_gamut_loss", d.max_out_of_gamut_loss}}},
        {"displayable", d.displayable()},
        {"allowed_undisplayable", allowed},
        {"conditions", std::move(conditions)},
        {"presentation", presentation_json.empty() ? Json(nullptr) : Json::parse(presentation_json)}};
    return store::dump_json(j);
}

}  // namespace atonlab::runner
