# needs: GL
"""What the observer sees, as numbers: Frame.display, Frame.displayed_cd_m2
against an independent decode of `atonlab render --png`'s codes, and
Frame.added_lux against `atonlab check`'s number."""
import numpy as np
import pytest

from conftest import QUICKSTART_SCENE, SOURCE, atonlab, cli, read_png

SMALL = {"display.width_px": 480, "display.height_px": 270}
# The quick start's lights at the question: 0.01 cd/m², a red test light beside a white reference.
RED_WHITE = {"eye.adaptation_cd_m2": 0.01, "environment.luminance_cd_m2": 0.01, "light.test.intensity_cd": 0.05,
             "light.test.colour": "red", "light.reference.intensity_cd": 0.05, "tonemap.operator": "perceptual"}
RED_WHITE_SET = ["display.width_px=480", "display.height_px=270", "eye.adaptation_cd_m2=0.01",
                 "environment.luminance_cd_m2=0.01", "light.test.intensity_cd=0.05", 'light.test.colour="red"',
                 "light.reference.intensity_cd=0.05", 'tonemap.operator="perceptual"']
RUN = SOURCE / "tests" / "data" / "run"


def srgb_eotf(v):
    """IEC 61966-2-1's decoding, V in [0, 1] to relative linear light."""
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def rec709_luminance_shares():
    """Y of each Rec.709 primary at full drive, white Y = 1: the middle row of
    the RGB→XYZ matrix from the primaries' and D65's xy (SMPTE RP 177, 1993, §3)."""
    xy = np.array([(0.64, 0.33), (0.30, 0.60), (0.15, 0.06)])
    primaries = np.stack([xy[:, 0] / xy[:, 1], np.ones(3), (1 - xy[:, 0] - xy[:, 1]) / xy[:, 1]])
    w = np.array([0.3127, 0.3290])
    white = np.array([w[0] / w[1], 1.0, (1 - w[0] - w[1]) / w[1]])
    return np.linalg.solve(primaries, white)  # the scale of each column: its Y


def test_display_as_numbers(gl):
    frame = atonlab.Scene.load(str(QUICKSTART_SCENE), {**SMALL, "display.peak_cd_m2": 250.0}).render()
    d = frame.display
    assert d["peak_cd_m2"] == 250.0 and d["encoding"] == "srgb" and d["bits"] == 8 == frame.bits
    # "transfer", the key's old name, still reads it, with a DeprecationWarning.
    with pytest.warns(DeprecationWarning, match=r'Frame.display\["transfer"\] is deprecated'):
        assert d["transfer"] == "srgb"
    with pytest.warns(DeprecationWarning):
        assert "transfer" in d and d.get("transfer") == "srgb"
    # Rec.709's channel shares of white and its primaries with D65.
    assert d["channel_white_cd_m2"] == pytest.approx(list(250 * rec709_luminance_shares()), rel=1e-9)
    assert d["primaries_xy"]["red"] == pytest.approx((0.64, 0.33), abs=1e-9)
    assert d["primaries_xy"]["white"] == pytest.approx((0.3127, 0.3290), abs=1e-9)
    assert d["focal_px"] == pytest.approx(0.9 * 480 / 0.598)


