#!/usr/bin/env python3
"""Glare matching from Python: the README's quick start as a script.

Renders the quick start's two frames (the test light with the eye's glare
beside the reference without, and both without), plots the displayed
luminance of a red and a white light at 0.01 cd/m² (what the display's codes
show, and the light each adds at the eye as `atonlab check` sums it), runs the quick start
headless with the model observer, reads the study into pandas, fits the
psychometric function and plots it; the figures are saved into --out.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/glare_matching.py --out out/glare-matching

Run by the test suite (GL.python.example_glare_matching); docs/python.md.
"""
import argparse
import pathlib

import matplotlib
import matplotlib.colors

matplotlib.use("Agg")  # files, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import atonlab  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
PROTOCOL = ROOT / "protocols" / "examples" / "quickstart.toml"
SCENE = ROOT / "protocols" / "examples" / "glare_side_by_side.scene.toml"
# The quick start's block "twilight" (protocols/examples/quickstart.toml): the
# eye adapted to 0.03 cd/m², the test light 0.0025 cd with the eye's glare,
# the reference as bright without, the perceptual tone mapper.
TWILIGHT = {"eye.adaptation_cd_m2": 0.03, "environment.luminance_cd_m2": 0.03, "light.test.intensity_cd": 0.0025,
            "light.reference.intensity_cd": 0.0025, "tonemap.operator": "perceptual",
            "light.reference.glare": "none"}


def crop(image, frame, x_m, size_px=64):
    """The square of size_px around where a light at x_m (the scene's metres, 500 m ahead) appears."""
    h, w = image.shape[:2]
    deg = np.degrees(np.arctan2(x_m, 500.0))
    cx, cy = int(round(w / 2 + deg / frame.deg_per_px)), h // 2
    return image[cy - size_px // 2:cy + size_px // 2, cx - size_px // 2:cx + size_px // 2]


def show_frames(out):
    frames = {
        "test with the eye's glare, reference without": atonlab.Scene.load(
            SCENE, {**TWILIGHT, "light.test.glare": "wave-optics"}).render(),
        "both without glare": atonlab.Scene.load(SCENE, {**TWILIGHT, "light.test.glare": "none"}).render(),
    }
    fig, axes = plt.subplots(2, 3, figsize=(11, 6.5), gridspec_kw={"width_ratios": [3, 1, 1]})
    for row, (title, frame) in zip(axes, frames.items()):
        row[0].imshow(frame.codes)
        row[0].set_title(f"{title}\n(the display's codes, {frame.deg_per_px:.4f}°/px)", fontsize=9)
        for ax, x_m, name in ((row[1], -43.74, "test (left)"), (row[2], 43.74, "reference (right)")):
            ax.imshow(crop(frame.codes, frame, x_m), interpolation="nearest")
            lum = crop(frame.hdr @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32), frame, x_m)
            ax.set_title(f"{name}\npeak {lum.max():.3g} cd/m²", fontsize=9)
        for ax in row:
            ax.set_axis_off()
    fig.tight_layout()
    fig.savefig(out / "frames.png", dpi=100)
    plt.close(fig)
    return frames


# The question: at 0.01 cd/m², a red light (the test) beside a white
# one (the reference), both 0.05 cd, with and without the eye's glare.
RED_WHITE = {"eye.adaptation_cd_m2": 0.01, "environment.luminance_cd_m2": 0.01, "light.test.intensity_cd": 0.05,
             "light.test.colour": "red", "light.reference.intensity_cd": 0.05, "tonemap.operator": "perceptual"}


