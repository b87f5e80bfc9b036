// The session's StimulusRenderer encodes a frame through stimuli::Pipeline
// (runner/src/session/stimulus_renderer.cpp; issue 13): its code values must
// be, pixel for pixel, (1) the first frame a fresh Pipeline renders, and (2)
// what the runner's own copy of the pipeline made before issue 13 (a
// FrameRenderer and a DisplayPipeline, the linear white written out, dither
// frame 0, adaptation reset), which is rebuilt here as the reference. Three
// frames: no glare, glare on the HDR path, glare on the LDR path; each with
// spatio-temporal dither, whose pattern depends on the frame index.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "atonlab/common/read_file.h"
#include "atonlab/display/tonemap.h"
#include "atonlab/protocols/protocol.h"
#include "atonlab/runner/session/session_inputs.h"
#include "atonlab/runner/session/stimulus_renderer.h"
#include "atonlab/stimuli/display_pipeline.h"
#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/glare_stage.h"
#include "atonlab/stimuli/pipeline.h"
#include "gl_test_support.h"

namespace atonlab {
namespace {

namespace s = atonlab::stimuli;

const std::filesystem::path kScene = std::filesystem::path(ATONLAB_SOURCE_DIR) / "tests/data/run/small.scene.toml";

/// The runner's encode path as run_session.cpp wrote it before issue 13.
s::EncodedImage old_runner_codes(const s::Scene& sc) {
    s::FrameRenderer frame;
    s::DisplayPipeline display;
    frame.render(sc, 0.0);
    const s::OutputSettings& os = sc.output;
    display.reset_adaptation();
    if (const gl::Texture2D* glare = frame.glare_texture();
        glare && os.ldr_glare && (sc.glare.model != s::GlareModel::none || s::any_light_glare(sc))) {
        const display::ToneMapSettings& tm = os.tonemap;
        const double white = tm.white_cd_m2
                                 ? *tm.white_cd_m2
                                 : sc.adaptation_cd_m2 * tm.display_peak_cd_m2 / display::display_adaptation_cd_m2(tm);
        display.process_ldr(frame.hdr_texture(), *glare, os, sc.adaptation_cd_m2, 0, 1.0 / white);
    } else {
        display.process(frame.hdr_texture(), os, sc.adaptation_cd_m2, 0.0, 0);
    }
    return display.read_codes();
}

/// A fresh Pipeline's first frame, with the renderer's frame options (no skips).
s::EncodedImage pipeline_codes(const s::Scene& sc) {
    s::Pipeline pipeline;
    pipeline.set_frame_options(s::FrameOptions{});
    pipeline.render(sc, 0.0, 0.0);
    return pipeline.display().read_codes();
}

void expect_same_codes(const s::EncodedImage& a, const s::EncodedImage& b, const std::string& what) {
    ASSERT_EQ(a.width, b.width) << what;
    ASSERT_EQ(a.height, b.height) << what;
    ASSERT_EQ(a.bits, b.bits) << what;
    ASSERT_EQ(a.rgb.size(), b.rgb.size()) << what;
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.rgb.size(); ++i) differ += a.rgb[i] != b.rgb[i] ? 1 : 0;
    EXPECT_EQ(differ, 0u) << what << ": channel values that differ";
}

class RendererPipeline : public test::GLTest {};

TEST_F(RendererPipeline, RendererCodesAreThePipelinesAndTheOldCopysEveryPixel) {
    runner::StimulusRenderer renderer(s::SceneTemplate::load(kScene), 0.5, 0.5);
    const SceneOverride dither{"display.dither", "true"};
    const SceneOverride spencer{"eye.glare", "spencer"};
    const std::vector<std::vector<SceneOverride>> frames{
        {dither},
        {dither, spencer},
        {dither, spencer, {"tonemap.ldr_glare", "true"}},
    };
    for (const std::vector<SceneOverride>& overrides : frames) {
        std::string what;
        for (const SceneOverride& o : overrides) what += o.text() + " ";
        const s::Scene sc = *renderer.scene(overrides);
        ASSERT_EQ(sc.output.encode.dither, display::Dither::spatiotemporal) << what;
        const auto codes = renderer.codes(protocols::Frame{std::nullopt, overrides}, {});
        expect_same_codes(*codes, pipeline_codes(sc), what + "(Pipeline)");
        expect_same_codes(*codes, old_runner_codes(sc), what + "(the runner's copy before issue 13)");
    }
    // Each override list went through the scene loader once, though scene(),
    // codes() and the frame's views each asked for its scene.
    EXPECT_EQ(renderer.scenes_parsed(), frames.size());
    (void)renderer.views(protocols::Frame{std::nullopt, frames[0]}, {});
    EXPECT_TRUE(renderer.animated(protocols::Frame{std::nullopt, frames[1]}) == false);
    EXPECT_EQ(renderer.scenes_parsed(), frames.size());
    // A display model set later is a different scene: the cache starts again.
    renderer.use_display_model(display::DisplayModel::srgb(80.0, 0.2));
    EXPECT_EQ(renderer.scene(frames[0])->output.display.peak_cd_m2, 80.0);
    EXPECT_EQ(renderer.scenes_parsed(), frames.size() + 1);
}

}  // namespace
}  // namespace atonlab
