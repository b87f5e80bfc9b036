#include "atonlab/stimuli/glare_stage.h"

#include <epoxy/gl.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/footprint.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/gl/objects.h"
#include "atonlab/stimuli/pupil_kernel_cache.h"
#include "atonlab/stimuli/psf_generator.h"
#include "atonlab/stimuli/spectral_path.h"

namespace atonlab::stimuli {

GlareModel light_glare_model(const Scene& scene, const Light& light) {
    return light.glare.value_or(scene.glare.model);
}

bool any_light_glare(const Scene& scene) {
    return std::any_of(scene.lights.begin(), scene.lights.end(),
                       [&](const Light& l) { return light_glare_model(scene, l) != GlareModel::none; });
}

std::vector<GlareModel> glare_models_used(const Scene& scene) {
    std::vector<GlareModel> out{scene.glare.model};
    for (const Light& l : scene.lights)
        if (const GlareModel m = light_glare_model(scene, l); std::find(out.begin(), out.end(), m) == out.end())
            out.push_back(m);
    return out;
}

std::string_view spectral_path_name(SpectralPath p) {
    switch (p) {
        case SpectralPath::anchored:
            return "anchored";
        case SpectralPath::rescaled:
            return "rescaled";
        case SpectralPath::exact:
            return "exact";
    }
    return "anchored";
}

std::optional<SpectralPath> spectral_path_from_name(std::string_view name) {
    for (SpectralPath p : {SpectralPath::anchored, SpectralPath::rescaled, SpectralPath::exact})
        if (spectral_path_name(p) == name) return p;
    return std::nullopt;
}

double glare_pupil_mm(const Scene& scene) {
    return scene.glare.pupil_mm ? *scene.glare.pupil_mm : pupil_diameter_mm_from_adaptation(scene.adaptation_cd_m2);
}

double cached_pupil_mm(double pupil_mm, double tolerance_mm) {
    if (!(tolerance_mm > 0)) return pupil_mm;
    return std::max(1.0, std::round(pupil_mm / tolerance_mm)) * tolerance_mm;
}

double glare_billboard_radius_deg(const GlareSettings& glare) {
    if (glare_path(glare.model) != GlarePath::billboard) return 0.0;  // none; cie: the whole frame
    return default_glare_radius_deg(glare, glare_psf_degrees_per_texel(glare));
}

double default_glare_radius_deg(const GlareSettings& glare, double psf_degrees_per_texel) {
    if (glare.radius_deg) return *glare.radius_deg;
    return glare_model_type(glare.model).default_radius_deg(glare, psf_degrees_per_texel);
}

double glare_psf_degrees_per_texel(const GlareSettings& glare) {
    return glare_model_type(glare.model).psf_degrees_per_texel(glare);
}


namespace {

display::Spectrum spd_for(const std::string& name) {
    if (name.empty() || name == "d65") return display::d65_spectrum();
    if (auto s = display::named_spectrum(name)) return *s;
    throw InputError(SourceLocation{"", 0, 0, "spd"}, fmt::format("unknown spectrum \"{}\".", name));
}

}  // namespace

struct GlareStage::Impl {
    struct Group {
        GlareModel model = GlareModel::none;
        std::string spd;
        std::optional<RgbPsf> psf;
        GlareKernel kernel;
        AreaLayers layers;
        double layers_radius_px = -1;  // the radius the layers were built for
        int layers_max = 0;
        gl::Buffer layer_buffer;
        GlareGroupReport report;
        std::vector<float> envelope;  // billboard crop table (see envelope_buffer())
        // The moving pupil (GlareSettings::pupil_tolerance_mm not given): the
        // grid kernels, the last pupil and whether it changed at the last frame.
        PupilKernelCache pupil_cache;
        std::string base_key;  // everything the kernel depends on but the pupil
        bool has_pupil = false, pupil_changed = false;
        double pupil = 0;
        double pupil_time_s = 0;  ///< the frame time the pupil was last seen at
    };
    std::map<std::string, Group> groups;  // by model and SPD name ("wave-optics|d65"), kept between frames
    std::vector<std::string> order;       // this frame's groups, index = group id
    std::vector<GlareGroupReport> reports;
    std::vector<unsigned> light_groups;
    std::unique_ptr<GpuPsfGenerator> generator;
    gl::Program billboard;
    gl::VertexArray vao;
    gl::Buffer envelope_buffer;
    unsigned envelope_stride = 0;
    GlareBuildCounts counts;

