"""fogdrift.allan.segments: the Allan variance of gap-free segments, pooled without bridging a gap."""

import dataclasses

import numpy as np
import pytest

from fogdrift.allan import allan_variance
from fogdrift.allan.segments import allan_variance_segments, check_segments
from fogdrift.errors import ConfigError, InsufficientDataError
from fogdrift.noise import fit_noise
from fogdrift.simulate import simulate

allantools = pytest.importorskip("allantools")


def _oracle(y, dt, segments, taus):
    """allantools' overlapping ADEV of each segment, pooled by hand with its term counts."""
    num = np.zeros(len(taus))
    cnt = np.zeros(len(taus))
    for a, b in segments:
        t, ad, _, ns = allantools.oadev(y[a:b], rate=1.0 / dt, data_type="freq", taus=np.asarray(taus))
        for tt, dev, n in zip(t, ad, ns):
            i = int(np.argmin(np.abs(np.asarray(taus) - tt)))
            assert abs(taus[i] - tt) < 1e-9 * tt  # allantools kept this tau as asked
            num[i] += dev**2 * n
            cnt[i] += n
    return num / cnt, cnt


def test_pooled_avar_equals_allantools_per_segment_combined_by_term_counts():
    dt = 0.1
    y = simulate(6000, dt, arw_dprh=0.05, bias_instability_dph=0.3, seed=11) + 5.0  # offset: means differ per segment
    y[2000:2400] += 40.0  # a level the gap holds: bridging it would add a step
    segments = [(0, 2000), (2400, 5000), (5300, 5420)]  # the last one allows only m <= 60
    taus = dt * np.array([1, 2, 4, 8, 16, 32, 64, 128, 256, 500])
    r = allan_variance_segments(y, dt, segments, taus=taus)
    want, cnt = _oracle(y, dt, segments, taus)
    np.testing.assert_allclose(r.avar_dph2, want, rtol=1e-10)
    assert r.n_terms.tolist() == cnt.astype(int).tolist()
    # the short segment contributes up to m = 60 and not beyond
    assert r.n_terms[list(r.m).index(32)] == (2000 - 63) + (2600 - 63) + (120 - 63)
    assert r.n_terms[list(r.m).index(64)] == (2000 - 127) + (2600 - 127)
    assert r.n_samples == 2000 + 2600 + 120
    # concatenating the segments bridges the cuts and is measurably different
    cat = allan_variance(np.concatenate([y[a:b] for a, b in segments]), dt, taus=taus[:-1])
    assert np.max(np.abs(cat.avar_dph2 / r.avar_dph2[:-1] - 1)) > 1e-3


def test_one_segment_equals_allan_variance_field_by_field():
    y = simulate(3000, 0.5, arw_dprh=0.02, rrw_dphrh=0.5, seed=4)
    a = allan_variance(y, 0.5, taus="decade")
    b = allan_variance_segments(y, 0.5, [(0, 3000)], taus="decade")
    for f in dataclasses.fields(a):
        if f.name == "edf_rule":
            continue
        va, vb = getattr(a, f.name), getattr(b, f.name)
        if isinstance(va, np.ndarray):
            assert np.array_equal(va, vb), f.name
        else:
            assert va == vb, f.name


def test_edf_is_the_sum_of_the_used_segments_edfs():
    from fogdrift.allan.ci import edf_simple

    y = np.random.default_rng(2).normal(size=3000)
    r = allan_variance_segments(y, 1.0, [(0, 1000), (1000, 1100), (1500, 3000)], taus=[4, 64], noise_alpha=0)
    assert r.edf[0] == pytest.approx(edf_simple(1001, 4, 0) + edf_simple(101, 4, 0) + edf_simple(1501, 4, 0))
    assert r.edf[1] == pytest.approx(edf_simple(1001, 64, 0) + edf_simple(1501, 64, 0))  # 100 < 2*64
    # adjacent segments are not one record: the cut removes terms (and EDF)
    whole = allan_variance(y[:1100], 1.0, taus=[4], noise_alpha=0)
    split = allan_variance_segments(y, 1.0, [(0, 1000), (1000, 1100)], taus=[4], noise_alpha=0)
    assert split.n_terms[0] == whole.n_terms[0] - 7  # the 2m - 1 terms across the cut
    assert split.edf[0] < whole.edf[0]
    assert np.all(r.dev_lo95 < r.dev) and np.all(r.dev < r.dev_hi95)


def test_bad_segments_are_refused():
    assert check_segments([(5, 9), (0, 5)], 10) == [(0, 5), (5, 9)]
    with pytest.raises(ConfigError):
        check_segments([(0, 6), (5, 9)], 10)
    with pytest.raises(ConfigError):
        check_segments([(0, 11)], 10)
    with pytest.raises(ConfigError):
        allan_variance_segments(np.zeros(100), 1.0, [(0, 50)], taus=[30.0])  # 2m > longest segment
    with pytest.raises(InsufficientDataError):
        allan_variance_segments(np.zeros(100), 1.0, [(3, 4)])


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_noise_fit_of_the_quiet_segments_covers_the_truth(seed):
    # white + flicker with a burst of 8x the quiet deviation cut out: the fit of the two quiet
    # pieces recovers N and B within its 95 % intervals; the whole record's fit would not
    n, dt, arw, bi = 2**16, 0.1, 0.02, 0.3
    rng = np.random.default_rng(100 + seed)
    y = simulate(n, dt, arw_dprh=arw, bias_instability_dph=bi, seed=seed)
    a = int(rng.integers(n // 5, n // 2))
    b = a + n // 8
    y[a:b] += rng.normal(scale=8 * y.std(), size=b - a)
    fit = fit_noise(allan_variance_segments(y, dt, [(0, a), (b, n)]))
    for term, truth in (("N", arw), ("B", bi)):
        t = fit.terms[term]
        assert t.status == "resolved", (term, t.status)
        assert t.lo95 <= truth <= t.hi95, (term, t.lo95, truth, t.hi95)
    whole = fit_noise(allan_variance(y, dt)).terms["N"]
    assert whole.value > 2 * arw  # uncut, the burst passes for sensor white noise
