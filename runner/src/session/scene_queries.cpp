#include "atonlab/runner/session/scene_queries.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "atonlab/stimuli/rhythm.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;
namespace s = atonlab::stimuli;

std::vector<std::string> judged_lights(const p::Stimulus& stimulus, std::size_t f) {
    std::vector<std::string> lights;
    for (const p::StimulusView& v : stimulus.views)
        if (v.frame == f) lights.push_back(v.light);
    return lights;
}

const s::Light* find_light(const s::Scene& scene, std::string_view name) {
    for (const s::Light& l : scene.lights)
        if (l.name == name) return &l;
    return nullptr;
}

const s::Disc* find_disc(const s::Scene& scene, std::string_view name) {
    for (const s::Disc& d : scene.discs)
        if (d.name == name) return &d;
    return nullptr;
}

SceneOverride judged_off_override(const s::Scene& scene, const std::string& name) {
    if (find_disc(scene, name) && !find_light(scene, name)) return {fmt::format("disc.{}.diameter_deg", name), "0"};
    return {fmt::format("light.{}.intensity_cd", name), "0"};
}

double brightest_moment_s(const s::Scene& scene, const std::vector<std::string>& lights, double interval_s) {
    std::vector<const s::Light*> judged;
    for (const std::string& name : lights)
        if (const s::Light* l = find_light(scene, name); l && l->rhythm_period_s > 0) judged.push_back(l);
    if (judged.empty() || !(interval_s > 0)) return 0.0;
    std::vector<double> cuts{0.0, interval_s};
    for (const s::Light* l : judged) {
        const double period = l->rhythm_period_s;
        for (const s::RhythmKnot& k : l->rhythm) {
            double t = k.t_s - l->rhythm_phase_s;
            t -= std::floor(t / period) * period;
            for (int n = 0; t <= interval_s && n < 100000; t += period, ++n) cuts.push_back(t);
        }
    }
    std::sort(cuts.begin(), cuts.end());
    cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
    double best_t = 0.0;
    double best = -1.0;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
        const double t = 0.5 * (cuts[i] + cuts[i + 1]);
        double level = 0.0;
        for (const s::Light* l : judged) level += s::rhythm_level(l->rhythm, l->rhythm_period_s, t + l->rhythm_phase_s);
        if (level > best) {
            best = level;
            best_t = t;
        }
    }
    return best_t;
}

}  // namespace atonlab::runner
