"""Shared fixtures of the Python module's tests (tests/python/CMakeLists.txt).

A test that cannot run here skips with a reason that starts with one of
tests/support/skip.h's kinds ("no GPU: ", "missing tool: ", "not applicable: ");
the reasons are printed again on lines of their own at the end, where CTest's
SKIP_REGULAR_EXPRESSION and scripts/skipped_tests.py read them.
"""
import os
import pathlib
import subprocess

import pytest

atonlab = pytest.importorskip("atonlab", reason="missing tool: the atonlab module (PYTHONPATH=build/python)")

SOURCE = pathlib.Path(os.environ.get("ATONLAB_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BINARY = os.environ.get("ATONLAB_BINARY", str(SOURCE / "build" / "runner" / "atonlab"))
QUICKSTART_SCENE = SOURCE / "protocols" / "examples" / "glare_side_by_side.scene.toml"
QUICKSTART = SOURCE / "protocols" / "examples" / "quickstart.toml"

_skips = []


def pytest_runtest_logreport(report):
    if report.skipped and isinstance(report.longrepr, tuple):
        _skips.append(str(report.longrepr[2]).removeprefix("Skipped: "))


def pytest_terminal_summary(terminalreporter):
    for reason in dict.fromkeys(_skips):
        terminalreporter.write_line(reason)


@pytest.fixture(scope="session")
def gl():
    """A GL 4.5 context can be made (the module's own, kept for the process)."""
    try:
        atonlab.Scene.load(str(QUICKSTART_SCENE), {"display.width_px": 64, "display.height_px": 36}).render()
    except atonlab.NoContextError as e:
        pytest.skip(f"no GPU: {e}")


def cli(*args, check=True):
    """Runs the atonlab binary; returns the CompletedProcess (text)."""
    r = subprocess.run([BINARY, *map(str, args)], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"atonlab {' '.join(map(str, args))} exited {r.returncode}: {r.stderr}")
    return r


def read_png(path):
    """8-bit PNG codes as an H×W×3 uint8 array (matplotlib, python3-matplotlib)."""
    image = pytest.importorskip("matplotlib.image", reason="missing tool: python3-matplotlib")
    import numpy as np
    return np.rint(image.imread(str(path))[..., :3] * 255.0).astype(np.uint8)
