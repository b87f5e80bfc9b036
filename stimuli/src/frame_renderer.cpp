#include "atonlab/stimuli/frame_renderer.h"

#include <epoxy/gl.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/glare_stage.h"

namespace atonlab::stimuli {

CameraProjection CameraProjection::from_scene(const Scene& scene) {
    CameraProjection p;
    p.width_px = scene.display.width_px;
    p.height_px = scene.display.height_px;
    const double fov_y = scene.camera.fov_y_deg ? *scene.camera.fov_y_deg * std::numbers::pi / 180.0
                                                : scene.display.fov_y_rad();
    p.focal_px = 0.5 * p.height_px / std::tan(0.5 * fov_y);
    p.world_from_view = glm::mat3_cast(scene.camera.orientation());
    p.eye_position_m = scene.camera.position_m;
    return p;
}

double CameraProjection::degrees_per_pixel_at_centre() const { return 180.0 / std::numbers::pi / focal_px; }

GpuLightTables pack_lights(const Scene& scene, glm::dvec3 eye, std::span<const unsigned> glare_groups) {
    GpuLightTables t;
    // Profiles: every table once, lights refer to them by offset (K2012 §5.1 ids).
    std::vector<std::pair<std::uint32_t, std::uint32_t>> vert, hor;
    for (const auto& v : scene.profiles.vertical) {
        vert.emplace_back(static_cast<std::uint32_t>(t.profile_values.size()), static_cast<std::uint32_t>(v.table.size()));
        t.profile_values.insert(t.profile_values.end(), v.table.begin(), v.table.end());
    }
    for (const auto& h : scene.profiles.horizontal) {
        hor.emplace_back(static_cast<std::uint32_t>(t.profile_values.size()), static_cast<std::uint32_t>(h.table.size()));
        t.profile_values.insert(t.profile_values.end(), h.table.begin(), h.table.end());
    }
    auto bits = [](std::uint32_t u) { return std::bit_cast<float>(u); };
    for (std::size_t li = 0; li < scene.lights.size(); ++li) {
        const Light& L = scene.lights[li];
        const unsigned group = li < glare_groups.size() ? glare_groups[li] : 0u;
        const auto knot_offset = static_cast<std::uint32_t>(t.rhythm_knots.size());
        for (const RhythmKnot& k : L.rhythm)
            t.rhythm_knots.emplace_back(static_cast<float>(k.t_s), static_cast<float>(k.level));
        const glm::dvec3 rel = L.position_m - eye;
        const glm::dvec3 I = L.rgb_per_cd * L.intensity_cd;
        const auto& v = vert.at(static_cast<std::size_t>(L.vertical_profile));
        const auto& h = hor.at(static_cast<std::size_t>(L.horizontal_profile));
        const float rec[24] = {
            static_cast<float>(rel.x), static_cast<float>(rel.y), static_cast<float>(rel.z), static_cast<float>(L.radius_m),
            static_cast<float>(L.orientation.x), static_cast<float>(L.orientation.y),
            static_cast<float>(L.orientation.z), static_cast<float>(L.orientation.w),
            static_cast<float>(I.r), static_cast<float>(I.g), static_cast<float>(I.b), static_cast<float>(L.rhythm_phase_s),
            bits(v.first), bits(v.second), bits(h.first), bits(h.second),
            bits(knot_offset), bits(static_cast<std::uint32_t>(L.rhythm.size())), bits(group), bits(0),
            static_cast<float>(L.rhythm_period_s), 0.0f, 0.0f, 0.0f};
        t.lights.insert(t.lights.end(), std::begin(rec), std::end(rec));
    }
    if (t.profile_values.empty()) t.profile_values.push_back(1.0f);
    if (t.rhythm_knots.empty()) t.rhythm_knots.emplace_back(0.0f, 1.0f);
    return t;
}

struct FrameRenderer::Impl {
    gl::Program background = gl::Program::build(
        {{gl::ShaderStage::vertex, "fullscreen.vert"}, {gl::ShaderStage::fragment, "background.frag"}});
    gl::Program light_eval = gl::Program::build({{gl::ShaderStage::compute, "light_eval.comp"}});
    gl::Program light_direct = gl::Program::build(
        {{gl::ShaderStage::vertex, "light_direct.vert"}, {gl::ShaderStage::fragment, "light_direct.frag"}});
    gl::VertexArray vao = gl::VertexArray::create();
    gl::Texture2D hdr, depth, glare_only;
    gl::Framebuffer fbo, glare_fbo;
    gl::Buffer lights, profiles, knots, draws;
    int light_count = 0;
    GlareStage glare;

