#pragma once
// The glare models' frames on the GPU, one suite (GlareFrames) across the files
// that test them: what every model shares in tests/gl/test_glare.cpp, a model's
// own in tests/gl/glare_models/NAME.cpp. A small eye, a black 320×240 scene of
// one glare model, a light, and the fixture: RendererTest with the energy of
// its frame.
#include <glm/glm.hpp>

#include "atonlab/stimuli/eye_model.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/scene.h"
#include "gl_test_support.h"

namespace atonlab::test {

/// An eye with obstacles but no gratings (those need N ≥ 512 to be resolved), so
/// small sizes exercise every part of the pupil plane quickly.
inline stimuli::EyeModel small_eye() {
    stimuli::EyeModel e;
    e.pupil_diameter_mm = 6.0;
    e.gratings.enabled = false;
    e.halo_radius_deg.reset();
    e.defocus_diopters = 0.5;
    return e;
}

/// 320×240 px at f = 2880 px (about 50 px per degree), black.
inline stimuli::Scene black_scene(stimuli::GlareModel model) {
    stimuli::Scene s;
    s.display = {320, 240, 0.1, 0.9};
    s.camera.position_m = {0, 0, 0};
    s.environment.background = stimuli::Background::uniform;
    s.environment.luminance_cd_m2 = 0.0;
    s.glare.model = model;
    s.glare.eye = small_eye();
    s.glare.psf_size = 256;
    s.glare.pupil_mm = 6.0;
    s.glare.values["bloom_sigma_deg"] = 0.2;
    s.glare.radius_deg = 1.0;
    return s;
}

inline stimuli::Light light_at(glm::dvec3 p, double intensity_cd = 100.0, double radius_m = 0.1) {
    stimuli::Light L;
    L.position_m = p;
    L.intensity_cd = intensity_cd;
    L.radius_m = radius_m;
    return L;
}

/// Outside an anonymous namespace: the suite's tests in several files share this one fixture
/// class (GoogleTest refuses a suite whose tests name different classes).
class GlareFrames : public RendererTest {
protected:
    /// The frame's illuminance at the eye (lux), the energy rule's left-hand side.
    double energy(const stimuli::Scene& scene) {
        renderer->render(scene, 0.0);
        return image_illuminance_lux(renderer->read_hdr(), renderer->projection().focal_px);
    }
};

}  // namespace atonlab::test
