// `spencer`: the analytic PSF of Spencer et al. 1995 (eye_model.h spencer_psf)
// for the photopic, mesopic or scotopic eye (spencer_vision).
#include <fmt/format.h>

#include <string>

#include "atonlab/common/toml_reader.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {
namespace {

constexpr std::string_view kVision = "spencer_vision";

const GlareSetting kSettings[] = {
    {.key = kVision,
     .type = "string",
     .unit = "—",
     .default_text = "`\"auto\"`",
     .doc = "`\"photopic\"`, `\"mesopic\"`, `\"scotopic\"`; auto: ≥ 3 cd/m² photopic, ≤ 0.001 cd/m² scotopic",
     .example = "\"photopic\"",
     .default_value = std::string("auto"),
     .check =
         [](const GlareSettingValue& v) {
             const std::string& s = std::get<std::string>(v);
             if (s == "photopic" || s == "mesopic" || s == "scotopic" || s == "auto") return std::string();
             return fmt::format(
                 "unknown vision \"{}\"; it must be \"photopic\", \"mesopic\", \"scotopic\" or \"auto\".", s);
         }},
};
constexpr double kDefaultRadiusDeg = 6.0;  // the billboard radius glare_stage.h gives Spencer's PSF

class Spencer final : public GlareModelType {
public:
    Spencer() : GlareModelType(GlareModel::spencer) {}
    std::string_view summary() const override {
        return "the analytic PSF of Spencer et al. 1995, photopic, mesopic or scotopic (spencer_vision)";
    }
    std::span<const GlareSetting> settings() const override { return kSettings; }
    bool on_images() const override { return true; }
    double default_radius_deg(const GlareSettings&, double) const override { return kDefaultRadiusDeg; }
    std::string kernel_scene_key(const Scene& scene) const override {
        return fmt::format("vision {}", static_cast<int>(spencer_vision_for(scene)));
    }

    GlareModelKernel billboard_kernel(const GlareKernelRequest& r) const override {
        GlareModelKernel k;
        k.radius_deg = default_glare_radius_deg(r.glare, 0.0);
        k.kernel = kernel(r, k.radius_deg);
        return k;
    }
    GlareKernel image_kernel(const GlareKernelRequest& r) const override {
        return kernel(r, default_glare_radius_deg(r.glare, 0.0));
    }

private:
    static GlareKernel kernel(const GlareKernelRequest& r, double radius_deg) {
        const SpencerVision vision = spencer_vision_for(r.scene);
        return glare_kernel_from_radial(
            [vision](double theta, double lambda) { return spencer_psf(theta, lambda, vision); }, r.samples,
            r.pixels_per_degree, radius_deg, r.glare.window);
    }
};

}  // namespace

SpencerVision spencer_vision_for(const Scene& scene) {
    const std::string v = glare_text(scene.glare, kVision);
    if (v == "photopic") return SpencerVision::photopic;
    if (v == "mesopic") return SpencerVision::mesopic;
    if (v == "scotopic") return SpencerVision::scotopic;
    if (scene.adaptation_cd_m2 >= 3.0) return SpencerVision::photopic;
    if (scene.adaptation_cd_m2 <= 0.001) return SpencerVision::scotopic;
    return SpencerVision::mesopic;
}

const GlareModelType& glare_model_spencer() {
    static const Spencer model;
    return model;
}

}  // namespace atonlab::stimuli
