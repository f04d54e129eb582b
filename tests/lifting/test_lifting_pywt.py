"""Every registered lifting wavelet against PyWavelets in periodization mode, and the
orthogonality of the periodized drift/noise split.

Oracle: ``pywt.wavedec``/``pywt.waverec(..., mode="periodization")``; the drift and noise
are PyWavelets' separate reconstructions (``waverec`` on zeroed bands, trimmed to n).
Parametrised over :func:`fogdrift.lifting.wavelist`, so a new table entry is tested here
without a code change.  Tolerance 1e-12 * max|x| (measured errors ~5e-15).
"""

from __future__ import annotations

import numpy as np
import pytest
import pywt

from fogdrift import lifting as L

BACKENDS = ["numba", "numpy"]
LENGTHS = [16, 17, 31, 48, 63, 100, 101, 255, 256, 1000, 1001, 4097, 12345, 65536, 100_000, 100_001]


@pytest.fixture(params=BACKENDS)
def backend(request):
    old = L._get_backend()
    L._set_backend(request.param)
    yield request.param
    L._set_backend(old)


def _pywt_name(wavelet):
    name = L.get_wavelet(wavelet).pywt_name
    assert name is not None, f"{wavelet} has no PyWavelets counterpart"
    return name


def _pywt_drift_noise(x, name, level):
    c = pywt.wavedec(x, name, mode="periodization", level=level)
    zero = [np.zeros_like(b) for b in c]
    drift = pywt.waverec([c[0]] + zero[1:], name, mode="periodization")[: len(x)]
    noise = pywt.waverec([zero[0]] + c[1:], name, mode="periodization")[: len(x)]
    return drift, noise


def test_every_registered_wavelet_has_a_pywt_counterpart():
    assert L.wavelist() == list(L.WAVELETS)
    for w in L.wavelist():
        scheme = L.get_wavelet(w)
        assert scheme.filter_length == pywt.Wavelet(_pywt_name(w)).dec_len
        for n in (5, 7, 47, 48, 112, 1000, 12345):
            assert L.max_level(n, w) == pywt.dwt_max_level(n, scheme.filter_length)


@pytest.mark.parametrize("wavelet", L.wavelist())
@pytest.mark.parametrize("n", LENGTHS)
def test_pywt_equivalence(n, wavelet, backend):
    name = _pywt_name(wavelet)
    rng = np.random.default_rng(1000 + n)
    x = 2.0 * rng.standard_normal(n) + np.linspace(0, 3, n)
    tol = 1e-12 * np.abs(x).max()
    level = min(6, pywt.dwt_max_level(n, name))
    assert level >= 1
    c = L.wavedec(x, wavelet, level=level)
    p = pywt.wavedec(x, name, mode="periodization", level=level)
    assert [len(b) for b in c] == [len(b) for b in p]
    for a, b in zip(c, p):
        np.testing.assert_allclose(a, b, atol=tol, rtol=0)
    np.testing.assert_allclose(L.waverec(c, wavelet, length=n), x, atol=tol, rtol=0)
    drift, noise = L.separate(x, wavelet, level=level)
    pdrift, pnoise = _pywt_drift_noise(x, name, level)
    np.testing.assert_allclose(drift, pdrift, atol=tol, rtol=0)
    np.testing.assert_allclose(noise, pnoise, atol=tol, rtol=0)
    # the noise branch reconstructed on its own, W^-1(0, cD_J, ..., cD_1), equals x - drift
    sep_noise = L.waverec([np.zeros_like(c[0])] + c[1:], wavelet, length=n)
    np.testing.assert_allclose(noise, sep_noise, atol=tol, rtol=0)


@pytest.mark.parametrize("wavelet", L.wavelist())
@pytest.mark.parametrize("n", [8, 17, 100, 101])
def test_lift_unlift_one_level(n, wavelet, backend):
    x = np.random.default_rng(n).standard_normal(n)
    a, d = L.lift(x, wavelet)
    pa, pd = pywt.dwt(x, _pywt_name(wavelet), mode="periodization")
    np.testing.assert_allclose(a, pa, atol=1e-12)
    np.testing.assert_allclose(d, pd, atol=1e-12)
    np.testing.assert_allclose(L.unlift(a, d, wavelet, length=n), x, atol=1e-12)
    a, d = L.lift(x, wavelet, mode="symmetric")
    assert len(a) + len(d) == n
    np.testing.assert_allclose(L.unlift(a, d, wavelet, mode="symmetric"), x, atol=1e-12)


def test_db4_impulse_bands_equal_pywt_filters():
    # one level on unit impulses: the periodized db4 analysis rows are pywt's dec_lo/dec_hi
    n = 32
    rows_a = np.array([L.lift(np.eye(n)[j], "db4")[0] for j in range(n)]).T
    rows_d = np.array([L.lift(np.eye(n)[j], "db4")[1] for j in range(n)]).T
    pa = np.array([pywt.dwt(np.eye(n)[j], "db4", mode="periodization")[0] for j in range(n)]).T
    pd = np.array([pywt.dwt(np.eye(n)[j], "db4", mode="periodization")[1] for j in range(n)]).T
    np.testing.assert_allclose(rows_a, pa, atol=1e-14)
    np.testing.assert_allclose(rows_d, pd, atol=1e-14)
    w = pywt.Wavelet("db4")
    # row 8 holds the 8 filter taps (in some order), and nothing else
    np.testing.assert_allclose(np.sort(rows_a[8][np.abs(rows_a[8]) > 1e-14]), np.sort(w.dec_lo), atol=1e-14)
    np.testing.assert_allclose(np.sort(rows_d[8][np.abs(rows_d[8]) > 1e-14]), np.sort(w.dec_hi), atol=1e-14)


# ---------------------------------------------------------------- orthogonality (periodization)
# For an orthogonal wavelet and n a multiple of 2**J (no padding), W is an orthogonal matrix,
# so the drift W^T diag(1, 0) W x is an orthogonal projection of x: the two parts are
# orthogonal, their energies add up to ||x||^2, and separating the drift again returns it.


@pytest.mark.parametrize("wavelet", L.wavelist())
@pytest.mark.parametrize("n,level", [(64, 4), (192, 6), (4096, 4), (16_000, 5)])
def test_periodized_split_is_an_orthogonal_projection(n, level, wavelet, backend):
    rng = np.random.default_rng(n + level)
    x = rng.standard_normal(n) + np.sin(np.arange(n) / 40.0)
    level = min(level, L.max_level(n, wavelet))
    assert n % 2**level == 0
    energy = float(x @ x)
    c = L.wavedec(x, wavelet, level=level)
    assert sum(float(b @ b) for b in c) == pytest.approx(energy, rel=1e-12)  # Parseval
    drift, noise = L.separate(x, wavelet, level=level)
    assert abs(float(drift @ noise)) <= 1e-12 * energy
    assert float(drift @ drift) + float(noise @ noise) == pytest.approx(energy, rel=1e-12)
    d2, n2 = L.separate(drift, wavelet, level=level)  # P^2 = P
    np.testing.assert_allclose(d2, drift, atol=1e-12 * np.abs(x).max())
    np.testing.assert_allclose(n2, 0.0, atol=1e-12 * np.abs(x).max())
    d3, n3 = L.separate(noise, wavelet, level=level)  # (I - P)^2 = I - P
    np.testing.assert_allclose(d3, 0.0, atol=1e-12 * np.abs(x).max())
    np.testing.assert_allclose(n3, noise, atol=1e-12 * np.abs(x).max())
