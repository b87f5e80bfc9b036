"""atonlab from Python (docs/python.md).

Scenes rendered to numpy arrays (linear Rec.709, absolute cd/m²), the tone
mappers, glare models and Allard's law on any array, protocols checked and
run, studies read as pandas DataFrames and analysed, psychometric functions
fitted: the same code as the `atonlab` command line, with its checks and its
sentences. Luminance in cd/m², intensity in cd, angles in degrees, time in s.

The module keeps one headless OpenGL 4.5 context for the process, made on the
first render (Scene.render, psf, check, run) and used from any thread, one
call at a time. Nothing is printed on stdout unless asked (run(verbose=True)).
"""
import json
import math
import os
import tempfile

from ._atonlab import (  # noqa: F401  (re-exported)
    Frame,
    InputError,
    InputFileNotFoundError,
    NoContextError,
    Scene,
    StudyFileError,
    __version__,
    glare,
    light,
    psf,
    read_exr,
    tonemap,
    write_exr,
)
from . import _atonlab

__all__ = ["Scene", "Frame", "InputError", "InputFileNotFoundError", "NoContextError", "StudyFileError", "tonemap", "glare", "psf",
           "light", "read_exr", "write_exr", "check", "run", "read_study", "analyze", "fit", "Check", "Analysis",
           "Fit", "__version__"]


def __dir__():
    """atonlab's own names (PEP 562): not the standard modules it uses."""
    return sorted(__all__)


def _paths(paths):
    if isinstance(paths, (str, os.PathLike)):
        return [os.fspath(paths)]
    return [os.fspath(p) for p in paths]


# ---------------------------------------------------------------------------
# check

class Check:
    """What a display shows of a protocol's stimuli (docs/running.md "Displayability").

    displayable: every condition can produce a match; table: a pandas DataFrame,
    one row per condition, end of its level range and judged light (added_lux
    and resolution_lux in lx, peak_code, clipped, background codes and cd/m²);
    conditions: per condition, displayable, problems (sentences) and
    equal_level; display: the geometry; text: the table `atonlab check`
    prints; refusal: the sentences `atonlab run` refuses it with ("" if none).
    """

    def __init__(self, data, text, refusal):
        self.data = data
        self.display = data["display"]
        self.displayable = data["displayable"]
        self.conditions = {c["name"]: {"displayable": c["displayable"], "problems": c["problems"],
                                       "equal_level": c["equal_level"]} for c in data["conditions"]}
        self.text = text
        self.refusal = refusal

    @property
    def table(self):
        import pandas as pd
        rows = []
        for c in self.data["conditions"]:
            for end_name, end in zip(("low", "high"), c["ends"]):
                for light_ in end["lights"]:
                    r, g, b = light_["background_code"]
                    rows.append({"condition": c["name"], "end": end_name, "level": end["level"],
                                 "role": light_["role"], "light": light_["light"],
                                 "added_lux": light_["added_lux"], "resolution_lux": light_["resolution_lux"],
                                 "peak_code": light_["peak_code"], "clipped": light_["clipped"],
                                 "background_r": r, "background_g": g, "background_b": b,
                                 "background_cd_m2": light_["background_cd_m2"],
                                 "displayable": c["displayable"]})
        return pd.DataFrame(rows)

    def __bool__(self):
        return bool(self.displayable)

    def __repr__(self):
        return f"<atonlab.Check displayable={self.displayable}, {len(self.conditions)} condition(s)>"


def check(protocol, display=None, db=None):
    """Renders every condition of a protocol at both ends of its level range on
    its display (or another: display={"width_px": 1280, "height_px": 720,
    "width_m": 0.30, "viewing_distance_m": 0.6}) and judges whether a match can
    be shown there, as `atonlab check` does; db: a study file whose calibration
    of the protocol's display encodes the frames (read only). Returns a Check.
    Raises InputError (the protocol, scene or display), StudyFileError (db),
    NoContextError. The GIL is released while rendering."""
    sets = []
    for key, value in (display or {}).items():
        key = key if key.startswith("display.") else "display." + key
        sets.append(f"{key}={value!r}" if not isinstance(value, str) else f"{key}={value}")
    data, table, refusal = _atonlab._check(os.fspath(protocol), sets, "" if db is None else os.fspath(db))
    return Check(json.loads(data), table, refusal)


# ---------------------------------------------------------------------------
# run

