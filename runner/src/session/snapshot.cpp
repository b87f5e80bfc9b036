// Condition snapshots (snapshot.h).
#include "session/snapshot.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <string>
#include <system_error>

#include "atonlab/common/read_file.h"
#include "atonlab/runner/session/scene_queries.h"
#include "atonlab/runner/session/session_inputs.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;

std::vector<std::byte> snapshot_exr(StimulusRenderer& renderer, const p::Protocol& protocol, const p::Condition& c,
                                    const p::ScheduledTrial& t, std::int64_t session) {
    s::ImageRGBA32F stacked;
    double dpp = 0.0;
    std::string frames_note, lights_note;
    for (std::size_t f = 0; f < t.stimulus.frames.size(); ++f) {
        std::vector<glm::dvec2> light_px;
        const s::ImageRGBA32F img = renderer.hdr(t.stimulus.frames[f], judged_lights(t.stimulus, f), dpp, &light_px);
        if (f == 0) {
            stacked.width = img.width;
        } else if (img.width != stacked.width) {
            break;  // frames of different sizes (a condition overriding the display) are not stacked
        }
        frames_note +=
            fmt::format("{}rows {}-{}: frame {} ({})", f ? "; " : "", stacked.height, stacked.height + img.height - 1,
                        f, t.stimulus.frames[f].role ? p::to_string(*t.stimulus.frames[f].role) : "both");
        // Where each judged light of the frame is in the stacked image, so that
        // the report crops around every one of them (docs/analysis.md, "Stimulus
        // pictures"): "frame F ROLE at X,Y (LIGHT)", in view order.
        std::size_t k = 0;
        for (const p::StimulusView& v : t.stimulus.views) {
            if (v.frame != f || k >= light_px.size()) continue;
            const glm::dvec2 at = light_px[k++];
            lights_note += fmt::format("{}frame {} {} at {:.1f},{:.1f} ({})", lights_note.empty() ? "" : "; ", f,
                                       p::to_string(v.role), at.x, at.y + stacked.height, v.light);
        }
        stacked.height += img.height;
        stacked.rgba.insert(stacked.rgba.end(), img.rgba.begin(), img.rgba.end());
    }
    s::ExrMetadata meta;
    meta.units = "cd/m2";
    meta.degrees_per_pixel = dpp;
    meta.strings["software"] = "atonlab " ATONLAB_VERSION;
    meta.strings["protocol"] = protocol.file;
    meta.strings["condition"] = c.name;
    meta.strings["frames"] = frames_note;
    if (!lights_note.empty()) meta.strings["lights"] = lights_note;
    meta.strings["level"] = fmt::format("{} ({} = {})", t.stimulus.level, c.level_key, t.stimulus.scene_value);
    const std::filesystem::path tmp =
        std::filesystem::temp_directory_path() / fmt::format("atonlab-snapshot-{}-{}.exr", getpid(), session);
    s::write_exr(tmp, stacked, meta);
    std::string bytes;
    try {
        bytes = files::read_text(tmp, "snapshot", std::numeric_limits<std::uintmax_t>::max());  // written just now
    } catch (...) {
        std::error_code ec;
        std::filesystem::remove(tmp, ec);
        throw;
    }
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    std::vector<std::byte> out(bytes.size());
    std::transform(bytes.begin(), bytes.end(), out.begin(), [](char ch) { return static_cast<std::byte>(ch); });
    return out;
}

}  // namespace atonlab::runner
