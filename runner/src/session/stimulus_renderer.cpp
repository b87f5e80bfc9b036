// StimulusRenderer (stimulus_renderer.h): frames rendered through the display
// pipeline, cached, and cut into the windows the observer looks at.
#include "atonlab/runner/session/stimulus_renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <glm/common.hpp>
#include <glm/vector_relational.hpp>
#include <map>
#include <numbers>

#include "atonlab/common/input_error.h"
#include "atonlab/display/tonemap.h"
#include "atonlab/runner/session/scene_queries.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/scene_file.h"
#include "calibrate/calibration_policy.h"
#include "session/progress.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;

namespace {

/// An override list as one cache key (each "key=value" ends in a newline).
/// Where an override was written does not change the scene it makes.
std::string overrides_key(const std::vector<SceneOverride>& overrides) {
    std::string key;
    for (const SceneOverride& o : overrides) (key += o.text()) += '\n';
    return key;
}

std::string cache_key(const p::Frame& frame, const std::vector<std::string>& lights) {
    std::string key = overrides_key(frame.overrides);
    key += '\x1f';
    for (const std::string& l : lights) (key += l) += '\n';
    return key;
}

/// The codes of pixel (x, y), row 0 at the top.
glm::ivec3 code_at(const s::EncodedImage& codes, int x, int y) {
    const std::size_t i =
        (static_cast<std::size_t>(y) * static_cast<std::size_t>(codes.width) + static_cast<std::size_t>(x)) * 3;
    return {codes.rgb[i], codes.rgb[i + 1], codes.rgb[i + 2]};
}

/// Calls f(i, code) for each of the n x n pixels from (x0, y0) (row 0 at the top)
/// that lies on the screen, i the pixel's index in the window (row-major).
template <class F>
void for_each_window_code(const s::EncodedImage& codes, int x0, int y0, int n, F&& f) {
    for (int v = 0; v < n; ++v) {
        const int y = y0 + v;
        if (y < 0 || y >= codes.height) continue;
        for (int u = 0; u < n; ++u) {
            const int x = x0 + u;
            if (x < 0 || x >= codes.width) continue;
            f(static_cast<std::size_t>(v) * static_cast<std::size_t>(n) + static_cast<std::size_t>(u),
              code_at(codes, x, y));
        }
    }
}

/// The luminance (cd/m²) the screen emits at the n x n pixels from (x0, y0)
/// (row 0 at the top) for the codes given: the display model's luminance,
/// memoised per distinct code (a frame has few). Pixels beyond the screen are 0.
std::vector<float> emitted_window(const s::EncodedImage& codes, const display::DisplayModel& model, int x0, int y0,
                                  int n) {
    std::map<std::uint64_t, float> emitted;
    std::vector<float> out(static_cast<std::size_t>(n) * static_cast<std::size_t>(n), 0.0f);
    for_each_window_code(codes, x0, y0, n, [&](std::size_t i, const glm::ivec3& code) {
        const std::uint64_t k = (static_cast<std::uint64_t>(code.r) << 32) |
                                (static_cast<std::uint64_t>(code.g) << 16) | static_cast<std::uint64_t>(code.b);
        auto [it, fresh] = emitted.try_emplace(k, 0.0f);
        if (fresh) it->second = static_cast<float>(display::displayed_luminance_cd_m2(model, code, codes.bits));
        out[i] = it->second;
    });
    return out;
}

/// The codes of the n x n pixels from (x0, y0) (row 0 at the top), R, G, B
/// per pixel; 0 beyond the screen.
std::vector<std::uint16_t> codes_window(const s::EncodedImage& codes, int x0, int y0, int n) {
    std::vector<std::uint16_t> out(static_cast<std::size_t>(n) * static_cast<std::size_t>(n) * 3, 0);
    for_each_window_code(codes, x0, y0, n, [&](std::size_t i, const glm::ivec3& code) {
        for (int ch = 0; ch < 3; ++ch) out[i * 3 + static_cast<std::size_t>(ch)] = static_cast<std::uint16_t>(code[ch]);
    });
    return out;
}

/// The codes of window `w` (n x n pixels from (x0, y0), row 0 at the top)
/// against the same pixels of `off` (the judged lights off, the same dither
/// frame; null: none, then the frame is its own background), and the
/// displayed luminance of one code step at the pixel where the light adds most
/// (displayability.h, the display's resolution there). `w.image` holds the
/// window's displayed luminance (and, with `off`, its background).
void summarise_codes(const s::EncodedImage& codes, const s::EncodedImage* off, const display::DisplayModel& model,
                     int x0, int y0, int n, LightWindow& w) {
    w.white_code = (1 << codes.bits) - 1;
    const s::EncodedImage& bg = off ? *off : codes;
    for (int y = std::max(y0, 0); y < std::min(y0 + n, codes.height); ++y)
        for (int x = std::max(x0, 0); x < std::min(x0 + n, codes.width); ++x) {
            const glm::ivec3 on = code_at(codes, x, y);
            const glm::ivec3 dark = code_at(bg, x, y);
            for (int ch = 0; ch < 3; ++ch) {
                w.peak_code = std::max(w.peak_code, on[ch]);
                w.clipped = w.clipped || (on[ch] == w.white_code && dark[ch] < w.white_code);
            }
        }
    // The pixel where the light adds most; where it adds nothing, the one under its centre.
    glm::ivec2 at = glm::clamp(glm::ivec2(glm::floor(w.light_px)), glm::ivec2(0), glm::ivec2(n - 1));
    float most = 0.0f;
    if (w.image.has_background())
        for (int v = 0; v < n; ++v)
            for (int u = 0; u < n; ++u) {
                const std::size_t i =
                    static_cast<std::size_t>(v) * static_cast<std::size_t>(n) + static_cast<std::size_t>(u);
                const float added = w.image.luminance_cd_m2[i] - w.image.background_cd_m2[i];
                if (added > most) {
                    most = added;
                    at = {u, v};
                }
            }
    w.brightest_px = at;
    const int x = std::clamp(x0 + at.x, 0, codes.width - 1);
    const int y = std::clamp(y0 + at.y, 0, codes.height - 1);
    const glm::ivec3 on = code_at(codes, x, y);
    w.background_code = code_at(bg, x, y);
    w.background_cd_m2 = display::displayed_luminance_cd_m2(model, w.background_code, codes.bits);
    // One code step of the channels the light raises there (of all three
    // where it raises none), each as far as the display's white allows.
    glm::ivec3 step = glm::ivec3(glm::greaterThan(on, w.background_code));
    if (step == glm::ivec3(0)) step = glm::ivec3(1);
    const glm::ivec3 up = glm::min(w.background_code + step, glm::ivec3(w.white_code));
    w.code_step_cd_m2 = display::displayed_luminance_cd_m2(model, up, codes.bits) - w.background_cd_m2;
}

}  // namespace

