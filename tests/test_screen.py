"""fogdrift.screen: disturbed intervals found, characterised and cut out before a noise fit."""

import json
from pathlib import Path

import numpy as np
import pytest

from fogdrift.allan.segments import allan_variance_segments
from fogdrift.noise import fit_noise
from fogdrift.screen import default_window, dynamic_adev, screen_record
from fogdrift.simulate import simulate

N, DT = 2**16, 0.1
ROMY = Path(__file__).resolve().parents[1] / ".." / "shared" / "data" / "romy_teleseism_1hz" / "romy_teleseism_1hz.csv.gz"


def _with_transient(seed):
    """White + flicker with a transient 5-10x the quiet deviation over 5-20 % of the record.

    Even seeds: a burst of extra white noise; odd seeds: a wave train (period 2-20 s) whose
    envelope decays by e^-2 over the interval.  Returns the record and the true (start, stop).
    """
    rng = np.random.default_rng(1000 + seed)
    y = simulate(N, DT, arw_dprh=0.02, bias_instability_dph=0.3, seed=seed)
    quiet = np.std(np.diff(y)) / np.sqrt(2)
    k = rng.uniform(5, 10)
    dur = int(rng.uniform(0.05, 0.2) * N)
    a = int(rng.integers(0, N - dur))
    if seed % 2 == 0:
        y[a:a + dur] += rng.normal(scale=np.sqrt(k * k - 1) * quiet, size=dur)
    else:
        u = np.arange(dur) / dur
        y[a:a + dur] += np.sqrt(2) * k * quiet * np.exp(-2 * u) * np.sin(2 * np.pi * np.arange(dur) / rng.uniform(20, 200))
    return y, a, a + dur


def test_transient_found_with_its_edges_in_at_least_19_of_20_seeds():
    found = 0
    for seed in range(20):
        y, a, b = _with_transient(seed)
        r = screen_record(y, DT)
        hit = [d for d in r.intervals if abs(d.start - a) <= 0.05 * N and abs(d.stop - b) <= 0.05 * N]
        found += bool(hit) and hit[0].kind == "transient"
    assert found >= 19, found


def test_level_step_found_by_the_window_means_and_characterised():
    # a step of one sample deviation: no window level rises beyond its threshold, only the means move
    y = simulate(N, DT, arw_dprh=0.02, bias_instability_dph=0.3, seed=7)
    p = 40_000
    y[p:] += 1.0 * np.std(y)
    r = screen_record(y, DT)
    assert [d.kind for d in r.intervals] == ["level step"], r.text()
    d = r.intervals[0]
    assert abs(d.start - p) <= default_window(N)
    assert d.step > 0
    assert "level step at t = " in d.text()
    assert all(b <= p - default_window(N) or a >= p + default_window(N) for a, b in r.quiet_segments)


def test_large_step_inside_a_disturbed_interval_is_named_a_level_step():
    # a burst that ends at a new level: the interval is a level step, not a transient
    y = simulate(N, DT, arw_dprh=0.02, seed=8)
    q = np.std(y)
    y[20_000:24_000] += np.random.default_rng(8).normal(scale=6 * q, size=4000)
    y[22_000:] += 2.0 * q
    r = screen_record(y, DT)
    assert [d.kind for d in r.intervals] == ["level step"], r.text()
    assert r.intervals[0].step == pytest.approx(2.0 * q, rel=0.2)


def test_shock_is_found_and_told_from_a_transient():
    y = simulate(N, DT, arw_dprh=0.02, bias_instability_dph=0.3, seed=9)
    q = np.std(y)
    y[30_001:30_006] += 40 * q * np.array([1, -1, 1, -1, 1])  # a five-sample spike train
    r = screen_record(y, DT)
    assert [d.kind for d in r.intervals] == ["shock"], r.text()
    assert r.intervals[0].start <= 30_001 < 30_006 <= r.intervals[0].stop


def test_result_is_json_able_and_says_what_it_found():
    y, a, b = _with_transient(0)
    r = screen_record(y, DT)
    d = json.loads(json.dumps(r.to_dict()))
    assert d["stationary"] is False and d["intervals"][0]["kind"] == "transient"
    assert r.text().startswith("transient t = ") and "x the quiet level" in r.text()
    assert 0 < r.false_alarm == d["false_alarm"] and r.threshold > 1


