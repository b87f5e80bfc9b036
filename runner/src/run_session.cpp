// The engine of `atonlab run` (run_session.h; docs/running.md).
#include "run_session.h"

#include "json_text.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>
#include <system_error>
#include <type_traits>
#include <variant>

#include "atonlab/common/input_text.h"
#include "atonlab/protocols/protocol_file.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/protocols/rng.h"
#include "atonlab/runner/presenter.h"
#include "atonlab/runner/screen_presenter.h"
#include "atonlab/runner/text.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/rhythm.h"
#include "atonlab/stimuli/scene_file.h"
#include "atonlab/stimuli/tonemap.h"
#include "atonlab/store/sha256.h"
#include "atonlab/store/store.h"
#include "calibration_policy.h"
#include "displayability.h"
#include "profile_location.h"
#include "session_display.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;
namespace st = atonlab::store;

namespace {

// ---------------------------------------------------------------------------
// SIGINT / SIGTERM: a flag checked between trials. The trial being shown is
// finished and committed; then the session is marked "quit".

volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void on_stop_signal(int signal_number) {
    g_stop_signal = signal_number;
}

class StopSignals {
public:
    StopSignals() {
        g_stop_signal = 0;
        struct sigaction sa {};
        sa.sa_handler = on_stop_signal;
        sa.sa_flags = SA_RESTART;  // a write or fsync of the study file is not cut short
        sigemptyset(&sa.sa_mask);
        sigaction(SIGINT, &sa, &old_int_);
        sigaction(SIGTERM, &sa, &old_term_);
    }
    ~StopSignals() { restore(); }
    StopSignals(const StopSignals&) = delete;
    StopSignals& operator=(const StopSignals&) = delete;
    /// Back to what was there (after the last trial, a signal ends the summary at once).
    void restore() {
        if (restored_) return;
        sigaction(SIGINT, &old_int_, nullptr);
        sigaction(SIGTERM, &old_term_, nullptr);
        restored_ = true;
    }

private:
    struct sigaction old_int_ {};
    struct sigaction old_term_ {};
    bool restored_ = false;
};

// ---------------------------------------------------------------------------
// Small helpers

std::string read_text(const std::filesystem::path& file, std::string_view what,
                      std::uintmax_t max_bytes = text::kMaxInputFileBytes) {
    text::FileText read = text::read_text_file(file, max_bytes);  // only up to a limit (/dev/zero is refused)
    if (!read.ok())
        throw InputError(SourceLocation{file.string(), 0, 0, ""},
                         fmt::format("cannot read the {}: {}.", what, read.error));
    return std::move(read.text);
}

/// The response codes of trials the procedure never saw (docs/running.md,
/// "Missed frames and timeouts"): shown again, skipped on replay.
bool is_uncounted(std::string_view response) {
    return response == "missed" || response == "timeout";
}

bool valid_observer_code(std::string_view code) {
    if (code.empty() || code.size() > 32) return false;
    return std::all_of(code.begin(), code.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    });
}

double seconds_since(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

std::string clock_text(double seconds) {
    const auto total = static_cast<long long>(std::llround(std::max(0.0, seconds)));
    if (total >= 3600) return fmt::format("{}:{:02}:{:02}", total / 3600, total / 60 % 60, total % 60);
    return fmt::format("{}:{:02}", total / 60, total % 60);
}

/// The lights judged in frame `f` of a stimulus, in view order.
std::vector<std::string> judged_lights(const p::Stimulus& stimulus, std::size_t f) {
    std::vector<std::string> lights;
    for (const p::StimulusView& v : stimulus.views)
        if (v.frame == f) lights.push_back(v.light);
    return lights;
}

const s::Light* find_light(const s::Scene& scene, std::string_view name) {
    for (const s::Light& l : scene.lights)
        if (l.name == name) return &l;
    return nullptr;
}

/// The scene's disc (an extended reference, scene.h Disc) called `name`, or nullptr.
const s::Disc* find_disc(const s::Scene& scene, std::string_view name) {
    for (const s::Disc& d : scene.discs)
        if (d.name == name) return &d;
    return nullptr;
}

/// The override that takes a judged light or disc out of a frame: a light dark,
/// a disc of zero diameter (the background shows where it was).
std::string judged_off_override(const s::Scene& scene, const std::string& name) {
    if (find_disc(scene, name) && !find_light(scene, name)) return fmt::format("disc.{}.diameter_deg=0", name);
    return fmt::format("light.{}.intensity_cd=0", name);
}

/// The moment within [0, interval_s] at which the judged lights are brightest
/// (their rhythms' summed level), so that a model observer looking at one
/// frame sees, e.g., the flash that the interval holds. Rhythms are piecewise
/// linear between knots: the levels at the midpoints between consecutive knot
/// times pick a plateau's middle, away from the edges where the GPU's
/// tabulated rhythm and the CPU's could disagree. All fixed: 0.
double brightest_moment_s(const s::Scene& scene, const std::vector<std::string>& lights, double interval_s) {
    std::vector<const s::Light*> judged;
    for (const std::string& name : lights)
        if (const s::Light* l = find_light(scene, name); l && l->rhythm_period_s > 0) judged.push_back(l);
    if (judged.empty() || !(interval_s > 0)) return 0.0;
    std::vector<double> cuts{0.0, interval_s};
    for (const s::Light* l : judged) {
        const double period = l->rhythm_period_s;
        for (const s::RhythmKnot& k : l->rhythm) {
            double t = k.t_s - l->rhythm_phase_s;
            t -= std::floor(t / period) * period;
            for (int n = 0; t <= interval_s && n < 100000; t += period, ++n) cuts.push_back(t);
        }
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
    double best_t = 0.0;
    double best = -1.0;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
        const double t = 0.5 * (cuts[i] + cuts[i + 1]);
        double level = 0.0;
        for (const s::Light* l : judged) level += s::rhythm_level(l->rhythm, l->rhythm_period_s, t + l->rhythm_phase_s);
        if (level > best) {
            best = level;
            best_t = t;
        }
    }
    return best_t;
}

std::string cache_key(const p::Frame& frame, const std::vector<std::string>& lights) {
    std::string key;
    for (const std::string& o : frame.overrides) (key += o) += '\n';
    key += '\x1f';
    for (const std::string& l : lights) (key += l) += '\n';
    return key;
}

}  // namespace

// ---------------------------------------------------------------------------
// StimulusRenderer

StimulusRenderer::StimulusRenderer(std::string scene_text, std::filesystem::path scene_file, double window_radius_deg,
                                   double interval_s, std::size_t cache_frames)
    : scene_text_(std::move(scene_text)),
      scene_file_(std::move(scene_file)),
      window_radius_deg_(window_radius_deg),
      interval_s_(interval_s),
      capacity_(std::max<std::size_t>(cache_frames, 1)) {}

s::Scene StimulusRenderer::scene(const std::vector<std::string>& overrides) const {
    std::vector<s::SceneOverride> parsed;
    parsed.reserve(overrides.size());
    for (const std::string& o : overrides) parsed.push_back(s::SceneOverride::parse(o));
    s::Scene scene = s::parse_scene(scene_text_, scene_file_.string(), parsed);
    if (display_model_) apply_display_model(scene, *display_model_);
    s::validate_output_settings(scene.output);
    return scene;
}

std::shared_ptr<const FrameViews> StimulusRenderer::views(const p::Frame& frame,
                                                          const std::vector<std::string>& lights) {
    ++requested_;
    const std::string key = cache_key(frame, lights);
    if (auto it = index_.find(key); it != index_.end()) {
        lru_.splice(lru_.begin(), lru_, it->second);
        return it->second->second;
    }
    return render(frame, lights, nullptr, nullptr);
}

s::ImageRGBA32F StimulusRenderer::hdr(const p::Frame& frame, const std::vector<std::string>& lights,
                                      double& degrees_per_pixel) {
    s::ImageRGBA32F image;
    render(frame, lights, &image, &degrees_per_pixel);
    return image;
}

void StimulusRenderer::remember(const std::string& key, std::shared_ptr<const FrameViews> views) {
    if (auto it = index_.find(key); it != index_.end()) {
        it->second->second = std::move(views);
        lru_.splice(lru_.begin(), lru_, it->second);
        return;
    }
    lru_.emplace_front(key, std::move(views));
    index_[key] = lru_.begin();
    while (lru_.size() > capacity_) {
        index_.erase(lru_.back().first);
        lru_.pop_back();
    }
}

s::EncodedImage StimulusRenderer::render_codes(const s::Scene& sc, double time_s) {
    encode_scene(sc, time_s);
    return display_.read_codes();
}

void StimulusRenderer::encode_scene(const s::Scene& sc, double time_s) {
    // stimuli::Pipeline::render, with two differences that make a frame a pure
    // function of its overrides (so a cached frame, and a resumed session, see
    // exactly what an uninterrupted run saw): each frame adapts afresh
    // (reset_adaptation, dt = 0: a dynamic scene adopts its own log-average; a
    // fixed one is unaffected), and the dither pattern is that of frame 0
    // instead of advancing with the number of frames rendered so far.
    frame_.render(sc, time_s);
    const s::OutputSettings& os = sc.output;
    display_.reset_adaptation();
    if (const gl::Texture2D* glare = frame_.glare_texture();
        glare && os.ldr_glare && (sc.glare.model != s::GlareModel::none || s::any_light_glare(sc))) {
        const s::ToneMapSettings& tm = os.tonemap;
        const double white = tm.white_cd_m2
                                 ? *tm.white_cd_m2
                                 : os.adaptation.fixed_cd_m2 * tm.display_peak_cd_m2 / s::display_adaptation_cd_m2(tm);
        display_.process_ldr(frame_.hdr_texture(), *glare, os, 0, 1.0 / white);
    } else {
        display_.process(frame_.hdr_texture(), os, 0.0, 0);
    }
    ++rendered_;
}

