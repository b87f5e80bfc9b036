#pragma once
// The glare models: the one list of them, and the only place their names are
// spelled (docs/architecture.md "How to add a glare model"). Each entry is
// X(enumerator, "name"): the enumerator of GlareModel and the name a scene file
// (`[eye] glare`, a light's `glare`), `--set` and `atonlab glare --model` use.
// Each model is one file (one folder for wave optics) under
// stimuli/src/glare_models/ defining glare_model_<enumerator>() (glare_model.h).
// The order is GlareModel's, and the order help texts, error messages and
// `atonlab view`'s m key list the models in.
#include <cstdint>

#define ATONLAB_GLARE_MODELS(X)         \
    X(none, "none")                     \
    X(wave_optics, "wave-optics")       \
    X(gaussian_bloom, "gaussian-bloom") \
    X(spencer, "spencer")               \
    X(aperture, "aperture")             \
    X(cie, "cie")

namespace atonlab::stimuli {

/// The glare model of the eye or of a light (docs/architecture.md "The pipeline, one
/// frame", step 3; K2012 §4.2-4.3): what each one draws is its GlareModelType's summary().
enum class GlareModel : std::uint8_t {
#define ATONLAB_GLARE_MODEL_ENUMERATOR(id, name) id,
    ATONLAB_GLARE_MODELS(ATONLAB_GLARE_MODEL_ENUMERATOR)
#undef ATONLAB_GLARE_MODEL_ENUMERATOR
};

}  // namespace atonlab::stimuli