StimulusRenderer::StimulusRenderer(s::SceneTemplate scene_template, double window_radius_deg, double interval_s,
                                   std::size_t cache_frames)
    : template_(std::move(scene_template)),
      window_radius_deg_(window_radius_deg),
      interval_s_(interval_s),
      views_(cache_frames) {
    // The renderer's frames as they always were: no display skips (the
    // Pipeline's default culls invisible lights and crops billboards).
    pipeline_.set_frame_options(s::FrameOptions{});
}

std::shared_ptr<const s::Scene> StimulusRenderer::scene(const std::vector<SceneOverride>& overrides) const {
    const std::string key = overrides_key(overrides);
    if (const auto* hit = scenes_.find(key)) return *hit;
    s::Scene sc = template_.instantiate(overrides);
    if (display_model_) apply_display_model(sc, *display_model_);
    s::validate_output_settings(sc.output, sc.adaptation_cd_m2);
    ++parsed_;
    return scenes_.put(key, std::make_shared<const s::Scene>(std::move(sc)));
}

std::shared_ptr<const FrameViews> StimulusRenderer::views(const p::Frame& frame,
                                                          const std::vector<std::string>& lights) {
    ++requested_;
    if (const auto* hit = views_.find(cache_key(frame, lights))) return *hit;
    return render(frame, lights, nullptr, nullptr);
}