std::shared_ptr<const s::EncodedImage> StimulusRenderer::codes(const p::Frame& frame,
                                                               const std::vector<std::string>& lights) {
    const std::string key = cache_key(frame, lights);
    for (auto it = codes_lru_.begin(); it != codes_lru_.end(); ++it)
        if (it->first == key) {
            codes_lru_.splice(codes_lru_.begin(), codes_lru_, it);
            return codes_lru_.front().second;
        }
    const auto started = std::chrono::steady_clock::now();
    const s::Scene sc = scene(frame.overrides);
    auto out = std::make_shared<const s::EncodedImage>(render_codes(sc, brightest_moment_s(sc, lights, interval_s_)));
    render_s_ += seconds_since(started);
    codes_lru_.emplace_front(key, out);
    constexpr std::size_t kKeep = 8;  // a trial's frames and its background, with room to spare
    while (codes_lru_.size() > kKeep) codes_lru_.pop_back();
    return out;
}

bool StimulusRenderer::animated(const p::Frame& frame) {
    const s::Scene sc = scene(frame.overrides);
    return std::any_of(sc.lights.begin(), sc.lights.end(), [](const s::Light& l) { return l.rhythm_period_s > 0; });
}

void StimulusRenderer::encode(const p::Frame& frame, double time_s) {
    // Parsed once per frame, not once per flip.
    const std::string key = cache_key(frame, {});
    if (!last_scene_.second || last_scene_.first != key)
        last_scene_ = {key, std::make_shared<const s::Scene>(scene(frame.overrides))};
    encode_scene(*last_scene_.second, time_s);
}

void StimulusRenderer::present(int x, int y) const {
    display_.present(x, y);
}

std::vector<std::string> StimulusRenderer::light_names(const std::vector<std::string>& overrides) const {
    std::vector<std::string> names;
    for (const s::Light& l : scene(overrides).lights) names.push_back(l.name);
    return names;
}

std::vector<std::string> StimulusRenderer::all_off(const std::vector<std::string>& overrides) const {
    const s::Scene sc = scene(overrides);
    std::vector<std::string> off;
    for (const s::Light& l : sc.lights) off.push_back(fmt::format("light.{}.intensity_cd=0", l.name));
    for (const s::Disc& d : sc.discs) off.push_back(fmt::format("disc.{}.diameter_deg=0", d.name));
    return off;
}

const s::EncodedImage& StimulusRenderer::background_codes(const p::Frame& frame, const std::vector<std::string>& lights,
                                                          double time_s) {
    // The frame with every judged light off, at the same moment: what the
    // screen shows around the lights without them. In a glare / no-glare
    // comparison it is the same for every level of a condition, so a few
    // cached frames serve a whole session.
    p::Frame off = frame;
    const s::Scene on = scene(frame.overrides);
    for (const std::string& name : lights)
        if (!name.empty()) off.overrides.push_back(judged_off_override(on, name));
    const std::string key = fmt::format("{}@{:a}", cache_key(off, {}), time_s);
    for (auto it = background_lru_.begin(); it != background_lru_.end(); ++it)
        if (it->first == key) {
            background_lru_.splice(background_lru_.begin(), background_lru_, it);
            return background_lru_.front().second;
        }
    background_lru_.emplace_front(key, render_codes(scene(off.overrides), time_s));
    constexpr std::size_t kBackgroundFrames = 8;
    while (background_lru_.size() > kBackgroundFrames) background_lru_.pop_back();
    return background_lru_.front().second;
}

namespace {

/// The luminance (cd/m²) the screen emits at the n x n pixels from (x0, y0)
/// (row 0 at the top) for the codes given: the display model's luminance,
/// memoised per distinct code (a frame has few). Pixels beyond the screen are 0.
std::vector<float> emitted_window(const s::EncodedImage& codes, const s::DisplayModel& display, int x0, int y0, int n) {
    std::map<std::uint64_t, float> emitted;
    std::vector<float> out(static_cast<std::size_t>(n) * static_cast<std::size_t>(n), 0.0f);
    for (int v = 0; v < n; ++v) {
        const int y = y0 + v;
        if (y < 0 || y >= codes.height) continue;
        for (int u = 0; u < n; ++u) {
            const int x = x0 + u;
            if (x < 0 || x >= codes.width) continue;
            const std::size_t i =
                (static_cast<std::size_t>(y) * static_cast<std::size_t>(codes.width) + static_cast<std::size_t>(x)) *
                3;
            const glm::ivec3 code{codes.rgb[i], codes.rgb[i + 1], codes.rgb[i + 2]};
            const std::uint64_t k = (static_cast<std::uint64_t>(code.r) << 32) |
                                    (static_cast<std::uint64_t>(code.g) << 16) | static_cast<std::uint64_t>(code.b);
            auto [it, fresh] = emitted.try_emplace(k, 0.0f);
            if (fresh) it->second = static_cast<float>(s::displayed_luminance_cd_m2(display, code, codes.bits));
            out[static_cast<std::size_t>(v) * static_cast<std::size_t>(n) + static_cast<std::size_t>(u)] = it->second;
        }
    }
    return out;
}

/// The codes of window `w` (n x n pixels from (x0, y0), row 0 at the top)
/// against the same pixels of `off` (the judged lights off; null: none).
void summarise_codes(const s::EncodedImage& codes, const s::EncodedImage* off, int x0, int y0, int n, LightWindow& w) {
    w.white_code = (1 << codes.bits) - 1;
    for (int y = std::max(y0, 0); y < std::min(y0 + n, codes.height); ++y)
        for (int x = std::max(x0, 0); x < std::min(x0 + n, codes.width); ++x)
            for (int ch = 0; ch < 3; ++ch) {
                const std::size_t i =
                    (static_cast<std::size_t>(y) * static_cast<std::size_t>(codes.width) + static_cast<std::size_t>(x)) *
                        3 +
                    static_cast<std::size_t>(ch);
                const int on = codes.rgb[i];
                const int bg = off ? off->rgb[i] : 0;
                w.peak_code = std::max(w.peak_code, on);
                w.background_code = std::max(w.background_code, bg);
                w.rise_codes = std::max(w.rise_codes, on - bg);
                w.clipped = w.clipped || (on == w.white_code && bg < w.white_code);
            }
}

}  // namespace

std::shared_ptr<const FrameViews> StimulusRenderer::render(const p::Frame& frame,
                                                           const std::vector<std::string>& lights, s::ImageRGBA32F* hdr,
                                                           double* degrees_per_pixel) {
    const auto started = std::chrono::steady_clock::now();
    const s::Scene sc = scene(frame.overrides);
    auto out = std::make_shared<FrameViews>();
    out->time_s = brightest_moment_s(sc, lights, interval_s_);

    const s::EncodedImage codes = render_codes(sc, out->time_s);
    const std::vector<s::LightDrawRecord> draws = frame_.read_light_draws();
    const s::CameraProjection proj = frame_.projection();
    const double dpp = proj.degrees_per_pixel_at_centre();
    if (hdr) *hdr = frame_.read_hdr();
    const int half = static_cast<int>(std::ceil(2.0 * window_radius_deg_ / dpp)) + 2;
    const int n = 2 * half + 1;

    struct Placed {
        glm::ivec2 origin{0};
        bool on_screen = false;
    };
    std::vector<Placed> placed;
    for (const std::string& name : lights) {
        // The light's centre in window coordinates (origin lower-left): the GPU's
        // own projection when it drew the light, else the same pinhole on the CPU
        // (a dark or culled light still has a place on the screen).
        glm::dvec2 centre_win{0.5 * codes.width, 0.5 * codes.height};
        bool behind = false;
        if (!name.empty()) {
            std::size_t index = sc.lights.size();
            for (std::size_t i = 0; i < sc.lights.size() && index == sc.lights.size(); ++i)
                if (sc.lights[i].name == name) index = i;
            const s::Disc* disc = index == sc.lights.size() ? find_disc(sc, name) : nullptr;
            if (index < draws.size() && draws[index].area_px2 > 0) {
                centre_win = draws[index].centre_px;
            } else if (index < sc.lights.size() || disc) {
                // A disc's centre: the same pinhole (its outline is a circle of visual angle around it).
                const glm::dvec3 v = proj.view_from_world((disc ? disc->position_m : sc.lights[index].position_m) -
                                                          proj.eye_position_m);
                if (v.z < 0) {
                    centre_win = glm::dvec2(0.5 * proj.width_px, 0.5 * proj.height_px) +
                                 proj.focal_px * glm::dvec2(v.x, v.y) / -v.z;
                } else {
                    behind = true;
                }
            }
        }
        // Row 0 at the top, as the codes are.
        const glm::dvec2 centre{centre_win.x, static_cast<double>(codes.height) - centre_win.y};
        LightWindow w;
        w.image.width = n;
        w.image.height = n;
        w.image.deg_per_px = dpp;
        const int x0 = static_cast<int>(std::floor(centre.x)) - half;
        const int y0 = static_cast<int>(std::floor(centre.y)) - half;
        w.light_px = centre - glm::dvec2(x0, y0);
        const bool on_screen = !behind && std::isfinite(centre.x) && std::isfinite(centre.y);
        w.image.luminance_cd_m2 = on_screen ? emitted_window(codes, sc.output.display, x0, y0, n)
                                            : std::vector<float>(static_cast<std::size_t>(n) * n, 0.0f);
        placed.push_back({{x0, y0}, on_screen});
        out->windows.push_back(std::move(w));
    }
    // What each window shows with the judged lights off, at the same pixels, so
    // that the model observer judges what a light adds to its surround
    // (observer.h window_light_lux), not the surround itself.
    bool any_named = false;
    for (const std::string& name : lights) any_named = any_named || !name.empty();
    if (any_named) {
        const s::EncodedImage& off = background_codes(frame, lights, out->time_s);
        for (std::size_t i = 0; i < out->windows.size(); ++i) {
            out->windows[i].image.background_cd_m2 =
                placed[i].on_screen
                    ? emitted_window(off, sc.output.display, placed[i].origin.x, placed[i].origin.y, n)
                    : std::vector<float>(static_cast<std::size_t>(n) * n, 0.0f);
            if (placed[i].on_screen)
                summarise_codes(codes, &off, placed[i].origin.x, placed[i].origin.y, n, out->windows[i]);
        }
    } else {
        for (std::size_t i = 0; i < out->windows.size(); ++i)
            if (placed[i].on_screen)
                summarise_codes(codes, nullptr, placed[i].origin.x, placed[i].origin.y, n, out->windows[i]);
    }
    if (degrees_per_pixel) *degrees_per_pixel = dpp;
    remember(cache_key(frame, lights), out);
    render_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return out;
}

