// `toy-disc`: a glare model written for the tests, in one file, to hold
// docs/architecture.md's claim that a model with a setting of its own is its
// file and one registry line (here register_glare_model below, where a model
// of the library has its X(...) line in glare_model_list.h). Its PSF is a
// uniform disc of angular radius toy_radius_deg: each light's energy spread
// evenly over the disc, nothing beyond it (tests/gl/test_toy_glare_model.cpp).
#include <fmt/format.h>

#include <string>

#include "atonlab/common/toml_reader.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {
namespace {

constexpr std::string_view kRadius = "toy_radius_deg";

const GlareSetting kSettings[] = {
    {.key = kRadius,
     .type = "number",
     .unit = "°",
     .default_text = "0.5",
     .doc = "`toy-disc`: the disc's angular radius",
     .example = "1",
     .default_value = 0.5,
     .check =
         [](const GlareSettingValue& v) {
             const double r = std::get<double>(v);
             return r > 0 && r <= 5
                        ? std::string()
                        : fmt::format("toy_radius_deg must be between 0 and 5, got {}.", toml_reader::number_text(r));
         }},
};

class ToyDisc final : public GlareModelType {
public:
    explicit ToyDisc(GlareModel id) : GlareModelType(id) {}
    std::string_view summary() const override { return "a uniform disc of toy_radius_deg (a test's model)"; }
    std::span<const GlareSetting> settings() const override { return kSettings; }
    bool on_images() const override { return true; }
    double default_radius_deg(const GlareSettings& g, double) const override { return glare_number(g, kRadius); }
    GlareModelKernel billboard_kernel(const GlareKernelRequest& r) const override {
        GlareModelKernel k;
        k.radius_deg = glare_number(r.glare, kRadius);
        k.kernel = image_kernel(r);
        return k;
    }
    // No window: the disc ends at its radius by itself.
    GlareKernel image_kernel(const GlareKernelRequest& r) const override {
        const double radius = glare_number(r.glare, kRadius);
        return glare_kernel_from_radial([radius](double theta, double) { return theta <= radius ? 1.0 : 0.0; },
                                        r.samples, r.pixels_per_degree, radius, GlareWindow::none);
    }
};

const GlareModelType& toy_disc(GlareModel id) {
    static const ToyDisc model(id);
    return model;
}

}  // namespace

// The registry line.
[[maybe_unused]] const GlareModel kToyDisc = register_glare_model("toy-disc", toy_disc);

}  // namespace atonlab::stimuli
