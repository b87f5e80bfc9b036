# needs: GL
"""Studies from Python against the command line: check, run (and a run
stopped by KeyboardInterrupt that --resume-last completes to the same trials),
read_study against trials.csv, fit and analyze against `atonlab analyze`."""
import csv
import math
import os
import shutil
import signal

import numpy as np
import pytest

from conftest import QUICKSTART, atonlab, cli

pd = pytest.importorskip("pandas", reason="missing tool: python3-pandas")

# The quick start on a display of half the pixels (the same width, so the same
# field of view): a quarter of the work.
SMALL_DISPLAY = "width_px = 960\nheight_px = 540\nwidth_m = 0.598\n"


@pytest.fixture(scope="module")
def protocol(tmp_path_factory):
    folder = tmp_path_factory.mktemp("protocol")
    text = QUICKSTART.read_text()
    text = text.replace("width_px = 1920\nheight_px = 1080\nwidth_m = 0.598\n", SMALL_DISPLAY)
    assert SMALL_DISPLAY in text
    (folder / "quickstart.toml").write_text(text)
    shutil.copy(QUICKSTART.parent / "glare_side_by_side.scene.toml", folder)
    return folder / "quickstart.toml"


@pytest.fixture(scope="module")
def study(gl, protocol, tmp_path_factory):
    """The quick start run uninterrupted, and `atonlab analyze`'s outputs for it."""
    folder = tmp_path_factory.mktemp("study")
    db = folder / "quickstart.db"
    result = atonlab.run(protocol, db, observer="model", headless=True, true_pse=False)
    assert result["completed"] and result["exit_status"] == 0
    cli("analyze", db, "--out", folder / "report", "--bootstrap", 0)
    return db, folder / "report"


def cell_equal(text, value, dtype):
    if text == "":
        return value is pd.NA or value is None or (isinstance(value, float) and math.isnan(value))
    if str(dtype) == "boolean":
        return bool(value) == (text == "1")
    if str(dtype) in ("Int64", "float64"):
        return float(value) == float(text)
    return str(value) == text


def test_read_study_equals_trials_csv(study):
    db, report = study
    df = atonlab.read_study(db)
    with open(report / "trials.csv", newline="") as f:
        rows = list(csv.reader(f))
    header, rows = rows[0], rows[1:]
    assert list(df.columns) == header
    assert len(df) == len(rows) and len(rows) >= 16
    for i, row in enumerate(rows):
        for name, text in zip(header, row):
            assert cell_equal(text, df[name].iloc[i], df[name].dtype), (i, name, text, df[name].iloc[i])
    # Typed: numbers are numbers, 0/1 columns booleans, factors categorical.
    assert df["level"].dtype == np.float64 and df["trial_index"].dtype == "Int64"
    assert str(df["outcome"].dtype) == "boolean"
    assert isinstance(df["response"].dtype, pd.CategoricalDtype)
    assert set(df["response"].cat.categories) <= {"left", "right"}
    assert isinstance(df["condition"].dtype, pd.CategoricalDtype)
    assert df["adaptation_cd_m2"].eq(0.03).all()


def test_fit_equals_analyze(study):
    db, report = study
    df = atonlab.read_study(db)
    scored = df[df["outcome"].notna()]
    # The analysis counts levels on a 1e-9 grid (sums of steps differ in the last bits).
    levels = (scored["level"] * 1e9).round() / 1e9
    counts = scored.assign(level=levels).groupby("level")["outcome"].agg(["count", "sum"]).reset_index()
    f = atonlab.fit(counts["level"], counts["count"], counts["sum"].astype(int), task="2afc")
    fits = pd.read_csv(report / "fits.csv")
    row = fits[(fits["condition"] == "twilight") & (fits["observer"] == "model") &
               fits["analysis"].str.contains("psychometric")]
    assert len(row) == 1, fits[["condition", "observer", "analysis"]]
    assert f.threshold == pytest.approx(float(row["estimate"].iloc[0]), abs=5e-4)  # fits.csv's printed digits
    assert f.n_trials == len(scored)


def test_analyze_equals_the_command_line(study, tmp_path):
    db, report = study
    a = atonlab.analyze(db, bootstrap=0)
    assert a.out is None and a.exit_status in (0, 5)
    expected = pd.read_csv(report / "fits.csv")
    pd.testing.assert_frame_equal(a.fits, expected)
    assert a.summary["trials"] if "trials" in a.summary else True
    written = atonlab.analyze(db, tmp_path / "report", bootstrap=0)
    assert (tmp_path / "report" / "report.html").exists() and written.out == str(tmp_path / "report")


