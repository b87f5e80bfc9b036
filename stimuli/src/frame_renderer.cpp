#include "atonlab/stimuli/frame_renderer.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <string>

#include "atonlab/common/input_error.h"
#include "atonlab/display/colour.h"
#include "atonlab/display/mesopic.h"
#include "atonlab/display/tonemap.h"
#include "atonlab/stimuli/disc.h"
#include "atonlab/stimuli/display_threshold.h"
#include "atonlab/stimuli/footprint.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/glare_stage.h"

namespace atonlab::stimuli {

namespace {
constexpr std::size_t kDrawFloats = 16;  // struct LightDraw of light_eval.comp: 4 vec4

double s_p_of_spectrum(const std::string& name, const char* whose) {
    // Named spectra are few and fixed: each ratio is integrated once (mesopic.h) and kept.
    static std::mutex mutex;
    static std::map<std::string, double> cache;
    const std::lock_guard lock(mutex);
    if (auto it = cache.find(name); it != cache.end()) return it->second;
    const auto spd = display::named_spectrum(name);
    if (!spd) throw InputError(fmt::format("{} spectrum \"{}\" is not a named spectrum", whose, name));
    return cache[name] = display::scotopic_to_photopic_ratio(*spd);
}
}  // namespace

double light_s_p_ratio(const Light& light) {
    if (!light.spd.empty()) return s_p_of_spectrum(light.spd, "the light's");
    // No spectrum (an `xy` light, or one built in code): the rods see the drawn colour through the RGB
    // weights (display/tonemap.h scotopic_weights_rgb), which give IALA red and blue their dies' S/P and
    // white D65's; D65's own S/P would give a red xy light some 50 times the rod signal of a red die.
    return display::scotopic_luminance_rgb(light.rgb_per_cd) / display::luminance_of_linear_rgb(light.rgb_per_cd);
}

double sky_s_p_ratio(const Environment& environment) {
    return s_p_of_spectrum(environment.spd.empty() ? "d65" : environment.spd, "the sky's");
}

CameraProjection CameraProjection::from_scene(const Scene& scene) {
    CameraProjection p;
    p.width_px = scene.display.width_px;
    p.height_px = scene.display.height_px;
    const double fov_y =
        scene.camera.fov_y_deg ? *scene.camera.fov_y_deg * std::numbers::pi / 180.0 : scene.display.fov_y_rad();
    p.focal_px = 0.5 * p.height_px / std::tan(0.5 * fov_y);
    p.world_from_view = glm::mat3_cast(scene.camera.orientation());
    p.eye_position_m = scene.camera.position_m;
    return p;
}

double CameraProjection::degrees_per_pixel_at_centre() const {
    return 180.0 / std::numbers::pi / focal_px;
}

GpuLightTables pack_lights(const Scene& scene, glm::dvec3 eye, std::span<const unsigned> glare_groups,
                           std::span<const double> invisible_lux) {
    GpuLightTables t;
    // Profiles: every table once, lights refer to them by offset (K2012 §5.1 ids).
    std::vector<std::pair<std::uint32_t, std::uint32_t>> vert, hor;
    for (const auto& v : scene.profiles.vertical) {
        vert.emplace_back(static_cast<std::uint32_t>(t.profile_values.size()),
                          static_cast<std::uint32_t>(v.table.size()));
        t.profile_values.insert(t.profile_values.end(), v.table.begin(), v.table.end());
    }
    for (const auto& h : scene.profiles.horizontal) {
        hor.emplace_back(static_cast<std::uint32_t>(t.profile_values.size()),
                         static_cast<std::uint32_t>(h.table.size()));
        t.profile_values.insert(t.profile_values.end(), h.table.begin(), h.table.end());
    }
    auto bits = [](std::uint32_t u) { return std::bit_cast<float>(u); };
    for (std::size_t li = 0; li < scene.lights.size(); ++li) {
        const Light& L = scene.lights[li];
        const unsigned group = li < glare_groups.size() ? glare_groups[li] : 0u;
        // How its glare model draws it (scene.h GlarePath): light_eval.comp, the
        // direct pass and the billboards each take only their own lights.
        const auto path = static_cast<std::uint32_t>(glare_path(light_glare_model(scene, L)));
        const double invisible = li < invisible_lux.size() ? invisible_lux[li] : 0.0;
        const auto knot_offset = static_cast<std::uint32_t>(t.rhythm_knots.size());
        for (const RhythmKnot& k : L.rhythm)
            t.rhythm_knots.emplace_back(static_cast<float>(k.t_s), static_cast<float>(k.level));
        const glm::dvec3 rel = L.position_m - eye;
        const glm::dvec3 I = L.rgb_per_cd * L.intensity_cd;
        const auto& v = vert.at(static_cast<std::size_t>(L.vertical_profile));
        const auto& h = hor.at(static_cast<std::size_t>(L.horizontal_profile));
        const float rec[24] = {static_cast<float>(rel.x),
                               static_cast<float>(rel.y),
                               static_cast<float>(rel.z),
                               static_cast<float>(L.radius_m),
                               static_cast<float>(L.orientation.x),
                               static_cast<float>(L.orientation.y),
                               static_cast<float>(L.orientation.z),
                               static_cast<float>(L.orientation.w),
                               static_cast<float>(I.r),
                               static_cast<float>(I.g),
                               static_cast<float>(I.b),
                               static_cast<float>(L.rhythm_phase_s),
                               bits(v.first),
                               bits(v.second),
                               bits(h.first),
                               bits(h.second),
                               bits(knot_offset),
                               bits(static_cast<std::uint32_t>(L.rhythm.size())),
                               bits(group),
                               bits(path),
                               static_cast<float>(L.rhythm_period_s),
                               static_cast<float>(invisible),
                               static_cast<float>(light_s_p_ratio(L)),
                               0.0f};
        t.lights.insert(t.lights.end(), std::begin(rec), std::end(rec));
    }
    if (t.profile_values.empty()) t.profile_values.push_back(1.0f);
    if (t.rhythm_knots.empty()) t.rhythm_knots.emplace_back(0.0f, 1.0f);
    return t;
}

struct FrameRenderer::Impl {
    gl::Program background = gl::Program::build(
        {{gl::ShaderStage::vertex, "fullscreen.vert"}, {gl::ShaderStage::fragment, "background.frag"}});
    gl::Program disc =
        gl::Program::build({{gl::ShaderStage::vertex, "fullscreen.vert"}, {gl::ShaderStage::fragment, "disc.frag"}});
    gl::Program light_eval = gl::Program::build({{gl::ShaderStage::compute, "light_eval.comp"}});
    gl::Program light_direct = gl::Program::build(
        {{gl::ShaderStage::vertex, "light_direct.vert"}, {gl::ShaderStage::fragment, "light_direct.frag"}});
    gl::VertexArray vao = gl::VertexArray::create();
    gl::Texture2D hdr, depth, glare_only;
    gl::Framebuffer fbo, glare_fbo;
    gl::Buffer lights, profiles, knots, draws;
    gl::Buffer no_envelope{sizeof(float), nullptr, gl::BufferUsage::static_draw};
    const gl::Buffer* envelope_in_use = &no_envelope;  // at storage binding 4 this frame (light_eval.comp)
    int light_count = 0;
    GlareStage glare;
    VeilingGlare veil;
    std::vector<float> veil_light, veil_frame;  // the CPU veil's read-backs, kept between frames
    GpuVeilingGlare gpu_veil;
    VeilReport veil_report;
    FrameOptions options;
    double pre_exposure = 1.0;
    gl::GpuTimer timers[3];
    bool timed = false;
    FrameTimings cpu_timings;
    // ΔY (cd/m²) per display state and light colour and S/P (display_threshold.h): the
    // search takes milliseconds, the answer is the same frame after frame.
    std::map<std::string, std::map<std::array<double, 4>, double>> invisible_cache;

