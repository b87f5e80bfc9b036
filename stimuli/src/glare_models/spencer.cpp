// `spencer`: the analytic PSF of Spencer et al. 1995 (eye_model.h spencer_psf)
// for the photopic, mesopic or scotopic eye (spencer_vision).
#include <fmt/format.h>

#include "atonlab/common/toml_reader.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {
namespace {

constexpr std::string_view kKeys[] = {"spencer_vision"};
constexpr double kDefaultRadiusDeg = 6.0;  // the billboard radius glare_stage.h gives Spencer's PSF

class Spencer final : public GlareModelType {
public:
    Spencer() : GlareModelType(GlareModel::spencer) {}
    std::string_view summary() const override {
        return "the analytic PSF of Spencer et al. 1995, photopic, mesopic or scotopic (spencer_vision)";
    }
    std::span<const std::string_view> glare_keys() const override { return kKeys; }
    void read_glare_keys(const toml_reader::Document&, const toml_reader::Section& s, GlareSettings& g,
                         double) const override {
        const auto v = s.string("spencer_vision");
        if (!v) return;
        if (*v == "photopic")
            g.spencer_vision = SpencerVision::photopic;
        else if (*v == "mesopic")
            g.spencer_vision = SpencerVision::mesopic;
        else if (*v == "scotopic")
            g.spencer_vision = SpencerVision::scotopic;
        else if (*v != "auto")
            s.fail(s.get("spencer_vision"), "spencer_vision",
                   fmt::format("unknown vision \"{}\"; it must be \"photopic\", \"mesopic\", \"scotopic\" or \"auto\".",
                               *v));
    }
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

const GlareModelType& glare_model_spencer() {
    static const Spencer model;
    return model;
}

}  // namespace atonlab::stimuli
