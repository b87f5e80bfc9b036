#pragma once
// The report's stimulus pictures (docs/analysis.md, "Stimulus pictures"): a
// condition's stored snapshot (scene-referred EXR, cd/m², session/snapshot.h)
// tone-mapped as the session's display pass did, with the CPU references of
// the tone mapper and the sRGB curve. In runner/, not analysis/: analysis has
// no stimuli or display dependency.
#include <filesystem>
#include <string>

#include "atonlab/analysis/study_analysis.h"
#include "atonlab/store/store.h"

namespace atonlab::runner {

/// The condition's snapshot as a PNG at `png`: each judged light (or each frame's
/// brightest pixel, for a snapshot without the "lights" attribute) cropped to 6°,
/// tone-mapped with the frame's recorded settings and each pixel's scotopic
/// channel where the snapshot has them, sRGB-encoded, side by side. Empty on
/// success, with `caption` set; else why it could not be shown (one phrase).
std::string snapshot_png(const store::Snapshot& snap, const analysis::ConditionInfo& c,
                         const std::filesystem::path& png, std::string& caption);

}  // namespace atonlab::runner