def run(protocol, db, observer="model", headless=True, progress=None, *, script=None, resume=None,
        resume_last=False, seed=None, observer_seed=None, allow_undisplayable=False, true_pse=True, verbose=False,
        observer_code=None, observer_name=None):
    """Runs one session of a protocol into the study file db, as `atonlab run`
    does (docs/running.md): every trial committed before the next is shown.

    observer: "model" (the model observer, headless), an observer code (a
    person at the screen: headless=False), or the code stored with script (a
    file of answers). progress(stored, bound) is called after each trial is
    committed, with the session's stored trials and the schedule's bound (None
    when unbounded). resume (a session id) or resume_last continue a session;
    seed and observer_seed as the command's --seed and --observer-seed.

    KeyboardInterrupt (Ctrl-C, or raised by progress) stops the run as SIGINT
    stops the command: the trial being shown is finished and committed, the
    session is marked quit and the study file closed, then KeyboardInterrupt
    is raised; run(..., resume_last=True) continues it to the same trials as
    an uninterrupted run. Returns {"completed", "status", "exit_status", "db",
    "conditions"}: conditions lists what the session found, one dict per
    condition (pandas.DataFrame(result["conditions"]) makes it a table):
    condition, estimate (the mean of its tracks' estimates, the procedure's
    units; None without one), tracks, method, n_tracks, finished, responses,
    and for a model observer's completed session with true_pse the model's
    true_value (its PSE, or its level at the procedure's target probability,
    true_kind says which; None with true_value_why where it has none).

    observer may also be a callable, your own observer (docs/python.md "Your
    own observer"): observer(trial) gets each trial's facts and what the model
    observer would see (trial["views"]: each judged light's window of
    displayed luminance, cd/m², and of display codes) and returns a response word ("left", "right",
    "yes", "no", ...) or (word, response_time_s). It is stored with the code
    observer_code (default "custom") and, in each trial's state, the kind
    "custom" and observer_name (default the callable's __name__). An exception
    it raises ends the session there: that trial is not stored, every
    committed one is kept, the session stays open, and the exception is
    raised; run(..., resume_last=True) continues it.
    Raises InputError, StudyFileError, NoContextError. The GIL is released
    while the session runs; nothing is printed on stdout unless verbose."""
    custom = None
    if callable(observer):
        custom = observer
        observer_name = observer_name or getattr(observer, "__name__", type(observer).__name__)
        observer = observer_code or "custom"
    elif observer_code is not None or observer_name is not None:
        raise InputError("observer_code and observer_name are for a callable observer")
    return _atonlab._run(os.fspath(protocol), os.fspath(db), observer, headless, progress,
                         None if script is None else os.fspath(script), resume, resume_last, seed, observer_seed,
                         allow_undisplayable, true_pse, verbose, custom, observer_name or "")


# ---------------------------------------------------------------------------
# read_study

_BOOL = ("outcome", "test_on_left", "missed_deadline", "chose_reference", "reversal")
_INT = ("trial_index", "block_index", "dropped_frames")
_FLOAT = ("level", "response_value", "response_time_s", "onset_time_s", "adaptation_cd_m2", "test_intensity_cd",
          "guess_rate", "target_p", "posterior_mean", "posterior_sd", "posterior_lower", "posterior_upper")
#: A text column becomes categorical when it has at most this many distinct values ...
CATEGORY_MAX_VALUES = 64
#: ... and at most this fraction of the rows.
CATEGORY_MAX_FRACTION = 0.5


def _number(text):
    """float(text) (correctly rounded, as the file's shortest round-trip form needs), or None."""
    try:
        return float(text)
    except ValueError:
        return None


def _typed(df):
    """trials.csv's text cells as typed columns (docs/python.md "read_study")."""
    import pandas as pd
    out = {}
    for name in df.columns:
        text = df[name]
        empty = text == ""
        if name in _BOOL:
            col = pd.Series(pd.array([None if e else t == "1" for t, e in zip(text, empty)], dtype="boolean"))
        elif name in _INT:
            col = pd.Series(pd.array([None if e else int(t) for t, e in zip(text, empty)], dtype="Int64"))
        elif name in _FLOAT:
            col = pd.Series([math.nan if e else float(t) for t, e in zip(text, empty)], dtype="float64")
        else:
            numbers = [_number(t) for t in text]
            if name != "session" and (~empty).any() and all(e or n is not None for n, e in zip(numbers, empty)):
                # a setting whose values are all numbers
                col = pd.Series([math.nan if e else n for n, e in zip(numbers, empty)], dtype="float64")
            else:
                col = text.mask(empty).astype("object")
                distinct = col.nunique(dropna=True)
                if distinct <= CATEGORY_MAX_VALUES and distinct <= max(1, CATEGORY_MAX_FRACTION * len(col)):
                    col = col.astype("category")
        out[name] = col.reset_index(drop=True)
    return pd.DataFrame(out, columns=list(df.columns))


