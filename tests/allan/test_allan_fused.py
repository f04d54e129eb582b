"""The fused overlapping-Allan kernel (``_kernels.fused2``): the angle rebuilt block by block from the rate.

Contract: the same per-block sums, bit for bit, as the angle array (``phase``) followed by the per-tau kernel
(``diff2``) with the same block -- so :func:`fogdrift.allan.allan_variance` gives the same numbers with or
without it, and :mod:`fogdrift.allan.chunked` stays equal to it.  Short blocks (``fused_part(..., block)``)
put many lags, block edges, run starts and record ends into a small record; one test goes through
``allan_variance`` at the real block on a record just above :data:`FUSED_MIN`.  An off-by-one in the carried
running sum, the window start of a long lag or the end of the record changes bits and fails these tests.
"""

from __future__ import annotations

import allantools
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.allan import _kernels as K
from fogdrift.allan import allan_variance
from fogdrift.errors import DataFormatError


def _rate(n, seed):
    """White noise + random walk + a tone + an offset [deg/h]."""
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    return 2.0 * rng.standard_normal(n) + 0.01 * np.cumsum(rng.standard_normal(n)) + 0.7 * np.sin(0.013 * t) + 30.0


def _reference_part(y, m, block):
    """Per-block sums of the angle array + per-tau kernel with this block."""
    kern = K._compiled()
    mu = float(np.mean(y))
    p = np.empty(y.size + 1)
    kern["phase"](y, mu, kern["offsets"](y, mu, block), p, block)
    return kern["diff2"](p, np.asarray(m, dtype=np.int64), np.ones(len(m), dtype=np.int64), block)


@pytest.mark.parametrize("n", [127, 640, 641, 1000, 1999])
@pytest.mark.parametrize("chunks", [1, 3, 8])
def test_block_sums_equal_the_angle_array_kernel_bit_for_bit(n, chunks):
    """block 64: lags below, at and above one block, 2m = N and N - 1, runs starting mid-record."""
    block = 64
    m = np.unique(np.array([1, 2, 3, 31, 32, 33, 63, 64, 65, 100, 128, 257, (n - 1) // 2, n // 2], dtype=np.int64))
    got = K.fused_part(_rate(n, n), m, block, chunks)
    want = _reference_part(_rate(n, n), m, block)
    assert got.shape == want.shape
    assert_array_equal(got, want)


@pytest.mark.parametrize("grid", ["octave", "decade"])
def test_octave_and_decade_grids_with_short_blocks(grid):
    """The named grids up to m = N/2, block 256: many long-lag streams (15 for the octave grid)."""
    n = 1 << 15 | 77
    y = _rate(n, 5)
    m = allan_variance(y[:n], 1.0, taus=grid, max_fraction=0.5).m
    for chunks in (1, 5):
        assert_array_equal(K.fused_part(y, m, 256, chunks), _reference_part(y, m, 256))


@pytest.fixture(scope="module")
def long_rate():
    return _rate(K.FUSED_MIN + 12_345, 11)  # just above FUSED_MIN, not a multiple of BLOCK


@pytest.mark.parametrize("grid", ["octave", "decade"])
def test_allan_variance_takes_the_fused_path_with_the_same_numbers(long_rate, grid, monkeypatch):
    """The named grid plus m next to one block and 2m = N - 1 (one term), at dt = 1 s."""
    y = long_rate
    n = y.size
    named = allan_variance(y, 1.0, taus=grid).m
    taus = np.unique(np.concatenate([named, [K.BLOCK - 1, K.BLOCK + 1, n // 2 - 1, n // 2]])).astype(float)
    r_fused = allan_variance(y, 1.0, taus=taus)
    assert K.fused_lags(n, r_fused.m) is not None
    # the angle-array path on the same grid: forced by declaring the fused kernel inapplicable
    monkeypatch.setattr(K, "fused_lags", lambda n, m: None)
    r_array = allan_variance(y, 1.0, taus=taus)
    assert_array_equal(r_fused.m, r_array.m)
    assert_array_equal(r_fused.avar_dph2, r_array.avar_dph2)
    assert_array_equal(r_fused.edf, r_array.edf)
    assert_array_equal(r_fused.adev_lo68_dph, r_array.adev_lo68_dph)
    assert r_fused.m[-1] == n // 2 and r_fused.n_terms[-1] == n - 2 * (n // 2) + 1  # 2m = N - 1: two terms


def test_fused_path_does_not_build_the_angle_array(long_rate, monkeypatch):
    def refuse(y):
        raise AssertionError("the angle array was built")

    monkeypatch.setattr(K, "phase_dph_samples", refuse)
    calls = []
    r = allan_variance(long_rate, 0.01, taus="octave", progress=lambda d, t: calls.append((d, t)))
    assert calls == [(len(r), len(r))]


def test_fused_path_matches_allantools(long_rate):
    y = long_rate[:K.FUSED_MIN + 1001]
    r = allan_variance(y, 0.01, taus="octave")
    assert K.fused_lags(y.size, r.m) is not None
    taus, dev, _, ns = allantools.oadev(y, rate=100.0, data_type="freq", taus=r.tau_s)
    assert_allclose(taus, r.tau_s, rtol=1e-12)
    assert_allclose(r.adev_dph, dev, rtol=1e-9)
    assert_array_equal(r.n_terms, ns)


def test_non_finite_rate_is_refused_as_before(long_rate):
    y = long_rate.copy()
    y[K.FUSED_MIN // 2] = np.nan
    with pytest.raises(DataFormatError):
        allan_variance(y, 0.01, taus="octave")


def test_fused_lags_applies_to_named_grids_only():
    n = 100_000_000
    assert K.fused_lags(n, 2 ** np.arange(25)).size == 10  # lags 2^16 .. 2^25
    assert K.fused_lags(n, np.arange(1, 1000)) is not None  # no long lag at all
    assert K.fused_lags(n, np.unique(np.geomspace(1, n // 4, 100).astype(np.int64))) is None  # 100 log taus
    assert K.fused_lags(K.FUSED_MIN - 1, np.array([1, 2])) is None  # short record: angle array in cache
    with pytest.raises(ValueError):
        K.allan_sums_fused(np.zeros(10), np.array([1]))
