#pragma once
// A GoogleTest environment that owns one headless GL 4.5 context for a test
// executable. GL tests skip (with the context error as the reason) only where
// no GL 4.5 core context can be made; on llvmpipe they run.
#include <gtest/gtest.h>

#include <glm/glm.hpp>
#include <memory>
#include <string>

#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/stimuli/image_io.h"

namespace atonlab::test {

/// The shared context, created on first use; nullptr if unavailable.
gl::Context* gl_context();
/// Why the context is unavailable (empty if it is available).
const std::string& gl_unavailable_reason();

/// Σ L·Ω over an HDR frame (top row first), per channel (lux), Ω the exact
/// pinhole solid angle of each pixel for focal length focal_px.
glm::dvec3 image_illuminance_rgb_lux(const stimuli::ImageRGBA32F& img, double focal_px);
/// The same for luminance Y (lux): the energy rule's left-hand side.
double image_illuminance_lux(const stimuli::ImageRGBA32F& img, double focal_px);

/// Base fixture: makes the shared context current or skips the test.
class GLTest : public ::testing::Test {
protected:
    void SetUp() override;
};

/// A GL test with one FrameRenderer, made once the context is there; render() draws a scene at
/// t = 0 and reads its HDR frame back (cd/m², the alpha its scotopic channel).
class RendererTest : public GLTest {
protected:
    void SetUp() override {
        GLTest::SetUp();
        if (!IsSkipped()) renderer = std::make_unique<stimuli::FrameRenderer>();
    }
    stimuli::ImageRGBA32F render(const stimuli::Scene& scene) {
        renderer->render(scene, 0.0);
        return renderer->read_hdr();
    }
    std::unique_ptr<stimuli::FrameRenderer> renderer;
};

}  // namespace atonlab::test