def comparable(df):
    return df.drop(columns=["session", "source"]).reset_index(drop=True)


def test_keyboard_interrupt_stops_cleanly_and_resumes_to_the_same_trials(study, protocol, tmp_path):
    db_whole, _ = study
    db = tmp_path / "interrupted.db"
    seen = []

    def progress(stored, bound):
        seen.append((stored, bound))
        if stored == 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        atonlab.run(protocol, db, progress=progress, true_pse=False)
    assert seen[0][0] == 1 and seen[-1][0] == 5 and seen[0][1] is not None
    kept = atonlab.read_study(db)
    assert len(kept) == 5  # every committed trial kept, nothing after
    r = cli("run", protocol, "--db", db, "--model-observer", "--headless", "--resume-last", "--no-true-pse", "--quiet")
    assert r.returncode == 0
    pd.testing.assert_frame_equal(comparable(atonlab.read_study(db)), comparable(atonlab.read_study(db_whole)))


def test_sigint_during_a_run_raises_keyboard_interrupt_after_the_trial(gl, protocol, tmp_path, capfd):
    db = tmp_path / "sigint.db"

    def progress(stored, bound):
        if stored == 3:
            os.kill(os.getpid(), signal.SIGINT)  # as Ctrl-C at the terminal

    capfd.readouterr()
    with pytest.raises(KeyboardInterrupt):
        atonlab.run(protocol, db, progress=progress, true_pse=False)
    assert capfd.readouterr().out == ""  # nothing on stdout unless asked
    assert len(atonlab.read_study(db)) == 3


def test_check_returns_the_table_as_data(gl, protocol):
    c = atonlab.check(protocol)
    assert c.displayable and bool(c)
    t = c.table
    assert set(t["end"]) == {"low", "high"} and set(t["role"]) == {"test", "reference"}
    assert (t["added_lux"] > 0).all()
    r = cli("check", protocol)
    assert c.text == r.stdout.removesuffix("every condition can produce a match on this display\n")


def test_check_refusal_equals_the_command_line(gl, protocol, tmp_path):
    # A level range wholly below the test (log10 0.0025 cd = -2.6): it cannot straddle it (R4).
    narrow = tmp_path / "narrow.toml"
    narrow.write_text(protocol.read_text().replace("start = [-2.1, -3.1], min_level = -3.6, max_level = -1.6",
                                                   "start = [-3.4, -3.5], min_level = -3.6, max_level = -3.3"))
    shutil.copy(protocol.parent / "glare_side_by_side.scene.toml", tmp_path)
    other = {"width_px": 640, "height_px": 360}
    c = atonlab.check(narrow, display=other)
    r = cli("check", narrow, *[a for k, v in other.items() for a in ("--set", f"display.{k}={v}")], check=False)
    assert r.returncode == 2 and not c.displayable and not c.conditions["twilight"]["displayable"]
    assert "atonlab: " + c.refusal == r.stderr.strip()
    assert c.display["width_px"] == 640


def test_a_bad_protocol_raises_input_error_with_file_line_and_key(gl, protocol, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(protocol.read_text().replace("stimulus_s = 0.5", "stimulus_s = -0.5"))
    shutil.copy(protocol.parent / "glare_side_by_side.scene.toml", tmp_path)
    with pytest.raises(atonlab.InputError) as e:
        atonlab.run(bad, tmp_path / "x.db")
    r = cli("run", bad, "--db", tmp_path / "y.db", "--model-observer", "--headless", check=False)
    assert r.returncode == 2
    assert "atonlab: " + str(e.value).splitlines()[0] == r.stderr.strip().splitlines()[0]
    assert e.value.file == str(bad) and e.value.line > 0 and e.value.key == "timing.stimulus_s"
    assert not (tmp_path / "x.db").exists()


def test_a_foreign_file_raises_study_file_error(tmp_path):
    foreign = tmp_path / "notes.db"
    foreign.write_text("not a study\n")
    with pytest.raises(atonlab.StudyFileError) as e:
        atonlab.read_study(foreign)
    assert e.value.file == str(foreign)
