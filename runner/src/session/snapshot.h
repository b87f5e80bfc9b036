#pragma once
// The snapshot a session stores of each condition: its first trial's frames.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "atonlab/display/tonemap.h"
#include "atonlab/protocols/protocol.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/runner/session/stimulus_renderer.h"

namespace atonlab::runner {

/// How the display pass showed one frame of a snapshot (docs/analysis.md, "Stimulus
/// pictures"): the frame's scene settings, so that the report tone-maps it as the session did.
struct SnapshotToneMap {
    /// The frame's [tonemap] settings; out_of_gamut is display.out_of_gamut, as
    /// DisplayPipeline passes it to the tone mapper.
    display::ToneMapSettings tonemap;
    bool dynamic = false;           ///< [adaptation] mode = "dynamic": the frame's own log-average (eq 4.15)
    double adaptation_cd_m2 = 1.0;  ///< fixed: eye.adaptation_cd_m2 (cd/m²)
    double epsilon_cd_m2 = display::kLogAverageEpsilonCdM2;  ///< dynamic: ε of eq 4.15 (cd/m²)
    bool ldr_glare = false;  ///< [output] ldr_glare: the glare was tone-mapped on its own
};

/// The EXR attribute "tonemap": a JSON array, one object per stacked frame.
std::string snapshot_tonemap_json(const std::vector<SnapshotToneMap>& frames);
/// Its frames back; std::nullopt for text that is not such an array or holds
/// invalid settings (validate_tonemap_settings), e.g. a damaged file.
std::optional<std::vector<SnapshotToneMap>> read_snapshot_tonemap(const std::string& json);

/// One EXR of the condition's first trial: its frames stacked top to bottom
/// in presentation order, scene-referred (cd/m²), as the file's bytes: RGB and,
/// in A, each pixel's scotopic luminance (scotopic cd/m², docs/tone-mapping.md
/// "The scotopic channel"), with the frames' tone-mapping settings in "tonemap".
std::vector<std::byte> snapshot_exr(StimulusRenderer& renderer, const protocols::Protocol& protocol,
                                    const protocols::Condition& c, const protocols::ScheduledTrial& t,
                                    std::int64_t session);

}  // namespace atonlab::runner
