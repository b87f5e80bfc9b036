# needs: GL
"""Scene.render against `atonlab render`: the same pixels, metadata and codes;
the HDR array is a view of the frame's memory; psf against `atonlab psf`."""
import numpy as np
import pytest

from conftest import QUICKSTART_SCENE, atonlab, cli, read_png

# A display of fewer pixels (the same width, so the same field of view) keeps
# the software renderer quick; the two lights of the
# quick start stand at the twilight block's settings (README quick start).
SMALL = {"display.width_px": 480, "display.height_px": 270}
TWILIGHT = {"eye.adaptation_cd_m2": 0.03, "environment.luminance_cd_m2": 0.03, "light.test.intensity_cd": 0.0025,
            "light.reference.intensity_cd": 0.0025, "tonemap.operator": "perceptual",
            "light.test.glare": "wave-optics"}
TWILIGHT_SET = ["display.width_px=480", "display.height_px=270", "eye.adaptation_cd_m2=0.03",
                "environment.luminance_cd_m2=0.03", "light.test.intensity_cd=0.0025",
                "light.reference.intensity_cd=0.0025", 'tonemap.operator="perceptual"',
                'light.test.glare="wave-optics"']


def same_metadata(ours, exr):
    """Equal attribute for attribute; the EXR holds its numbers (degreesPerPixel,
    adaptationLuminance) as 32-bit floats."""
    assert ours.keys() == exr.keys()
    for k, v in ours.items():
        assert v == (pytest.approx(exr[k], rel=1e-7) if isinstance(v, float) else exr[k]), k
    return True


def sets(items):
    return [a for s in items for a in ("--set", s)]


def test_render_equals_the_command_line_pixel_for_pixel(gl, tmp_path):
    frame = atonlab.Scene.load(str(QUICKSTART_SCENE), {**SMALL, **TWILIGHT}).render(time_s=0.0)
    exr, png = tmp_path / "frame.exr", tmp_path / "frame.png"
    cli("render", QUICKSTART_SCENE, "-o", exr, "--png", png, *sets(TWILIGHT_SET))
    hdr, meta = atonlab.read_exr(str(exr))
    assert frame.hdr.shape == (270, 480, 3) and frame.hdr.dtype == np.float32
    assert np.array_equal(frame.hdr, hdr)  # bit for bit
    assert frame.hdr.max() > 0.03  # the lights are in it
    assert same_metadata(frame.metadata, meta)
    assert frame.deg_per_px == pytest.approx(meta["degreesPerPixel"], rel=1e-7)
    assert frame.bits == 8 and frame.codes.dtype == np.uint8
    assert np.array_equal(frame.codes, read_png(png))


def test_hdr_is_a_view_of_the_frames_memory(gl):
    frame = atonlab.Scene.load(str(QUICKSTART_SCENE), SMALL).render()
    hdr = frame.hdr
    assert not hdr.flags.owndata and hdr.base is not None  # borrowed, not copied
    assert hdr.strides == (480 * 16, 16, 4)  # R, G, B of the frame's RGBA pixels in place
    assert np.shares_memory(hdr, frame.rgba)
    assert frame.hdr.__array_interface__["data"][0] == hdr.__array_interface__["data"][0]
    # The alpha is the frame's scotopic channel (scotopic cd/m², docs/tone-mapping.md "The scotopic
    # channel"): over the D65 sky, D65's S/P times its luminance. D65's S/P from the CIE tables is
    # 2.46 (1700/683 × ∫V′(λ)S(λ)dλ / ∫V(λ)S(λ)dλ; e.g. Berman 1990's tables give 2.47).
    luminance = frame.hdr @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
    sky = frame.rgba[..., 3][:20, :] / luminance[:20, :]  # the top rows: sky only
    assert np.allclose(sky, 2.4645, rtol=2e-3)


def test_typed_overrides_equal_set_text(gl, tmp_path):
    frame = atonlab.Scene.load(str(QUICKSTART_SCENE), {**SMALL, "camera.position_m": [0, 3.5, 0],
                                                        "environment.luminance_cd_m2": 1}).render()
    exr = tmp_path / "f.exr"
    cli("render", QUICKSTART_SCENE, "-o", exr, *sets(TWILIGHT_SET[:2]), "--set", "camera.position_m=[0.0, 3.5, 0.0]",
        "--set", "environment.luminance_cd_m2=1.0")
    assert np.array_equal(frame.hdr, atonlab.read_exr(str(exr))[0])


def test_a_bad_override_names_its_key(gl):
    with pytest.raises(atonlab.InputError) as e:
        atonlab.Scene.load(str(QUICKSTART_SCENE), {"camera.yaw_deg": "north"})
    assert isinstance(e.value, ValueError)
    # An override is read as a `--set` value is: the command's sentence, naming
    # the `overrides` argument instead of --set and echoing the value given.
    assert e.value.key == "camera.yaw_deg" and e.value.option == "overrides" and e.value.file is None
    r = cli("render", QUICKSTART_SCENE, "-o", "unused.exr", "--set", 'camera.yaw_deg="north"', check=False)
    assert r.returncode == 2
    command = r.stderr.strip().removeprefix("atonlab: ")
    assert str(e.value) == command.replace("--set", "overrides", 1).removesuffix(".") + " (the value given: 'north')."



def test_psf_equals_the_command_line(gl, tmp_path):
    rgb, meta = atonlab.psf(pupil_mm=4.0, size=128, samples=8)
    cli("psf", "--pupil-mm", 4.0, "--size", 128, "--samples", 8, "-o", tmp_path / "psf.exr")
    hdr, exr_meta = atonlab.read_exr(str(tmp_path / "psf.exr"))
    assert np.array_equal(rgb, hdr)
    assert same_metadata(meta, exr_meta) and meta["units"] == "relative"
    # Normalised: its luminance sums to 1 (docs/glare.md).
    y = 0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]
    assert y.sum(dtype=np.float64) == pytest.approx(1.0, abs=1e-4)


def test_the_image_psychopy_would_receive_holds_the_codes(gl):
    # docs/python.md "Showing atonlab frames in PsychoPy": ImageStim(image=Image.fromarray(frame.codes, "RGB")).
    pil = pytest.importorskip("PIL.Image", reason="missing tool: python3-pil")
    frame = atonlab.Scene.load(str(QUICKSTART_SCENE), {**SMALL, **TWILIGHT}).render()
    image = pil.fromarray(frame.codes, mode="RGB")
    assert image.mode == "RGB" and image.size == (480, 270)
    assert np.array_equal(np.asarray(image), frame.codes)
    y, x = np.unravel_index(np.argmax(frame.codes.sum(axis=2)), frame.codes.shape[:2])
    assert image.getpixel((int(x), int(y))) == tuple(int(c) for c in frame.codes[y, x])  # (x, y): top row first