    static gl::PixelFormat pixel_format(HdrFormat f) {
        return f == HdrFormat::rgba16f ? gl::PixelFormat::rgba16f : gl::PixelFormat::rgba32f;
    }
    std::vector<double> invisible_lux(const Scene& scene, const CameraProjection& P);
    // Parts of render()'s passes (frame_renderer.cpp).
    void set_background_uniforms(const Scene& scene, const CameraProjection& P);
    void draw_discs(const Scene& scene, const CameraProjection& P);
    void upload_light_tables(const Scene& scene, const GpuLightTables& tables);
    void convolve_veil(const Scene& scene, const CameraProjection& P, bool ldr);
    void bind_light_tables() const;

    void resize(int w, int h) {
        const gl::PixelFormat format = pixel_format(options.hdr_format);
        if (hdr && hdr.width() == w && hdr.height() == h && hdr.format() == format) return;
        fbo = {};
        hdr = gl::Texture2D(w, h, format);
        depth = gl::Texture2D(w, h, gl::PixelFormat::r32f);
        fbo = gl::Framebuffer::create();
        fbo.attach_colour(hdr, 0);
        fbo.attach_colour(depth, 1);
        fbo.check_complete("HDR frame");
        glare_fbo = {};
        glare_only = {};
    }
    void ensure_glare_target() {
        if (glare_only) return;
        glare_only = gl::Texture2D(hdr.width(), hdr.height(), gl::PixelFormat::rgba32f);
        glare_fbo = gl::Framebuffer::create();
        glare_fbo.attach_colour(glare_only, 0);
        glare_fbo.check_complete("glare buffer");
    }
};

// Each light's invisible illuminance (lux, Y): ΔY · Ω_min, ΔY the luminance
// that moves no code by threshold_codes on the frame's darkest background, Ω_min
// the smallest pixel solid angle (a corner's), so that E · K_peak < ΔY · Ω_min
// keeps every pixel the light touches below ΔY. Empty when the skips are off or
// cannot be bounded (dynamic adaptation, the LDR glare path, a sky not D65: the bound is
// computed over D65 backgrounds).
std::vector<double> FrameRenderer::Impl::invisible_lux(const Scene& scene, const CameraProjection& P) {
    const DisplaySkips& k = options.skips;
    const OutputSettings& out = scene.output;
    const bool d65_sky = scene.environment.spd.empty() || scene.environment.spd == "d65";
    if (!(k.cull_invisible_lights || k.crop_billboards) || !(k.threshold_codes > 0) ||
        out.adaptation.mode != AdaptationMode::fixed || out.ldr_glare || scene.lights.empty() || !d65_sky)
        return {};
    const Environment& env = scene.environment;
    double floor_cd_m2 = std::max(0.0, env.luminance_cd_m2);
    if (env.background == Background::sky_sea) floor_cd_m2 *= std::clamp(env.sea_reflectance_f0, 0.0, 1.0);
    // A disc darker than the background is a darker surround for a light over it.
    for (const Disc& d : scene.discs)
        if (d.diameter_deg > 0.0) floor_cd_m2 = std::min(floor_cd_m2, std::max(0.0, d.luminance_cd_m2));
    const double omega_min = pixel_solid_angle_sr(-0.5 * P.width_px, -0.5 * P.height_px, P.focal_px);

    std::string key;
    auto bytes = [&key](const void* p, std::size_t n) { key.append(static_cast<const char*>(p), n); };
    const display::ToneMapGpuParams tp = display::tonemap_gpu_params(out.tonemap);
    const display::GpuDisplayParams dp = display::gpu_display_params(out.display, out.encode);
    const std::vector<double> lut = display::gpu_display_lut(out.display);
    const double state[3] = {scene.adaptation_cd_m2, floor_cd_m2, k.threshold_codes};
    bytes(&tp, sizeof(tp));
    bytes(&dp, sizeof(dp));
    bytes(lut.data(), lut.size() * sizeof(double));
    bytes(state, sizeof(state));
    if (invisible_cache.size() > 64) invisible_cache.clear();
    auto& per_colour = invisible_cache[key];
    if (per_colour.size() > 4096) per_colour.clear();

    std::vector<double> result(scene.lights.size(), 0.0);
    const double background_s_p = sky_s_p_ratio(env);
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const glm::dvec3 c = scene.lights[i].rgb_per_cd;
        const double s_p = light_s_p_ratio(scene.lights[i]);
        auto [it, fresh] = per_colour.try_emplace({c.r, c.g, c.b, s_p}, 0.0);
        if (fresh)
            it->second = invisible_luminance_cd_m2(out, scene.adaptation_cd_m2, floor_cd_m2, c, s_p, background_s_p,
                                                   k.threshold_codes);
        result[i] = it->second * omega_min;
    }
    return result;
}