// ---------------------------------------------------------------------------
// The session

namespace {

/// Where an override a frame applies was written in the protocol.
struct OverrideSource {
    int line = 0;
    int column = 0;
};

/// `text` is the frame's override the scene refused ("key=value"; the last of
/// its key: the scene loader validates the value each key ends with).
OverrideSource override_source(const p::Condition& c, const std::string& key, const std::string& text) {
    for (const auto* list : {&c.reference_set, &c.test_set, &c.set})
        for (auto it = list->rbegin(); it != list->rend(); ++it)
            if ((text.empty() ? it->key == key : it->text() == text) && it->line > 0) return {it->line, it->column};
    // The level, the display or a side-by-side position: the condition's own line.
    return {c.line, 0};
}

/// A frame's override parsed; one of the protocol's [display] keys keeps its
/// line, so that a limit the scene derives from the display (a glare billboard
/// too wide for it) names the protocol's line rather than "--set".
s::SceneOverride parsed_override(const p::Protocol& protocol, const std::string& text) {
    s::SceneOverride o = s::SceneOverride::parse(text);
    const std::vector<std::string> display = protocol.display_overrides();
    if (std::find(display.begin(), display.end(), text) != display.end())
        if (auto it = protocol.display.lines.find(o.key.substr(o.key.find('.') + 1));
            it != protocol.display.lines.end())
            o.origin = SourceLocation{protocol.file, it->second, 0, o.key};
    return o;
}

/// The scene of one of a condition's frames, with an error in an override
/// re-thrown at the protocol's line that wrote it (the condition named).
s::Scene condition_scene(const std::string& scene_text, const std::filesystem::path& scene_file,
                         const p::Protocol& protocol, const p::Condition& condition, const p::Frame& frame) {
    try {
        std::vector<s::SceneOverride> parsed;
        for (const std::string& o : frame.overrides) parsed.push_back(parsed_override(protocol, o));
        s::Scene scene = s::parse_scene(scene_text, scene_file.string(), parsed);
        // parse_scene has checked that the glare billboard fits the display
        // (GL-free, naming the keys), so a session refuses it before it opens anything.
        s::validate_output_settings(scene.output);
        return scene;
    } catch (const InputError& e) {
        const std::optional<SourceLocation>& w = e.where();
        const bool from_override = w && w->option == "--set";
        if (!from_override) {
            // The scene file's own error (it names its file and line), or a
            // setting that only the combination of overrides breaks.
            if (w && !w->file.empty() && w->file != scene_file.string()) throw;
            throw InputError(SourceLocation{protocol.file, condition.line, 0, w ? w->key : std::string()},
                             fmt::format("in condition \"{}\", the scene {} with this condition's overrides is "
                                         "refused: {}",
                                         condition.name, scene_file.filename().string(), e.message()));
        }
        // "--set KEY" (a value) or "--set" with the key: the override's key.
        std::string key = w->key;
        std::string text;
        for (const std::string& o : frame.overrides)
            if (o.compare(0, key.size() + 1, key + "=") == 0) text = o;
        const OverrideSource src = override_source(condition, key, text);
        throw InputError(SourceLocation{protocol.file, src.line, src.column, key},
                         fmt::format("in condition \"{}\" (line {}), the scene override '{}' is refused by the scene "
                                     "{}: {}",
                                     condition.name, condition.line, text.empty() ? key : text,
                                     scene_file.filename().string(), e.message()));
    }
}

/// Every frame of one proposal through the scene loader, and the judged lights exist.
void check_stimulus(const p::Protocol& protocol, const std::string& scene_text, const std::filesystem::path& scene_file,
                    const p::Condition& c, const p::Proposal& proposal) {
    const p::Stimulus stim = p::make_stimulus(protocol, c, proposal);
    for (std::size_t f = 0; f < stim.frames.size(); ++f) {
        const s::Scene scene = condition_scene(scene_text, scene_file, protocol, c, stim.frames[f]);
        for (const p::StimulusView& v : stim.views) {
            if (v.frame != f || v.light.empty()) continue;
            if (v.role == p::Role::Reference && !c.reference_disc.empty()) {
                if (find_disc(scene, v.light)) continue;
                std::string names;
                for (const s::Disc& d : scene.discs) names += (names.empty() ? "\"" : ", \"") + d.name + "\"";
                throw InputError(SourceLocation{protocol.file, c.line, 0, "reference_disc"},
                                 fmt::format("in condition \"{}\", the reference disc \"{}\" is not a [[disc]] of the "
                                             "scene {} (its discs: {}).",
                                             c.name, v.light, scene_file.filename().string(),
                                             names.empty() ? "none" : names));
            }
            if (find_light(scene, v.light)) continue;
            std::string names;
            for (const s::Light& l : scene.lights) names += (names.empty() ? "\"" : ", \"") + l.name + "\"";
            throw InputError(
                SourceLocation{protocol.file, c.line, 0, v.role == p::Role::Test ? "test_light" : "reference_light"},
                fmt::format("in condition \"{}\", the {} light \"{}\" is not a light of the scene {} (its lights: {}).",
                            c.name, p::to_string(v.role), v.light, scene_file.filename().string(),
                            names.empty() ? "none" : names));
        }
    }
}

/// Load-time checks of every condition: each frame's scene for a proposal at
/// the procedure's first level and at its level bounds where it has them
/// (2AFC: in both orders), and the judged lights exist.
void validate_conditions(const p::Protocol& protocol, const std::string& scene_text,
                         const std::filesystem::path& scene_file) {
    for (const p::Block& block : protocol.blocks) {
        for (const p::Condition& c : block.conditions) {
            std::unique_ptr<p::Procedure> proc;
            try {
                proc = p::make_procedure(c, 0);
            } catch (const p::ProcedureError& e) {
                throw InputError(SourceLocation{protocol.file, c.line, 0, e.parameter()},
                                 fmt::format("in condition \"{}\", {}", c.name, e.message()));
            }
            const std::optional<p::Proposal> first = proc->next();
            if (!first) continue;
            std::vector<double> levels{first->level};
            for (const double b : c.procedure.level_bounds()) levels.push_back(b);
            p::Proposal proposal = *first;
            for (const double level : levels) {
                proposal.level = level;
                if (c.task != p::Task::TwoAfc) {
                    check_stimulus(protocol, scene_text, scene_file, c, proposal);
                    continue;
                }
                for (const bool left : {true, false}) {
                    proposal.test_on_left = left;
                    check_stimulus(protocol, scene_text, scene_file, c, proposal);
                }
            }
        }
    }
}

}  // namespace

p::Shown shown_for(const p::ScheduledTrial& t, StimulusRenderer& renderer,
                   std::vector<std::shared_ptr<const FrameViews>>& frames) {
    frames.assign(t.stimulus.frames.size(), nullptr);
    p::Shown shown;
    shown.task = t.task;
    shown.adjusted_view = t.stimulus.adjusted_view;
    for (std::size_t f = 0; f < frames.size(); ++f)
        frames[f] = renderer.views(t.stimulus.frames[f], judged_lights(t.stimulus, f));
    std::vector<std::size_t> seen(frames.size(), 0);
    for (const p::StimulusView& v : t.stimulus.views) {
        const LightWindow& w = frames[v.frame]->windows[seen[v.frame]++];
        shown.views.push_back(p::View{&w.image, w.light_px});
    }
    return shown;
}

