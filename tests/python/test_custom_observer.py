# needs: GL
"""Your own observer: atonlab.run(protocol, db, observer=callable) answers
every trial from what the model observer is shown; it is stored as its own
kind with its code and name; an exception in it stops the run with every
committed trial kept, and resume_last continues it to the same trials."""
import json
import sqlite3

import numpy as np
import pytest

from conftest import SOURCE, atonlab
from test_displayed import rec709_luminance_shares, srgb_eotf

pd = pytest.importorskip("pandas", reason="missing tool: python3-pandas")

TINY = SOURCE / "tests" / "data" / "run" / "tiny_2afc.toml"  # 3 trials, two-interval 2AFC
SMALL = SOURCE / "tests" / "data" / "run" / "small_2afc.toml"  # 2 conditions of 12 trials


def brighter(trial):
    """An energy observer: the view whose light adds more displayed luminance
    over its window, Σ (L − L_off) weighted by nothing (equal pixels)."""
    added = [float(np.sum(v["displayed_cd_m2"] - v["background_cd_m2"])) for v in trial["views"]]
    return "left" if added[0] > added[1] else "right"


def brighter_after(trial):
    """brighter() answering 0.2345 s after the stimulus: not a whole number of
    60 Hz refreshes, so the resumed session's clock (the last stored onset plus
    response time) falls between flips as the uninterrupted one's does."""
    return brighter(trial), 0.2345


def comparable(df):
    return df.drop(columns=["session", "source"]).reset_index(drop=True)


def states(db):
    with sqlite3.connect(db) as c:
        return [json.loads(s) for (s,) in c.execute("SELECT procedure_state_json FROM trials ORDER BY id")]


def test_a_custom_observer_answers_and_is_stored_as_its_own_kind(gl, tmp_path):
    db = tmp_path / "custom.db"
    seen = []

    def energy(trial):
        seen.append(trial)
        return brighter(trial), 0.25

    result = atonlab.run(TINY, db, observer=energy, observer_code="E01", observer_name="energy-sum")
    assert result["completed"]
    df = atonlab.read_study(db)
    assert len(df) == 3 == len(seen)
    assert set(df["observer"]) == {"E01"}
    assert [s["answer_after_offset_s"] for s in states(db)] == [0.25] * 3
    assert [s["observer"] for s in states(db)] == ["custom"] * 3
    assert [s["observer_name"] for s in states(db)] == ["energy-sum"] * 3
    # What it was given: the trial's facts and each judged light's window.
    t = seen[0]
    assert t["task"] == "2afc" and t["condition"] == "dark-empirical" and t["level"] == pytest.approx(2.9)
    assert [v["role"] for v in t["views"]] in (["test", "reference"], ["reference", "test"])
    v = t["views"][0]
    assert v["displayed_cd_m2"].shape == v["background_cd_m2"].shape and v["displayed_cd_m2"].ndim == 2
    assert v["focal_px"] == pytest.approx(0.9 * 320 / 0.1)
    # The codes it was shown, decoded independently (the scene's sRGB display:
    # each channel between its Rec.709 share of black and of peak, IEC 61966-2-1),
    # sum to the displayed luminance it was given.
    assert v["codes"].shape == v["displayed_cd_m2"].shape + (3,) and v["codes"].dtype == np.uint16
    assert v["bits"] == 8 and v["codes"].max() > 0
    d = atonlab.Scene.load(str(TINY.parent / "small.scene.toml")).render().display
    assert d["encoding"] == "srgb"
    share = rec709_luminance_shares()
    black, white = share * d["black_cd_m2"], share * d["peak_cd_m2"]
    decoded = (black + (white - black) * srgb_eotf(v["codes"] / 255.0)).sum(axis=2)
    np.testing.assert_allclose(v["displayed_cd_m2"], decoded, rtol=1e-5, atol=1e-9)
    # The answers are the energy observer's: the stored responses follow from what it was shown.
    assert list(df["response"]) == [brighter(t) for t in seen]


def test_an_exception_stops_the_run_and_resume_gives_the_same_trials(gl, tmp_path):
    whole = tmp_path / "whole.db"
    atonlab.run(TINY, whole, observer=brighter_after, observer_code="E01")

    db = tmp_path / "interrupted.db"

    def failing(trial):
        if trial["step"] == 1:
            raise ValueError("the model diverged")
        return brighter_after(trial)

    with pytest.raises(ValueError, match="the model diverged"):
        atonlab.run(TINY, db, observer=failing, observer_code="E01", observer_name="brighter")
    assert len(atonlab.read_study(db)) == 1  # the committed trial kept, the failed one not stored
    result = atonlab.run(TINY, db, observer=brighter_after, observer_code="E01", resume_last=True)
    assert result["completed"]
    pd.testing.assert_frame_equal(comparable(atonlab.read_study(db)), comparable(atonlab.read_study(whole)))


def test_a_wrong_answer_names_the_observer(gl, tmp_path):
    with pytest.raises(atonlab.InputError, match="answered \"yes\", which does not fit a 2afc trial"):
        atonlab.run(TINY, tmp_path / "wrong.db", observer=lambda trial: "yes")


def test_run_returns_what_it_found(gl, tmp_path, capfd):
    """The per-condition estimates and the model's true PSEs of
    tests/data/run/small_2afc.toml (two conditions, 12 trials each): the
    numbers `atonlab run` prints at its end (verbose=True prints them here)."""
    capfd.readouterr()
    result = atonlab.run(SMALL, tmp_path / "model.db", verbose=True)
    printed = capfd.readouterr().out
    assert [c["condition"] for c in result["conditions"]] == ["dark-empirical", "dusk-perceptual"]
    for c in result["conditions"]:
        assert c["n_tracks"] == 1 and c["responses"] == 12 and c["true_kind"] == "PSE"
        estimate = "no estimate" if c["estimate"] is None else f"{c['estimate']:.3f}"
        line = (f"{c['condition']:<24} {estimate} [{c['method']}; {c['finished']} of 1 tracks finished, 12 "
                f"responses]; model's true PSE {c['true_value']:.3f}")
        assert line in printed, printed
        # The estimate is the procedure's: the mean of its track's.
        assert c["estimate"] is None or c["estimate"] == pytest.approx(np.mean(c["tracks"]))
    assert result["conditions"][1]["estimate"] is not None
    # A custom observer has no true values.
    result = atonlab.run(TINY, tmp_path / "custom.db", observer=brighter)
    assert result["conditions"][0]["true_value"] is None and result["conditions"][0]["responses"] == 3