def test_displayed_luminance_is_the_png_decoded(gl, tmp_path):
    frame = atonlab.Scene.load(str(QUICKSTART_SCENE), {**SMALL, **RED_WHITE}).render()
    png = tmp_path / "frame.png"
    cli("render", QUICKSTART_SCENE, "-o", tmp_path / "frame.exr", "--png", png,
        *[a for s in RED_WHITE_SET for a in ("--set", s)])
    codes = read_png(png)
    # The scene's display: sRGB, each channel between its Rec.709 share of black and of peak.
    d = frame.display
    share = rec709_luminance_shares()
    black, white = share * d["black_cd_m2"], share * d["peak_cd_m2"]
    expected = black + (white - black) * srgb_eotf(codes / 255.0)
    shown = frame.displayed_cd_m2
    assert shown.shape == codes.shape and shown.dtype == np.float32
    # float32 values: 1e-6 relative.
    np.testing.assert_allclose(shown, expected, rtol=1e-6, atol=1e-9)
    # The red light shows red: over the sky around it, its red channel adds more than its green.
    h, w = codes.shape[:2]
    x = int(round(w / 2 - 5.0 / frame.deg_per_px))  # the test light, 5° left of the centre
    patch = shown[h // 2 - 3:h // 2 + 3, x - 3:x + 3]
    added = patch.max(axis=(0, 1)) - np.median(shown[h // 2 - 3:h // 2 + 3, w // 2 - 3:w // 2 + 3], axis=(0, 1))
    assert added[0] > 0 and added[0] > added[1]


def test_added_lux_is_checks_number(gl):
    """The reference light of tests/data/run/tiny_2afc.toml at both ends of its
    range: the frame's overrides as the protocol makes them (its display, the
    block's and condition's sets, reference_set, the level)."""
    c = atonlab.check(RUN / "tiny_2afc.toml")
    ends = c.data["conditions"][0]["ends"]
    overrides = {"display.width_px": 320, "display.height_px": 180, "display.width_m": 0.1,
                 "display.viewing_distance_m": 0.9, "eye.adaptation_cd_m2": 0.001,
                 "environment.luminance_cd_m2": 0.001, "tonemap.operator": "empirical",
                 "eye.glare": "gaussian-bloom", "light.test.intensity_cd": 0}
    for end in ends:
        [ref] = [light for light in end["lights"] if light["role"] == "reference"]
        frame = atonlab.Scene.load(str(RUN / "small.scene.toml"),
                                   {**overrides, "light.reference.intensity_cd": 10.0 ** end["level"]}).render()
        assert frame.added_lux("reference") == pytest.approx(ref["added_lux"], rel=1e-12)
    with pytest.raises(atonlab.InputError, match="no light or disc named \"buoy\""):
        frame.added_lux("buoy")


def test_numpy_scalars_are_accepted(gl):
    """np.int64 where an integer is asked (display.width_px), np.float32 and
    np.float64 where a float is: the same scene as the Python numbers give."""
    scene = atonlab.Scene.load(str(QUICKSTART_SCENE), {"display.width_px": np.int64(480),
                                                       "display.height_px": np.int32(270),
                                                       "eye.adaptation_cd_m2": np.float32(0.25),
                                                       "light.test.intensity_cd": np.float64(0.05)})
    assert scene.width_px == 480 and scene.height_px == 270
    assert scene.adaptation_cd_m2 == float(np.float32(0.25))


def test_dir_lists_only_atonlabs_names():
    names = dir(atonlab)
    assert {"Scene", "Frame", "run", "check", "read_study"} <= set(names)
    assert not {"json", "math", "os", "tempfile"} & set(names)


def test_an_overrides_error_names_the_argument_and_echoes_the_value():
    with pytest.raises(atonlab.InputError) as e:
        atonlab.Scene.load(str(QUICKSTART_SCENE), {"display.width_px": 1920.5})
    assert e.value.option == "overrides" and e.value.key == "display.width_px"
    assert "--set" not in str(e.value) and "(the value given: 1920.5)" in str(e.value), str(e.value)
    with pytest.raises(atonlab.InputError) as e:
        atonlab.Scene.load(str(QUICKSTART_SCENE), {"light.test.intensity_cd": -1.0})
    assert e.value.option == "overrides" and "(the value given: -1.0)" in str(e.value), str(e.value)


def test_metadata_is_typed(gl):
    frame = atonlab.Scene.load(str(QUICKSTART_SCENE), {**SMALL, "camera.yaw_deg": 2.5}).render(time_s=1.25)
    m = frame.metadata
    assert m["time_s"] == 1.25 and isinstance(m["time_s"], float)
    # The pinhole of a veridical camera: the viewing distance in pixel pitches, 0.9 m × 480 px / 0.598 m.
    assert m["camera"]["focal_px"] == pytest.approx(0.9 * 480 / 0.598, rel=1e-4)
    assert m["camera"]["position_m"] == [0.0, 3.0, 0.0] and m["camera"]["yaw_deg"] == 2.5
    assert m["tonemap"]["operator"] == "empirical" and m["tonemap"]["bits"] == 8.0
    assert isinstance(m["software"], str)


def test_a_missing_file_is_an_input_error_and_file_not_found(tmp_path):
    missing = tmp_path / "no-such.scene.toml"
    for call in (lambda: atonlab.Scene.load(str(missing)), lambda: atonlab.check(tmp_path / "no-such.toml")):
        with pytest.raises(FileNotFoundError) as e:
            call()
        assert isinstance(e.value, atonlab.InputError) and "no-such" in str(e.value) and "no-such" in e.value.filename
    # An error inside a file that exists is an InputError only.
    bad = tmp_path / "bad.scene.toml"
    bad.write_text("[display]\nwidth_px = \"wide\"\n")
    with pytest.raises(atonlab.InputError) as e:
        atonlab.Scene.load(str(bad))
    assert not isinstance(e.value, FileNotFoundError)


def test_a_typo_in_a_protocol_is_reported_before_any_gl_work(tmp_path):
    """run() reads and checks the protocol before it makes the GL context: with
    no EGL vendor library (no context can be made) a typo still raises the
    InputError naming its key, not NoContextError, and no study file is made."""
    import os
    import subprocess
    import sys
    from conftest import BINARY
    typo = tmp_path / "typo.toml"
    typo.write_text((RUN / "tiny_2afc.toml").read_text().replace("max_trials = 3", "max_trails = 3"))
    (tmp_path / "small.scene.toml").write_text((RUN / "small.scene.toml").read_text())  # the protocol's scene
    env = {**os.environ, "__EGL_VENDOR_LIBRARY_FILENAMES": str(tmp_path / "none.json")}
    c = subprocess.run([BINARY, "render", str(RUN / "small.scene.toml"), "-o", str(tmp_path / "x.exr")],
                       capture_output=True, text=True, env=env)
    if c.returncode != 3:
        pytest.skip("not applicable: this machine's EGL does not honour __EGL_VENDOR_LIBRARY_FILENAMES")
    code = ("import sys, atonlab\n"
            "try:\n"
            "    atonlab.run(sys.argv[1], sys.argv[2])\n"
            "except atonlab.InputError as e:\n"
            "    print('InputError', e.key)\n")
    r = subprocess.run([sys.executable, "-c", code, str(typo), str(tmp_path / "x.db")], capture_output=True,
                       text=True, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("InputError") and "max_trails" in r.stdout, r.stdout
    assert not (tmp_path / "x.db").exists()
