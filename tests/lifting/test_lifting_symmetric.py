"""The symmetric lifting mode (the pipeline's default) against an independent reference.

PyWavelets has no equivalent of this mode (its ``"symmetric"`` is an expansive convolution),
so the oracle is written here, from the definition only: split into even/odd channels,
apply each step ``target[l] += sum_k c_k * other[refl(l + k)]`` with the whole-sample
reflection of the *other* channel's index (``i -> -i`` below 0, ``i -> 2(m-1) - i`` above
m-1, repeated until inside; a one-sample channel repeats its sample), scale, and invert by
running the steps backwards with flipped signs.  No modular arithmetic, no interior/edge
split, no fusion, one NumPy expression per tap: nothing shared with the library's kernels.

Both backends are checked (numba: step kernels below ``_FUSED_MIN`` samples and the fused
block kernels from ``_FUSED_MIN`` on; numpy: the reference step applier), for every
registered wavelet and a custom 3-tap scheme, odd and even lengths.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fogdrift import lifting as L
from fogdrift.lifting._drift import _FUSED_MIN

BACKENDS = ["numba", "numpy"]

# A CDF-5/3-like scheme with a 3-tap step and reach 2 exercises the generic step applier.
CUSTOM = L.LiftingScheme(
    name="custom",
    steps=(
        L.LiftingStep("predict", ((0, -0.5), (1, -0.5))),
        L.LiftingStep("update", ((-1, 0.25), (0, 0.2), (1, 0.05))),
        L.LiftingStep("predict", ((-2, 0.01),)),
    ),
    scale_approx=math.sqrt(2.0),
    scale_detail=1 / math.sqrt(2.0),
    input_shift=3,
    detail_shift=2,
    detail_sign=-1.0,
    filter_length=6,
)
SCHEMES = [*L.wavelist(), CUSTOM]
LENGTHS = [37, 100, 101, 1001, _FUSED_MIN, _FUSED_MIN + 1, 4097, 10_000, 30_001]


@pytest.fixture(params=BACKENDS)
def backend(request):
    old = L._get_backend()
    L._set_backend(request.param)
    yield request.param
    L._set_backend(old)


# ---------------------------------------------------------------- independent reference


def _reflect(idx, m):
    """Whole-sample symmetric extension of a channel of m samples (index array -> index array)."""
    if m == 1:
        return np.zeros_like(idx)
    idx = idx.copy()
    while True:
        low, high = idx < 0, idx > m - 1
        if not (low.any() or high.any()):
            return idx
        idx[low] = -idx[low]
        idx[high] = 2 * (m - 1) - idx[high]


def _ref_step(target, other, taps, sign):
    pos = np.arange(target.shape[0])
    acc = np.zeros(target.shape[0])
    for off, c in taps:
        acc += c * other[_reflect(pos + off, other.shape[0])]
    return target + sign * acc


def ref_forward(x, scheme):
    even, odd = x[0::2].copy(), x[1::2].copy()
    for st in scheme.steps:
        if st.kind == "predict":
            odd = _ref_step(odd, even, st.taps, 1.0)
        else:
            even = _ref_step(even, odd, st.taps, 1.0)
    return scheme.scale_approx * even, scheme.detail_sign * scheme.scale_detail * odd


def ref_inverse(approx, detail, scheme):
    even = approx / scheme.scale_approx
    odd = detail / (scheme.detail_sign * scheme.scale_detail)
    for st in reversed(scheme.steps):
        if st.kind == "predict":
            odd = _ref_step(odd, even, st.taps, -1.0)
        else:
            even = _ref_step(even, odd, st.taps, -1.0)
    x = np.empty(even.shape[0] + odd.shape[0])
    x[0::2], x[1::2] = even, odd
    return x


def _extend(x, level):
    """Whole-sample reflection of the end to a multiple of 2**level (what separate() does in symmetric mode)."""
    n = len(x)
    pad = (-n) % (2**level)
    return np.concatenate([x, x[n - 2 :: -1][:pad]]) if pad else x


def ref_wavedec(x, scheme, level):
    a, details = np.asarray(x, float), []
    for _ in range(level):
        a, d = ref_forward(a, scheme)
        details.append(d)
    return [a] + details[::-1]


def ref_waverec(coeffs, scheme):
    a = coeffs[0]
    for d in coeffs[1:]:
        a = ref_inverse(a, d, scheme)
    return a


def test_reference_reflection_rule_by_hand():
    # the oracle itself: channel [a, b, c] extended as ... c b | a b c | b a ...
    np.testing.assert_array_equal(_reflect(np.arange(-4, 7), 3), [0, 1, 2, 1, 0, 1, 2, 1, 0, 1, 2])
    np.testing.assert_array_equal(_reflect(np.array([-2, 3]), 1), [0, 0])
    # haar, one level, by hand: E = [1, 3], O = [2]; d = O - E = [1]; s = E + d[refl(l)]/2 with
    # the one-sample detail channel repeated: [1.5, 3.5]; cA = sqrt2 s, cD = -d/sqrt2
    a, d = ref_forward(np.array([1.0, 2.0, 3.0]), L.get_wavelet("haar"))
    np.testing.assert_allclose(a, [1.5 * math.sqrt(2), 3.5 * math.sqrt(2)])
    np.testing.assert_allclose(d, [-1 / math.sqrt(2)])
    np.testing.assert_allclose(L.lift([1.0, 2.0, 3.0], "haar", mode="symmetric")[0], a)


# ---------------------------------------------------------------- library vs reference


@pytest.mark.parametrize("wavelet", SCHEMES, ids=lambda w: getattr(w, "name", w))
@pytest.mark.parametrize("n", LENGTHS)
def test_symmetric_mode_equals_reference(n, wavelet, backend):
    scheme = L.get_wavelet(wavelet)
    x = 3.0 * np.random.default_rng(n).standard_normal(n) + np.linspace(-2.0, 5.0, n)
    jmax = L.max_level(n, scheme)
    for level in sorted({1, min(4, jmax), jmax}):
        ref = ref_wavedec(x, scheme, level)
        # relative to the largest value involved: odd lengths at deep levels amplify the ends
        tol = 1e-12 * max(np.abs(x).max(), max(np.abs(b).max() for b in ref))
        c = L.wavedec(x, scheme, level=level, mode="symmetric")
        assert [len(b) for b in c] == [len(b) for b in ref]
        assert sum(len(b) for b in c) == n  # no padding
        for got, want in zip(c, ref):
            np.testing.assert_allclose(got, want, atol=tol, rtol=0)
        np.testing.assert_allclose(L.waverec(c, scheme, mode="symmetric"), x, atol=tol, rtol=0)
        drift, noise = L.separate(x, scheme, level=level, mode="symmetric")
        refx = ref_wavedec(_extend(x, level), scheme, level)  # separate() extends to a multiple of 2**J
        ref_drift = ref_waverec([refx[0]] + [np.zeros_like(b) for b in refx[1:]], scheme)[:n]
        ref_noise = ref_waverec([np.zeros_like(refx[0])] + refx[1:], scheme)[:n]
        tol = max(tol, 1e-12 * np.abs(ref_drift).max())
        np.testing.assert_allclose(drift, ref_drift, atol=tol, rtol=0)
        np.testing.assert_allclose(noise, ref_noise, atol=tol, rtol=0)


@pytest.mark.parametrize("wavelet", SCHEMES, ids=lambda w: getattr(w, "name", w))
@pytest.mark.parametrize("n", [2, 3, 4, 5, 6, 7, 9])
def test_short_signals_equal_reference(n, wavelet, backend):
    # channels shorter than a step's reach: every output sample of the step is a reflected (edge) sample
    scheme = L.get_wavelet(wavelet)
    x = np.random.default_rng(100 + n).standard_normal(n) + 1.0
    for level in range(1, L.max_level(n, scheme) + 1):
        ref = ref_wavedec(x, scheme, level)
        c = L.wavedec(x, scheme, level=level, mode="symmetric")
        for got, want in zip(c, ref):
            np.testing.assert_allclose(got, want, atol=1e-12 * max(np.abs(b).max() for b in ref), rtol=0)


@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize(("n_t", "m", "offs"), [(3, 1, [2]), (2, 2, [2, 3]), (4, 3, [-1, 3]), (5, 2, [-4, 0, 1])])
def test_step_kernels_when_every_sample_is_an_edge_sample(n_t, m, offs, periodic):
    # offsets at least the other channel's length: no interior sample (a case max_level keeps the public API
    # out of); both step appliers against the rule written out here (whole-sample reflection or wrap-around)
    from fogdrift.lifting import _kernels as K

    def idx(j):
        if periodic:
            return j % m
        if m == 1:
            return 0
        p = 2 * (m - 1)
        j %= p
        return p - j if j > m - 1 else j

    rng = np.random.default_rng(n_t * 10 + m)
    other, target = rng.standard_normal(m), rng.standard_normal(n_t)
    coefs = rng.standard_normal(len(offs))
    want = target + [sum(c * other[idx(l + o)] for o, c in zip(offs, coefs)) for l in range(n_t)]
    offs_a = np.array(offs, dtype=np.int64)
    got_np = target.copy()
    K._np_step(got_np, other, offs_a, coefs, periodic)
    got_nb = target.copy()
    K._numba_kernels()[0](got_nb, other, offs_a, coefs, periodic)
    np.testing.assert_allclose(got_np, want, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(got_nb, want, rtol=1e-14, atol=1e-14)


def test_symmetric_differs_from_pywt_symmetric():
    pywt = pytest.importorskip("pywt")
    x = np.random.default_rng(0).standard_normal(256)
    assert [len(b) for b in pywt.wavedec(x, "db2", mode="symmetric", level=4)] == [18, 18, 34, 66, 129]
    assert [len(b) for b in L.wavedec(x, "db2", level=4, mode="symmetric")] == [16, 16, 32, 64, 128]


# ---------------------------------------------------------------- locality at the end of the record
# Reach asserted: S = (L - 1) * (2**J - 1), L the filter length (haar 2, db2 4, db4 8).  Why:
# the level-J approximation coefficient cA_J[l] is an inner product of x with an equivalent
# filter of (L - 1)(2**J - 1) + 1 taps, and away from the ends the unshifted lifting transform
# is a circular shift of PyWavelets' orthogonal one, so the synthesis function of cA_J[l]
# (W^-1 = W^T) has the same support.  drift[i] = sum_l phi_l(i) <phi_l, x> therefore depends on
# x[k] only for |i - k| <= S.  The symmetric rule folds indices that leave the record back
# inside it, so x[n-1] cannot reach further than S from the end either (measured: up to S,
# e.g. haar J = 1: S; db4 J = 4: 103 of 105).  A wrap-around (periodic) rule in symmetric mode
# would carry x[n-1] to the start of the record and fail this test.


@pytest.mark.parametrize("wavelet", L.wavelist())
@pytest.mark.parametrize("n", [600, 601, 5000, 5001])
@pytest.mark.parametrize("level", [1, 4, 6])
def test_changing_last_sample_leaves_early_drift_bit_identical(level, n, wavelet, backend):
    scheme = L.get_wavelet(wavelet)
    reach = (scheme.filter_length - 1) * (2**level - 1)
    x = np.random.default_rng(n).standard_normal(n)
    y = x.copy()
    y[-1] += 1000.0
    before, _ = L.separate(x, wavelet, level=level, mode="symmetric")
    after, _ = L.separate(y, wavelet, level=level, mode="symmetric")
    np.testing.assert_array_equal(after[: n - 1 - reach], before[: n - 1 - reach])
    assert not np.array_equal(after[n - 1 - reach :], before[n - 1 - reach :])  # it does reach
    if scheme.filter_length > 2:  # (haar has no neighbours to wrap)
        # the contrast that makes the test meaningful: periodization wraps the end onto the start
        p_before, _ = L.separate(x, wavelet, level=level, mode="periodization")
        p_after, _ = L.separate(y, wavelet, level=level, mode="periodization")
        assert p_after[0] != p_before[0]


@pytest.mark.parametrize("wavelet", SCHEMES, ids=lambda w: getattr(w, "name", w))
@pytest.mark.parametrize("n", [16, 37, 100, 101, 1001, 2048, 2049, 4097, 30001])
def test_symmetric_perfect_reconstruction(n, wavelet, backend):
    x = np.random.default_rng(n).standard_normal(n) + 5.0
    level = L.max_level(n, wavelet)
    c = L.wavedec(x, wavelet, level=level, mode="symmetric")
    np.testing.assert_allclose(L.waverec(c, wavelet, mode="symmetric"), x, atol=1e-12 * 6)
    drift, noise = L.separate(x, wavelet, level=level, mode="symmetric")
    ce = L.wavedec(_extend(x, level), wavelet, level=level, mode="symmetric")
    sep = L.waverec([np.zeros_like(ce[0])] + ce[1:], wavelet, mode="symmetric")[:n]
    np.testing.assert_allclose(noise, sep, atol=1e-12 * 6)


# ---------------------------------------------------------------- documented edge gain
# The caveat in fogdrift.lifting.transform: odd lengths at some level amplify the end of the
# drift of the raw symmetric transform (up to 9.3x for db2, n = 16k + 1).  separate() and
# causal_drift() therefore extend the record by whole-sample reflection to a multiple of 2**J
# first; the gains below are pinned so that the documented numbers stay true.


def _last_row_gain(n, wavelet, mode, level=4):
    # causal_drift of the n unit vectors (columns of the identity) with a window of n samples:
    # its last row is the last row of the drift operator (checked against separate() below)
    last = L.causal_drift(np.eye(n), n, wavelet, level=level, mode=mode)[-1]
    return float(np.linalg.norm(last))


def test_last_row_gain_helper():
    n = 259
    eye = np.eye(n)
    last = [L.separate(eye[i], "db2", level=4, mode="symmetric")[0][-1] for i in range(n)]
    assert _last_row_gain(n, "db2", "symmetric") == pytest.approx(float(np.linalg.norm(last)), rel=1e-12)


def _raw_last_row_gain(n, wavelet, level=4):
    # last row of the drift operator of the raw symmetric transform (no extension)
    from fogdrift.lifting._drift import _drift_1d
    from fogdrift.lifting.schemes import get_wavelet

    eye = np.eye(n)
    return float(np.linalg.norm([_drift_1d(eye[i], get_wavelet(wavelet), level, False)[-1] for i in range(n)]))


def test_documented_end_gain_of_the_symmetric_mode():
    ns = range(256, 272)  # every residue mod 16; the gains are the same for n = 1024..1039
    raw = {n: _raw_last_row_gain(n, "db2") for n in (256, 257)}
    assert raw[256] == pytest.approx(0.41, abs=0.01) and raw[257] == pytest.approx(9.34, abs=0.01)
    # with the extension to a multiple of 2**J every length behaves like a multiple of 16
    for wavelet, top in (("db2", 0.44), ("db4", 0.40), ("haar", 0.35)):
        gains = [_last_row_gain(n, wavelet, "symmetric") for n in ns]
        assert max(gains) <= top, (wavelet, max(gains))
    assert max(_last_row_gain(n, "db2", "periodization") for n in ns) <= 0.48