s::ImageRGBA32F StimulusRenderer::hdr(const p::Frame& frame, const std::vector<std::string>& lights,
                                      double& degrees_per_pixel, std::vector<glm::dvec2>* light_px) {
    s::ImageRGBA32F image;
    const auto views = render(frame, lights, &image, &degrees_per_pixel);
    if (light_px) {
        light_px->clear();
        for (const LightWindow& w : views->windows) light_px->push_back(w.frame_px);
    }
    return image;
}

s::EncodedImage StimulusRenderer::render_codes(const s::Scene& sc, double time_s) {
    encode_scene(sc, time_s);
    return pipeline_.display().read_codes();
}

void StimulusRenderer::encode_scene(const s::Scene& sc, double time_s) {
    // stimuli::Pipeline::render at dither frame 0 with fresh adaptation, so
    // that a frame is a pure function of its overrides (a cached frame, and a
    // resumed session, see exactly what an uninterrupted run saw): dt = 0
    // makes a dynamic scene adopt its own log-average; a fixed one is unaffected.
    pipeline_.display().reset_adaptation();
    pipeline_.render_at(sc, time_s, 0.0, 0);
    ++rendered_;
}

std::shared_ptr<const s::EncodedImage> StimulusRenderer::codes(const p::Frame& frame,
                                                               const std::vector<std::string>& lights) {
    const std::string key = cache_key(frame, lights);
    if (const auto* hit = codes_.find(key)) return *hit;
    const auto started = std::chrono::steady_clock::now();
    const auto scene_ptr = scene(frame.overrides);
    const s::Scene& sc = *scene_ptr;
    auto out = std::make_shared<const s::EncodedImage>(render_codes(sc, brightest_moment_s(sc, lights, interval_s_)));
    render_s_ += seconds_since(started);
    return codes_.put(key, std::move(out));
}

bool StimulusRenderer::animated(const p::Frame& frame) {
    const auto sc = scene(frame.overrides);
    return std::any_of(sc->lights.begin(), sc->lights.end(), [](const s::Light& l) { return l.rhythm_period_s > 0; });
}

void StimulusRenderer::encode(const p::Frame& frame, double time_s) {
    // Parsed once per frame (scene()'s cache), not once per flip.
    encode_scene(*scene(frame.overrides), time_s);
}

void StimulusRenderer::present(int x, int y) const {
    pipeline_.present(x, y);
}

std::vector<std::string> StimulusRenderer::light_names(const std::vector<SceneOverride>& overrides) const {
    std::vector<std::string> names;
    for (const s::Light& l : scene(overrides)->lights) names.push_back(l.name);
    return names;
}

std::vector<SceneOverride> StimulusRenderer::all_off(const std::vector<SceneOverride>& overrides) const {
    const auto sc = scene(overrides);
    std::vector<SceneOverride> off;
    for (const s::Light& l : sc->lights) off.push_back({fmt::format("light.{}.intensity_cd", l.name), "0"});
    for (const s::Disc& d : sc->discs) off.push_back({fmt::format("disc.{}.diameter_deg", d.name), "0"});
    return off;
}

