"""separate() and causal_drift(): API, errors, the noise branch, multi-axis, causality.

``separate`` computes the noise as ``x - drift``, so ``drift + noise == x`` proves nothing;
the checks here compare the noise with its own separate reconstruction
``W^-1(0, cD_J, ..., cD_1)`` (both modes, both backends, fused and step paths), and the
branches with PyWavelets' separate reconstructions in ``tests/lifting/test_lifting_pywt.py``.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fogdrift import lifting as L
from fogdrift.errors import ConfigError, DataFormatError, InsufficientDataError

BACKENDS = ["numba", "numpy"]
MODES = ["periodization", "symmetric"]


@pytest.fixture(params=BACKENDS)
def backend(request):
    old = L._get_backend()
    L._set_backend(request.param)
    yield request.param
    L._set_backend(old)


def _noise_branch(x, wavelet, level, mode):
    # in symmetric mode separate() works on the record extended to a multiple of 2**level
    xe = _extend(x, level) if mode == "symmetric" else x
    c = L.wavedec(xe, wavelet, level=level, mode=mode)
    return L.waverec([np.zeros_like(c[0])] + c[1:], wavelet, mode=mode, length=len(xe))[: len(x)]

def _extend(x, level):
    """Whole-sample reflection of the end to a multiple of 2**level (what separate() does in symmetric mode)."""
    n = len(x)
    pad = (-n) % (2**level)
    return np.concatenate([x, x[n - 2 :: -1][:pad]]) if pad else x



@pytest.mark.parametrize("wavelet", L.wavelist())
@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("n", [64, 101, 1000, 2048, 2049, 10_001])
def test_noise_equals_its_separate_reconstruction(n, mode, wavelet, backend):
    x = np.random.default_rng(n).standard_normal(n) * 4.0 + np.cos(np.arange(n) / 50.0)
    for level in sorted({1, min(4, L.max_level(n, wavelet)), L.max_level(n, wavelet)}):
        _, noise = L.separate(x, wavelet, level=level, mode=mode)
        ref = _noise_branch(x, wavelet, level, mode)
        tol = 1e-12 * max(np.abs(x).max(), np.abs(ref).max())
        np.testing.assert_allclose(noise, ref, atol=tol, rtol=0)


def test_level_must_be_an_integer():
    x = np.zeros(64)
    with pytest.raises(ConfigError, match=r"choose_level\(level_scan\(") as err:
        L.separate(x, level="auto")
    assert "level=" in str(err.value) and "--level" in err.value.render({"level": "--level"})
    with pytest.raises(ConfigError, match="level"):
        L.separate(x, level="4")
    with pytest.raises(TypeError):
        L.separate(x, level=4, dt_s=0.1)  # the level is resolved outside separate()


def test_level_rule_and_errors():
    assert L.max_level(47) == 3 and L.max_level(48) == 4
    assert L.max_level(16, "haar") == 4
    with pytest.raises(ConfigError, match="maximum is 3") as err:
        L.separate(np.zeros(47), "db2", level=4)
    assert "pass level= 3 or lower" in str(err.value)
    with pytest.raises(ConfigError, match="maximum is 3"):
        L.wavedec(np.zeros(47), "db2", level=4, mode="symmetric")
    with pytest.raises(ConfigError, match=r"maximum is 0 .*; use a longer record"):
        L.separate(np.zeros(2), "db2", level=1)
    with pytest.raises(ConfigError, match="'db2'"):
        L.get_wavelet("db99")
    with pytest.raises(ConfigError, match="mode"):
        L.separate(np.zeros(64), mode="zero")
    with pytest.raises(ConfigError, match="level"):
        L.separate(np.zeros(64), level=0)
    with pytest.raises(ConfigError, match="level"):
        L.separate(np.zeros(64), level=2.5)
    with pytest.raises(ConfigError, match="level"):
        L.separate(np.zeros(64), level=True)
    with pytest.raises(InsufficientDataError):
        L.separate(np.zeros(1))


def test_non_finite_input_reports_index():
    x = np.zeros(100)
    x[42] = np.nan
    with pytest.raises(DataFormatError, match=r"x\[42\]"):
        L.separate(x)
    y = np.zeros((100, 2))
    y[17, 1] = np.inf
    with pytest.raises(DataFormatError, match=r"x\[17, 1\]"):
        L.separate(y)
    with pytest.raises(DataFormatError, match="shape"):
        L.wavedec(np.zeros((10, 2, 2)))


@pytest.mark.parametrize("wavelet", L.wavelist())
@pytest.mark.parametrize("mode", MODES)
def test_constant_passes_to_drift_any_length(mode, wavelet):
    for n in (128, 201, 3001):  # db4 level 4 needs n >= 112
        drift, noise = L.separate(np.full(n, -7.25), wavelet, level=4, mode=mode)
        np.testing.assert_allclose(drift, -7.25, atol=1e-11)
        np.testing.assert_allclose(noise, 0.0, atol=1e-11)


@pytest.mark.parametrize("mode", MODES)
def test_multi_axis_equals_columns(mode):
    x = np.random.default_rng(7).standard_normal((3001, 3)) * [1.0, 10.0, 0.1]
    drift, noise = L.separate(x, "db2", level=5, mode=mode)
    assert drift.shape == noise.shape == x.shape
    for k in range(3):
        d1, n1 = L.separate(x[:, k], "db2", level=5, mode=mode)
        np.testing.assert_array_equal(drift[:, k], d1)
        np.testing.assert_array_equal(noise[:, k], n1)


@settings(max_examples=60)
@given(
    n=st.integers(min_value=8, max_value=3000),
    wavelet=st.sampled_from(L.wavelist()),
    mode=st.sampled_from(MODES),
    level=st.integers(min_value=1, max_value=8),
    seed=st.integers(min_value=0, max_value=2**31),
)
def test_property_round_trip_and_noise_branch(n, wavelet, mode, level, seed):
    level = min(level, L.max_level(n, wavelet))
    if level < 1:
        return
    x = np.random.default_rng(seed).normal(0.0, 100.0, n)
    c = L.wavedec(x, wavelet, level=level, mode=mode)
    big = max(np.abs(x).max(), max(np.abs(b).max() for b in c))
    np.testing.assert_allclose(L.waverec(c, wavelet, mode=mode, length=n), x, atol=1e-12 * big, rtol=0)
    _, noise = L.separate(x, wavelet, level=level, mode=mode)
    ref = _noise_branch(x, wavelet, level, mode)
    np.testing.assert_allclose(noise, ref, atol=1e-12 * max(big, np.abs(ref).max()), rtol=0)


# ---------------------------------------------------------------- causal drift


@pytest.mark.parametrize("wavelet", L.wavelist())
@pytest.mark.parametrize("mode", ["symmetric", "periodization"])
def test_causal_drift_equals_naive(mode, wavelet):
    x = np.cumsum(np.random.default_rng(4).standard_normal(700)) * 0.1
    window = 129
    cd = L.causal_drift(x, window, wavelet, level=4, mode=mode)
    assert np.isnan(cd[: window - 1]).all()
    for k in (window - 1, 200, 431, 699):
        naive = L.separate(x[k - window + 1 : k + 1], wavelet, level=4, mode=mode)[0][-1]
        assert cd[k] == pytest.approx(naive, abs=1e-12 * max(1.0, abs(naive)))
    x2 = np.stack([x, -2 * x], axis=1)
    cd2 = L.causal_drift(x2, window, wavelet, level=4, mode=mode)
    np.testing.assert_allclose(cd2[window - 1 :, 1], -2 * cd[window - 1 :], atol=1e-11)
    with pytest.raises(InsufficientDataError):
        L.causal_drift(x[:100], window)


def test_causal_drift_uses_no_future_sample():
    x = np.random.default_rng(8).standard_normal(400)
    y = x.copy()
    y[300:] += 50.0
    for w in L.wavelist():
        a = L.causal_drift(x, 128, w, level=4)
        b = L.causal_drift(y, 128, w, level=4)
        np.testing.assert_array_equal(a[:300], b[:300])
        assert not np.allclose(a[300:], b[300:])


@pytest.mark.parametrize("wavelet", L.wavelist())
@pytest.mark.parametrize("window", [128, 256, 1024])
def test_causal_drift_white_noise_gain_for_windows_of_whole_blocks(window, wavelet):
    # a window that is a multiple of 2**J has even lengths at every level; the real-time drift
    # of unit white noise then has a standard deviation ||g|| below 1/2 (measured 0.21 .. 0.41)
    x = np.random.default_rng(window).standard_normal(20_000)
    cd = L.causal_drift(x, window, wavelet, level=4)
    assert np.nanstd(cd) < 0.5
    with pytest.raises(ConfigError):
        L.causal_drift(x, 1)
