// The nominal display's calibration row (display_record.h).
#include "session/display_record.h"

#include <fmt/format.h>

#include <ctime>
#include <string>

#include "atonlab/display/fit_json.h"

namespace atonlab::runner {

namespace s = atonlab::stimuli;
namespace st = atonlab::store;

st::CalibrationId record_display(st::Store& store, const s::Scene& scene, const std::filesystem::path& scene_file) {
    const display::DisplayModel& d = scene.output.display;
    st::Calibration c;
    c.display_name = d.name.empty() ? "display" : d.name;
    c.width_px = scene.display.width_px;
    c.height_px = scene.display.height_px;
    c.width_m = scene.display.width_m;
    c.height_m = scene.display.height_m();
    c.viewing_distance_m = scene.display.viewing_distance_m;
    c.fit_json = display::nominal_fit_json(d, scene.output.encode);
    c.source = fmt::format("the [display] table of the scene {} (not measured)", scene_file.string());
    if (const auto last = store.latest_calibration(c.display_name)) {
        if (last->width_px == c.width_px && last->height_px == c.height_px && last->width_m == c.width_m &&
            last->height_m == c.height_m && last->viewing_distance_m == c.viewing_distance_m &&
            display::same_fit_json(last->fit_json, c.fit_json) && last->source == c.source)
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