const s::EncodedImage& StimulusRenderer::background_codes(const p::Frame& frame, const std::vector<std::string>& lights,
                                                          double time_s) {
    // The frame with every judged light off, at the same moment: what the
    // screen shows around the lights without them. In a glare / no-glare
    // comparison it is the same for every level of a condition, so a few
    // cached frames serve a whole session.
    p::Frame off = frame;
    const auto on = scene(frame.overrides);
    std::vector<SceneOverride> offs;
    for (const std::string& name : lights)
        if (!name.empty()) offs.push_back(judged_off_override(*on, name));
    // An override the off ones set again (the level's intensity, where the
    // level sets a judged light) is shadowed: left out, the frame with the
    // lights off has the same scene and one cache key for every level, so a
    // decision table's levels share one background render.
    std::erase_if(off.overrides, [&](const SceneOverride& o) {
        return std::any_of(offs.begin(), offs.end(), [&](const SceneOverride& x) { return x.key == o.key; });
    });
    off.overrides.insert(off.overrides.end(), offs.begin(), offs.end());
    const std::string key = fmt::format("{}@{:a}", cache_key(off, {}), time_s);
    if (const auto* hit = background_.find(key)) return *hit;
    return background_.put(key, render_codes(*scene(off.overrides), time_s));
}

std::shared_ptr<const FrameViews> StimulusRenderer::render(const p::Frame& frame,
                                                           const std::vector<std::string>& lights, s::ImageRGBA32F* hdr,
                                                           double* degrees_per_pixel) {
    const auto started = std::chrono::steady_clock::now();
    const auto scene_ptr = scene(frame.overrides);
    const s::Scene& sc = *scene_ptr;
    auto out = std::make_shared<FrameViews>();
    out->time_s = brightest_moment_s(sc, lights, interval_s_);

    const s::EncodedImage codes = render_codes(sc, out->time_s);
    const s::FrameRenderer& rendered = pipeline_.frame();
    const std::vector<s::LightDrawRecord> draws = rendered.read_light_draws();
    const s::CameraProjection proj = rendered.projection();
    // The observer's eye sees the screen's pixels: their solid angles follow
    // from the display's geometry (its viewing distance in pixel pitches), the
    // camera's projection for a veridical camera.
    const double eye_focal_px = sc.display.focal_px();
    const double dpp = 180.0 / std::numbers::pi / eye_focal_px;
    if (hdr) *hdr = rendered.read_hdr();
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
                const glm::dvec3 v =
                    proj.view_from_world((disc ? disc->position_m : sc.lights[index].position_m) - proj.eye_position_m);
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
        w.image.focal_px = eye_focal_px;
        w.image.principal_px = glm::dvec2(0.5 * codes.width - x0, 0.5 * codes.height - y0);
        w.light_px = centre - glm::dvec2(x0, y0);
        w.frame_px = centre;
        const bool on_screen = !behind && std::isfinite(centre.x) && std::isfinite(centre.y);
        w.image.luminance_cd_m2 = on_screen ? emitted_window(codes, sc.output.display, x0, y0, n)
                                            : std::vector<float>(static_cast<std::size_t>(n) * n, 0.0f);
        w.image.codes_rgb = on_screen ? codes_window(codes, x0, y0, n)
                                      : std::vector<std::uint16_t>(static_cast<std::size_t>(n) * n * 3, 0);
        w.image.code_bits = codes.bits;
        placed.push_back({{x0, y0}, on_screen});
        out->windows.push_back(std::move(w));
    }
    // What each window shows with the judged lights off, at the same pixels
    // (the same frame at the same moment and dither frame), so that the model
    // observer judges what a light adds to its surround (observer.h
    // window_light_lux), not the surround itself.
    bool any_named = false;
    for (const std::string& name : lights) any_named = any_named || !name.empty();
    const s::EncodedImage* off = any_named ? &background_codes(frame, lights, out->time_s) : nullptr;
    for (std::size_t i = 0; i < out->windows.size(); ++i) {
        LightWindow& w = out->windows[i];
        if (off)
            w.image.background_cd_m2 =
                placed[i].on_screen ? emitted_window(*off, sc.output.display, placed[i].origin.x, placed[i].origin.y, n)
                                    : std::vector<float>(static_cast<std::size_t>(n) * n, 0.0f);
        if (placed[i].on_screen)
            summarise_codes(codes, off, sc.output.display, placed[i].origin.x, placed[i].origin.y, n, w);
    }
    if (degrees_per_pixel) *degrees_per_pixel = dpp;
    views_.put(cache_key(frame, lights), out);
    render_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return out;
}

}  // namespace atonlab::runner