namespace {

// --- The observer ------------------------------------------------------------

/// A model observer's answers are a pure function of (observer seed, the
/// trial's first step, what it was shown): each trial (each adjustment match)
/// gets a fresh ModelObserver seeded derive_seed(observer_seed, step), so a
/// resumed session answers exactly as an uninterrupted one would have.
class SessionObserver {
public:
    SessionObserver(const RunOptions& o, std::uint64_t observer_seed, std::optional<p::ScriptedObserver> script)
        : model_(o.model_observer), seed_(observer_seed), script_(std::move(script)) {}

    bool model() const noexcept { return model_; }
    bool person() const noexcept { return !model_ && !script_; }  ///< a person answers at the screen
    std::uint64_t seed() const noexcept { return seed_; }
    const p::ModelObserverParams& params() const noexcept { return params_; }

    /// The answer to trial `t`. Renders what the model observer looks at.
    p::Answer answer(const p::ScheduledTrial& t, StimulusRenderer* renderer) {
        if (!model_) return script_->answer(p::Shown{t.task, {}, t.stimulus.adjusted_view});
        const std::string match = fmt::format("{}#{}", t.procedure_id, t.proposal.trial);
        if (!current_ || t.task != p::Task::Adjust || match != match_) {
            current_ = std::make_unique<p::ModelObserver>(params_, p::derive_seed(seed_, t.step));
            match_ = match;
        }
        std::vector<std::shared_ptr<const FrameViews>> frames;
        return current_->answer(shown_for(t, *renderer, frames));
    }

    /// A scripted observer skips the lines the logged trials used.
    void skip(p::Task task, std::optional<std::size_t> adjusted_view) {
        if (script_) script_->answer(p::Shown{task, {}, adjusted_view});
    }

private:
    bool model_;
    std::uint64_t seed_;
    p::ModelObserverParams params_{};
    std::optional<p::ScriptedObserver> script_;
    std::unique_ptr<p::ModelObserver> current_;
    std::string match_;
};

// --- Progress ----------------------------------------------------------------

class Progress {
public:
    Progress(bool quiet, int every, std::optional<std::size_t> bound)
        : quiet_(quiet),
          tty_(isatty(STDOUT_FILENO) == 1),
          every_(every > 0 ? every : 25),
          bound_(bound),
          start_(std::chrono::steady_clock::now()) {}

    void block(const p::Protocol& protocol, const p::ScheduledTrial& t, std::size_t runs, bool on_screen) {
        if (quiet_) return;
        end_line();
        const p::Block& b = protocol.blocks[t.block];
        std::printf("block \"%s\" (run %zu of %zu, repetition %d of %d): adaptation %s%s\n", b.name.c_str(), t.run + 1,
                    runs, t.repetition + 1, b.repetitions, clock_text(b.adaptation_s).c_str(),
                    on_screen ? "" : " simulated");
        std::fflush(stdout);
    }

    /// After trial `committed` (1-based count of the session's stored trials) is stored.
    void trial(const p::Protocol& protocol, const p::ScheduledTrial& t, std::size_t committed) {
        ++done_here_;
        if (quiet_) return;
        const double elapsed = seconds();
        std::string line = fmt::format("{} · trial {}", protocol.blocks[t.block].name, committed);
        if (bound_) line += fmt::format(" of ≤ {}", *bound_);
        line += fmt::format(" · {} elapsed", clock_text(elapsed));
        if (bound_ && done_here_ > 0 && *bound_ > committed)
            line += fmt::format(" · ETA ≤ {}", clock_text(elapsed / static_cast<double>(done_here_) *
                                                          static_cast<double>(*bound_ - committed)));
        if (tty_) {
            std::printf("\r\x1b[K%s", line.c_str());
            open_line_ = true;
        } else if (committed % static_cast<std::size_t>(every_) == 0) {
            std::printf("%s\n", line.c_str());
        }
        std::fflush(stdout);
    }

