"""The vectorised sum-of-squares kernels of fogdrift.allan._kernels.

Independent reference: the operator evaluated with NumPy on the whole angle array (``np.sum`` of the squared
differences, pairwise summation) -- the kernels reassociate the sum, so they agree to rounding, not bits.
The out-of-core form (``block_sums2``) must give the in-memory kernel's block sums bit for bit: that is the
contract that keeps ``fogdrift.allan.chunked`` equal to ``allan_variance``.
"""

from __future__ import annotations

import numpy as np
import pytest

from fogdrift.allan import _kernels as K


def _angle(n, seed=0):
    rng = np.random.default_rng(seed)
    return K.phase_dph_samples(1e4 + rng.standard_normal(n) + np.cumsum(rng.normal(scale=1e-3, size=n)))


def _numpy_sums(p, m, s, coef):
    out = []
    for mm, ss in zip(m, s):
        span = (len(coef) - 1) * mm
        k = np.arange(0, p.size - span, ss)
        d = sum(c * p[k + l * mm] for l, c in enumerate(coef))
        out.append(float(np.sum(d * d)))
    return np.array(out)


@pytest.mark.parametrize("coef", [(1, -2, 1), (-1, 3, -3, 1)])
@pytest.mark.parametrize("strided", [False, True])
def test_sums_equal_numpy_on_every_tau(coef, strided):
    n = 300_000  # several 65536-blocks, a partial last block
    p = _angle(n)
    m = np.array([1, 2, 3, 7, 64, 1000, 65535, 65536, 70_000, n // 4], dtype=np.int64)
    s = m.copy() if strided else np.ones_like(m)
    got = K.operator_sums(p, m, s, coef, False)
    ref = _numpy_sums(p, m, s, coef)
    np.testing.assert_allclose(got, ref, rtol=1e-12)


def test_block_sums2_gives_the_in_memory_block_sums_bit_for_bit():
    n = 200_000
    p = _angle(n, 3)
    block = K.BLOCK
    m = np.array([1, 5, 333, 40_000], dtype=np.int64)
    for s in (1, 7):
        part = K._compiled()["diff2"](p, m, np.full_like(m, s), block)
        for j, mm in enumerate(m):
            mm = int(mm)
            k_end = p.size - 2 * mm
            for k_first in (0, block, 3):  # aligned and unaligned windows of start indices
                length = k_end - k_first
                out = np.empty((k_end - 1) // block - k_first // block + 1)
                K.block_sums2(p[k_first + 2 * mm: k_end + 2 * mm], p[k_first + mm: k_end + mm], p[k_first:k_end],
                              k_first, s, block, out)
                first = k_first // block
                if k_first % block == 0:
                    assert np.array_equal(out, part[first:first + out.size, j]), (s, mm, k_first)
                else:  # a window starting inside a block: the later blocks are still equal
                    assert np.array_equal(out[1:], part[first + 1:first + out.size, j]), (s, mm, k_first)
                assert length > 0


def test_large_offset_does_not_cost_precision():
    """A 1e4 deg/h offset is removed before integrating: the sums equal those of the offset-free series."""
    rng = np.random.default_rng(7)
    y = rng.standard_normal(150_000)
    m = np.array([1, 10, 1000, 30_000], dtype=np.int64)
    a = K.operator_sums(K.phase_dph_samples(y), m, np.ones_like(m), (1, -2, 1), False)
    b = K.operator_sums(K.phase_dph_samples(y + 1e4), m, np.ones_like(m), (1, -2, 1), False)
    np.testing.assert_allclose(a, b, rtol=1e-9)


def test_one_thread_and_two_give_the_same_bits(monkeypatch):
    """Small work runs serially (PARALLEL_MIN); the blocks and their order do not change, so neither do the sums."""
    p = _angle(300_000, 11)
    m = np.array([1, 9, 500, 70_000], dtype=np.int64)
    monkeypatch.setattr(K, "PARALLEL_MIN", 0)             # always parallel
    par = (K.phase_dph_samples(p[:200_000]), K.operator_sums(p, m, np.ones_like(m), (1, -2, 1), False))
    monkeypatch.setattr(K, "PARALLEL_MIN", 1 << 62)       # always serial
    ser = (K.phase_dph_samples(p[:200_000]), K.operator_sums(p, m, np.ones_like(m), (1, -2, 1), False))
    assert np.array_equal(par[0], ser[0]) and np.array_equal(par[1], ser[1])