namespace {
// Per-frame data: keep the buffer and overwrite it while it is large enough,
// so a steady scene allocates nothing frame to frame.
void upload(gl::Buffer& buffer, const void* data, std::size_t bytes, gl::BufferUsage usage) {
    if (!buffer || buffer.size() < bytes) {
        buffer = gl::Buffer(bytes, data, usage);
        return;
    }
    if (data) buffer.upload(0, bytes, data);
}

/// Which glare paths a frame's lights take (each light's own glare model, else the eye's).
struct GlarePaths {
    bool direct = false, billboard = false, veil = false;
};

GlarePaths glare_paths(const Scene& scene) {
    GlarePaths any;
    for (const Light& L : scene.lights) {
        const GlarePath path = glare_path(light_glare_model(scene, L));
        any.direct |= path == GlarePath::direct;
        any.billboard |= path == GlarePath::billboard;
        any.veil |= path == GlarePath::veil;
    }
    return any;
}
}  // namespace

// The uniforms of pass 1, the background and linear view depth.
void FrameRenderer::Impl::set_background_uniforms(const Scene& scene, const CameraProjection& P) {
    const auto w = static_cast<float>(P.width_px), h = static_cast<float>(P.height_px);
    const auto f = static_cast<float>(P.focal_px);
    const glm::mat3 world_from_view(P.world_from_view);
    const auto pre = static_cast<float>(pre_exposure);
    const Environment& env = scene.environment;
    background.set("principal_px", 0.5f * w, 0.5f * h);
    background.set("focal_px", f);
    background.set_mat3("world_from_view", glm::value_ptr(world_from_view));
    background.set("eye_position_m", static_cast<float>(P.eye_position_m.x), static_cast<float>(P.eye_position_m.y),
                   static_cast<float>(P.eye_position_m.z));
    background.set("sky_luminance", static_cast<float>(env.luminance_cd_m2));
    background.set("sea_f0", static_cast<float>(env.sea_reflectance_f0));
    background.set("sky_sea", env.background == Background::sky_sea ? 1 : 0);
    background.set("pre_exposure", pre);
    background.set("sky_s_p", static_cast<float>(sky_s_p_ratio(env)));
    background.set("sky_rgb", static_cast<float>(env.rgb_per_cd_m2.r), static_cast<float>(env.rgb_per_cd_m2.g),
                   static_cast<float>(env.rgb_per_cd_m2.b));
}

