// Studies from Python (docs/python.md "Studies"): atonlab.check, atonlab.run,
// and the cores under read_study, analyze and fit (the pandas side is in
// python/atonlab/__init__.py). Each calls what the command line calls:
// check_protocol (displayability.h), run_session (run_session.h), the
// analysis library's reader, trials.csv writer and fits, run_analyze.
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "atonlab/analysis/dataset.h"
#include "atonlab/analysis/psychometric.h"
#include "atonlab/common/input_error.h"
#include "atonlab/protocols/observer.h"
#include "atonlab/protocols/protocol_schedule.h"
#include "atonlab/runner/analyze_command.h"
#include "atonlab/runner/check_command.h"
#include "atonlab/runner/displayability.h"
#include "atonlab/runner/run_command.h"
#include "atonlab/runner/session/run_session.h"
#include "atonlab/runner/session/session_inputs.h"
#include "atonlab/runner/session/stop_signals.h"
#include "atonlab/runner/session/summary.h"
#include "bindings.h"

namespace atonlab::python {

namespace an = atonlab::analysis;

namespace {

/// What a custom observer is given for one trial (docs/python.md "Your own observer").
py::dict trial_dict(const protocols::ScheduledTrial& t, const protocols::Shown& shown) {
    py::dict d;
    d["step"] = t.step;
    d["block_index"] = t.block;
    d["condition"] = t.condition_id;
    d["procedure"] = t.procedure_id;
    d["task"] = std::string(protocols::to_string(t.task));
    d["level"] = t.proposal.level;
    d["adjusted_view"] = t.stimulus.adjusted_view ? py::object(py::int_(*t.stimulus.adjusted_view)) : py::none();
    py::list views;
    for (std::size_t i = 0; i < shown.views.size(); ++i) {
        const protocols::View& v = shown.views[i];
        const protocols::DisplayedImage& img = *v.image;
        const auto window = [&img](const std::vector<float>& values) -> py::object {
            if (values.empty()) return py::none();
            py::array_t<float> a({py::ssize_t{img.height}, py::ssize_t{img.width}});
            std::copy(values.begin(), values.end(), a.mutable_data());
            return a;
        };
        py::dict view;
        const protocols::StimulusView& sv = t.stimulus.views.at(i);
        view["role"] = std::string(protocols::to_string(sv.role));
        view["light"] = sv.light;
        view["frame"] = sv.frame;
        view["displayed_cd_m2"] = window(img.luminance_cd_m2);
        view["background_cd_m2"] = window(img.background_cd_m2);
        if (img.codes_rgb.empty()) {
            view["codes"] = py::none();
        } else {
            py::array_t<std::uint16_t> codes({py::ssize_t{img.height}, py::ssize_t{img.width}, py::ssize_t{3}});
            std::copy(img.codes_rgb.begin(), img.codes_rgb.end(), codes.mutable_data());
            view["codes"] = codes;
        }
        view["bits"] = img.code_bits;
        view["light_px"] = py::make_tuple(v.light_px.x, v.light_px.y);
        view["deg_per_px"] = img.deg_per_px;
        view["focal_px"] = img.focal_px;
        view["principal_px"] = py::make_tuple(img.principal_px.x, img.principal_px.y);
        views.append(view);
    }
    d["views"] = views;
    return d;
}

/// A custom observer's return value: a response word, or (word, response time in s).
protocols::Answer answer_of(const py::object& r, protocols::Task task) {
    const auto where = SourceLocation::command_line("observer");
    py::object word = r;
    protocols::Answer a;
    if (py::isinstance<py::tuple>(r) && py::len(r) == 2) {
        word = r.cast<py::tuple>()[0];
        a.response_time_s = r.cast<py::tuple>()[1].cast<double>();
        if (!(a.response_time_s >= 0.0) || !std::isfinite(a.response_time_s))
            throw InputError(where, "the observer's response time must be a finite number of seconds >= 0");
    }
    if (!py::isinstance<py::str>(word))
        throw InputError(where,
                         "the observer must return a response word (\"left\", \"right\", \"yes\", "
                         "\"no\", ...) or (word, response_time_s), not " +
                             std::string(py::str(py::repr(r))));
    const std::string text = word.cast<std::string>();
    const std::optional<protocols::Response> response = protocols::parse_response_word(text);
    bool fits = false;
    for (const protocols::Action act : protocols::task_actions(task))
        fits = fits || (response && protocols::response_of(act) == *response);
    if (!fits)
        throw InputError(where, "the observer answered \"" + text + "\", which does not fit a " +
                                    std::string(protocols::to_string(task)) + " trial");
    a.response = *response;
    return a;
}

bool is_csv(const std::string& path) {
    return std::filesystem::path(path).extension() == ".csv";
}

/// The study files and CSVs read and merged, as `atonlab analyze` reads them.
an::Dataset read_inputs(const std::vector<std::string>& paths, bool salvage) {
    if (paths.empty()) throw InputError(SourceLocation::command_line("paths"), "give at least one study file or CSV");
    an::Dataset data;
    for (const std::string& f : paths) an::merge(data, is_csv(f) ? an::read_trials_csv(f) : an::read_study(f, salvage));
    return data;
}

/// (the displayability JSON stored with a session, the table `atonlab check` prints, the refusal sentences)
std::tuple<std::string, std::string, std::string> check(const std::string& protocol,
                                                        const std::vector<std::string>& sets, const std::string& db) {
    runner::CheckOptions o;
    o.protocol = protocol;
    o.sets = sets;
    o.db = db;
    py::gil_scoped_release release;
    std::optional<GlUse> gl;
    const runner::Displayability d = runner::check_protocol(o, [&gl] { gl.emplace(); });
    return {runner::displayability_json(d, false), runner::displayability_table(d),
            runner::displayability_refusal(d, protocol)};
}

/// Thrown through the session engine when the custom observer raised: the
/// session ends there and run() raises the Python exception.
struct ObserverRaised : std::runtime_error {
    ObserverRaised() : std::runtime_error("the observer raised an exception") {}
};

py::dict run(const std::string& protocol, const std::string& db, const std::string& observer, bool headless,
             const std::optional<py::function>& progress, const std::optional<std::string>& script,
             const std::optional<std::int64_t>& resume, bool resume_last, const std::optional<std::uint64_t>& seed,
             const std::optional<std::uint64_t>& observer_seed, bool allow_undisplayable, bool true_pse, bool verbose,
             const std::optional<py::function>& custom, const std::string& custom_name) {
    runner::RunOptions o;
    o.protocol = protocol;
    o.db = db;
    o.model_observer = observer == "model" && !script && !custom;
    if (script) o.script = *script;
    if (!o.model_observer) o.observer = observer == "model" ? std::string() : observer;
    // The custom observer (docs/python.md "Your own observer"): its exception
    // is kept and raised once the session has let go of the study file.
    std::optional<py::error_already_set> observer_raised;
    if (custom) {
        o.custom_observer = [&](const protocols::ScheduledTrial& t, const protocols::Shown& shown) {
            py::gil_scoped_acquire gil;
            try {
                return answer_of((*custom)(trial_dict(t, shown)), t.task);
            } catch (py::error_already_set& e) {
                observer_raised = std::move(e);
                throw ObserverRaised();
            }
        };
        o.custom_observer_name = custom_name;
    }
    o.headless = headless;
    o.resume = resume;
    o.resume_last = resume_last;
    o.seed = seed;
    o.observer_seed = observer_seed;
    o.allow_undisplayable = allow_undisplayable;
    o.true_pse = true_pse;
    o.quiet = !verbose;
    o.gl_context_current = headless;
    // After each committed trial: the Python side's Ctrl-C (a SIGINT that
    // reached Python's handler before the session installed its own) and the
    // progress callback; either raising asks the session to stop as SIGINT
    // does, and the exception is raised once the study file is closed.
    std::optional<py::error_already_set> raised;
    o.after_trial = [&](std::size_t stored, std::optional<std::size_t> bound) {
        py::gil_scoped_acquire gil;
        if (raised) return;
        try {
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            if (progress) (*progress)(stored, bound ? py::object(py::int_(*bound)) : py::object(py::none()));
        } catch (py::error_already_set& e) {
            raised = std::move(e);
            runner::request_stop(SIGINT);
        }
    };
    // What the session found, handed over as it ends (returned as "conditions").
    std::vector<runner::ConditionSummary> found;
    o.on_summary = [&found](const std::vector<runner::ConditionSummary>& s) { found = s; };
    int status = 0;
    {
        py::gil_scoped_release release;
        // The protocol, its scene and the observer read and checked first: a
        // typo is reported before the GL context is made (seconds on llvmpipe
        // the first time).
        (void)runner::checked_observer_code(o);
        (void)runner::load_session_inputs(o);
        std::optional<GlUse> gl;
        if (headless) gl.emplace();
        try {
            status = runner::run_session(o);
        } catch (const ObserverRaised&) {
        }
    }
    if (observer_raised) throw std::move(*observer_raised);
    if (raised) throw std::move(*raised);
    if (status >= 128) {
        // A Ctrl-C (or SIGTERM) the session caught itself: every committed trial is kept.
        PyErr_SetNone(PyExc_KeyboardInterrupt);
        throw py::error_already_set();
    }
    if (status == 2)
        throw InputError(SourceLocation{protocol, 0, 0, ""},
                         "a condition cannot produce a match on this display (atonlab.check says why); nothing "
                         "was written. Give allow_undisplayable=True to run it anyway.");
    py::dict out;
    out["completed"] = status == 0;
    out["status"] = status == 0 ? "completed" : status == 6 ? "ended by the observer" : "stopped";
    out["exit_status"] = status;
    out["db"] = db;
    const auto optional = [](const std::optional<double>& v) { return v ? py::object(py::float_(*v)) : py::none(); };
    py::list conditions;
    for (const runner::ConditionSummary& c : found) {
        py::dict row;
        row["condition"] = c.condition;
        row["estimate"] = optional(c.estimate);
        row["tracks"] = c.tracks;
        row["method"] = c.method;
        row["n_tracks"] = c.n_tracks;
        row["finished"] = c.finished;
        row["responses"] = c.responses;
        row["true_value"] = optional(c.true_value);
        row["true_kind"] = c.true_kind;
        row["true_value_why"] = c.true_value_why;
        conditions.append(row);
    }
    out["conditions"] = conditions;
    return out;
}

void write_trials_csv(const std::vector<std::string>& paths, const std::string& csv, bool salvage) {
    py::gil_scoped_release release;
    const an::Dataset data = read_inputs(paths, salvage);
    an::write_trials_csv(csv, data);
}

int analyze(const std::vector<std::string>& paths, const std::string& out, const std::optional<int>& bootstrap,
            const std::optional<std::uint64_t>& seed, const std::string& family, const std::optional<int>& threads,
            bool salvage) {
    if (!family.empty() && !an::parse_family(family))
        throw InputError(SourceLocation::command_line("family"),
                         "the family must be normal, logistic, weibull or gumbel, not '" + family + "'");
    if (bootstrap && *bootstrap < 0)
        throw InputError(SourceLocation::command_line("bootstrap"), "the number of resamples must be 0 or more");
    runner::AnalyzeOptions o;
    for (const std::string& f : paths) (is_csv(f) ? o.csv : o.studies).push_back(f);
    o.out = out;
    o.bootstrap = bootstrap;
    o.seed = seed;
    o.family = family;
    o.threads = threads;
    o.quiet = true;
    o.salvage = salvage;
    py::gil_scoped_release release;
    // Read first, so that bad input raises (InputError, StudyFileError) rather
    // than only printing as the command does; then the command's own work.
    const an::Dataset data = read_inputs(paths, salvage);
    if (data.trials.empty() && data.sessions.empty())
        throw InputError(SourceLocation::command_line("paths"), "the input holds no sessions and no trials");
    return runner::run_analyze(o);
}

py::dict fit(const std::vector<double>& levels, const std::vector<int>& n_trials, const std::vector<int>& n_yes,
             double guess_rate, double target_p, const std::string& family, double lapse_max, int bootstrap,
             const std::optional<std::uint64_t>& seed) {
    const auto where = [](const char* name) { return SourceLocation::command_line(name); };
    if (levels.size() != n_trials.size() || levels.size() != n_yes.size())
        throw InputError(where("levels"), "levels, n_trials and n_yes must have the same length");
    const std::optional<an::Family> f = an::parse_family(family);
    if (!f) throw InputError(where("family"), "the family must be normal, logistic, weibull or gumbel, not '" +
                                                  family + "'");
    if (!(guess_rate >= 0.0 && guess_rate < 1.0))
        throw InputError(where("guess_rate"), "the guess rate must lie in [0, 1)");
    if (!(target_p > guess_rate && target_p < 1.0))
        throw InputError(where("target_p"), "the target probability must lie between the guess rate and 1");
    if (!(lapse_max >= 0.0 && lapse_max + guess_rate < 1.0))
        throw InputError(where("lapse_max"), "the largest lapse rate must be ≥ 0 and leave guess + lapse below 1");
    std::vector<an::LevelCounts> counts;
    for (std::size_t i = 0; i < levels.size(); ++i) {
        if (n_trials[i] < 0 || n_yes[i] < 0 || n_yes[i] > n_trials[i])
            throw InputError(where("n_yes"), "each n_yes must lie between 0 and its n_trials");
        counts.push_back({levels[i], n_trials[i], n_yes[i]});
    }
    // As the study analysis fits a group (analysis/src/study_analysis.cpp):
    // gamma fixed at the guess rate, lambda free, the threshold where Psi
    // reaches target_p, i.e. F = (target_p - gamma) / (1 - gamma).
    an::FitOptions fo;
    fo.family = *f;
    fo.guess = an::RateConstraint::fixed_at(guess_rate);
    fo.lapse = an::RateConstraint::free_in(0.0, lapse_max);
    fo.threshold_proportion = (target_p - guess_rate) / (1.0 - guess_rate);
    an::PsychometricFit r;
    std::optional<an::PsychometricBootstrap> b;
    {
        py::gil_scoped_release release;
        r = an::fit_psychometric(counts, fo);
        if (bootstrap > 0 && r.estimate) {
            an::ResampleOptions ro;
            ro.n_resamples = bootstrap;
            if (seed) ro.seed = *seed;
            b = an::bootstrap_psychometric(counts, r, ro);
        }
    }
    py::dict out;
    out["reliable"] = r.reliable && (!b || b->reliable);
    out["reason"] = !r.reason.empty() ? r.reason : b ? b->reason : std::string();
    out["n_trials"] = r.n_trials;
    out["n_levels"] = r.n_levels;
    out["family"] = std::string(an::to_string(*f));
    if (r.estimate) {
        const an::PsychometricEstimate& e = *r.estimate;
        out["threshold"] = e.threshold;
        out["slope"] = e.slope;
        out["width"] = e.width;
        out["alpha"] = e.params.alpha;
        out["beta"] = e.params.beta;
        out["gamma"] = e.params.gamma;
        out["lambda"] = e.params.lambda;
        out["log_likelihood"] = e.log_likelihood;
        out["deviance"] = e.deviance;
    }
    if (b && b->threshold) {
        out["ci_lower"] = b->threshold->lower;
        out["ci_upper"] = b->threshold->upper;
    }
    return out;
}

std::vector<double> psi(const std::vector<double>& x, const std::string& family, double alpha, double beta,
                        double gamma, double lambda) {
    const std::optional<an::Family> f = an::parse_family(family);
    if (!f) throw InputError(SourceLocation::command_line("family"), "unknown family '" + family + "'");
    std::vector<double> out;
    for (const double v : x) out.push_back(an::psi(*f, v, {alpha, beta, gamma, lambda}));
    return out;
}

}  // namespace

void bind_study(py::module_& m) {
    m.def("_psi", &psi, py::arg("x"), py::arg("family"), py::arg("alpha"), py::arg("beta"), py::arg("gamma"),
          py::arg("lambda_"));
    m.def("_check", &check, py::arg("protocol"), py::arg("sets"), py::arg("db"));
    m.def("_run", &run, py::arg("protocol"), py::arg("db"), py::arg("observer"), py::arg("headless"),
          py::arg("progress"), py::arg("script"), py::arg("resume"), py::arg("resume_last"), py::arg("seed"),
          py::arg("observer_seed"), py::arg("allow_undisplayable"), py::arg("true_pse"), py::arg("verbose"),
          py::arg("custom"), py::arg("custom_name"));
    m.def("_write_trials_csv", &write_trials_csv, py::arg("paths"), py::arg("csv"), py::arg("salvage"));
    m.def("_analyze", &analyze, py::arg("paths"), py::arg("out"), py::arg("bootstrap"), py::arg("seed"),
          py::arg("family"), py::arg("threads"), py::arg("salvage"));
    m.def("_fit", &fit, py::arg("levels"), py::arg("n_trials"), py::arg("n_yes"), py::arg("guess_rate"),
          py::arg("target_p"), py::arg("family"), py::arg("lapse_max"), py::arg("bootstrap"), py::arg("seed"));
}

}  // namespace atonlab::python
