// `none`: each light's direct image only, no glare (docs/scene-file.md "[eye]").
#include "atonlab/stimuli/glare_models/glare_model.h"

namespace atonlab::stimuli {
namespace {

class NoGlare final : public GlareModelType {
public:
    NoGlare() : GlareModelType(GlareModel::none) {}
    std::string_view summary() const override { return "no glare: each light's direct image only"; }
    GlarePath path() const override { return GlarePath::direct; }
};

}  // namespace

const GlareModelType& glare_model_none() {
    static const NoGlare model;
    return model;
}

}  // namespace atonlab::stimuli
