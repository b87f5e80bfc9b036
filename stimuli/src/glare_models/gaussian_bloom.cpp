// `gaussian-bloom`: a monochromatic Gaussian blur of standard deviation
// bloom_sigma_deg (K2012 §3.4.1, after Kawase 2005 and Kakimoto et al. 2005).
#include <fmt/format.h>

#include <cmath>
#include <string>

#include "atonlab/common/toml_reader.h"
#include "atonlab/stimuli/error.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {
namespace {

constexpr std::string_view kSigma = "bloom_sigma_deg";

const GlareSetting kSettings[] = {
    {.key = kSigma,
     .type = "number",
     .unit = "°",
     .default_text = "0.25",
     .doc = "`gaussian-bloom`: standard deviation",
     .example = "0.5",
     .default_value = 0.25,
     .check =
         [](const GlareSettingValue& v) {
             const double s = std::get<double>(v);
             return s > 0 ? std::string()
                          : fmt::format("bloom_sigma_deg must be greater than 0, got {}.", toml_reader::number_text(s));
         }},
};

class GaussianBloom final : public GlareModelType {
public:
    GaussianBloom() : GlareModelType(GlareModel::gaussian_bloom) {}
    std::string_view summary() const override {
        return "a monochromatic Gaussian blur of standard deviation bloom_sigma_deg (K2012 §3.4.1)";
    }
    std::span<const GlareSetting> settings() const override { return kSettings; }
    bool on_images() const override { return true; }
    /// 4σ: the Gaussian's tail beyond holds 3e-4 of its energy (restored by the renormalisation).
    double default_radius_deg(const GlareSettings& g, double) const override { return 4.0 * glare_number(g, kSigma); }

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
        const double s = glare_number(r.glare, kSigma);
        if (!(s > 0))
            throw InputError(SourceLocation{"", 0, 0, "bloom_sigma_deg"},
                             fmt::format("the bloom's standard deviation must be positive, not {} degrees.", s));
        return glare_kernel_from_radial([s](double theta, double) { return std::exp(-0.5 * theta * theta / (s * s)); },
                                        r.samples, r.pixels_per_degree, radius_deg, r.glare.window);
    }
};

}  // namespace

const GlareModelType& glare_model_gaussian_bloom() {
    static const GaussianBloom model;
    return model;
}

}  // namespace atonlab::stimuli
