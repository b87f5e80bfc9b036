#pragma once
// One frame of a scene, rendered headless with what its EXR header carries:
// the core of `atonlab render` (render_command.cpp) and of the Python module's
// Scene.render (docs/python.md), so both give the same pixels and metadata.
#include <string>

#include "atonlab/stimuli/frame_renderer.h"
#include "atonlab/stimuli/image_io.h"
#include "atonlab/stimuli/pipeline.h"
#include "atonlab/stimuli/scene_file.h"

namespace atonlab::runner {

struct RenderedFrame {
    stimuli::ImageRGBA32F hdr;  ///< linear Rec.709, absolute cd/m², row 0 at the top
    stimuli::ExrMetadata meta;  ///< the EXR header's attributes (units, degreesPerPixel, adaptation, strings)
    std::string glare_note;     ///< one line per glare kernel drawn, for stdout
    stimuli::FrameStats stats;  ///< lights drawn
};

/// Renders `scene` at time_s (s) with `pipeline` (a GL 4.5 context must be
/// current) as one frame: dynamic adaptation adopts the frame's log-average at
/// once. scene_label names the scene file in the metadata. The display codes
/// are then in pipeline.display() (read_codes()).
RenderedFrame render_frame(stimuli::Pipeline& pipeline, const stimuli::Scene& scene, const std::string& scene_label,
                           double time_s);

}  // namespace atonlab::runner
