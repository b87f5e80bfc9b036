#pragma once
// Small questions a session asks of a stimulus or of a frame's scene.

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "atonlab/protocols/protocol.h"
#include "atonlab/stimuli/scene.h"

namespace atonlab::runner {

/// The lights judged in frame `f` of a stimulus, in view order.
std::vector<std::string> judged_lights(const protocols::Stimulus& stimulus, std::size_t f);

/// The scene's light called `name`, or nullptr.
const stimuli::Light* find_light(const stimuli::Scene& scene, std::string_view name);

/// The scene's disc (an extended reference, scene.h Disc) called `name`, or nullptr.
const stimuli::Disc* find_disc(const stimuli::Scene& scene, std::string_view name);

/// The override that takes a judged light or disc out of a frame: a light dark,
/// a disc of zero diameter (the background shows where it was).
SceneOverride judged_off_override(const stimuli::Scene& scene, const std::string& name);

/// The moment within [0, interval_s] at which the judged lights are brightest
/// (their rhythms' summed level), so that a model observer looking at one
/// frame sees, e.g., the flash that the interval holds. Rhythms are piecewise
/// linear between knots: the levels at the midpoints between consecutive knot
/// times pick a plateau's middle, away from the edges where the GPU's
/// tabulated rhythm and the CPU's could disagree. All fixed: 0.
double brightest_moment_s(const stimuli::Scene& scene, const std::vector<std::string>& lights, double interval_s);

}  // namespace atonlab::runner