def read_study(paths, salvage=False):
    """Reads study files (read only; readable while a session runs) or trials
    CSVs into a pandas DataFrame of trials: the rows and columns of the
    trials.csv `atonlab analyze` writes (docs/analysis.md), one row per trial,
    typed: 0/1 columns as nullable booleans (outcome, test_on_left,
    missed_deadline, chose_reference, reversal), counts as Int64, numbers as
    float64 (level in the procedure's units, times in s, luminances in cd/m²,
    intensities in cd), text factors as categoricals where they have few
    values; a setting column (a scene key such as "eye.glare") as numbers when
    all its values are numbers. salvage: read what is left of a damaged file.
    Raises InputError, StudyFileError."""
    import pandas as pd
    with tempfile.TemporaryDirectory(prefix="atonlab-") as tmp:
        csv = os.path.join(tmp, "trials.csv")
        _atonlab._write_trials_csv(_paths(paths), csv, salvage)
        text = pd.read_csv(csv, dtype=str, keep_default_na=False, na_filter=False)
    return _typed(text)


# ---------------------------------------------------------------------------
# analyze

class Analysis:
    """What `atonlab analyze` computed: fits (a DataFrame: fits.csv, one row per
    estimate), summary (a dict: summary.json, every number of the report),
    out (the report's folder, or None) and exit_status (5: written without
    some figures)."""

    def __init__(self, fits, summary, out, exit_status):
        self.fits = fits
        self.summary = summary
        self.out = out
        self.exit_status = exit_status

    def __repr__(self):
        return f"<atonlab.Analysis {len(self.fits)} estimate(s){', report in ' + self.out if self.out else ''}>"


def analyze(paths, out=None, *, bootstrap=None, seed=None, family="normal", threads=None, salvage=False):
    """Analyses study files or trials CSVs as `atonlab analyze` does
    (docs/analysis.md): psychometric fits with bootstrap intervals (bootstrap
    resamples, default 999; seed), staircase and QUEST summaries. The report
    (report.html, summary.json, fits.csv, trials.csv, figures) is written into
    out only when out is given. Returns an Analysis. Raises InputError,
    StudyFileError. The GIL is released while fitting and bootstrapping."""
    import pandas as pd
    paths = _paths(paths)

    def result(folder, status):
        fits = pd.read_csv(os.path.join(folder, "fits.csv"))
        with open(os.path.join(folder, "summary.json"), encoding="utf-8") as f:
            summary = json.load(f)
        return Analysis(fits, summary, None if out is None else os.fspath(out), status)

    if out is not None:
        status = _atonlab._analyze(paths, os.fspath(out), bootstrap, seed, family, threads, salvage)
        return result(os.fspath(out), status)
    with tempfile.TemporaryDirectory(prefix="atonlab-analysis-") as tmp:
        status = _atonlab._analyze(paths, tmp, bootstrap, seed, family, threads, salvage)
        return result(tmp, status)


# ---------------------------------------------------------------------------
# fit

class Fit(dict):
    """A psychometric fit: threshold (level units; the PSE when target_p is
    0.5 and the guess rate 0), slope (dPsi/dx at it), width, alpha, beta,
    gamma, lambda, log_likelihood, deviance, reliable and reason, n_trials,
    n_levels, and with bootstrap ci_lower and ci_upper (95 % percentile
    interval of the threshold). Keys are also attributes."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    def psi(self, x):
        """The fitted function Psi(x) = gamma + (1 - gamma - lambda) F(x) at the levels x (a list)."""
        return _atonlab._psi([float(v) for v in x], self["family"], self["alpha"], self["beta"], self["gamma"],
                             self["lambda"])


_TASKS = {"2afc": (0.0, 0.5), "yes-no": (0.0, 0.5), "2afc-correct": (0.5, 0.75)}


def fit(levels, n_trials, n_yes, task="2afc", family="normal", *, guess_rate=None, target_p=None, lapse_max=0.06,
        bootstrap=0, seed=None):
    """Fits a psychometric function to your own counts by binomial maximum
    likelihood, exactly as `atonlab analyze` fits a condition
    (docs/analysis-fits.md): at each level (any units; log10 cd for atonlab's
    intensity levels), n_yes of n_trials answers were "yes" (the counted
    outcome). task: "2afc" (atonlab's comparison, "chose the level's
    stimulus": guess rate 0, threshold at P = 0.5, the PSE), "yes-no" (the
    same rates), "2afc-correct" (scored correct/incorrect: guess rate 0.5,
    threshold at P = 0.75); guess_rate and target_p override the task's.
    family: normal, logistic, weibull, gumbel; lambda free in [0, lapse_max];
    bootstrap: parametric resamples for the threshold's interval (seed).
    Returns a Fit. The GIL is released while fitting."""
    if task not in _TASKS:
        raise InputError(f"task: must be one of {', '.join(_TASKS)}, not {task!r}")
    g, p = _TASKS[task]
    return Fit(_atonlab._fit([float(x) for x in levels], [int(n) for n in n_trials], [int(k) for k in n_yes],
                             g if guess_rate is None else float(guess_rate), p if target_p is None else float(target_p),
                             family, float(lapse_max), int(bootstrap), seed))
