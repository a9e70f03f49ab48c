"""fignet.compare_paired against values computed here, independently of the library."""

import math

import numpy as np
import pytest

import fignet


def test_a_constant_ratio_has_an_interval_of_that_ratio_alone():
    a = np.linspace(0.1, 2.0, 25)
    c = fignet.compare_paired(list(a), list(0.9 * a))
    assert c["pairs"] == 25
    assert c["relative"] == pytest.approx(-0.1, abs=1e-12)
    assert c["relative_low"] == pytest.approx(-0.1, abs=1e-12)
    assert c["relative_high"] == pytest.approx(-0.1, abs=1e-12)
    assert (c["b_lower"], c["a_lower"]) == (25, 0)
    assert c["sign_test_p"] == pytest.approx(2 * 0.5**25, rel=1e-9)
    assert c["mean_a"] == pytest.approx(a.mean(), rel=1e-12)


def test_the_interval_matches_a_numpy_bootstrap_of_the_scenes():
    rng = np.random.default_rng(7)
    a = rng.lognormal(mean=-0.5, sigma=0.8, size=300)
    b = a * rng.lognormal(mean=-0.05, sigma=0.3, size=300)
    c = fignet.compare_paired(list(a), list(b), resamples=20000, seed=3)
    assert c["relative"] == pytest.approx(b.sum() / a.sum() - 1, rel=1e-12)
    picks = rng.integers(0, len(a), size=(20000, len(a)))
    ratios = b[picks].sum(axis=1) / a[picks].sum(axis=1) - 1
    low, high = np.quantile(ratios, [0.025, 0.975])
    # Two different streams of resamples: the percentiles agree to what 20000 draws resolve.
    assert c["relative_low"] == pytest.approx(low, abs=0.004)
    assert c["relative_high"] == pytest.approx(high, abs=0.004)
    assert c["relative_low"] < c["relative"] < c["relative_high"]


def test_the_sign_test_counts_wins_and_leaves_ties_out():
    a = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]
    b = [0.5, 1.0, 1.5, 2.0, 2.5, 7.0, 7.0, 8.0]  # 5 lower, 1 higher, 2 tied
    c = fignet.compare_paired(a, b)
    assert (c["b_lower"], c["a_lower"]) == (5, 1)
    p = 2 * sum(math.comb(6, k) for k in range(0, 2)) / 2**6
    assert c["sign_test_p"] == pytest.approx(p, rel=1e-9)


def test_the_same_seed_gives_the_same_interval_and_another_seed_another():
    rng = np.random.default_rng(1)
    a, b = list(rng.uniform(0.1, 1, 40)), list(rng.uniform(0.1, 1, 40))
    first, again = fignet.compare_paired(a, b, seed=5), fignet.compare_paired(a, b, seed=5)
    other = fignet.compare_paired(a, b, seed=6)
    assert (first["relative_low"], first["relative_high"]) == (
        again["relative_low"], again["relative_high"])
    assert (first["relative_low"], first["relative_high"]) != (
        other["relative_low"], other["relative_high"])


def test_bad_input_raises_config_errors_naming_what_is_wrong():
    with pytest.raises(fignet.ConfigError, match="3 errors against 2"):
        fignet.compare_paired([0.1, 0.2, 0.3], [0.1, 0.2])
    with pytest.raises(fignet.ConfigError, match="b's error 1 is nan"):
        fignet.compare_paired([0.1, 0.2], [0.1, float("nan")])
    with pytest.raises(fignet.ConfigError, match="all zero"):
        fignet.compare_paired([0.0, 0.0], [0.1, 0.2])
    with pytest.raises(fignet.ConfigError, match="confidence 1.5"):
        fignet.compare_paired([0.1, 0.2], [0.1, 0.2], confidence=1.5)