    ComputePlacement placement = ComputePlacement::automatic;  // the scene's [glare] placement, this frame

    GpuPsfGenerator& generator_for(int n) {
        if (!generator || generator->size() != n ||
            generator->fft_placement() != resolve_placement(placement))
            generator = std::make_unique<GpuPsfGenerator>(n, TwiddleSource::table_from_double, placement);
        return *generator;
    }

    void build_kernel(Group& g, const Scene& scene, double ppd, double time_s, double pupil_mm) {
        // The eye's settings with the group's model (a light may ask for its own).
        GlareSettings gs = scene.glare;
        gs.model = g.model;
        const SpectralSamples samples = spectral_samples(spd_for(g.spd), gs.spectral_samples);
        g.psf.reset();
        g.report = {};
        g.report.model = g.model;
        g.report.spd = g.spd;
        g.report.pupil_mm = pupil_mm;
        GlareModelKernel k = glare_model_type(g.model).billboard_kernel(
            {gs, scene, samples, ppd, pupil_mm, time_s, [this](int n) -> GpuPsfGenerator& { return generator_for(n); }});
        if (k.psf) g.report.psf_fft = glare_model_type(g.model).psf_fft_placement(gs);
        g.psf = std::move(k.psf);
        g.kernel = std::move(k.kernel);
        const double radius = k.radius_deg;
        if (g.psf) g.report.degrees_per_texel = g.psf->degrees_per_texel;
        g.report.kernel_size_px = g.kernel.size;
        g.report.radius_deg = radius;
        g.report.window_cut = g.kernel.window_cut;
        g.envelope = crop_envelope(g.kernel);
        g.report.kernel_peak = g.envelope.empty() ? 0.0 : g.envelope[0];
        g.layers_radius_px = -1;  // rebuild the layers from the new kernel
        ++counts.kernels;
    }

    // The kernel of a moving pupil: interpolated between grid pupils
    // (pupil_kernel_cache.h), their PSFs built only when first needed.
    void interpolate_kernel(Group& g, const Scene& scene, double ppd, double time_s, double pupil_mm) {
        GlareSettings gs = scene.glare;
        gs.model = g.model;
        const SpectralSamples samples = spectral_samples(spd_for(g.spd), gs.spectral_samples);
        const GlareModelType& type = glare_model_type(g.model);
        auto gpu = [this](int n) -> GpuPsfGenerator& { return generator_for(n); };
        auto build = [&](double grid_pupil_mm, const GlareKernelAhead* ahead) {
            GlareKernelRequest r{gs, scene, samples, ppd, grid_pupil_mm, time_s, gpu};
            r.ahead = ahead;
            GlareModelKernel k = type.billboard_kernel(r);
            ++counts.kernels;
            counts.kernels_ahead += ahead ? 1 : 0;
            return std::move(k.kernel);
        };
        // The next grid pupil's work without GL (the GPU build's pupil planes)
        // on a worker thread, ready when the pupil gets there.
        auto plan = [&](double grid_pupil_mm) {
            return type.work_ahead({gs, scene, samples, ppd, grid_pupil_mm, time_s, gpu});
        };
        g.kernel = g.pupil_cache.kernel_at(pupil_mm, build, plan);
        g.psf.reset();  // no PSF at this pupil: the kernel is the grid kernels' cubic
        g.report = {};
        g.report.model = g.model;
        g.report.spd = g.spd;
        g.report.pupil_mm = pupil_mm;
        gs.eye.pupil_diameter_mm = pupil_mm;
        g.report.degrees_per_texel = type.psf_degrees_per_texel(gs);
        g.report.kernel_size_px = g.kernel.size;
        g.report.radius_deg = g.kernel.radius_px / ppd;
        g.report.window_cut = g.kernel.window_cut;
        g.envelope = crop_envelope(g.kernel);
        g.report.kernel_peak = g.envelope.empty() ? 0.0 : g.envelope[0];
        g.layers_radius_px = -1;
        ++counts.interpolations;
    }

