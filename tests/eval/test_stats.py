import numpy as np
import pytest

from arena.eval import stats
from arena.eval.stats import MIN_N, bootstrap_mean


def test_too_few_values_get_no_interval_and_a_flag():
    e = bootstrap_mean([0.0, 40.0])  # n = 2, huge spread: a t interval would be ± 254
    assert (e.n, e.mean) == (2, 20.0)
    assert e.low_n and not e.has_interval
    assert np.isnan(e.lower) and np.isnan(e.upper)
    e = bootstrap_mean([1.0] * (MIN_N - 1) + [np.nan, np.inf])
    assert e.n == MIN_N - 1 and e.low_n
    e = bootstrap_mean([np.nan])
    assert e.n == 0 and not e.low_n and np.isnan(e.mean)


def test_rates_stay_inside_zero_one_and_counts_above_zero():
    success = np.array([1, 1, 1, 1, 0, 1, 1, 1], float)  # mean 0.875
    e = bootstrap_mean(success)
    assert e.has_interval and not e.low_n
    assert 0.0 <= e.lower <= e.mean <= e.upper <= 1.0
    assert e.upper == 1.0  # most resamples hold no failure at all
    e = bootstrap_mean(np.array([0, 0, 0, 0, 0, 0, 3], np.int64))  # collisions
    assert 0.0 <= e.lower <= e.mean <= e.upper <= 3.0
    assert e.lower == 0.0


def test_constant_values_give_a_zero_width_interval():
    e = bootstrap_mean(np.ones(6))
    assert (e.lower, e.mean, e.upper) == (1.0, 1.0, 1.0)


def test_same_input_same_interval_and_chunks_do_not_matter(monkeypatch):
    v = np.random.default_rng(3).exponential(2.0, 40)
    a, b = bootstrap_mean(v), bootstrap_mean(v.copy())
    assert (a.lower, a.upper) == (b.lower, b.upper)
    assert bootstrap_mean(v, seed=1).lower != a.lower  # the seed is used
    monkeypatch.setattr(stats, "_CHUNK", 7 * 40)  # 7 resamples per draw
    c = bootstrap_mean(v)
    assert (c.lower, c.upper) == (a.lower, a.upper)


def test_large_normal_sample_matches_the_normal_interval():
    # n = 400 draws of N(5, 2): the bootstrap interval approaches mean ± 1.96 s / sqrt(n)
    v = np.random.default_rng(0).normal(5.0, 2.0, 400)
    e = bootstrap_mean(v)
    half = 1.96 * v.std(ddof=1) / np.sqrt(v.size)
    assert e.mean == pytest.approx(v.mean())
    assert e.lower == pytest.approx(v.mean() - half, abs=0.1 * half)
    assert e.upper == pytest.approx(v.mean() + half, abs=0.1 * half)


def test_rejects_bad_arguments():
    with pytest.raises(ValueError, match="confidence"):
        bootstrap_mean([1.0] * 6, confidence=1.0)
    with pytest.raises(ValueError, match="resamples"):
        bootstrap_mean([1.0] * 6, resamples=0)
