// The nominal display's calibration row (display_record.h).
#include "session/display_record.h"

#include <fmt/format.h>

#include <ctime>
#include <string>

#include "json_text.h"

namespace atonlab::runner {

namespace s = atonlab::stimuli;
namespace st = atonlab::store;

st::CalibrationId record_display(st::Store& store, const s::Scene& scene, const std::filesystem::path& scene_file) {
    const s::DisplayModel& d = scene.output.display;
    std::string channels;
    for (const s::ChannelTransfer& ch : d.channels) {
        const char* kind = ch.kind == s::TransferKind::srgb  ? "srgb"
                           : ch.kind == s::TransferKind::gog ? "gog"
                           : ch.kind == s::TransferKind::lut ? "lut"
                                                             : "pq";
        channels +=
            fmt::format("{}{{\"transfer\":\"{}\",\"black_cd_m2\":{},\"white_cd_m2\":{}}}", channels.empty() ? "" : ",",
                        kind, json_number(ch.min_cd_m2()), json_number(ch.max_cd_m2()));
    }
    st::Calibration c;
    c.display_name = d.name.empty() ? "display" : d.name;
    c.width_px = scene.display.width_px;
    c.height_px = scene.display.height_px;
    c.width_m = scene.display.width_m;
    c.height_m = scene.display.height_m();
    c.viewing_distance_m = scene.display.viewing_distance_m;
    c.fit_json = fmt::format(
        "{{\"model\":\"nominal\",\"peak_cd_m2\":{},\"black_cd_m2\":{},\"bits\":{},\"dither\":{},\"channels\":[{}]}}",
        json_number(d.peak_cd_m2), json_number(d.black_cd_m2), scene.output.encode.bits,
        scene.output.encode.dither == s::Dither::spatiotemporal ? "true" : "false", channels);
    c.source = fmt::format("the [display] table of the scene {} (not measured)", scene_file.string());
    if (const auto last = store.latest_calibration(c.display_name)) {
        if (last->width_px == c.width_px && last->height_px == c.height_px && last->width_m == c.width_m &&
            last->height_m == c.height_m && last->viewing_distance_m == c.viewing_distance_m &&
            last->fit_json == c.fit_json && last->source == c.source)
            return last->id;
    }
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    char date[16];
    std::strftime(date, sizeof date, "%Y-%m-%d", &utc);
    c.measured_at = date;
    return store.put_calibration(c);
}

}  // namespace atonlab::runner
