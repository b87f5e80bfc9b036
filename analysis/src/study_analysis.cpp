#include "atonlab/analysis/study_analysis.h"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <set>
#include <span>
#include <stdexcept>
#include <string_view>

#include "atonlab/common/toml_value.h"
#include "atonlab/protocols/procedures.h"

namespace atonlab::analysis {

namespace {

namespace p = atonlab::protocols;

/// What analysis follows in a track of the procedure `name` (procedures.h); None for an unknown one.
p::TrackEstimate track_estimate(std::string_view name) {
    const p::ProcedureType* type = p::find_procedure_type(name);
    return type ? type->track_estimate : p::TrackEstimate::None;
}

/// std::vector<bool> is not contiguous; the statistics take std::span<const bool>.
std::unique_ptr<bool[]> as_bools(const std::vector<bool>& v) {
    std::unique_ptr<bool[]> out(new bool[v.size() + 1]);
    for (std::size_t i = 0; i < v.size(); ++i) out[i] = v[i];
    return out;
}

/// ConditionInfo::differences of a condition whose first trial is `f`.
std::vector<std::string> side_differences(const ConditionInfo& c, const Trial& f) {
    std::vector<std::string> out;
    if (c.lights_known()) {
        const bool colour = c.test_look.colour != c.reference_look.colour;
        if (colour) out.push_back("colour");
        if (c.test_look.rhythm != c.reference_look.rhythm) out.push_back("rhythm");
        // Another colour has its own glare spectrum; a spectrum is a difference of its own only
        // between lights of one colour.
        if (!colour && c.test_look.spectrum != c.reference_look.spectrum) out.push_back("spectrum");
    }
    if (c.glare_test != c.glare_reference) out.push_back("glare");
    // Frame-wide keys the test's and the reference's frames set differently
    // (Trial::settings "test.KEY" / "reference.KEY"); a light's own keys there
    // are the lights switched off in each other's frame, and the glare is above.
    std::set<std::string> keys;
    for (const auto& [key, value] : f.settings) {
        for (const std::string_view side : {"test.", "reference."}) {
            if (!key.starts_with(side)) continue;
            const std::string k = key.substr(side.size());
            if (!k.starts_with("light") && !k.starts_with("disc") && k != "eye.glare") keys.insert(k);
        }
    }
    out.insert(out.end(), keys.begin(), keys.end());
    return out;
}

ConditionInfo condition_info(const std::string& name, const std::vector<const Trial*>& trials) {
    ConditionInfo c;
    c.condition = name;
    c.n_trials = static_cast<int>(trials.size());
    if (trials.empty()) return c;
    const Trial& f = *trials.front();
    c.task = f.task;
    c.procedure = f.procedure;
    c.level_key = f.level_key;
    c.level_scale = f.level_scale;
    c.level_on = f.level_on;
    c.adaptation_cd_m2 = f.adaptation_cd_m2;
    c.tone_operator = f.tone_operator;
    c.glare_test = f.glare_test;
    c.glare_reference = f.glare_reference;
    c.test_intensity_cd = f.test_intensity_cd;
    c.test_look = f.test_look;
    c.reference_look = f.reference_look;
    c.guess_rate = f.guess_rate;
    c.target_p = f.target_p;
    auto check = [&](const char* what, auto get) {
        for (const Trial* t : trials) {
            if (get(*t) != get(f)) {
                c.mixed.push_back(what);
                return;
            }
        }
    };
    check("task", [](const Trial& t) { return t.task; });
    check("procedure", [](const Trial& t) { return t.procedure; });
    check("level_key", [](const Trial& t) { return t.level_key; });
    check("level_scale", [](const Trial& t) { return t.level_scale; });
    check("level_on", [](const Trial& t) { return t.level_on; });
    check("adaptation_cd_m2", [](const Trial& t) { return t.adaptation_cd_m2; });
    check("tone_operator", [](const Trial& t) { return t.tone_operator; });
    check("glare_test", [](const Trial& t) { return t.glare_test; });
    check("glare_reference", [](const Trial& t) { return t.glare_reference; });
    // With the level on the test, the test's intensity is the level: not a parameter of the condition.
    if (c.level_on != "test") check("test_intensity_cd", [](const Trial& t) { return t.test_intensity_cd; });
    if (c.level_on == "test") c.test_intensity_cd.reset();
    check("test light", [](const Trial& t) { return t.test_look; });
    check("reference light", [](const Trial& t) { return t.reference_look; });
    check("guess_rate", [](const Trial& t) { return t.guess_rate; });
    check("target_p", [](const Trial& t) { return t.target_p; });
    // A setting that changes within the condition is not one of its factors.
    for (const auto& [key, value] : f.settings) {
        bool same = true;
        for (const Trial* t : trials) {
            const auto it = t->settings.find(key);
            if (it == t->settings.end() || it->second != value) {
                same = false;
                break;
            }
        }
        if (same) c.settings[key] = value;
    }
    c.differences = side_differences(c, f);
    return c;
}

/// Adaptive tracks of a group, each in trial order.
std::vector<TrackResult> tracks_of(const std::vector<const Trial*>& trials, const AnalysisOptions& o) {
    std::map<std::pair<std::string, std::string>, std::vector<const Trial*>> by_track;
    std::vector<std::pair<std::string, std::string>> order;
    for (const Trial* t : trials) {
        if (track_estimate(t->procedure) == p::TrackEstimate::None) continue;
        const auto key = std::make_pair(t->session, t->track.empty() ? t->condition : t->track);
        auto [it, fresh] = by_track.try_emplace(key);
        if (fresh) order.push_back(key);
        it->second.push_back(t);
    }
    std::vector<TrackResult> out;
    for (const auto& key : order) {
        std::vector<const Trial*>& ts = by_track[key];
        std::stable_sort(ts.begin(), ts.end(),
                         [](const Trial* a, const Trial* b) { return a->trial_index < b->trial_index; });
        TrackResult r;
        r.session = key.first;
        r.track = key.second;
        r.observer = ts.front()->observer;
        r.procedure = ts.front()->procedure;
        bool all_flags = true;
        for (const Trial* t : ts) {
            r.levels.push_back(t->level);
            r.outcomes.push_back(t->outcome);
            all_flags = all_flags && t->reversal.has_value();
        }
        if (track_estimate(r.procedure) == p::TrackEstimate::Reversals) {
            if (all_flags) {
                for (const Trial* t : ts) r.reversal.push_back(*t->reversal);
                const std::unique_ptr<bool[]> flags = as_bools(r.reversal);
                r.reversals = summarize_reversals(r.levels, std::span<const bool>(flags.get(), r.reversal.size()),
                                                  o.last_reversals);
            } else {
                ReversalSummary s;
                s.n_trials = static_cast<int>(ts.size());
                s.reason = "the reversals are unknown (the track could not be replayed through its procedure)";
                r.reversals = s;
            }
        } else {
            const Trial& last = *ts.back();
            StoredPosterior q;
            q.mean = last.posterior_mean;
            q.sd = last.posterior_sd;
            if (last.posterior_lower && last.posterior_upper) {
                q.quantiles.emplace_back(0.025, *last.posterior_lower);
                q.quantiles.emplace_back(0.975, *last.posterior_upper);
            }
            r.posterior = summarize_posterior(q, 0.95);
            if (!last.posterior_mean && r.posterior->reason.empty())
                r.posterior->reason = "QUEST's posterior is unknown (the track could not be replayed)";
        }
        out.push_back(std::move(r));
    }
    return out;
}

std::optional<double> mean_of(const std::vector<double>& v) {
    if (v.empty()) return std::nullopt;
    return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

ResampleOptions resample_options(const AnalysisOptions& o, const std::string& label) {
    ResampleOptions r;
    r.n_resamples = std::max(o.bootstrap, 0);
    r.level = o.ci_level;
    r.seed = o.seed;
    r.n_threads = std::max(o.n_threads, 1);
    if (o.progress) {
        auto cb = o.progress;
        r.progress = [cb, label](int done, int total) {
            cb(label, done, total);
            return true;
        };
    }
    return r;
}

/// The method of adjustment's headline: the mean of the confirmed matches
/// (and of log10(match / test) when the level is the reference's log10
/// intensity), with bootstrap intervals over matches.
void analyse_matches(GroupResult& g, const ConditionInfo& info, const std::vector<const Trial*>& trials,
                     const AnalysisOptions& o, const std::string& label) {
    HeadlineEstimate& h = g.headline;
    const bool log_levels = info.level_scale == "log10";
    std::vector<double> matched;
    for (const Trial* t : trials)
        if (t->is_match()) matched.push_back(t->level);
    g.n_scored = static_cast<int>(matched.size());
    g.matches = summarize_log_ratios(matched, resample_options(o, label));
    const AdjustmentSummary& m = *g.matches;
    h.value = m.mean_log10_ratio;
    h.ci = m.mean_ci;
    h.method = "mean of the matched levels (bootstrap over matches)";
    h.reliable = m.reliable;
    h.reason = matched.empty() ? "no match was confirmed" : m.reason;
    if (log_levels && info.level_on == "reference" && info.test_intensity_cd) {
        const double test = std::log10(*info.test_intensity_cd);
        std::vector<double> ratios;
        for (const double v : matched) ratios.push_back(v - test);
        const AdjustmentSummary r = summarize_log_ratios(ratios, resample_options(o, label));
        MatchRatio mr;
        mr.value = r.mean_log10_ratio;
        mr.ci = r.mean_ci;
        mr.method = "mean of log10(match / test) over matches";
        mr.reliable = r.reliable;
        mr.reason = r.reason;
        g.match_ratio = mr;
    }
}

GroupResult analyse_group(const ConditionInfo& info, const std::string& observer,
                          const std::vector<const Trial*>& trials, const AnalysisOptions& o,
                          std::vector<std::string>& warnings) {
    GroupResult g;
    g.condition = info.condition;
    g.observer = observer;
    g.n_trials = static_cast<int>(trials.size());
    std::set<std::string> sessions;
    for (const Trial* t : trials) sessions.insert(t->session);
    g.n_sessions = static_cast<int>(sessions.size());
    const std::string label = fmt::format("{} / {}", info.condition, observer);
    HeadlineEstimate& h = g.headline;
    if (trials.empty()) {
        h.reason = "no trials were recorded for this condition";
        return g;
    }
    const bool log_levels = info.level_scale == "log10";

    if (info.task == protocols::Task::Adjust) {
        analyse_matches(g, info, trials, o, label);
        return g;
    }

    // 2AFC and yes-no: the psychometric function of the outcome.
    std::vector<double> levels;
    std::vector<bool> yes;
    for (const Trial* t : trials) {
        if (!t->outcome) continue;
        // Levels a staircase reached by different sums of steps (-2.3 + 0.2 and
        // -2.1) differ in the last bits: count them as one level (1e-9 grid).
        levels.push_back(std::round(t->level * 1e9) / 1e9);
        yes.push_back(*t->outcome);
    }
    g.n_scored = static_cast<int>(levels.size());
    const std::unique_ptr<bool[]> yes_flags = as_bools(yes);
    g.counts = tabulate(levels, std::span<const bool>(yes_flags.get(), yes.size()));
    FitOptions fo;
    g.family = o.family;
    if (o.family == Family::Weibull && log_levels) {
        // psychometric.h: the Weibull of 10^x is the Gumbel of x with alpha = log10(alpha_W), same beta.
        g.family = Family::Gumbel;
        g.family_note =
            "the Weibull of the intensity 10^level is fitted as the Gumbel (log-Weibull) of the log10 level";
    }
    fo.family = g.family;
    fo.guess = RateConstraint::fixed_at(info.guess_rate);
    double prop = (info.target_p - info.guess_rate) / (1.0 - info.guess_rate);
    if (!(prop > 0.0 && prop < 1.0)) {
        warnings.push_back(
            fmt::format("condition \"{}\": target P {} with guess rate {} gives no threshold on the "
                        "sigmoid; the threshold is given at F = 0.5",
                        info.condition, info.target_p, info.guess_rate));
        prop = 0.5;
    }
    fo.threshold_proportion = prop;
    g.threshold_proportion = prop;
    g.fit = fit_psychometric(g.counts, fo);
    if (o.bootstrap > 0 && g.fit->estimate)
        g.bootstrap = bootstrap_psychometric(g.counts, *g.fit, resample_options(o, label));

    g.tracks = tracks_of(trials, o);
    std::vector<double> rev_means, posterior_means;
    for (const TrackResult& tr : g.tracks) {
        if (tr.reversals && tr.reversals->mean) rev_means.push_back(*tr.reversals->mean);
        if (tr.posterior && tr.posterior->mean) posterior_means.push_back(*tr.posterior->mean);
    }
    g.reversal_mean = mean_of(rev_means);
    g.posterior_mean = mean_of(posterior_means);

    const std::string what = std::abs(info.target_p - 0.5) < 1e-12 && info.guess_rate == 0.0
                                 ? std::string("PSE")
                                 : fmt::format("threshold at P = {:.3g}", info.target_p);
    if (g.fit->estimate) {
        h.value = g.fit->estimate->threshold;
        h.method = fmt::format("{} of the fitted {} psychometric function", what, to_string(g.family));
        h.reliable = g.fit->reliable;
        h.reason = g.fit->reason;
        if (g.bootstrap) {
            h.ci = g.bootstrap->threshold;
            if (!g.bootstrap->reliable) {
                h.reliable = false;
                if (h.reason.empty()) h.reason = "bootstrap: " + g.bootstrap->reason;
            } else if (h.ci && !(h.ci->upper > h.ci->lower)) {
                h.reliable = false;
                if (h.reason.empty())
                    h.reason =
                        "the bootstrap interval has no width: every resample gave the same threshold, so the "
                        "data do not constrain it (answers perfectly separated by level)";
            }
        } else if (o.bootstrap > 0) {
            h.reliable = false;
        } else {
            h.reason = h.reason.empty() ? "no bootstrap was asked for (--bootstrap 0): no interval" : h.reason;
        }
    } else {
        // No fit: the procedure's own estimate, where it has one.
        const std::string why = g.fit->reason.empty() ? "no psychometric fit" : g.fit->reason;
        if (g.tracks.size() == 1 && g.tracks[0].posterior && g.tracks[0].posterior->mean) {
            const PosteriorSummary& q = *g.tracks[0].posterior;
            h.value = q.mean;
            h.ci = q.interval;
            h.method = "QUEST's posterior mean (no psychometric fit)";
            h.reliable = false;
            h.reason = "the psychometric fit failed (" + why + "); QUEST's own estimate is shown";
        } else if (g.posterior_mean) {
            h.value = g.posterior_mean;
            h.method = "mean of the QUEST tracks' posterior means (no psychometric fit)";
            h.reason = "the psychometric fit failed (" + why + "); QUEST's own estimate is shown, without an interval";
        } else if (g.reversal_mean) {
            h.value = g.reversal_mean;
            h.method = fmt::format("mean of the tracks' last {} reversals (no psychometric fit)", o.last_reversals);
            h.reason = "the psychometric fit failed (" + why +
                       "); the staircases' reversal mean is shown, without "
                       "an interval";
        } else {
            h.reason = why;
        }
    }

    // log10(PSE / test intensity): a brightness enhancement by glare when glare
    // is the only difference (ConditionInfo::difference_label).
    if (log_levels && info.level_on == "reference" && std::abs(info.target_p - 0.5) < 1e-12 && info.guess_rate == 0.0) {
        MatchRatio mr;
        mr.method = "log10(PSE / test intensity)";
        if (!info.test_intensity_cd) {
            mr.reason = "the test's intensity is not among the stored overrides (the scene file's value was used)";
        } else if (!g.fit->estimate) {
            mr.reason = h.reason;
        } else {
            const std::vector<double> none;
            const Enhancement e =
                brightness_enhancement(g.fit->estimate->threshold, g.bootstrap ? g.bootstrap->threshold_samples : none,
                                       std::log10(*info.test_intensity_cd), o.ci_level);
            mr.value = e.log10_enhancement;
            mr.ci = e.ci;
            mr.reliable = e.reliable && h.reliable;
            mr.reason = !h.reliable && !h.reason.empty() ? h.reason : e.reason;
        }
        g.match_ratio = mr;
    }
    return g;
}

/// The one stimulus parameter in which two conditions differ, or "" (none or several).
std::string single_factor(const ConditionInfo& a, const ConditionInfo& b) {
    if (a.task != b.task || a.level_key != b.level_key || a.level_scale != b.level_scale || a.level_on != b.level_on ||
        a.target_p != b.target_p)
        return {};
    std::vector<std::string> differ;
    if (a.adaptation_cd_m2 != b.adaptation_cd_m2) differ.push_back("adaptation luminance");
    if (a.tone_operator != b.tone_operator) differ.push_back("tone mapper");
    if (a.glare_test != b.glare_test) differ.push_back("glare on the test");
    if (a.glare_reference != b.glare_reference) differ.push_back("glare on the reference");
    if (a.test_intensity_cd != b.test_intensity_cd) differ.push_back("test intensity");
    return differ.size() == 1 ? differ.front() : std::string();
}

}  // namespace

std::string ConditionInfo::difference_label() const {
    return glare_only_difference() ? "enhancement by glare" : "test − reference";
}

std::string ConditionInfo::level_unit() const {
    std::string unit;
    const auto dot = level_key.rfind('.');
    const std::string leaf = dot == std::string::npos ? level_key : level_key.substr(dot + 1);
    if (leaf.ends_with("_cd_m2"))
        unit = "cd/m2";
    else if (leaf.ends_with("_cd"))
        unit = "cd";
    else if (leaf.ends_with("_deg"))
        unit = "deg";
    else if (leaf.ends_with("_m"))
        unit = "m";
    else if (leaf.ends_with("_s"))
        unit = "s";
    if (level_scale == "log10") return unit.empty() ? "log10 units" : "log10 " + unit;
    return unit.empty() ? "level units" : unit;
}

const ConditionInfo* StudyResults::condition(const std::string& name) const {
    for (const ConditionInfo& c : conditions)
        if (c.condition == name) return &c;
    return nullptr;
}

const GroupResult* StudyResults::main_group(const std::string& name) const {
    const GroupResult* first = nullptr;
    for (const GroupResult& g : groups) {
        if (g.condition != name) continue;
        if (g.observer == kPooled) return &g;
        if (!first) first = &g;
    }
    return first;
}

SettingValue setting_value(std::string_view toml_value) {
    SettingValue v;
    v.text = std::string(toml_value);
    const std::optional<TomlValue> parsed = TomlValue::parse(v.text);
    if (!parsed) return v;
    const toml::node* n = &parsed->node();
    if (const auto x = n->value<double>(); x && (n->is_integer() || n->is_floating_point()))
        v.number = *x;
    else if (const auto b = n->value<bool>(); b && n->is_boolean())
        v.boolean = *b;
    else if (const auto t = n->value<std::string>(); t && n->is_string())
        v.text = *t;
    else if (const toml::array* a = n->as_array(); a && !a->empty()) {
        std::vector<double> xs;
        for (const toml::node& e : *a) {
            if (!e.is_integer() && !e.is_floating_point()) return v;
            xs.push_back(*e.value<double>());
        }
        v.numbers = std::move(xs);
    }
    return v;
}

StudyResults analyze_study(const Dataset& data, const AnalysisOptions& options) {
    if (options.bootstrap < 0) throw std::invalid_argument("bootstrap must be >= 0");
    if (!(options.ci_level > 0.0 && options.ci_level < 1.0)) throw std::invalid_argument("ci_level must be in (0, 1)");
    if (options.last_reversals < 1) throw std::invalid_argument("last_reversals must be >= 1");
    StudyResults out;
    out.options = options;
    out.options.progress = nullptr;
    out.warnings = data.notes;

    // Conditions: protocol order first, then any met only in the trials.
    std::vector<std::string> order;
    std::set<std::string> known;
    for (const SessionInfo& s : data.sessions)
        for (const std::string& c : s.protocol_conditions)
            if (known.insert(c).second) order.push_back(c);
    std::map<std::string, std::vector<const Trial*>> by_condition;
    std::set<std::string> observers;
    for (const SessionInfo& s : data.sessions) observers.insert(s.observer);
    for (const Trial& t : data.trials) {
        if (known.insert(t.condition).second) order.push_back(t.condition);
        by_condition[t.condition].push_back(&t);
        observers.insert(t.observer);
    }
    out.observers.assign(observers.begin(), observers.end());

    for (const std::string& name : order) {
        const std::vector<const Trial*>& trials = by_condition[name];
        ConditionInfo info = condition_info(name, trials);
        if (!info.mixed.empty()) {
            std::string list;
            for (const std::string& m : info.mixed) list += (list.empty() ? "" : ", ") + m;
            out.warnings.push_back(
                fmt::format("condition \"{}\": its trials differ in {} (two protocols with one "
                            "condition name?); the first trial's values are shown",
                            name, list));
        }
        if (trials.empty()) {
            out.groups.push_back(
                analyse_group(info, out.observers.size() == 1 ? out.observers[0] : kPooled, {}, options, out.warnings));
        } else {
            std::map<std::string, std::vector<const Trial*>> per_observer;
            for (const Trial* t : trials) per_observer[t->observer].push_back(t);
            for (const auto& [obs, ts] : per_observer)
                out.groups.push_back(analyse_group(info, obs, ts, options, out.warnings));
            if (out.observers.size() > 1)
                out.groups.push_back(analyse_group(info, kPooled, trials, options, out.warnings));
        }
        out.conditions.push_back(std::move(info));
    }

    // Factor columns: settings whose value (or absence) is not the same in every condition.
    {
        std::set<std::string> keys;
        for (const ConditionInfo& c : out.conditions)
            for (const auto& kv : c.settings) keys.insert(kv.first);
        for (const std::string& key : keys) {
            std::set<std::string> values;
            for (const ConditionInfo& c : out.conditions) {
                if (c.n_trials == 0) continue;
                const auto it = c.settings.find(key);
                values.insert(it == c.settings.end() ? std::string() : it->second);  // a TOML value is never ""
            }
            if (values.size() > 1) out.factor_columns.push_back(key);
        }
    }

    // Paired comparisons across observers.
    if (out.observers.size() > 1) {
        for (std::size_t i = 0; i < out.conditions.size(); ++i) {
            for (std::size_t j = i + 1; j < out.conditions.size(); ++j) {
                const ConditionInfo& a = out.conditions[i];
                const ConditionInfo& b = out.conditions[j];
                if (a.n_trials == 0 || b.n_trials == 0) continue;
                const std::string factor = single_factor(a, b);
                if (factor.empty()) continue;
                PairedResult pr;
                pr.condition_a = a.condition;
                pr.condition_b = b.condition;
                pr.factor = factor;
                std::vector<double> va, vb;
                for (const std::string& obs : out.observers) {
                    const GroupResult *ga = nullptr, *gb = nullptr;
                    for (const GroupResult& g : out.groups) {
                        if (g.observer != obs) continue;
                        if (g.condition == a.condition) ga = &g;
                        if (g.condition == b.condition) gb = &g;
                    }
                    if (!ga || !gb || !ga->headline.value || !gb->headline.value) continue;
                    pr.observers.push_back(obs);
                    va.push_back(*ga->headline.value);
                    vb.push_back(*gb->headline.value);
                }
                if (pr.observers.size() < 2) continue;
                pr.comparison = compare_paired(va, vb, resample_options(options, a.condition + " vs " + b.condition));
                out.paired.push_back(std::move(pr));
            }
        }
    }

    // Frame timing per session.
    std::map<std::string, std::size_t> at;
    for (const Trial& t : data.trials) {
        auto [it, fresh] = at.try_emplace(t.session, out.timing.size());
        if (fresh) out.timing.push_back({t.session, t.observer, 0, 0, 0, 0});
        SessionTiming& s = out.timing[it->second];
        ++s.n_trials;
        s.dropped_frames += t.dropped_frames;
        s.trials_with_drops += t.dropped_frames > 0 ? 1 : 0;
        s.missed_deadlines += t.missed_deadline ? 1 : 0;
    }
    return out;
}

}  // namespace atonlab::analysis
