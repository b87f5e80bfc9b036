"""atonlab.fit on counts whose psychometric function is known (no GL)."""
import math

import pytest

from conftest import atonlab


def phi(x):
    return 0.5 * (1.0 + math.erf(x / math.sqrt(2.0)))


def test_fit_recovers_a_known_normal_function():
    # Expected counts of a cumulative normal (mean -2.6, SD 0.2; no lapses),
    # 10000 trials per level: the ML fit lands on the generating PSE.
    levels = [-3.2, -3.0, -2.8, -2.6, -2.4, -2.2, -2.0]
    n = [10000] * len(levels)
    k = [round(10000 * phi((x + 2.6) / 0.2)) for x in levels]
    f = atonlab.fit(levels, n, k, task="2afc")
    assert f.threshold == pytest.approx(-2.6, abs=2e-3)
    # slope at the PSE of Phi((x - mu) / sigma) = 1 / (sigma sqrt(2 pi)) (times 1 - lambda)
    assert f.slope == pytest.approx(1.0 / (0.2 * math.sqrt(2 * math.pi)), rel=0.02)
    assert f.gamma == 0.0 and f.reliable and f.n_trials == 70000


def test_two_afc_correct_puts_the_threshold_at_75_percent():
    # 2AFC scored correct: Psi = 0.5 + 0.5 F; F = Phi((x - 1) / 0.5) is 0.5 at x = 1, Psi = 0.75 there.
    levels = [0.0, 0.5, 1.0, 1.5, 2.0]
    k = [round(10000 * (0.5 + 0.5 * phi((x - 1.0) / 0.5))) for x in levels]
    f = atonlab.fit(levels, [10000] * 5, k, task="2afc-correct")
    assert f.gamma == 0.5 and f.threshold == pytest.approx(1.0, abs=5e-3)


def test_bootstrap_interval_contains_the_threshold():
    levels = [-1.0, -0.5, 0.0, 0.5, 1.0]
    k = [3, 12, 20, 29, 37]
    f = atonlab.fit(levels, [40] * 5, k, bootstrap=200, seed=3)
    assert f.ci_lower < f.threshold < f.ci_upper


def test_bad_counts_are_input_errors():
    with pytest.raises(atonlab.InputError) as e:
        atonlab.fit([0, 1], [10, 10], [11, 5])
    assert e.value.option == "n_yes"
    with pytest.raises(atonlab.InputError):
        atonlab.fit([0, 1], [10, 10], [1, 5], family="cauchy")
    with pytest.raises(atonlab.InputError):
        atonlab.fit([0, 1], [10, 10], [1, 5], task="3afc")