// Pass 1b of render(): the discs, alpha-blended into the colour target only.
void FrameRenderer::Impl::draw_discs(const Scene& scene, const CameraProjection& P) {
    const auto w = static_cast<float>(P.width_px), h = static_cast<float>(P.height_px);
    const auto f = static_cast<float>(P.focal_px);
    const GLenum only_colour[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
    glNamedFramebufferDrawBuffers(fbo.id(), 2, only_colour);
    glEnable(GL_BLEND);
    // Colour: (1 − c) below + c disc (the fragment's alpha is the coverage c). Alpha, the scotopic
    // channel: c · V_disc (the blend constant) + (1 − c) · below.
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_CONSTANT_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glBlendEquation(GL_FUNC_ADD);
    disc.set("principal_px", 0.5f * w, 0.5f * h);
    disc.set("focal_px", f);
    for (const Disc& d : scene.discs) {
        const glm::dvec3 c = disc_direction_view(d, P);
        if (!(d.diameter_deg > 0.0) || glm::length(c) == 0.0) continue;
        const glm::dvec3 rgb = d.rgb_per_cd_m2 * d.luminance_cd_m2 * pre_exposure;
        disc.set("centre_view", static_cast<float>(c.x), static_cast<float>(c.y), static_cast<float>(c.z));
        disc.set("radius_rad", static_cast<float>(0.5 * d.diameter_deg * std::numbers::pi / 180.0));
        disc.set("rgb", static_cast<float>(rgb.r), static_cast<float>(rgb.g), static_cast<float>(rgb.b));
        // A disc is drawn in RGB (no spectrum): its scotopic luminance from the RGB weights.
        glBlendColor(0.0f, 0.0f, 0.0f, static_cast<float>(display::scotopic_luminance_rgb(rgb)));
        disc.use();
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }
    glDisable(GL_BLEND);
    const GLenum both[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(fbo.id(), 2, both);
}

// The frame's light tables into the storage buffers light_eval.comp reads (bindings 0-3).
void FrameRenderer::Impl::upload_light_tables(const Scene& scene, const GpuLightTables& tables) {
    light_count = static_cast<int>(scene.lights.size());
    upload(lights, tables.lights.data(), tables.lights.size() * sizeof(float), gl::BufferUsage::stream_draw);
    upload(profiles, tables.profile_values.data(), tables.profile_values.size() * sizeof(float),
           gl::BufferUsage::stream_draw);
    upload(knots, tables.rhythm_knots.data(), tables.rhythm_knots.size() * sizeof(glm::vec2),
           gl::BufferUsage::stream_draw);
    upload(draws, nullptr, std::max<std::size_t>(1, scene.lights.size()) * kDrawFloats * sizeof(float),
           gl::BufferUsage::dynamic_read);
    bind_light_tables();
}

// The frame's storage bindings 0-3 (light_eval.comp, the direct images, the billboards).
void FrameRenderer::Impl::bind_light_tables() const {
    lights.bind_storage(0);
    profiles.bind_storage(1);
    knots.bind_storage(2);
    draws.bind_storage(3);
}

namespace {

// The GPU where the placement says so and this GPU's workgroups hold the
// frame's transform lengths; a forced GPU placement that cannot is an error.
ComputePlacement veil_placement(const Scene& scene, int width, int height) {
    const ComputePlacement where = resolve_placement(scene.glare.placement);
    if (where != ComputePlacement::gpu) return where;
    const std::string why = GpuVeilingGlare::unsupported_reason(width, height);
    if (why.empty()) return where;
    if (scene.glare.placement == ComputePlacement::gpu)
        throw InputError(SourceLocation{"", 0, 0, "placement"},
                         fmt::format("placement = \"gpu\": the whole-frame veil cannot run on this GPU: {}; use "
                                     "\"automatic\" or \"cpu\".",
                                     why));
    return ComputePlacement::cpu;
}

}  // namespace

// The `cie` veil: the veil lights' direct images (already drawn into the glare
// buffer, cd/m²) convolved with the CIE GSF; the result is the glare buffer
// of the LDR path, or is added to the HDR frame.
void FrameRenderer::Impl::convolve_veil(const Scene& scene, const CameraProjection& P, bool ldr) {
    const auto pre = static_cast<float>(pre_exposure);
    const ComputePlacement where = veil_placement(scene, P.width_px, P.height_px);
    veil_report.placement = where;
    veil_report.applied = true;
    veil_report.observer = cie_observer(scene.glare);
    if (where == ComputePlacement::gpu) {
        veil_report.outside_frame = gpu_veil.apply(glare_only, ldr ? nullptr : &hdr, ldr ? 1.0 : pre_exposure,
                                                   P.focal_px, cie_observer(scene.glare));
        // The veil's passes took storage bindings 0-7 and texture unit 0: give
        // the frame's back (the LDR path draws its billboards after the veil,
        // reading `draws` at binding 3).
        bind_light_tables();
        envelope_in_use->bind_storage(4);
        depth.bind(0);
        return;
    }
    // Into buffers kept from frame to frame (Texture2D::download_floats).
    std::vector<float>& light = veil_light;
    glare_only.download_floats(light);
    veil_report.outside_frame = veil.apply(light, P.width_px, P.height_px, P.focal_px, cie_observer(scene.glare));
    // The veil's scotopic luminance from its RGB (as veil_gpu.comp).
    const glm::dvec3 sw = display::scotopic_weights_rgb();
    if (ldr) {
        for (std::size_t i = 0; i + 3 < light.size(); i += 4)
            light[i + 3] = static_cast<float>(glm::dot(sw, glm::dvec3(light[i], light[i + 1], light[i + 2])));
        glare_only.upload(light.data());
    } else {
        std::vector<float>& frame = veil_frame;
        hdr.download_floats(frame);
        for (std::size_t i = 0; i + 3 < frame.size(); i += 4) {
            for (int c = 0; c < 3; ++c) frame[i + c] += light[i + c] * pre;
            frame[i + 3] += static_cast<float>(glm::dot(sw, glm::dvec3(light[i], light[i + 1], light[i + 2])) * pre);
        }
        hdr.upload(frame.data());
    }
}

FramePlacements frame_placements(const Scene& scene, int width, int height) {
    FramePlacements out;
    for (const Light& l : scene.lights) {
        const GlareModel model = light_glare_model(scene, l);
        if (model == GlareModel::cie && !out.veil) out.veil = veil_placement(scene, width, height);
        GlareSettings g = scene.glare;
        g.model = model;
        if (auto p = glare_model_type(model).psf_fft_placement(g))
            out.psf_fft = out.psf_fft == ComputePlacement::cpu ? ComputePlacement::cpu : *p;
    }
    return out;
}

std::string_view placement_name(const std::optional<ComputePlacement>& p) {
    return p ? placement_name(*p) : "none";
}

FrameRenderer::FrameRenderer() : impl_(std::make_unique<Impl>()) {}
FrameRenderer::~FrameRenderer() = default;

void FrameRenderer::set_options(const FrameOptions& options) {
    impl_->options = options;
}
const FrameOptions& FrameRenderer::options() const {
    return impl_->options;
}
double FrameRenderer::pre_exposure() const {
    return impl_->pre_exposure;
}

FrameTimings FrameRenderer::timings() const {
    const Impl& m = *impl_;
    FrameTimings t = m.cpu_timings;
    if (m.timed) {
        t.background_gpu_ms = m.timers[0].elapsed_ms().value_or(0);
        t.light_eval_gpu_ms = m.timers[1].elapsed_ms().value_or(0);
        t.lights_draw_gpu_ms = m.timers[2].elapsed_ms().value_or(0);
    }
    return t;
}

void FrameRenderer::render(const Scene& scene, double time_s) {
    using Clock = std::chrono::steady_clock;
    auto ms_since = [](Clock::time_point t) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    };
    const auto started = Clock::now();
    Impl& m = *impl_;
    projection_ = CameraProjection::from_scene(scene);
    const CameraProjection& P = projection_;
    m.resize(P.width_px, P.height_px);
    m.pre_exposure = m.options.pre_exposure > 0 ? m.options.pre_exposure : 1.0 / scene.adaptation_cd_m2;
    const auto pre = static_cast<float>(m.pre_exposure);
    m.timed = m.options.gpu_timing;
    if (m.timed && !m.timers[0])
        for (auto& t : m.timers) t = gl::GpuTimer::create();
    // Every timer is begun and ended every timed frame, so none is read unissued.
    auto begin = [&m](int i) {
        if (m.timed) m.timers[i].begin();
    };
    auto end = [&m](int i) {
        if (m.timed) m.timers[i].end();
    };
    const auto w = static_cast<float>(P.width_px), h = static_cast<float>(P.height_px);
    const auto f = static_cast<float>(P.focal_px);
    const glm::mat3 world_from_view(P.world_from_view);
    const glm::mat3 view_from_world = glm::transpose(world_from_view);

    // 1. Background and linear view depth.
    m.fbo.bind();
    glViewport(0, 0, P.width_px, P.height_px);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    const Environment& env = scene.environment;
    m.set_background_uniforms(scene, P);
    m.background.use();
    m.vao.bind();
    begin(0);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    // 1b. Discs (scene.h Disc): uniform patches over the background, under the
    // lights; colour only, the depth target keeps the background's depth.
    if (!scene.discs.empty()) m.draw_discs(scene, P);
    end(0);

    // 2. Per-light evaluation, projection and occlusion (compute).
    // The glare kernels first: the light pass culls with the billboard's extent.
    m.veil_report = {};
    m.cpu_timings.veil_cpu_ms = 0;
    const auto prepare_started = Clock::now();
    const double glare_extent_px = m.glare.prepare(scene, P, time_s);
    m.cpu_timings.glare_prepare_cpu_ms = ms_since(prepare_started);
    // Which paths this frame's lights take (each light's own glare model, else the eye's).
    const auto [any_direct, any_billboard, any_veil] = glare_paths(scene);
    const bool glare = any_billboard || any_veil;
    const std::vector<double> invisible = m.invisible_lux(scene, P);
    const GpuLightTables tables = pack_lights(scene, P.eye_position_m, m.glare.light_groups(), invisible);
    m.upload_light_tables(scene, tables);
    const bool skips = !invisible.empty();
    const bool crop = skips && any_billboard && m.options.skips.crop_billboards && m.glare.envelope_stride() > 0;
    m.envelope_in_use = any_billboard && m.glare.envelope_stride() > 0 ? &m.glare.envelope_buffer() : &m.no_envelope;
    m.envelope_in_use->bind_storage(4);
    if (m.light_count == 0 && m.timed) {
        begin(1);
        end(1);
        begin(2);
        end(2);
    }
    if (m.light_count > 0) {
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
        m.depth.bind(0);
        m.light_eval.set("light_count", static_cast<unsigned>(m.light_count));
        m.light_eval.set_mat3("view_from_world", glm::value_ptr(view_from_world));
        m.light_eval.set("focal_px", f);
        m.light_eval.set("image_size", w, h);
        m.light_eval.set("time_s", time_s);
        m.light_eval.set("extinction_per_m", static_cast<float>(env.extinction_per_m));
        m.light_eval.set("glare_extent_px", static_cast<float>(glare_extent_px));
        m.light_eval.set("cull_invisible", skips && m.options.skips.cull_invisible_lights ? 1 : 0);
        m.light_eval.set("crop_billboards", crop ? 1 : 0);
        m.light_eval.set("envelope_stride", any_billboard ? m.glare.envelope_stride() : 0u);
        m.light_eval.use();
        begin(1);
        glDispatchCompute(static_cast<unsigned>((m.light_count + 63) / 64), 1, 1);
        end(1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

        // 3. Direct images, additively (the background already holds its radiance).
        // Only colour attachment 0 is written: the depth target keeps the scene's depth.
        const GLenum only_colour[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
        glNamedFramebufferDrawBuffers(m.fbo.id(), 2, only_colour);
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE);
        glBlendEquation(GL_FUNC_ADD);
        // The LDR path (K2012 §6.2.2): every direct image in the HDR frame, the
        // glare alone in its own buffer. Kept whenever the eye or a light has a
        // glare model, so the buffer exists (and is black) without glare lights.
        const bool ldr = scene.output.ldr_glare && (glare || scene.glare.model != GlareModel::none);
        // path: the GlarePath whose lights are drawn; -1: every light.
        auto draw_direct = [&](float pre_exposure, int path) {
            m.light_direct.set("image_size", w, h);
            m.light_direct.set("focal_px", f);
            m.light_direct.set("pre_exposure", pre_exposure);
            m.light_direct.set("path", path);
            m.light_direct.use();
            m.vao.bind();
            glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, m.light_count);
        };
        begin(2);
        if (ldr) {
            draw_direct(pre, -1);
        } else {
            if (any_direct) draw_direct(pre, static_cast<int>(GlarePath::direct));
            // The glare billboard replaces the direct image (docs/architecture.md: energy-matched).
            if (any_billboard) m.glare.draw(m.light_count, P, m.pre_exposure);
        }
        if (ldr || any_veil) {
            m.ensure_glare_target();
            m.glare_fbo.bind();
            const float zero[4] = {0, 0, 0, 0};
            glClearBufferfv(GL_COLOR, 0, zero);
        }
        if (any_veil) {
            // `cie`: the direct images of its lights alone (cd/m²) convolved over
            // the whole frame with the CIE GSF (veiling_glare.h), which
            // replaces them in the HDR frame, or is the glare buffer of the LDR
            // path. Lights with another model are not in the convolution.
            const auto veil_started = Clock::now();
            draw_direct(1.0f, static_cast<int>(GlarePath::veil));
            m.convolve_veil(scene, P, ldr);
            m.veil_report.cpu_ms = ms_since(veil_started);
            m.cpu_timings.veil_cpu_ms = m.veil_report.cpu_ms;
        }
        if (ldr && any_billboard) {
            // K2012 §6.2.2: the billboards' glare alone, into the glare buffer (cd/m²).
            m.glare_fbo.bind();
            m.glare.draw(m.light_count, P, 1.0);
        }
        m.fbo.bind();
        end(2);
        glDisable(GL_BLEND);
        const GLenum both[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
        glNamedFramebufferDrawBuffers(m.fbo.id(), 2, both);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    m.cpu_timings.total_cpu_ms = ms_since(started);
}

namespace {
template <class T>
std::vector<T> flip_rows(const std::vector<T>& src, int w, int h, int channels) {
    std::vector<T> out(src.size());
    const std::size_t row = static_cast<std::size_t>(w) * channels;
    for (int y = 0; y < h; ++y)
        std::memcpy(&out[static_cast<std::size_t>(h - 1 - y) * row], &src[static_cast<std::size_t>(y) * row],
                    row * sizeof(T));
    return out;
}
}  // namespace

ImageRGBA32F FrameRenderer::read_hdr() const {
    ImageRGBA32F img;
    img.width = impl_->hdr.width();
    img.height = impl_->hdr.height();
    img.rgba = flip_rows(impl_->hdr.download_floats(), img.width, img.height, 4);
    if (impl_->pre_exposure != 1.0) {
        const auto inv = static_cast<float>(1.0 / impl_->pre_exposure);
        for (float& v : img.rgba) v *= inv;
    }
    return img;
}

std::vector<float> FrameRenderer::read_view_depth() const {
    return flip_rows(impl_->depth.download_floats(), impl_->depth.width(), impl_->depth.height(), 1);
}

std::vector<LightDrawRecord> FrameRenderer::read_light_draws() const {
    const Impl& m = *impl_;
    std::vector<float> raw(static_cast<std::size_t>(m.light_count) * kDrawFloats);
    m.draws.download(0, raw.size() * sizeof(float), raw.data());
    std::vector<LightDrawRecord> out(static_cast<std::size_t>(m.light_count));
    for (std::size_t i = 0; i < out.size(); ++i) {
        const float* r = &raw[i * kDrawFloats];
        LightDrawRecord& d = out[i];
        d.centre_px = {r[0], r[1]};
        d.view_depth_m = r[2];
        d.area_px2 = r[3];
        d.illuminance_rgb_lux = {r[4], r[5], r[6]};
        d.distance_m = r[7];
        d.vertical = r[8];
        d.horizontal = r[9];
        d.rhythm = r[10];
        d.transmittance = r[11];
        d.crop_half_extent_px = r[12];
        d.invisible_lux = r[13];
    }
    return out;
}

FrameStats FrameRenderer::stats() const {
    FrameStats s;
    s.lights = impl_->light_count;
    for (const auto& d : read_light_draws()) s.drawn += d.area_px2 > 0 ? 1 : 0;
    return s;
}

const GlareStage& FrameRenderer::glare() const {
    return impl_->glare;
}
const VeilReport& FrameRenderer::veil_report() const {
    return impl_->veil_report;
}

const gl::Texture2D* FrameRenderer::glare_texture() const {
    return impl_->glare_only ? &impl_->glare_only : nullptr;
}

const gl::Texture2D& FrameRenderer::hdr_texture() const {
    return impl_->hdr;
}
const gl::Texture2D& FrameRenderer::view_depth_texture() const {
    return impl_->depth;
}

}  // namespace atonlab::stimuli
