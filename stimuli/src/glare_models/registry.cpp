// The glare models' registry (glare_model.h): built from glare_model_list.h
// (and register_glare_model), and the defaults of GlareModelType. Adding a
// model touches none of this.
#include <fmt/format.h>

#include <array>
#include <stdexcept>
#include <vector>

#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/scene.h"
#include "glare_setting_reader.h"

namespace atonlab::stimuli {

// Each model's file defines its glare_model_<enumerator>().
#define ATONLAB_GLARE_MODEL_DECLARE(id, name) const GlareModelType& glare_model_##id();
ATONLAB_GLARE_MODELS(ATONLAB_GLARE_MODEL_DECLARE)
#undef ATONLAB_GLARE_MODEL_DECLARE

namespace {

constexpr std::string_view kListed[] = {
#define ATONLAB_GLARE_MODEL_NAME(id, name) name,
    ATONLAB_GLARE_MODELS(ATONLAB_GLARE_MODEL_NAME)
#undef ATONLAB_GLARE_MODEL_NAME
};

struct Entry {
    std::string_view name;
    const GlareModelType* type;
};

// The list's models, then the registered ones (register_glare_model), by enumerator.
struct Registry {
    std::vector<Entry> entries;
    std::vector<const GlareModelType*> types;
};

Registry& registry() {
    static Registry r = [] {
        Registry made;
        const GlareModelType* listed[] = {
#define ATONLAB_GLARE_MODEL_ENTRY(id, name) &glare_model_##id(),
            ATONLAB_GLARE_MODELS(ATONLAB_GLARE_MODEL_ENTRY)
#undef ATONLAB_GLARE_MODEL_ENTRY
        };
        for (std::size_t i = 0; i < std::size(kListed); ++i) {
            made.entries.push_back({kListed[i], listed[i]});
            made.types.push_back(listed[i]);
        }
        return made;
    }();
    return r;
}

}  // namespace

GlareModel register_glare_model(std::string_view name, const GlareModelType& (*instance)(GlareModel id)) {
    Registry& r = registry();
    if (glare_model_from_name(name)) throw std::logic_error(fmt::format("the glare model {} exists already", name));
    if (r.entries.size() > 255) throw std::logic_error("register_glare_model: GlareModel is full");
    const auto id = static_cast<GlareModel>(r.entries.size());
    // The name first: the instance's constructor may ask for it.
    r.entries.push_back({name, nullptr});
    const GlareModelType* type = &instance(id);
    r.entries.back().type = type;
    r.types.push_back(type);
    return id;
}

const GlareModelType& glare_model_type(GlareModel m) {
    const auto i = static_cast<std::size_t>(m);
    if (i >= registry().types.size()) throw std::logic_error("glare_model_type: not a GlareModel");
    return *registry().types[i];
}

std::span<const GlareModelType* const> glare_models() {
    return registry().types;
}

std::string_view glare_model_name(GlareModel m) {
    const auto i = static_cast<std::size_t>(m);
    const auto& e = registry().entries;
    return i < e.size() ? e[i].name : e[0].name;
}

std::optional<GlareModel> glare_model_from_name(std::string_view name) {
    const auto& e = registry().entries;
    for (std::size_t i = 0; i < e.size(); ++i)
        if (e[i].name == name) return static_cast<GlareModel>(i);
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

void GlareModelType::read_glare_keys(const toml_reader::Document&, const toml_reader::Section& s, GlareSettings& g,
                                     double) const {
    read_declared_settings(s, GlareTable::glare, settings(), g);
}

void GlareModelType::read_eye_keys(const toml_reader::Section& s, GlareSettings& g) const {
    read_declared_settings(s, GlareTable::eye, settings(), g);
}

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
