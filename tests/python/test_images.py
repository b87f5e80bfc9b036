"""atonlab.tonemap, atonlab.glare and atonlab.light on numpy arrays against
`atonlab tonemap`, `atonlab glare` and `atonlab light` on the same EXR; input
errors carry the command line's sentence and where. No GL."""
import re

import numpy as np
import pytest

from conftest import atonlab, cli, read_png

DEG_PER_PX = 0.02


def hdr_image():
    """A dim field (0.03 cd/m²) with two lights of 40 and 4000 cd/m², a red and a blue pixel: deterministic."""
    rng = np.random.default_rng(7)
    img = np.full((60, 90, 3), 0.03, dtype=np.float32) * rng.uniform(0.5, 1.5, (60, 90, 1)).astype(np.float32)
    img[20, 30] = 40.0
    img[40, 70] = (4000.0, 3000.0, 2000.0)
    img[10, 10] = (5.0, 0.0, 0.0)
    img[50, 20] = (0.0, 0.0, 8.0)
    return img


@pytest.fixture
def exr(tmp_path):
    path = tmp_path / "in.exr"
    atonlab.write_exr(str(path), hdr_image(), deg_per_px=DEG_PER_PX)
    return path


def test_exr_round_trip(exr):
    img, meta = atonlab.read_exr(str(exr))
    assert np.array_equal(img, hdr_image())
    assert meta["units"] == "cd/m2" and meta["degreesPerPixel"] == pytest.approx(DEG_PER_PX)


@pytest.mark.parametrize("settings", [
    {},
    {"operator": "perceptual", "adaptation_cd_m2": 0.03},
    {"operator": "reinhard", "reinhard_white": "max", "dither": False},
    {"operator": "linear", "white_cd_m2": 50.0, "blueshift": False, "hue_preservation": "rgb"},
    {"encoding": "pq", "peak_cd_m2": 1000.0, "black_cd_m2": 0.05},
])
def test_tonemap_equals_the_command_line(exr, tmp_path, settings):
    codes = atonlab.tonemap(hdr_image(), **settings)
    args = []
    for k, v in settings.items():
        v = ("on" if v else "off") if isinstance(v, bool) else v
        args += ["--" + k.replace("_", "-"), v]
    png = tmp_path / "out.png"
    cli("tonemap", exr, "-o", png, *args)
    assert codes.shape == (60, 90, 3) and codes.dtype == np.uint8
    assert np.array_equal(codes, read_png(png))


@pytest.mark.parametrize("settings", [
    {},
    {"model": "gaussian-bloom", "bloom_sigma_deg": 0.1},
    {"model": "spencer", "adaptation_cd_m2": 0.03, "window": "none", "radius_deg": 0.5},
    # Models' own settings, from their declarations: a keyword here, an option there.
    {"model": "spencer", "spencer_vision": "photopic"},
    {"model": "cie", "cie_age_years": 60},
])
def test_glare_equals_the_command_line(exr, tmp_path, settings):
    out = atonlab.glare(hdr_image(), DEG_PER_PX, **settings)
    args = []
    for k, v in settings.items():
        args += ["--" + k.replace("_", "-"), v]
    # The angle given to both (the EXR's degreesPerPixel attribute is a 32-bit float).
    cli("glare", exr, "-o", tmp_path / "out.exr", "--deg-per-px", DEG_PER_PX, *args)
    ref, _ = atonlab.read_exr(str(tmp_path / "out.exr"))
    assert out.shape == (60, 90, 3) and out.dtype == np.float32
    assert np.array_equal(out, ref)
    assert not out.flags.owndata and out.base is not None  # the library's buffer, not copied


def test_glare_takes_and_documents_each_models_declared_settings():
    # The docstring lists the settings from the models' declarations (glare_models/glare_setting.h).
    for key in ("bloom_sigma_deg", "spencer_vision", "cie_age_years", "eye_preset"):
        assert key in atonlab.glare.__doc__
    # A setting is checked as the scene file checks it, and a key no model declares is refused.
    with pytest.raises(Exception, match="bloom_sigma_deg must be greater than 0"):
        atonlab.glare(hdr_image(), DEG_PER_PX, model="gaussian-bloom", bloom_sigma_deg=-1.0)
    with pytest.raises(Exception, match="no glare model has a setting 'bloom_sigma'"):
        atonlab.glare(hdr_image(), DEG_PER_PX, model="gaussian-bloom", bloom_sigma=0.1)
    # Two values of a setting give two images.
    a = atonlab.glare(hdr_image(), DEG_PER_PX, model="spencer", spencer_vision="photopic")
    b = atonlab.glare(hdr_image(), DEG_PER_PX, model="spencer", spencer_vision="scotopic")
    assert not np.array_equal(a, b)


def test_glare_conserves_energy():
    img = hdr_image()
    out = atonlab.glare(img, DEG_PER_PX, model="gaussian-bloom", bloom_sigma_deg=0.05)
    # Energy-conserving (docs/glare.md): what leaves is what the kernel's
    # radial window and the frame's edge cut (`atonlab glare` reports both),
    # under 0.5 % here.
    assert out.sum(dtype=np.float64) == pytest.approx(img.sum(dtype=np.float64), rel=5e-3)


