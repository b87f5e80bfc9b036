// The glare models' registry (glare_model.h): built from glare_model_list.h,
// and the defaults of GlareModelType. Adding a model touches none of this.
#include <fmt/format.h>

#include <array>
#include <stdexcept>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {

// Each model's file defines its glare_model_<enumerator>().
#define ATONLAB_GLARE_MODEL_DECLARE(id, name) const GlareModelType& glare_model_##id();
ATONLAB_GLARE_MODELS(ATONLAB_GLARE_MODEL_DECLARE)
#undef ATONLAB_GLARE_MODEL_DECLARE

namespace {

constexpr std::string_view kNames[] = {
#define ATONLAB_GLARE_MODEL_NAME(id, name) name,
    ATONLAB_GLARE_MODELS(ATONLAB_GLARE_MODEL_NAME)
#undef ATONLAB_GLARE_MODEL_NAME
};

const std::array<const GlareModelType*, std::size(kNames)>& registry() {
    static const std::array<const GlareModelType*, std::size(kNames)> models = {
#define ATONLAB_GLARE_MODEL_ENTRY(id, name) &glare_model_##id(),
        ATONLAB_GLARE_MODELS(ATONLAB_GLARE_MODEL_ENTRY)
#undef ATONLAB_GLARE_MODEL_ENTRY
    };
    return models;
}

}  // namespace

const GlareModelType& glare_model_type(GlareModel m) {
    const auto i = static_cast<std::size_t>(m);
    if (i >= registry().size()) throw std::logic_error("glare_model_type: not a GlareModel");
    return *registry()[i];
}

std::span<const GlareModelType* const> glare_models() {
    return registry();
}

std::string_view glare_model_name(GlareModel m) {
    const auto i = static_cast<std::size_t>(m);
    return i < std::size(kNames) ? kNames[i] : kNames[0];
}

std::optional<GlareModel> glare_model_from_name(std::string_view name) {
    for (std::size_t i = 0; i < std::size(kNames); ++i)
        if (kNames[i] == name) return static_cast<GlareModel>(i);
    return std::nullopt;
}

std::string glare_model_choices(std::string_view quote, const std::function<bool(const GlareModelType&)>& keep) {
    std::vector<std::string_view> names;
    for (const GlareModelType* m : glare_models())
        if (!keep || keep(*m)) names.push_back(m->name());
    std::string s;
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (i > 0) s += i + 1 == names.size() ? " or " : ", ";
        s += fmt::format("{}{}{}", quote, names[i], quote);
    }
    return s;
}

GlarePath glare_path(GlareModel m) {
    return glare_model_type(m).path();
}

// ---------------------------------------------------------------------------
// GlareModelType's defaults: a model with no keys of its own, no PSF, drawn
// with the frame's pupil.

std::string_view GlareModelType::name() const {
    return glare_model_name(id_);
}

void GlareModelType::read_glare_keys(const toml_reader::Document&, const toml_reader::Section&, GlareSettings&,
                                     double) const {}

void GlareModelType::read_eye_keys(const toml_reader::Section&, GlareSettings&) const {}

bool GlareModelType::available(const GlareSettings&) const {
    return path() != GlarePath::direct;
}

double GlareModelType::psf_degrees_per_texel(const GlareSettings&) const {
    return 0.0;
}

double GlareModelType::default_radius_deg(const GlareSettings&, double) const {
    return 0.0;
}

double GlareModelType::kernel_pupil_mm(const GlareSettings&, double pupil_mm, double) const {
    return pupil_mm;
}

GlareModelKernel GlareModelType::billboard_kernel(const GlareKernelRequest&) const {
    throw std::logic_error(fmt::format("the glare model {} draws no billboard", name()));
}

GlareKernel GlareModelType::image_kernel(const GlareKernelRequest&) const {
    throw InputError(
        SourceLocation{"", 0, 0, "model"},
        fmt::format("an image's glare can be {}, not {}.",
                    glare_model_choices("", [](const GlareModelType& t) { return t.on_images(); }), name()));
}

}  // namespace atonlab::stimuli
