// The presentation margin (presentation_margin.h).
#include "session/presentation_margin.h"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

#include "atonlab/store/json.h"
#include "session/session_display.h"

namespace atonlab::runner {

namespace p = atonlab::protocols;

namespace {

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

PresentationMargin measure_margin(present::Presenter& presenter, StimulusRenderer& renderer, const p::Protocol& protocol,
                                  const Displayability& displayability, int bits, int times, double extra_s) {
    // Each condition's stimulus at the top of its level range; the first
    // animated one wins, else the first.
    std::optional<p::Stimulus> chosen;
    PresentationMargin m;
    for (const p::Block& b : protocol.blocks)
        for (const p::Condition& c : b.conditions) {
            if (chosen && m.animated) break;
            p::Proposal proposal;
            for (const ConditionDisplayability& d : displayability.conditions)
                if (d.name == c.name) {
                    proposal.level = d.high.level;
                    break;
                }
            if (c.task == p::Task::TwoAfc) proposal.test_on_left = true;
            p::Stimulus stim = p::make_stimulus(protocol, c, proposal);
            if (stim.frames.empty()) continue;
            const bool animated = renderer.animated(stim.frames[0]);
            if (!chosen || (animated && !m.animated)) {
                chosen = std::move(stim);
                m.condition = c.name;
                m.animated = animated;
            }
        }
    m.period_s = presenter.period_s();
    if (!chosen) return m;
    const present::Screen screen = stimulus_screen(renderer, *chosen, 0, bits, presenter.on_screen());
    const std::vector<present::ShowTiming> t = presenter.time_showing(screen, times, extra_s);
    std::vector<double> up, draw, show;
    for (const present::ShowTiming& s : t) {
        up.push_back(s.upload_s);
        draw.push_back(s.draw_s);
        show.push_back(s.show_s());
    }
    m.times = static_cast<int>(t.size());
    m.upload_s = median(up);
    m.draw_s = median(draw);
    m.show_s = median(show);
    m.worst_show_s = show.empty() ? 0.0 : *std::max_element(show.begin(), show.end());
    return m;
}

std::string margin_json(const PresentationMargin& m) {
    const nlohmann::ordered_json j{{"condition", m.condition},   {"animated", m.animated},
                                   {"times", m.times},           {"period_s", m.period_s},
                                   {"upload_s", m.upload_s},     {"draw_s", m.draw_s},
                                   {"show_s", m.show_s},         {"worst_show_s", m.worst_show_s},
                                   {"margin", m.margin()}};
    return store::dump_json(j);
}

std::string margin_text(const PresentationMargin& m) {
    return fmt::format(
        "presentation margin {:.0f} %: a frame of condition \"{}\"{} is shown in {:.2f} ms (upload {:.2f} ms, draw "
        "{:.2f} ms; median of {}, worst {:.2f} ms) of the {:.2f} ms refresh",
        m.margin() * 100.0, m.condition, m.animated ? " (rendered at every flip)" : "", m.show_s * 1e3,
        m.upload_s * 1e3, m.draw_s * 1e3, m.times, m.worst_show_s * 1e3, m.period_s * 1e3);
}

}  // namespace atonlab::runner