def test_light_equals_the_command_line():
    r = cli("light", "--intensity-cd", 250, "--visibility-nmi", 7)
    printed = float(re.search(r"range d: ([0-9.e+-]+) nmi", r.stdout).group(1))
    d = atonlab.light.range_nmi(250.0, visibility_nmi=7.0)
    assert d == pytest.approx(printed, rel=1e-5)  # printed with 6 digits
    assert atonlab.light.intensity_cd(d, visibility_nmi=7.0) == pytest.approx(250.0, rel=1e-9)


def test_the_old_names_of_encoding_still_work_with_a_note(exr, tmp_path):
    # tonemap(display=) and `--display`, the old names of encoding= and `--encoding`.
    settings = {"peak_cd_m2": 1000.0, "black_cd_m2": 0.05}
    expected = atonlab.tonemap(hdr_image(), encoding="pq", **settings)
    with pytest.warns(DeprecationWarning, match="display=.* is deprecated; write encoding="):
        assert np.array_equal(atonlab.tonemap(hdr_image(), display="pq", **settings), expected)
    with pytest.raises(ValueError, match="give encoding= alone"):
        atonlab.tonemap(hdr_image(), display="pq", encoding="pq")
    png = tmp_path / "old.png"
    r = cli("tonemap", exr, "-o", png, "--display", "pq", "--peak-cd-m2", "1000", "--black-cd-m2", "0.05")
    assert "--display: note: --display is deprecated; write --encoding" in r.stderr
    assert np.array_equal(read_png(png), expected)
    r = cli("tonemap", exr, "-o", png, "--display", "pq", "--encoding", "pq", check=False)
    assert r.returncode == 2 and "give --encoding alone" in r.stderr


def test_light_against_allard():
    # K2012 eq 2.1 (IALA E200-2): E_t = I 0.05^(d/V) / (3.43e6 d²), d in nmi;
    # at night E_t = 2e-7 lx, nominal V = 10 nmi.
    d = atonlab.light.range_nmi(1000.0)
    assert 1000.0 * 0.05 ** (d / 10.0) / (3.43e6 * d ** 2) == pytest.approx(2e-7, rel=1e-9)


def test_input_error_has_the_command_lines_sentence(exr, tmp_path):
    with pytest.raises(atonlab.InputError) as e:
        atonlab.tonemap(hdr_image(), operator="filmic")
    r = cli("tonemap", exr, "-o", tmp_path / "x.png", "--operator", "filmic", check=False)
    assert r.returncode == 2
    assert "atonlab: " + str(e.value) == r.stderr.strip()
    assert isinstance(e.value, ValueError)
    assert e.value.option == "--operator" and e.value.file is None and e.value.line is None


def test_input_error_from_a_file_has_file_line_and_key(tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text('[display]\nwidth_px = 640\nheight_px = 480\nwidth_m = 0.3\nviewing_distance_m = 0.6\n\n'
                     '[tonemap]\noperator = "filmic"\n')
    with pytest.raises(atonlab.InputError) as e:
        atonlab.tonemap(hdr_image(), scene=str(scene))
    assert e.value.file == str(scene) and e.value.line == 8 and e.value.key == "tonemap.operator"
    r = cli("tonemap", tmp_path / "none.exr", "-o", tmp_path / "x.png", "--scene", scene, check=False)
    assert "atonlab: " + str(e.value) == r.stderr.strip()


def test_a_bad_array_is_an_input_error():
    with pytest.raises(atonlab.InputError) as e:
        atonlab.tonemap(np.zeros((4, 4)))
    assert e.value.option == "hdr"


def test_no_gl_context_raises_no_context_error(tmp_path):
    # glvnd without a vendor library: no EGL display, as on a machine without
    # GL (`atonlab render` exits 3 with the same sentence). In a child process:
    # this one may hold a context already.
    import os
    import subprocess
    import sys
    code = ("import atonlab, sys\n"
            "try:\n"
            "    atonlab.Scene.load(sys.argv[1], {'display.width_px': 64, 'display.height_px': 36}).render()\n"
            "except atonlab.NoContextError as e:\n"
            "    assert isinstance(e, RuntimeError)\n"
            "    print('NoContextError:', e)\n")
    from conftest import QUICKSTART_SCENE
    env = {**os.environ, "__EGL_VENDOR_LIBRARY_FILENAMES": str(tmp_path / "none.json")}
    r = subprocess.run([sys.executable, "-c", code, str(QUICKSTART_SCENE)], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    from conftest import BINARY
    c = subprocess.run([BINARY, "render", str(QUICKSTART_SCENE), "-o", str(tmp_path / "x.exr")], capture_output=True,
                       text=True, env=env)
    if c.returncode != 3:
        pytest.skip("not applicable: this machine's EGL does not honour __EGL_VENDOR_LIBRARY_FILENAMES")
    assert r.stdout.strip() == "NoContextError: " + c.stderr.strip().removeprefix("atonlab: ")