    void resize(int w, int h) {
        if (hdr && hdr.width() == w && hdr.height() == h) return;
        fbo = {};
        hdr = gl::Texture2D(w, h, gl::PixelFormat::rgba32f);
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
}  // namespace

FrameRenderer::FrameRenderer() : impl_(std::make_unique<Impl>()) {}
FrameRenderer::~FrameRenderer() = default;

void FrameRenderer::render(const Scene& scene, double time_s) {
    Impl& m = *impl_;
    projection_ = CameraProjection::from_scene(scene);
    const CameraProjection& P = projection_;
    m.resize(P.width_px, P.height_px);
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
    m.background.set("principal_px", 0.5f * w, 0.5f * h);
    m.background.set("focal_px", f);
    m.background.set_mat3("world_from_view", glm::value_ptr(world_from_view));
    m.background.set("eye_position_m", static_cast<float>(P.eye_position_m.x), static_cast<float>(P.eye_position_m.y),
                     static_cast<float>(P.eye_position_m.z));
    m.background.set("sky_luminance", static_cast<float>(env.luminance_cd_m2));
    m.background.set("sea_f0", static_cast<float>(env.sea_reflectance_f0));
    m.background.set("sky_sea", env.background == Background::sky_sea ? 1 : 0);
    m.background.use();
    m.vao.bind();
    glDrawArrays(GL_TRIANGLES, 0, 3);

    // 2. Per-light evaluation, projection and occlusion (compute).
    // The glare kernels first: the light pass culls with the billboard's extent.
    const double glare_extent_px = m.glare.prepare(scene, P, time_s);
    const bool glare = scene.glare.model != GlareModel::none;
    const GpuLightTables tables = pack_lights(scene, P.eye_position_m, m.glare.light_groups());
    m.light_count = static_cast<int>(scene.lights.size());
    upload(m.lights, tables.lights.data(), tables.lights.size() * sizeof(float), gl::BufferUsage::stream_draw);
    upload(m.profiles, tables.profile_values.data(), tables.profile_values.size() * sizeof(float),
           gl::BufferUsage::stream_draw);
    upload(m.knots, tables.rhythm_knots.data(), tables.rhythm_knots.size() * sizeof(glm::vec2),
           gl::BufferUsage::stream_draw);
    upload(m.draws, nullptr, std::max<std::size_t>(1, scene.lights.size()) * 12 * sizeof(float),
           gl::BufferUsage::dynamic_read);
    m.lights.bind_storage(0);
    m.profiles.bind_storage(1);
    m.knots.bind_storage(2);
    m.draws.bind_storage(3);
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
        m.light_eval.use();
        glDispatchCompute(static_cast<unsigned>((m.light_count + 63) / 64), 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

        // 3. Direct images, additively (the background already holds its radiance).
        // Only colour attachment 0 is written: the depth target keeps the scene's depth.
        const GLenum only_colour[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
        glNamedFramebufferDrawBuffers(m.fbo.id(), 2, only_colour);
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE);
        glBlendEquation(GL_FUNC_ADD);
        const bool ldr = glare && scene.output.ldr_glare;
        if (glare && !ldr) {
            // The glare billboard replaces the direct image (DESIGN.md: energy-matched).
            m.glare.draw(m.light_count, P);
        } else {
            m.light_direct.set("image_size", w, h);
            m.light_direct.set("focal_px", f);
            m.light_direct.use();
            m.vao.bind();
            glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, m.light_count);
        }
        if (ldr) {
            // K2012 §6.2.2: the glare alone, into its own buffer, for the LDR path.
            m.ensure_glare_target();
            m.glare_fbo.bind();
            const float zero[4] = {0, 0, 0, 0};
            glClearBufferfv(GL_COLOR, 0, zero);
            m.glare.draw(m.light_count, P);
            m.fbo.bind();
        }
        glDisable(GL_BLEND);
        const GLenum both[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
        glNamedFramebufferDrawBuffers(m.fbo.id(), 2, both);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
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
    return img;
}

std::vector<float> FrameRenderer::read_view_depth() const {
    return flip_rows(impl_->depth.download_floats(), impl_->depth.width(), impl_->depth.height(), 1);
}

std::vector<LightDrawRecord> FrameRenderer::read_light_draws() const {
    const Impl& m = *impl_;
    std::vector<float> raw(static_cast<std::size_t>(m.light_count) * 12);
    m.draws.download(0, raw.size() * sizeof(float), raw.data());
    std::vector<LightDrawRecord> out(static_cast<std::size_t>(m.light_count));
    for (std::size_t i = 0; i < out.size(); ++i) {
        const float* r = &raw[i * 12];
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
    }
    return out;
}

FrameStats FrameRenderer::stats() const {
    FrameStats s;
    s.lights = impl_->light_count;
    for (const auto& d : read_light_draws()) s.drawn += d.area_px2 > 0 ? 1 : 0;
    return s;
}

const GlareStage& FrameRenderer::glare() const { return impl_->glare; }

const gl::Texture2D* FrameRenderer::glare_texture() const {
    return impl_->glare_only ? &impl_->glare_only : nullptr;
}

const gl::Texture2D& FrameRenderer::hdr_texture() const { return impl_->hdr; }
const gl::Texture2D& FrameRenderer::view_depth_texture() const { return impl_->depth; }

}  // namespace atonlab::stimuli
