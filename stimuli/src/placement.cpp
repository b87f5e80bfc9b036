// Where a glare stage's arithmetic runs (placement.h).
#include "atonlab/stimuli/placement.h"

#include <epoxy/gl.h>

#include <string>

namespace atonlab::stimuli {

std::string_view placement_name(ComputePlacement p) {
    switch (p) {
        case ComputePlacement::automatic: return "automatic";
        case ComputePlacement::gpu: return "gpu";
        case ComputePlacement::cpu: return "cpu";
    }
    return "automatic";
}

std::optional<ComputePlacement> placement_from_name(std::string_view name) {
    for (ComputePlacement p : {ComputePlacement::automatic, ComputePlacement::gpu, ComputePlacement::cpu})
        if (name == placement_name(p)) return p;
    return std::nullopt;
}

// The same rule as gl::ContextInfo::software, for the current context.
bool software_renderer() {
    const auto* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const std::string renderer = r ? r : "";
    return renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos ||
           renderer.find("swrast") != std::string::npos;
}

ComputePlacement resolve_placement(ComputePlacement p) {
    if (p != ComputePlacement::automatic) return p;
    if (glGetString(GL_RENDERER) == nullptr) return ComputePlacement::cpu;  // no current context
    return software_renderer() ? ComputePlacement::cpu : ComputePlacement::gpu;
}

}  // namespace atonlab::stimuli