    // The group's kernel for this frame's pupil: kept while the pupil stays,
    // built for it exactly when it has just changed (or was given a rounding
    // step), interpolated while it keeps moving (hippus, or a change at each of
    // the last two frames with the frame time advancing at each: a dusk-to-night
    // sequence, not a new trial). A frame at the same or an earlier time starts
    // a new sequence, so the kernel never depends on stimuli rendered before it
    // (a session's pre-check renders every condition at t = 0; a resumed session
    // must draw the same kernels as the uninterrupted one).
    void update_kernel(Group& g, const Scene& scene, double ppd, double time_s, double pupil_mm,
                       const std::string& base_key) {
        if (g.base_key != base_key) {
            g.pupil_cache.clear();
            g.has_pupil = g.pupil_changed = false;
            g.base_key = base_key;
        }
        const bool continues = g.has_pupil && time_s > g.pupil_time_s;
        g.pupil_time_s = time_s;
        if (g.has_pupil && pupil_mm == g.pupil) {
            g.pupil_changed = false;
            return;
        }
        const GlareSettings& gs = scene.glare;
        const bool moving = !gs.pupil_tolerance_mm && (gs.eye.hippus.enabled || (continues && g.pupil_changed));
        bool done = false;
        if (moving) {
            try {
                interpolate_kernel(g, scene, ppd, time_s, pupil_mm);
                done = true;
            } catch (const InputError&) {
                // A grid pupil the eye refuses (beyond its defocus limit, next to
                // the largest pupil): this pupil exactly, as without the cache.
            }
        }
        if (!done) build_kernel(g, scene, ppd, time_s, pupil_mm);
        g.pupil_changed = continues;
        g.has_pupil = true;
        g.pupil = pupil_mm;
    }