def show_red_and_white(out):
    """displayed.png: the displayed luminance (cd/m², the codes decoded through
    the display model) around a red and a white light, without and with glare,
    and a row through both; the titles give the light each adds at the eye."""
    fig, axes = plt.subplots(2, 3, figsize=(11, 6.5), gridspec_kw={"width_ratios": [1, 1, 2]})
    for row, glare in zip(axes, ("none", "wave-optics")):
        frame = atonlab.Scene.load(SCENE, {**RED_WHITE, "light.test.glare": glare,
                                           "light.reference.glare": glare}).render()
        shown = frame.displayed_cd_m2
        lum = shown.sum(axis=2)  # the channels add (docs/python.md)
        peak = frame.display["peak_cd_m2"]
        h = lum.shape[0]
        for ax, x_m, name in ((row[0], -43.74, "red (test)"), (row[1], 43.74, "white (reference)")):
            im = ax.imshow(crop(lum, frame, x_m, 32), interpolation="nearest", cmap="magma",
                           norm=matplotlib.colors.LogNorm(vmin=max(lum.min(), 1e-3), vmax=peak))
            light = "test" if x_m < 0 else "reference"
            ax.set_title(f"{name}, glare {glare}\nadds {frame.added_lux(light):.3g} lx at the eye", fontsize=9)
            ax.set_axis_off()
        fig.colorbar(im, ax=row[1], label="displayed cd/m²", fraction=0.046)
        deg = (np.arange(lum.shape[1]) - lum.shape[1] / 2) * frame.deg_per_px
        for c, colour in enumerate(("red", "green", "blue")):
            row[2].semilogy(deg, shown[h // 2, :, c] + 1e-4, color=colour, lw=0.8, label=f"{colour} channel")
        row[2].set_xlim(-6, 6)
        row[2].set_xlabel("degrees from the centre (row through both lights)")
        row[2].set_ylabel("cd/m² (+1e-4)")
        row[2].axhline(peak * 0.2126, color="red", ls=":", lw=0.6, label="red channel's white")
        row[2].legend(fontsize=7, loc="upper center")
    fig.tight_layout()
    fig.savefig(out / "displayed.png", dpi=100)
    plt.close(fig)


def run_study(out):
    db = out / "quickstart.db"
    db.unlink(missing_ok=True)
    result = atonlab.run(PROTOCOL, db, observer="model", headless=True,
                         progress=lambda stored, bound: print(f"\rtrial {stored} of ≤ {bound}", end="", flush=True))
    print(f"\nsession {result['status']}: {db}")
    return db


def fit_and_plot(db, out):
    trials = atonlab.read_study(db)
    scored = trials[trials["outcome"].notna()]
    # Levels a staircase reached by different sums of steps differ in the last bits: one level (as analyze does).
    scored = scored.assign(level=(scored["level"] * 1e9).round() / 1e9)
    counts = scored.groupby("level")["outcome"].agg(n="count", k="sum").reset_index()
    f = atonlab.fit(counts["level"], counts["n"], counts["k"].astype(int), task="2afc", bootstrap=999, seed=1)
    test_level = np.log10(0.0025)
    print(f"PSE {f.threshold:.3f} log10 cd [{f.ci_lower:.3f}, {f.ci_upper:.3f}] (95 % bootstrap), "
          f"test {test_level:.3f}: {trials['level_key'].iloc[0]} matched {f.threshold - test_level:+.3f} log10")
    x = np.linspace(counts["level"].min() - 0.2, counts["level"].max() + 0.2, 200)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.scatter(counts["level"], counts["k"] / counts["n"], s=20 * counts["n"], alpha=0.6,
               label="proportion chose the reference (area: trials)")
    ax.plot(x, f.psi(x), label=f"{f.family} fit, PSE {f.threshold:.3f}")
    ax.axvline(test_level, color="grey", linestyle=":", label="the test's intensity")
    ax.axvspan(f.ci_lower, f.ci_upper, color="C1", alpha=0.15, label="PSE 95 % interval")
    ax.set_xlabel("reference intensity, log10 cd")
    ax.set_ylabel("P(reference looked brighter)")
    ax.set_ylim(-0.03, 1.03)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(out / "psychometric.png", dpi=100)
    plt.close(fig)
    return trials, f


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/glare-matching", help="folder for the study file and the figures")
    out = pathlib.Path(parser.parse_args().out)
    out.mkdir(parents=True, exist_ok=True)
    show_frames(out)
    show_red_and_white(out)
    db = run_study(out)
    trials, f = fit_and_plot(db, out)
    print(f"{len(trials)} trials; figures: {out / 'frames.png'}, {out / 'displayed.png'}, "
          f"{out / 'psychometric.png'}")


if __name__ == "__main__":
    main()
