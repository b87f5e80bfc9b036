#!/usr/bin/env python3
"""The Python module's cost (docs/bench.md "The Python module"): importing
atonlab, and the overhead of a render call from Python at 1920×1080 (the
Python call, the argument conversion, the numpy arrays and the metadata dict:
the call's wall time minus Frame.render_s, the time spent inside the library
rendering and reading the frame back as `atonlab render` does).

    PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [--repeats N] [--out DIR]

Writes python_overhead.csv into --out when given. Targets (issue 28): import
≤ 0.5 s, render overhead ≤ 1 ms.
"""
import argparse
import csv
import pathlib
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCENE = ROOT / "protocols" / "examples" / "glare_side_by_side.scene.toml"


def quartiles(values):
    q = statistics.quantiles(values, n=4) if len(values) > 1 else [values[0]] * 3
    return q[0], statistics.median(values), q[2]


def import_times(repeats):
    """Wall time of `import atonlab` in a fresh interpreter, s (the interpreter's own start excluded)."""
    code = "import time; t = time.perf_counter(); import atonlab; print(time.perf_counter() - t)"
    return [float(subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                                 text=True).stdout) for _ in range(repeats)]


def render_overheads(repeats):
    """(overhead s, render_s) per call of Scene.render at 1920×1080 after one warm-up render."""
    import atonlab
    scene = atonlab.Scene.load(str(SCENE), {"display.width_px": 1920, "display.height_px": 1080})
    scene.render()  # shaders, PSF, caches (the frame is freed at once)
    out = []
    for i in range(repeats):
        t = time.perf_counter()
        frame = scene.render(time_s=0.0)
        wall = time.perf_counter() - t
        assert frame.hdr.shape == (1080, 1920, 3)
        out.append((wall - frame.render_s, frame.render_s))
        del frame  # freed here, outside the timed call (39 MB: the image and the codes)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--out", type=pathlib.Path)
    args = parser.parse_args()
    imports = import_times(args.repeats)
    renders = render_overheads(args.repeats)
    rows = [("import_s", *quartiles(imports), len(imports)),
            ("render_overhead_ms", *(1e3 * v for v in quartiles([o for o, _ in renders])), len(renders)),
            ("render_in_library_ms", *(1e3 * v for v in quartiles([r for _, r in renders])), len(renders))]
    print(f"{'quantity':<22} {'q1':>10} {'median':>10} {'q3':>10}  n")
    for name, q1, med, q3, n in rows:
        print(f"{name:<22} {q1:10.4g} {med:10.4g} {q3:10.4g}  {n}")
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        with open(args.out / "python_overhead.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["quantity", "q1", "median", "q3", "n"])
            w.writerows(rows)


if __name__ == "__main__":
    main()