    void end_line() {
        if (open_line_) std::printf("\n");
        open_line_ = false;
    }
    double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
    std::size_t done_here() const noexcept { return done_here_; }

private:
    bool quiet_;
    bool tty_;
    int every_;
    std::optional<std::size_t> bound_;
    std::chrono::steady_clock::time_point start_;
    std::size_t done_here_ = 0;
    bool open_line_ = false;
};

// --- Stored records ------------------------------------------------------------

/// The glare model a view's light is drawn with in its frame's scene: the
/// light's own, else the eye's (also for a view of the image centre, or of an
/// alternating light, whose channels are "NAME/W", ...).
std::string view_glare(const s::Scene& sc, const std::string& light) {
    for (const s::Light& l : sc.lights)
        if (!light.empty() && (l.name == light || l.name.starts_with(light + "/")))
            return std::string(s::glare_model_name(s::light_glare_model(sc, l)));
    return std::string(s::glare_model_name(sc.glare.model));
}

std::string stimulus_json(const p::Protocol& protocol, const p::Condition& c, const p::ScheduledTrial& t,
                          const std::vector<double>& frame_times, const std::string& frames_shown_json,
                          const std::vector<std::string>& view_glares) {
    const p::Stimulus& stim = t.stimulus;
    std::string j = "{";
    j += fmt::format("\"task\":{},\"presentation\":{},", json_string(p::to_string(c.task)),
                     json_string(p::to_string(c.presentation)));
    j += fmt::format("\"level_key\":{},\"level_scale\":{},\"level_on\":{},\"level\":{},\"scene_value\":{},",
                     json_string(c.level_key), json_string(p::to_string(c.level_scale)),
                     json_string(p::to_string(c.level_on)), json_number(stim.level), json_number(stim.scene_value));
    j += fmt::format("\"scene\":{},", json_string(protocol.scene.string()));
    j += "\"frames\":[";
    for (std::size_t f = 0; f < stim.frames.size(); ++f) {
        const p::Frame& fr = stim.frames[f];
        if (f) j += ',';
        j += fmt::format("{{\"role\":{},\"time_s\":{},\"overrides\":[",
                         fr.role ? json_string(p::to_string(*fr.role)) : std::string("\"both\""),
                         json_number(f < frame_times.size() ? frame_times[f] : 0.0));
        for (std::size_t i = 0; i < fr.overrides.size(); ++i) j += (i ? "," : "") + json_string(fr.overrides[i]);
        j += "]}";
    }
    j += "],\"views\":[";
    for (std::size_t i = 0; i < stim.views.size(); ++i) {
        const p::StimulusView& v = stim.views[i];
        j += fmt::format("{}{{\"frame\":{},\"light\":{},\"role\":{}", i ? "," : "", v.frame, json_string(v.light),
                         json_string(p::to_string(v.role)));
        if (i < view_glares.size()) j += fmt::format(",\"glare\":{}", json_string(view_glares[i]));
        j += '}';
    }
    j += "]";
    if (stim.adjusted_view) j += fmt::format(",\"adjusted_view\":{}", *stim.adjusted_view);
    const p::Timing& tm = protocol.timing;
    // The durations asked for (s) and, in "frames", what the flips gave:
    // whole refreshes at the measured (on screen) or nominal (headless) rate.
    j += fmt::format(",\"timing\":{{\"stimulus_s\":{},\"inter_stimulus_s\":{},\"inter_trial_s\":{},\"frames\":{}}}",
                     json_number(tm.stimulus_s), json_number(tm.inter_stimulus_s), json_number(tm.inter_trial_s),
                     frames_shown_json.empty() ? std::string("null") : frames_shown_json);
    return j + "}";
}

/// The procedure's state after the trial, who answered, and what: `answer` is
/// the answer given (kept for a "missed" trial, whose response column says it
/// was repeated), `input` the key or button, `step` the schedule's step.
std::string state_json(const p::Schedule& schedule, const SessionObserver& observer, double answer_rt_s,
                       const std::optional<p::Response>& answer, const std::string& input, std::size_t step) {
    std::string j =
        fmt::format("{{\"schedule\":{},\"observer\":{},\"observer_seed\":{},\"answer_after_offset_s\":{},\"step\":{}",
                    json_string(schedule.state()),
                    json_string(observer.person()  ? "person"
                                : observer.model() ? "model"
                                                   : "script"),
                    observer.seed(), json_number(answer_rt_s), step);
    if (answer) j += fmt::format(",\"answer\":{}", json_string(p::response_word(*answer)));
    if (!input.empty()) j += fmt::format(",\"input\":{}", json_string(input));
    return j + "}";
}

/// The observer seed a session's first trial recorded, if any.
std::optional<std::uint64_t> logged_observer_seed(const std::vector<st::TrialRecord>& trials) {
    if (trials.empty()) return std::nullopt;
    const std::string& j = trials.front().procedure_state_json;
    const std::string tag = "\"observer_seed\":";
    const auto at = j.find(tag);
    if (at == std::string::npos) return std::nullopt;
    std::size_t end = at + tag.size();
    std::uint64_t v = 0;
    bool any = false;
    for (; end < j.size() && j[end] >= '0' && j[end] <= '9'; ++end) {
        v = v * 10 + static_cast<std::uint64_t>(j[end] - '0');
        any = true;
    }
    return any ? std::optional<std::uint64_t>(v) : std::nullopt;
}

/// The display the session shows on, as a calibration row: the scene's
/// nominal display model (the geometry is the protocol's). Reused when the
/// latest row of that display says the same.
st::CalibrationId record_display(st::Store& store, const s::Scene& scene, const std::filesystem::path& scene_file) {
    const s::DisplayModel& d = scene.output.display;
    std::string channels;
    for (const s::ChannelTransfer& ch : d.channels) {
        const char* kind = ch.kind == s::TransferKind::srgb  ? "srgb"
                           : ch.kind == s::TransferKind::gog ? "gog"
                           : ch.kind == s::TransferKind::lut ? "lut"
                                                             : "pq";
        channels +=
            fmt::format("{}{{\"transfer\":\"{}\",\"black_cd_m2\":{},\"white_cd_m2\":{}}}", channels.empty() ? "" : ",",
                        kind, json_number(ch.min_cd_m2()), json_number(ch.max_cd_m2()));
    }
    st::Calibration c;
    c.display_name = d.name.empty() ? "display" : d.name;
    c.width_px = scene.display.width_px;
    c.height_px = scene.display.height_px;
    c.width_m = scene.display.width_m;
    c.height_m = scene.display.height_m();
    c.viewing_distance_m = scene.display.viewing_distance_m;
    c.fit_json = fmt::format(
        "{{\"model\":\"nominal\",\"peak_cd_m2\":{},\"black_cd_m2\":{},\"bits\":{},\"dither\":{},\"channels\":[{}]}}",
        json_number(d.peak_cd_m2), json_number(d.black_cd_m2), scene.output.encode.bits,
        scene.output.encode.dither == s::Dither::spatiotemporal ? "true" : "false", channels);
    c.source = fmt::format("the [display] table of the scene {} (not measured)", scene_file.string());
    if (const auto last = store.latest_calibration(c.display_name)) {
        if (last->width_px == c.width_px && last->height_px == c.height_px && last->width_m == c.width_m &&
            last->height_m == c.height_m && last->viewing_distance_m == c.viewing_distance_m &&
            last->fit_json == c.fit_json && last->source == c.source)
            return last->id;
    }
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char date[16];
    std::strftime(date, sizeof date, "%Y-%m-%d", &utc);
    c.measured_at = date;
    return store.put_calibration(c);
}

/// One EXR of the condition's first trial: its frames stacked top to bottom
/// in presentation order, scene-referred (cd/m²), as the file's bytes.
std::vector<std::byte> snapshot_exr(StimulusRenderer& renderer, const p::Protocol& protocol, const p::Condition& c,
                                    const p::ScheduledTrial& t, std::int64_t session) {
    s::ImageRGBA32F stacked;
    double dpp = 0.0;
    std::string frames_note;
    for (std::size_t f = 0; f < t.stimulus.frames.size(); ++f) {
        const s::ImageRGBA32F img = renderer.hdr(t.stimulus.frames[f], judged_lights(t.stimulus, f), dpp);
        if (f == 0) {
            stacked.width = img.width;
        } else if (img.width != stacked.width) {
            break;  // frames of different sizes (a condition overriding the display) are not stacked
        }
        frames_note +=
            fmt::format("{}rows {}-{}: frame {} ({})", f ? "; " : "", stacked.height, stacked.height + img.height - 1,
                        f, t.stimulus.frames[f].role ? p::to_string(*t.stimulus.frames[f].role) : "both");
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
    meta.strings["level"] = fmt::format("{} ({} = {})", t.stimulus.level, c.level_key, t.stimulus.scene_value);
    const std::filesystem::path tmp =
        std::filesystem::temp_directory_path() / fmt::format("atonlab-snapshot-{}-{}.exr", getpid(), session);
    s::write_exr(tmp, stacked, meta);
    std::string bytes;
    try {
        bytes = read_text(tmp, "snapshot", std::numeric_limits<std::uintmax_t>::max());  // written just now
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

// --- Summary ----------------------------------------------------------------------

}  // namespace

/// The model observer's true value for a condition: the level its procedure
/// should converge on (2AFC and adjust: where the level stimulus is chosen
/// with the procedure's target probability, 0.5 = the PSE; yes-no: the
/// detection threshold at the target P(yes)). Renders the level stimulus at
/// each level the root finder asks for.
std::string true_value(StimulusRenderer& renderer, const p::Protocol& protocol, const p::Condition& c,
                       const p::ModelObserverParams& params, double& value) {
    const std::optional<double> p_yes = c.procedure.target_p_yes();
    if (!p_yes) return "no target probability for this procedure";
    const auto [lo, hi] = c.procedure.search_range();
    auto stimulus_at = [&](double level) {
        p::Proposal proposal;
        proposal.level = level;
        if (c.task == p::Task::TwoAfc) proposal.test_on_left = true;
        return p::make_stimulus(protocol, c, proposal);
    };
    // The window around view `i` of the stimulus at `level`. Levels are rounded
    // to 0.001: the display's integer codes make the brightness a step function
    // of the level, on which the root finder would otherwise bisect down to
    // 1e-14 with a render per step; once its bracket is inside one 0.001 cell
    // every further call is a cache hit. So the true value is resolved to
    // ±0.001 (log10 units with level_scale = "log10").
    auto window_at = [&](double level, std::size_t i) {
        const p::Stimulus stim = stimulus_at(std::round(level * 1000.0) / 1000.0);
        const std::vector<std::string> lights = judged_lights(stim, stim.views[i].frame);
        std::size_t j = 0;
        for (std::size_t k = 0; k < i; ++k) j += stim.views[k].frame == stim.views[i].frame ? 1 : 0;
        return renderer.views(stim.frames[stim.views[i].frame], lights)->windows[j];
    };
    const double mid = 0.5 * (lo + hi);
    // Where the model's brightness of the level stimulus stands against the
    // other's (log10), to say why no crossing was found.
    auto no_crossing = [&](const LightWindow& other, std::size_t view) {
        const double r = params.window_radius_deg, e = params.exponent;
        const double b_other = std::log10(p::brightness(other.image, other.light_px, r, e));
        const LightWindow at_lo = window_at(lo, view), at_hi = window_at(hi, view);
        const double d_lo = std::log10(p::brightness(at_lo.image, at_lo.light_px, r, e)) - b_other;
        const double d_hi = std::log10(p::brightness(at_hi.image, at_hi.light_px, r, e)) - b_other;
        return fmt::format(
            "none in [{:.4g}, {:.4g}]: the level stimulus is {:+.3f} log10 brightness from the other "
            "at {:.4g} and {:+.3f} at {:.4g}{}",
            lo, hi, d_lo, lo, d_hi, hi,
            std::abs(d_hi - d_lo) < 1e-6 ? " (unchanged by the level: the display clips it)" : "");
    };
    try {
        if (c.task == p::Task::YesNo) {
            const LightWindow w = window_at(mid, 0);
            const LightWindow at_lo = window_at(lo, 0), at_hi = window_at(hi, 0);
            if ((p::model_p_yes(params, p::View{&at_lo.image, at_lo.light_px}) - *p_yes) *
                    (p::model_p_yes(params, p::View{&at_hi.image, at_hi.light_px}) - *p_yes) >
                0)
                return fmt::format("none in [{:.4g}, {:.4g}]: P(yes) does not cross {:.3f} there", lo, hi, *p_yes);
            value = p::true_threshold([&](double level) { return window_at(level, 0).image; }, w.light_px, *p_yes, lo,
                                      hi, params);
            return {};
        }
        const p::Stimulus probe = stimulus_at(mid);
        std::size_t level_view = probe.views.size(), other_view = probe.views.size();
        for (std::size_t i = 0; i < probe.views.size(); ++i)
            (probe.views[i].role == c.level_on ? level_view : other_view) = i;
        if (level_view >= probe.views.size() || other_view >= probe.views.size())
            return "the stimulus has no two views to compare";
        // Yes means "chose the level stimulus" when the choice and level_on name the same role.
        const double p_level = c.yes_means_level() ? *p_yes : 1.0 - *p_yes;
        const LightWindow level_w = window_at(mid, level_view);
        const LightWindow other_w = window_at(mid, other_view);
        {
            const LightWindow at_lo = window_at(lo, level_view), at_hi = window_at(hi, level_view);
            const double p_lo = p::model_p_first(params, p::View{&at_lo.image, at_lo.light_px},
                                                 p::View{&other_w.image, other_w.light_px});
            const double p_hi = p::model_p_first(params, p::View{&at_hi.image, at_hi.light_px},
                                                 p::View{&other_w.image, other_w.light_px});
            if ((p_lo - p_level) * (p_hi - p_level) > 0) return no_crossing(other_w, level_view);
        }
        value = p::true_matching_level([&](double level) { return window_at(level, level_view).image; },
                                       level_w.light_px, other_w.image, other_w.light_px, p_level, lo, hi, params);
        return {};
    } catch (const std::exception& e) {
        return fmt::format("not found in [{:.4g}, {:.4g}]: {}", lo, hi, e.what());
    }
}

namespace {

void print_summary(const p::Protocol& protocol, const p::Schedule& schedule, StimulusRenderer* renderer,
                   const SessionObserver& observer, bool compute_true) {
    struct Row {
        std::vector<double> values;
        std::string method;
        std::size_t tracks = 0, finished = 0, responses = 0;
    };
    std::map<std::string, Row> rows;
    for (const p::TrackResult& r : schedule.results()) {
        Row& row = rows[r.condition_id];
        ++row.tracks;
        row.finished += r.finished ? 1 : 0;
        row.responses += r.responses;
        if (std::isfinite(r.estimate.value)) row.values.push_back(r.estimate.value);
        if (row.method.empty()) row.method = r.estimate.method;
    }
    std::printf("\nper condition (levels in the procedure's units):\n");
    for (const p::Block& b : protocol.blocks) {
        for (const p::Condition& c : b.conditions) {
            const auto it = rows.find(c.name);
            if (it == rows.end()) continue;
            const Row& row = it->second;
            std::string est = "no estimate";
            if (!row.values.empty()) {
                const double mean =
                    std::accumulate(row.values.begin(), row.values.end(), 0.0) / static_cast<double>(row.values.size());
                std::string each;
                for (const double v : row.values) each += fmt::format("{}{:.3f}", each.empty() ? "" : ", ", v);
                est = fmt::format("{:.3f}", mean);
                if (row.values.size() > 1) est += fmt::format(" (tracks {})", each);
            }
            std::string truth;
            if (compute_true && renderer) {
                double v = 0.0;
                const std::string why = true_value(*renderer, protocol, c, observer.params(), v);
                if (why.empty()) {
                    const std::optional<double> pt = c.procedure.target_p_yes();
                    const bool pse = c.task != p::Task::YesNo && pt && *pt == 0.5;
                    truth = fmt::format("; model's true {} {:.3f}",
                                        pse ? "PSE" : fmt::format("level at P = {:.3f}", *pt), v);
                    if (!row.values.empty())
                        truth += fmt::format(" (estimate − true = {:+.3f})",
                                             std::accumulate(row.values.begin(), row.values.end(), 0.0) /
                                                     static_cast<double>(row.values.size()) -
                                                 v);
                } else {
                    truth = "; true value: " + why;
                }
            }
            std::printf("  %-24s %s [%s; %zu of %zu tracks finished, %zu responses]%s\n", c.name.c_str(), est.c_str(),
                        row.method.c_str(), row.finished, row.tracks, row.responses, truth.c_str());
        }
    }
}

}  // namespace

// ---------------------------------------------------------------------------

/// The study file opened read-only when it has content: checked by the store
/// (an atonlab study, undamaged, no newer than this build) before anything is
/// written. std::nullopt for a file that does not exist yet or is empty (a new
/// study; created when the session begins). A file of an older schema is
/// migrated first (a reader cannot migrate it), the one write made before the
/// session's other checks.
std::optional<st::Store> read_existing_study(const std::string& db, const st::StoreOptions& options) {
    std::error_code ec;
    const std::filesystem::path path(db);
    if (!std::filesystem::exists(path, ec)) return std::nullopt;
    if (std::filesystem::is_regular_file(path, ec) && std::filesystem::file_size(path, ec) == 0 &&
        !std::filesystem::exists(db + "-wal", ec))
        return std::nullopt;
    // The session will write to it: a write-protected file is refused now, with
    // the store's sentence for it (opening it for writing finds it read-only
    // before anything is written).
    if (::access(path.c_str(), W_OK) != 0) st::Store::open_existing(path, options);
    try {
        return st::Store::open_read_only(path, options);
    } catch (const st::StoreError& e) {
        if (e.kind() != st::StoreErrc::older_schema) throw;
    }
    { st::Store migrate = st::Store::create_or_open(path, options); }
    return st::Store::open_read_only(path, options);
}

int run_session(const RunOptions& o) {
    // Installed first: a signal during the setup ends the session before its first trial.
    StopSignals signals;
    // --- Options that need no file.
    // A person answers at the screen; the model or a script answer anywhere.
    const bool person = !o.model_observer && o.script.empty();
    if (person && o.headless)
        throw InputError(SourceLocation{"--headless", 0, 0, ""},
                         "a headless run has no screen for a person: give --model-observer or --script FILE with "
                         "--headless, or leave --headless out to run full screen.");
    if (person && o.observer.empty())
        throw InputError(SourceLocation{"--observer", 0, 0, ""},
                         "give the observer's code with --observer ID (or answer with --model-observer or --script "
                         "FILE).");
    if (o.inject_stall_frames > 0 && !o.inject_stall_at_trial)
        throw InputError(SourceLocation{"--inject-stall-frames", 0, 0, ""},
                         "name the trial to stall with --inject-stall-at-trial N.");
    if (o.capture_trial && o.capture_dir.empty())
        throw InputError(SourceLocation{"--capture-trial", 0, 0, ""}, "give the folder with --capture-dir DIR.");
    const std::string code = o.model_observer ? std::string("model") : (o.observer.empty() ? "script" : o.observer);
    if (!valid_observer_code(code))
        throw InputError(SourceLocation{"--observer", 0, 0, ""},
                         fmt::format("the observer code \"{}\" must be 1 to 32 letters, digits, '_' or '-' (a code, "
                                     "never a name).",
                                     code));

    // --- Load and validate everything before the first trial.
    p::Protocol protocol = p::load_protocol(o.protocol);
    std::optional<p::ScriptedObserver> script;
    if (!o.script.empty()) script = p::ScriptedObserver::load(o.script);
    // The protocol file's text, with its conditions files (if any) appended as
    // comments: the study stores the whole design (protocol_file.h).
    const std::string protocol_text = p::with_conditions_files(read_text(o.protocol, "protocol file"), o.protocol);
    const std::string protocol_sha = st::sha256_hex(protocol_text);
    const std::filesystem::path scene_file = protocol.scene;
    const std::string scene_text = read_text(scene_file, "scene template");
    // The template alone first: its own errors name its file and line.
    s::Scene display_scene;
    {
        std::vector<s::SceneOverride> display;
        for (const std::string& d : protocol.display_overrides()) display.push_back(parsed_override(protocol, d));
        display_scene = s::parse_scene(scene_text, scene_file.string(), display);
    }
    validate_conditions(protocol, scene_text, scene_file);
    const double interval_s = protocol.timing.stimulus_s;

    // --- The study file, read-only: checked (a study, undamaged, not newer:
    // exit 4) and read for the session to continue and the display's
    // calibration. Nothing is created or written until every check that can
    // refuse the session has passed (docs/running.md, "Before the session").
    st::StoreOptions store_options;
    store_options.max_size_bytes = o.db_max_bytes;
    std::optional<st::Store> existing = read_existing_study(o.db, store_options);
    if (!existing && (o.resume || o.resume_last))
        throw InputError(SourceLocation{o.resume ? "--resume" : "--resume-last", 0, 0, ""},
                         fmt::format("{} does not exist (or is empty): there is no session to continue.", o.db));
    std::uint64_t seed = o.seed.value_or(protocol.seed);
    st::SessionId session{};
    std::vector<st::TrialRecord> logged;
    bool resumed = false;
    if (o.resume || o.resume_last) {
        st::SessionRecord rec;
        if (o.resume) {
            try {
                rec = existing->session(st::SessionId{*o.resume});
            } catch (const st::StoreError& e) {
                if (e.kind() != st::StoreErrc::not_found) throw;
                throw InputError(SourceLocation{"--resume", 0, 0, ""},
                                 fmt::format("{} has no session {}.", o.db, *o.resume));
            }
        } else {
            std::optional<st::SessionRecord> last;
            for (const st::SessionRecord& r : existing->sessions())
                if (r.protocol_sha256 == protocol_sha && r.observer_code == code &&
                    r.status != st::SessionStatus::completed && (!last || r.id > last->id))
                    last = r;
            if (!last)
                throw InputError(SourceLocation{"--resume-last", 0, 0, ""},
                                 fmt::format("{} has no unfinished session of {} for observer \"{}\" to continue.",
                                             o.db, o.protocol, code));
            rec = *last;
        }
        if (rec.status == st::SessionStatus::completed)
            throw InputError(
                SourceLocation{"--resume", 0, 0, ""},
                fmt::format("session {} in {} is completed; there is nothing to continue.", rec.id.value, o.db));
        if (rec.protocol_sha256 != protocol_sha)
            throw InputError(SourceLocation{o.protocol, 0, 0, ""},
                             fmt::format("session {} in {} ran a different text of this protocol (SHA-256 {}…); a "
                                         "session continues only with the protocol it began with.",
                                         rec.id.value, o.db, rec.protocol_sha256.substr(0, 12)));
        if (rec.observer_code != code)
            throw InputError(SourceLocation{"--observer", 0, 0, ""},
                             fmt::format("session {} in {} is observer \"{}\"'s, not \"{}\".", rec.id.value, o.db,
                                         rec.observer_code, code));
        if (o.seed && *o.seed != rec.seed)
            throw InputError(
                SourceLocation{"--seed", 0, 0, ""},
                fmt::format("session {} in {} runs with seed {}, not {}.", rec.id.value, o.db, rec.seed, *o.seed));
        seed = rec.seed;
        session = rec.id;
        logged = existing->resume_point(session).trials;
        resumed = true;
    }

    std::uint64_t observer_seed = o.observer_seed.value_or(p::derive_seed(seed, 0x6f62736572766572ULL));  // "observer"
    if (resumed) {
        if (const auto stored = logged_observer_seed(logged)) {
            if (o.observer_seed && *o.observer_seed != *stored)
                throw InputError(SourceLocation{"--observer-seed", 0, 0, ""},
                                 fmt::format("session {} in {} runs with observer seed {}, not {}.", session.value,
                                             o.db, *stored, *o.observer_seed));
            observer_seed = *stored;
        }
    }
    SessionObserver observer(o, observer_seed, std::move(script));

    // --- Replay the logged responses: the schedule's state, checked step by step
    // against what was logged, and where the observer stands. A trial stored as
    // "missed" (repeated: its stimulus missed a refresh) or "timeout" was never
    // shown to the procedure: it is checked, then skipped, as the live session
    // skipped it and showed the same proposal again.
    std::vector<p::Response> responses;
    std::vector<std::pair<p::ScheduledTrial, std::size_t>> open_match;  // an adjustment match the log stops inside
    double clock_s = 0.0;                                               // the session clock at the last stored answer
    bool previous_ended_trial = true;                                   // the next trial gets the inter-trial fixation
    p::Schedule check(protocol, seed);
    {
        for (std::size_t row = 0; row < logged.size(); ++row) {
            const st::TrialRecord& t = logged[row];
            const std::optional<p::ScheduledTrial> next = check.next();
            const bool uncounted = is_uncounted(t.response);
            const std::optional<p::Response> r = uncounted ? std::nullopt : p::parse_response_word(t.response);
            if (!next || (!uncounted && !r) || next->condition_id != t.condition_id ||
                next->procedure_id != t.procedure_id || next->proposal.level != t.level ||
                next->proposal.test_on_left != t.test_on_left)
                throw InputError(
                    SourceLocation{o.db, 0, 0, ""},
                    fmt::format("trial {} of session {} ({} at level {}, answered \"{}\") is not what "
                                "this protocol and seed propose at that point ({}); the session cannot "
                                "be continued.",
                                t.trial_index, session.value, t.condition_id, t.level, t.response,
                                next ? fmt::format("{} at level {}", next->condition_id, next->proposal.level)
                                     : std::string("the schedule has ended")));
            observer.skip(next->task, next->stimulus.adjusted_view);
            clock_s = t.onset_time_s + t.response_time_s;
            if (uncounted) {
                previous_ended_trial = true;
                continue;
            }
            // Counted: r holds the answer (checked above). value_or keeps GCC's
            // -Wmaybe-uninitialized from misreading the optional's payload.
            const p::Response answer = r.value_or(p::Response::No);
            if (next->task == p::Task::Adjust) {
                if (!open_match.empty() && (open_match.front().first.procedure_id != next->procedure_id ||
                                            open_match.front().first.proposal.trial != next->proposal.trial))
                    open_match.clear();
                open_match.emplace_back(*next, row);
                if (answer == p::Response::Confirm) open_match.clear();
            } else {
                open_match.clear();
            }
            previous_ended_trial = next->task != p::Task::Adjust || answer == p::Response::Confirm;
            check.record(answer);
            responses.push_back(answer);
        }
    }
    p::Schedule schedule = p::Schedule::replay(protocol, seed, responses);
    if (schedule.state() != check.state())
        throw std::logic_error("Schedule::replay disagrees with the step-by-step replay of the same responses");

    // --- The display's calibration (calibration_policy.h): warnings before the
    // session; a measured calibration's model encodes every frame.
    // The lab's display-profile file (profile_location.h); a resumed session keeps its own calibration.
    const std::optional<st::Profiles> profiles = open_profiles_for_run(o.profiles, o.no_profiles || resumed);
    const SessionCalibration calibration = session_calibration(
        existing ? &*existing : nullptr, protocol.display,
        resumed ? existing->session(session).calibration : std::nullopt, utc_today(), o.db,
        profiles ? RunProfiles{&profiles->displays(), profiles->path().string()} : RunProfiles{});
    print_calibration_warnings(calibration, o.quiet);
    if (calibration.display) apply_display_model(display_scene, *calibration.display);

    // --- GL (and the screen, measured) before the session: a machine without GL,
    // or a display whose timing is refused, leaves no empty session behind.
    std::optional<Font> font;
    if (!o.headless)
        font = Font::load(o.font.empty() ? std::filesystem::path(kDefaultFontFile) : std::filesystem::path(o.font));
    std::unique_ptr<gl::Context> context;
    std::unique_ptr<Presenter> presenter;
    ScreenPresenter* screen = nullptr;
    if (o.headless) {
        context = gl::create_headless_context();
        presenter = std::make_unique<VirtualPresenter>(protocol.timing.refresh_hz.value_or(60.0),
                                                       protocol.display.width_px, protocol.display.height_px);
    } else {
        presenter = open_screen(o, protocol, display_scene, screen);
    }
    StimulusRenderer renderer(scene_text, scene_file, observer.params().window_radius_deg, interval_s);
    if (calibration.display) renderer.use_display_model(*calibration.display);
    // --- What this display will show of every condition (displayability.h):
    // a level range that cannot produce a match is refused, before anything is written.
    const Displayability displayability = check_displayability(renderer, protocol);
    if (!o.quiet) {
        std::printf("%s", displayability_table(displayability).c_str());
        std::fflush(stdout);
    }
    if (!displayability.displayable()) {
        std::fprintf(stderr, "atonlab: %s\n", displayability_refusal(displayability, o.protocol).c_str());
        if (!o.allow_undisplayable) {
            std::fprintf(stderr,
                         "atonlab: nothing was written; change the protocol as said, try it with `atonlab check %s`, "
                         "or run anyway with --allow-undisplayable (recorded with the session).\n",
                         o.protocol.c_str());
            return 2;
        }
        std::fprintf(stderr, "atonlab: warning: running anyway (--allow-undisplayable; recorded with the session)\n");
    }

    // --- Every check has passed: open the study file for writing (creating it
    // if it does not exist), then begin or reopen the session.
    existing.reset();
    st::Store store = st::Store::create_or_open(o.db, store_options);
    if (resumed) {
        const st::ResumePoint rp = store.resume_session(session);
        if (static_cast<std::size_t>(rp.next_trial_index) != logged.size())
            throw st::StoreError(st::StoreErrc::busy, o.db,
                                 fmt::format("{}: session {} gained trials while it was being resumed; another "
                                             "process is running it.",
                                             o.db, session.value));
    } else {
        st::SessionStart start;
        start.observer_code = code;
        start.protocol_text = protocol_text;
        start.protocol_name = std::filesystem::path(o.protocol).filename().string();
        start.seed = seed;
        start.displayability_json = displayability_json(displayability, o.allow_undisplayable);
        start.calibration = calibration.calibration     ? *calibration.calibration
                            : calibration.from_profiles ? copy_into_study(store, *calibration.from_profiles)
                                                        : record_display(store, display_scene, scene_file);
        session = store.begin_session(start);
    }
    // From here on a StoreError names the session to continue.
    try {
        std::set<std::string> snapshotted;
        if (resumed) {
            for (const p::Block& b : protocol.blocks)
                for (const p::Condition& c : b.conditions)
                    if (store.get_snapshot(session, c.name)) snapshotted.insert(c.name);
        }
        // A model observer inside an adjustment match when the log stopped:
        // show it that match's steps again (they are in the frame cache after
        // the first), so that it continues from the same state.
        if (observer.model() && !open_match.empty()) {
            for (const auto& [step, row] : open_match) {
                const p::Answer a = observer.answer(step, &renderer);
                const std::string_view logged_word = logged[row].response;
                if (p::response_word(a.response) != logged_word)
                    std::fprintf(stderr,
                                 "atonlab: warning: replaying step %zu of the open adjustment, the model observer "
                                 "answered \"%s\" where the log has \"%s\" (has the scene file changed?)\n",
                                 step.step, std::string(p::response_word(a.response)).c_str(),
                                 std::string(logged_word).c_str());
            }
        }

        Progress progress(o.quiet, o.progress_every, schedule.max_trials());
        if (!o.quiet) {
            std::printf("atonlab run: %s, observer \"%s\", seed %llu: session %lld in %s (%s)\n", protocol.name.c_str(),
                        code.c_str(), static_cast<unsigned long long>(seed), static_cast<long long>(session.value),
                        o.db.c_str(), resumed ? fmt::format("resumed after trial {}", logged.size()).c_str() : "new");
            std::fflush(stdout);
        }

        // --- What is shown: the screens and the trials, on screen or on the
        // virtual display (session_display.h). The session clock goes on from
        // the last stored answer.
        SessionDisplayOptions display_options;
        display_options.person = person;
        display_options.trace = o.trace;
        display_options.font = font ? &*font : nullptr;
        display_options.screen = screen;
        SessionDisplay display(*presenter, renderer, protocol, display_scene, display_options, clock_s);
        // On screen a signal ends the wait (or the stimulus) at once; headless a
        // trial takes no time to show, and is finished and stored first.
        if (presenter->on_screen()) presenter->set_interrupt([] { return g_stop_signal != 0; });
        if (screen && !o.quiet) {
            const RefreshEstimate& r = screen->refresh();
            std::printf(
                "screen: monitor %d \"%s\", %d×%d, %d bits per channel, mode %s; measured %.4f ms ± %.4f ms "
                "(SD) over %d flips (%d rejected) = %.3f Hz\n  flips timed by %s\n  %s\n",
                o.monitor, screen->monitor_name().c_str(), screen->width_px(), screen->height_px(),
                screen->framebuffer_bits(),
                screen->mode_hz() > 0 ? fmt::format("{} Hz", screen->mode_hz()).c_str() : "without a rate",
                r.period_s * 1e3, r.sd_s * 1e3, r.valid, r.rejected, r.hz(), screen->timing_method().c_str(),
                display.luminance_note().c_str());
            std::fflush(stdout);
        }

        const std::size_t runs = schedule.block_runs().size();
        const std::optional<std::size_t> bound = schedule.max_trials();
        auto progress_text = [&](const p::ScheduledTrial& t, std::size_t row) {
            return fmt::format("block {} of {}, trial {} of {}{}", t.run + 1, runs, row + 1, bound ? "at most " : "",
                               bound ? fmt::format("{}", *bound) : std::string("?"));
        };
        double snapshot_s = 0.0, store_s = 0.0;
        bool first_trial_here = true;
        bool observer_quit = false;
        std::size_t run_started = runs;   // the block run whose break, instructions and adaptation were shown
        std::size_t row = logged.size();  // the next trial_index: every stored trial, counted or not
        if (!display.text_screen(protocol.screens.instructions, resumed ? "Continuing the session." : "",
                                 "instructions"))
            observer_quit = g_stop_signal == 0;
        while (!observer_quit && !schedule.finished() && g_stop_signal == 0) {
            const p::ScheduledTrial t = *schedule.next();
            const p::Condition& c = protocol.blocks[t.block].conditions[t.condition];
            const p::Block& block = protocol.blocks[t.block];
            if (t.starts_run || first_trial_here) progress.block(protocol, t, runs, presenter->on_screen());
            // Before a block run: the break, the block's instructions, the
            // adaptation. Headless the simulated clock adapts only where a run
            // starts (as an uninterrupted session would); on screen a resumed
            // session adapts again, the observer having been away.
            if ((t.starts_run || (first_trial_here && presenter->on_screen())) && run_started != t.run) {
                run_started = t.run;  // once per run: a trial shown again after a pause does not start it again
                bool go_on = true;
                if (t.starts_run && t.run > 0)
                    go_on = display.text_screen(protocol.screens.between, progress_text(t, row), "break");
                go_on = go_on && display.text_screen(block.instructions, "", "block instructions");
                go_on = go_on && display.adapt(c, block.adaptation_s);
                if (!go_on) {
                    observer_quit = g_stop_signal == 0;
                    break;
                }
                previous_ended_trial = true;
            }
            first_trial_here = false;
            if (!snapshotted.count(c.name)) {
                const auto started = std::chrono::steady_clock::now();
                store.put_snapshot(session, c.name, snapshot_exr(renderer, protocol, c, t, session.value));
                snapshotted.insert(c.name);
                snapshot_s += seconds_since(started);
            }
            std::optional<p::Answer> answer;
            if (!person) {
                try {
                    answer = observer.answer(t, &renderer);
                } catch (const InputError& e) {
                    // The script ran out or does not fit: what is stored stays, and the session can go on.
                    throw InputError(e.where().value_or(SourceLocation{}),
                                     fmt::format("{} Session {} stays open: continue it with --resume {}.", e.message(),
                                                 session.value, session.value));
                }
            }
            TrialHooks hooks;
            if (o.inject_stall_at_trial && static_cast<std::size_t>(*o.inject_stall_at_trial) == row)
                hooks.stall_frames = o.inject_stall_frames;
            if (o.capture_trial && static_cast<std::size_t>(*o.capture_trial) == row) {
                hooks.before_frame_onset = [&, r = row](std::size_t f) {
                    capture_frame(o, screen, renderer, t, r, f, false);
                };
                hooks.after_frame_onset = [&, r = row](std::size_t f) {
                    capture_frame(o, screen, renderer, t, r, f, true);
                };
            }
            const TrialShown shown = display.present(t, c, previous_ended_trial, answer, hooks);
            if (shown.end == TrialEnd::interrupted) break;
            if (shown.end == TrialEnd::paused) {
                // Nothing of the interrupted trial is stored: it is shown again
                // (after a fixation) unless the observer ends the session here.
                if (display.confirm_quit(progress_text(t, row))) {
                    observer_quit = g_stop_signal == 0;
                    break;
                }
                previous_ended_trial = true;
                continue;
            }
            // A trial the procedure does not see: a timeout, or (repeat_missed)
            // a stimulus that missed a refresh. Stored, then shown again.
            const bool repeat_missed = shown.end == TrialEnd::answered && shown.missed_deadline &&
                                       protocol.timing.repeat_missed && t.task != p::Task::Adjust;
            const bool counted = shown.end == TrialEnd::answered && !repeat_missed;
            if (counted) {
                try {
                    schedule.record(*shown.response);
                } catch (const p::ProcedureError& e) {
                    throw InputError(SourceLocation{o.script.empty() ? o.protocol : o.script, 0, 0, ""},
                                     fmt::format("trial {} ({}) cannot take the answer \"{}\": {}", t.step + 1,
                                                 t.condition_id, p::response_word(*shown.response), e.message()));
                }
            }
            std::vector<double> frame_times;
            std::vector<std::string> view_glares(t.stimulus.views.size());
            for (std::size_t f = 0; f < t.stimulus.frames.size(); ++f) {
                const s::Scene sc = renderer.scene(t.stimulus.frames[f].overrides);
                frame_times.push_back(brightest_moment_s(sc, judged_lights(t.stimulus, f), interval_s));
                for (std::size_t v = 0; v < t.stimulus.views.size(); ++v)
                    if (t.stimulus.views[v].frame == f) view_glares[v] = view_glare(sc, t.stimulus.views[v].light);
            }
            st::TrialRecord tr;
            tr.trial_index = static_cast<std::int64_t>(row);
            tr.block = static_cast<int>(t.block);
            tr.condition_id = t.condition_id;
            tr.procedure_id = t.procedure_id;
            tr.level = t.proposal.level;
            tr.test_on_left = t.proposal.test_on_left;
            tr.stimulus_json = stimulus_json(protocol, c, t, frame_times, shown.timing_json, view_glares);
            tr.response = counted ? std::string(p::response_word(*shown.response))
                                  : std::string(shown.end == TrialEnd::timeout ? "timeout" : "missed");
            if (t.task == p::Task::Adjust) tr.response_value = t.stimulus.scene_value;
            tr.response_time_s = std::max(0.0, shown.response_time_s);  // onset to answer
            tr.onset_time_s = shown.onset_s;
            tr.dropped_frames = shown.dropped_frames;
            tr.missed_deadline = shown.missed_deadline;
            tr.procedure_state_json =
                state_json(schedule, observer, shown.answer_after_offset_s, shown.response, shown.input, t.step);
            const auto storing = std::chrono::steady_clock::now();
            store.record_trial(session, tr);  // durable before the next stimulus
            store_s += seconds_since(storing);
            ++row;
            previous_ended_trial = !counted || t.task != p::Task::Adjust || *shown.response == p::Response::Confirm;
            progress.trial(protocol, t, row);
        }
        progress.end_line();
        const int stop = g_stop_signal;
        const bool completed = schedule.finished();
        store.finish_session(session, completed ? st::SessionStatus::completed : st::SessionStatus::quit);
        if (completed && stop == 0) display.text_screen(protocol.screens.end, "", "end");
        signals.restore();

        const std::size_t total = schedule.history().size();
        if (!o.quiet) {
            std::printf("%s after %zu trials (%zu in this run, %s)\n",
                        completed       ? "completed"
                        : observer_quit ? "ended by the observer"
                                        : fmt::format("stopped by signal {}", stop).c_str(),
                        total, progress.done_here(), clock_text(progress.seconds()).c_str());
            if (row != total)
                std::printf("  %zu trials stored in all: %zu shown again (missed refreshes or timeouts)\n", row,
                            row - total);
            std::printf(
                "  %zu frames rendered for %zu shown (%.1f s, snapshots included); snapshots %.1f s; "
                "study file %.1f s\n",
                renderer.frames_rendered(), renderer.frames_requested(), renderer.render_seconds(), snapshot_s,
                store_s);
            const std::size_t frames_before = renderer.frames_rendered();
            const auto summarising = std::chrono::steady_clock::now();
            const bool with_true = completed && observer.model() && o.true_pse;
            print_summary(protocol, schedule, &renderer, observer, with_true);
            if (with_true)
                std::printf("  (the true values took %zu more frames, %.1f s; --no-true-pse skips them)\n",
                            renderer.frames_rendered() - frames_before, seconds_since(summarising));
            std::printf("\nstudy file: %s, session %lld (%s)%s\n", o.db.c_str(), static_cast<long long>(session.value),
                        completed ? "completed" : "quit",
                        completed ? "" : fmt::format("; continue with --resume {}", session.value).c_str());
        }
        if (observer_quit && !completed) return 6;
        return completed ? 0 : 128 + stop;
    } catch (const st::StoreError& e) {
        throw st::StoreError(
            e.kind(), e.file(),
            fmt::format("{}; session {} stays open: continue it with --resume {} (or --resume-last) once the "
                        "cause is fixed",
                        e.what(), session.value, session.value),
            e.sqlite_code());
    }
}

}  // namespace atonlab::runner