    // Largest texel (any channel) at Chebyshev distance ≥ e from the centre,
    // e = 0 … half, then a 0 sentinel: the table light_eval.comp crops with.
    static std::vector<float> crop_envelope(const GlareKernel& k) {
        const int h = k.half();
        std::vector<float> ring(static_cast<std::size_t>(h) + 2, 0.0f);
        for (int j = 0; j < k.size; ++j)
            for (int i = 0; i < k.size; ++i) {
                const auto d = static_cast<std::size_t>(std::max(std::abs(i - h), std::abs(j - h)));
                const glm::vec4& v = k.at(i, j);
                ring[d] = std::max({ring[d], v.r, v.g, v.b});
            }
        for (int d = h - 1; d >= 0; --d)
            ring[static_cast<std::size_t>(d)] =
                std::max(ring[static_cast<std::size_t>(d)], ring[static_cast<std::size_t>(d) + 1]);
        return ring;
    }
};

GlareStage::GlareStage() : impl_(std::make_unique<Impl>()) {}
GlareStage::~GlareStage() = default;

const std::vector<GlareGroupReport>& GlareStage::report() const {
    return impl_->reports;
}
const std::vector<unsigned>& GlareStage::light_groups() const {
    return impl_->light_groups;
}

const RgbPsf* GlareStage::psf(std::size_t group) const {
    if (group >= impl_->order.size()) return nullptr;
    const auto& g = impl_->groups.at(impl_->order[group]);
    return g.psf ? &*g.psf : nullptr;
}

const gl::Buffer& GlareStage::envelope_buffer() const {
    return impl_->envelope_buffer;
}
unsigned GlareStage::envelope_stride() const {
    return impl_->envelope_stride;
}
GlareBuildCounts GlareStage::build_counts() const {
    return impl_->counts;
}

const GlareKernel* GlareStage::kernel(std::size_t group) const {
    if (group >= impl_->order.size()) return nullptr;
    return &impl_->groups.at(impl_->order[group]).kernel;
}

double GlareStage::prepare(const Scene& scene, const CameraProjection& P, double time_s) {
    Impl& m = *impl_;
    const GlareSettings& gs = scene.glare;
    m.placement = gs.placement;
    m.order.clear();
    m.reports.clear();
    m.light_groups.assign(scene.lights.size(), 0u);
    m.envelope_stride = 0;

    // Groups of (model, SPD) in order of first appearance, for the lights whose
    // model draws a billboard; `none` and `cie` lights have none (the frame
    // renderer draws their direct images, and convolves the `cie` ones).
    std::vector<GlareModel> group_models;
    std::vector<std::string> group_spds;
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const GlareModel model = light_glare_model(scene, scene.lights[i]);
        if (glare_path(model) != GlarePath::billboard) continue;
        // "" is D65 (scene.h Light::spd): one group with the lights that name it.
        const std::string spd = scene.lights[i].spd.empty() ? "d65" : scene.lights[i].spd;
        const std::string name = fmt::format("{}|{}", glare_model_name(model), spd);
        auto it = std::find(m.order.begin(), m.order.end(), name);
        if (it == m.order.end()) {
            m.order.push_back(name);
            group_models.push_back(model);
            group_spds.push_back(spd);
            it = m.order.end() - 1;
        }
        m.light_groups[i] = static_cast<unsigned>(it - m.order.begin());
    }
    if (m.order.empty()) return 0.0;

    // The kernel depends on these, and only these: rebuilt when one changes.
    const double ppd = scene.display.pixels_per_degree_at_centre();
    const double pupil = glare_pupil_mm(scene);
    auto pupil_for = [&](GlareModel model) {
        return cached_pupil_mm(glare_model_type(model).kernel_pupil_mm(gs, pupil, time_s),
                               gs.pupil_tolerance_mm.value_or(0.0));
    };

