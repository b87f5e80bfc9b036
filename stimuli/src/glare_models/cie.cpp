// `cie`: the CIE glare spread function's veiling glare over the whole frame
// (cie_glare.h, veiling_glare.h), for an observer of cie_age_years and
// cie_pigmentation ([eye]). Not a billboard: the frame renderer convolves the
// direct images of its lights with the veil; `atonlab glare` convolves an
// image with it as a radial kernel.
#include <string>

#include "atonlab/common/input_error.h"
#include "atonlab/common/toml_reader.h"
#include "atonlab/stimuli/cie_glare.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {
namespace {

constexpr std::string_view kEyeKeys[] = {"cie_age_years", "cie_pigmentation"};
constexpr double kDefaultImageRadiusDeg = 20.0;  // `atonlab glare`'s kernel (docs/tone-mapping.md)

class CieVeil final : public GlareModelType {
public:
    CieVeil() : GlareModelType(GlareModel::cie) {}
    std::string_view summary() const override {
        return "the CIE glare spread function's veiling glare over the whole frame (CIE 135/1-1999, Vos & van den "
               "Berg)";
    }
    GlarePath path() const override { return GlarePath::veil; }
    std::span<const std::string_view> eye_keys() const override { return kEyeKeys; }
    void read_eye_keys(const toml_reader::Section& s, GlareSettings& glare) const override {
        if (auto a = s.number("cie_age_years")) {
            s.within("cie_age_years", *a, 0.0, 100.0);
            glare.cie.age_years = *a;
        }
        if (auto p = s.number("cie_pigmentation")) {
            s.within("cie_pigmentation", *p, 0.0, 1.2);
            glare.cie.pigmentation = *p;
        }
        try {
            (void)cie_glare_spread(glare.cie);
        } catch (const InputError& err) {
            // Only a combination of the two can fail here: name the one the file gives (the age first).
            const std::string key = s.get("cie_age_years") ? "cie_age_years" : "cie_pigmentation";
            s.fail(s.get(key), key, err.message());
        }
    }
    bool on_images() const override { return true; }
    double default_radius_deg(const GlareSettings&, double) const override { return kDefaultImageRadiusDeg; }

    GlareKernel image_kernel(const GlareKernelRequest& r) const override {
        const CieGlareSpread gsf = cie_glare_spread(r.glare.cie);
        return glare_kernel_from_radial([gsf](double theta, double) { return gsf.density_sr(theta); }, r.samples,
                                        r.pixels_per_degree, default_glare_radius_deg(r.glare, 0.0), r.glare.window);
    }
};

}  // namespace

const GlareModelType& glare_model_cie() {
    static const CieVeil model;
    return model;
}

}  // namespace atonlab::stimuli
