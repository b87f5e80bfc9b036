// `cie`: the CIE glare spread function's veiling glare over the whole frame
// (cie_glare.h, veiling_glare.h), for an observer of cie_age_years and
// cie_pigmentation ([eye]). Not a billboard: the frame renderer convolves the
// direct images of its lights with the veil; `atonlab glare` convolves an
// image with it as a radial kernel.
#include <fmt/format.h>

#include <string>

#include "atonlab/common/input_error.h"
#include "atonlab/common/toml_reader.h"
#include "atonlab/stimuli/cie_glare.h"
#include "atonlab/stimuli/glare_models/glare_model.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::stimuli {
namespace {

constexpr std::string_view kAge = "cie_age_years", kPigmentation = "cie_pigmentation";

const GlareSetting kSettings[] = {
    {.key = kAge,
     .table = GlareTable::eye,
     .type = "number",
     .unit = "years",
     .default_text = "25",
     .doc = "`cie`: the observer's age A, 0 … 100",
     .example = "60",
     .default_value = 25.0,
     .check =
         [](const GlareSettingValue& v) {
             const double a = std::get<double>(v);
             return a >= 0 && a <= 100
                        ? std::string()
                        : fmt::format("cie_age_years must be between 0 and 100, got {}.", toml_reader::number_text(a));
         }},
    {.key = kPigmentation,
     .table = GlareTable::eye,
     .type = "number",
     .unit = "—",
     .default_text = "0.5",
     .doc = "`cie`: ocular pigmentation p, 0 … 1.2 (0 very dark, 0.5 brown, 1.0 light blue-green, 1.2 very light "
            "blue eyes)",
     .example = "1",
     .default_value = 0.5,
     .check =
         [](const GlareSettingValue& v) {
             const double p = std::get<double>(v);
             return p >= 0 && p <= 1.2 ? std::string()
                                       : fmt::format("cie_pigmentation must be between 0 and 1.2, got {}.",
                                                     toml_reader::number_text(p));
         }},
};
constexpr double kDefaultImageRadiusDeg = 20.0;  // `atonlab glare`'s kernel (docs/tone-mapping.md)

class CieVeil final : public GlareModelType {
public:
    CieVeil() : GlareModelType(GlareModel::cie) {}
    std::string_view summary() const override {
        return "the CIE glare spread function's veiling glare over the whole frame (CIE 135/1-1999, Vos & van den "
               "Berg)";
    }
    GlarePath path() const override { return GlarePath::veil; }
    std::span<const GlareSetting> settings() const override { return kSettings; }
    void read_eye_keys(const toml_reader::Section& s, GlareSettings& glare) const override {
        GlareModelType::read_eye_keys(s, glare);
        try {
            (void)cie_glare_spread(cie_observer(glare));
        } catch (const InputError& err) {
            // Only a combination of the two can fail here: name the one the file gives (the age first).
            const std::string key(s.get(kAge) ? kAge : kPigmentation);
            s.fail(s.get(key), key, err.message());
        }
    }
    bool on_images() const override { return true; }
    double default_radius_deg(const GlareSettings&, double) const override { return kDefaultImageRadiusDeg; }

    GlareKernel image_kernel(const GlareKernelRequest& r) const override {
        const CieGlareSpread gsf = cie_glare_spread(cie_observer(r.glare));
        return glare_kernel_from_radial([gsf](double theta, double) { return gsf.density_sr(theta); }, r.samples,
                                        r.pixels_per_degree, default_glare_radius_deg(r.glare, 0.0), r.glare.window);
    }
};

}  // namespace

CieObserver cie_observer(const GlareSettings& g) {
    return CieObserver{glare_number(g, kAge), glare_number(g, kPigmentation)};
}

const GlareModelType& glare_model_cie() {
    static const CieVeil model;
    return model;
}

}  // namespace atonlab::stimuli