def test_quiet_segments_give_a_noise_fit_that_covers_the_truth():
    # the screen's own quiet segments, pooled without bridging: N and B within the 95 % intervals
    for seed in (0, 2):
        y, a, b = _with_transient(seed)
        r = screen_record(y, DT)
        fit = fit_noise(allan_variance_segments(y, DT, r.quiet_segments))
        for term, truth in (("N", 0.02), ("B", 0.3)):
            t = fit.terms[term]
            assert t.status == "resolved" and t.lo95 <= truth <= t.hi95, (seed, term, t.lo95, t.hi95)


def test_dynamic_adev_rises_inside_the_transient():
    y, a, b = _with_transient(0)
    t, tau, ad = dynamic_adev(y, DT, 200.0, 100.0, [0.1, 1.0])
    inside = (t > a * DT + 100) & (t < b * DT - 100)
    outside = (t < a * DT - 100) | (t > b * DT + 100)
    assert ad.shape == (t.size, 2)
    assert np.median(ad[inside, 0]) > 4 * np.median(ad[outside, 0])


@pytest.mark.skipif(not ROMY.exists(), reason="ROMY record not present")
@pytest.mark.parametrize("axis", ["ljz", "ljn", "lje"])
def test_romy_teleseism_is_named_on_each_axis(axis):
    import gzip

    with gzip.open(ROMY, "rt") as fh:
        head = fh.readline().strip().split(",")
        data = np.loadtxt(fh, delimiter=",")
    y = data[:, head.index(axis)]
    r = screen_record(y, 1.0)
    first = r.intervals[0]
    assert first.kind == "transient" and abs(first.start_s - 690) <= 100, r.text()
    assert first.end_s > 3700  # through the surface waves
    assert first.peak > 5
    assert r.quiet_segments[0][0] == 0 and r.quiet_segments[0][1] >= 400  # the pre-event part
    assert r.quiet_segments[0][1] <= 690


@pytest.mark.parametrize("batch", [1 << 20, 100])
def test_the_quiet_variogram_is_the_direct_mean_of_squared_differences(monkeypatch, batch):
    """The null law's variogram (FFT, windows transformed in batches) against the definition, by hand: gamma(k) =
    sum over the used windows of sum_i (x_{i+k} - x_i)^2 / 2, over the number of pairs, each window's first L
    samples with its mean removed (the mean cancels in a difference, so the plain samples serve)."""
    import fogdrift.screen as sc

    monkeypatch.setattr(sc, "VARIOGRAM_BATCH_VALUES", batch)  # 100 values: one window per batch
    rng = np.random.default_rng(11)
    y = np.cumsum(rng.standard_normal(5003)) * 0.1 + rng.standard_normal(5003) + 40.0
    L, M = 37, 5003 // 37
    edges = (np.arange(M + 1) * y.size) // M
    use = rng.random(M) > 0.3
    num, cnt = np.zeros(L), np.zeros(L)
    for j in np.flatnonzero(use):
        x = y[edges[j]: edges[j] + L]
        for k in range(L):
            d = x[k:] - x[: L - k]
            num[k] += float(d @ d)
            cnt[k] += L - k
    np.testing.assert_allclose(sc._variogram(y, edges, use, L), num / (2.0 * cnt), rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("batch", [1 << 20, 300])
def test_the_window_statistics_are_each_window_alone_bit_for_bit(monkeypatch, batch):
    """The levels s_j and means mu_j of the windows (gathered a batch of rows at a time) are the numbers each window
    gives on its own: its mean, then the variance about its least-squares line, exactly (a record whose windows
    have two lengths)."""
    import fogdrift.screen as sc

    monkeypatch.setattr(sc, "WINDOWS_BATCH_VALUES", batch)  # 300 values: a few windows per batch
    rng = np.random.default_rng(12)
    y = np.cumsum(rng.standard_normal(5003)) * 1e-3 + rng.standard_normal(5003) * 3.0 + 1e4
    L = 37
    edges, s, mu = sc._windows(y, L)
    assert np.unique(np.diff(edges)).size == 2
    for j in range(edges.size - 1):
        w = y[edges[j]:edges[j + 1]]
        t = np.arange(w.size) - (w.size - 1) / 2.0
        m = w.mean()
        c = w - m
        r = c - np.dot(t, c) / np.dot(t, t) * t
        assert mu[j] == m and s[j] == np.dot(r, r) / (w.size - 2)
