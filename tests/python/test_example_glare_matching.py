# needs: GL
"""examples/python/glare_matching.py runs end to end: its two figures are
written and its PSE lies near the model observer's true PSE (README quick
start: -2.603 log10 cd at 1920×1080)."""
import re
import subprocess
import sys

import pytest

from conftest import SOURCE

pytest.importorskip("matplotlib", reason="missing tool: python3-matplotlib")
pytest.importorskip("pandas", reason="missing tool: python3-pandas")


def test_glare_matching_example(gl, tmp_path):
    r = subprocess.run([sys.executable, str(SOURCE / "examples" / "python" / "glare_matching.py"), "--out",
                        str(tmp_path)], capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr
    for name in ("frames.png", "displayed.png", "psychometric.png", "quickstart.db"):
        assert (tmp_path / name).stat().st_size > 1000, name
    pse = float(re.search(r"PSE (-?[0-9.]+) log10 cd", r.stdout).group(1))
    # 22 staircase trials: the fit's PSE within 0.15 log10 of the true one
    # (the README's analysis gives -2.632).
    assert pse == pytest.approx(-2.603, abs=0.15)