    // The largest projected radius each group needs (lights in front whose glare can reach the image).
    std::vector<double> need(m.order.size(), 0.0);
    const glm::dmat3 view_from_world = glm::transpose(P.world_from_view);
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const Light& L = scene.lights[i];
        if (glare_path(light_glare_model(scene, L)) != GlarePath::billboard) continue;  // no billboard
        const Footprint fp = light_footprint(view_from_world * (L.position_m - P.eye_position_m), L.radius_m,
                                             P.focal_px, P.width_px, P.height_px);
        if (!fp.visible) continue;
        need[m.light_groups[i]] = std::max(need[m.light_groups[i]], std::sqrt(fp.area_px2 / std::numbers::pi));
    }

    double extent = 0;
    for (std::size_t gi = 0; gi < m.order.size(); ++gi) {
        auto& g = m.groups[m.order[gi]];
        g.model = group_models[gi];
        g.spd = group_spds[gi];
        // The pupil the kernel is computed for (hippus and the cache's tolerance applied).
        const double pupil_now = pupil_for(g.model);
        // What of the scene the model's kernel reads (Spencer's vision class; the
        // wave-optics eye's kernel does not change where the adaptation crosses
        // 0.001 cd/m², so a dusk-to-night sweep keeps its cached kernels), and
        // every setting the model declares (glare_kernel_key).
        const std::string key = glare_kernel_key(scene, g.model, g.spd);
        m.update_kernel(g, scene, ppd, time_s, pupil_now, key);
        // Layers only where a light covers more than a pixel; radius rounded up
        // to a power of two so a light approaching does not rebuild every frame.
        double r_build = 0;
        if (need[gi] >= 1.0) {
            r_build = 1;
            while (r_build < need[gi]) r_build *= 2;
            r_build = std::min(r_build, 256.0);  // beyond, the largest layer is used (energy still conserved)
        }
        if (r_build > g.layers_radius_px || gs.area_layers != g.layers_max || !g.layer_buffer) {
            g.layers = build_area_layers(g.kernel, r_build, std::max(2, gs.area_layers));
            g.layers_radius_px = r_build;
            g.layers_max = gs.area_layers;
            g.layer_buffer = gl::Buffer(g.layers.rgba.size() * sizeof(glm::vec4), g.layers.rgba.data(),
                                        gl::BufferUsage::static_draw);
            ++m.counts.layers;
        }
        g.report.area_layers = g.layers.layers;
        g.report.area_max_radius_px = g.layers.max_radius_px();
        m.reports.push_back(g.report);
        extent = std::max(extent, static_cast<double>(g.kernel.half()) + 1.0);
    }

    // The crop tables of this frame's groups, one stride apart: the envelope
    // zero-padded, then the group's area-layer step (px).
    std::size_t stride = 0;
    for (const auto& name : m.order) stride = std::max(stride, m.groups.at(name).envelope.size() + 1);
    std::vector<float> table(std::max<std::size_t>(1, stride * m.order.size()), 0.0f);
    for (std::size_t gi = 0; gi < m.order.size(); ++gi) {
        const auto& g = m.groups.at(m.order[gi]);
        std::copy(g.envelope.begin(), g.envelope.end(), table.begin() + static_cast<std::ptrdiff_t>(gi * stride));
        table[gi * stride + stride - 1] = static_cast<float>(g.layers.radius_step_px);
    }
    const std::size_t bytes = table.size() * sizeof(float);
    if (!m.envelope_buffer || m.envelope_buffer.size() < bytes)
        m.envelope_buffer = gl::Buffer(bytes, table.data(), gl::BufferUsage::dynamic_draw);
    else
        m.envelope_buffer.upload(0, bytes, table.data());
    m.envelope_stride = static_cast<unsigned>(stride);
    return extent;
}

void GlareStage::draw(int light_count, const CameraProjection& P, double pre_exposure) {
    Impl& m = *impl_;
    if (m.order.empty() || light_count == 0) return;
    if (!m.billboard) {
        m.billboard = gl::Program::build({{gl::ShaderStage::vertex, "glare_billboard.vert"},
                                          {gl::ShaderStage::geometry, "glare_billboard.geom"},
                                          {gl::ShaderStage::fragment, "glare_billboard.frag"}});
        m.vao = gl::VertexArray::create();
    }
    const auto w = static_cast<float>(P.width_px), h = static_cast<float>(P.height_px);
    m.billboard.set("image_size", w, h);
    m.billboard.set("focal_px", static_cast<float>(P.focal_px));
    m.billboard.set("pre_exposure", static_cast<float>(pre_exposure));
    m.billboard.use();
    m.vao.bind();
    for (std::size_t gi = 0; gi < m.order.size(); ++gi) {
        const auto& g = m.groups.at(m.order[gi]);
        g.layer_buffer.bind_storage(5);
        m.billboard.set("group", static_cast<unsigned>(gi));
        m.billboard.set("kernel_half_px", static_cast<float>(g.kernel.half()));
        m.billboard.set("layer_half_px", static_cast<float>(g.layers.half()));
        m.billboard.set("layer_step_px", static_cast<float>(g.layers.radius_step_px));
        m.billboard.set("layer_count", g.layers.layers);
        m.billboard.set("layer_size", g.layers.size);
        glDrawArrays(GL_POINTS, 0, light_count);
    }
}

}  // namespace atonlab::stimuli
