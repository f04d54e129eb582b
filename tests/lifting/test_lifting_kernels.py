"""The kernels: fused numba block kernels == step-by-step path, backends agree, custom tables.

The fused path (numba, n >= ``_FUSED_MIN``) is checked against ``_drift_ref`` (step by step)
for every registered wavelet and a custom scheme with a 3-tap step, in both modes, at
lengths around the block size and the fused threshold, and at levels where the symmetric
head/tail segments fall back to the step path (short channels).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fogdrift import lifting as L
from fogdrift.errors import ConfigError
from fogdrift.lifting._drift import _FUSED_MIN, _drift_ref, _fused_drift

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


@pytest.fixture
def numpy_backend():
    old = L._get_backend()
    L._set_backend("numpy")
    yield
    L._set_backend(old)


@pytest.mark.parametrize("wavelet", SCHEMES, ids=lambda w: getattr(w, "name", w))
@pytest.mark.parametrize("mode", ["periodization", "symmetric"])
@pytest.mark.parametrize("n", [_FUSED_MIN, _FUSED_MIN + 1, 2051, 3000, 10001, 65537])
def test_fused_kernels_equal_reference(n, mode, wavelet):
    x = np.random.default_rng(n).standard_normal(n)
    scheme = L.get_wavelet(wavelet)
    periodic = mode == "periodization"
    for level in (1, 3, 6):
        drift, noise = np.empty(n), np.empty(n)
        _fused_drift(x, scheme, level, periodic, drift, noise)
        ref = _drift_ref(x, scheme, level, periodic)
        tol = 1e-13 * max(1.0, np.abs(ref).max())
        np.testing.assert_allclose(drift, ref, atol=tol, rtol=0)
        np.testing.assert_allclose(noise, x - ref, atol=tol, rtol=0)


@pytest.mark.parametrize("wavelet", SCHEMES, ids=lambda w: getattr(w, "name", w))
@pytest.mark.parametrize("mode", ["periodization", "symmetric"])
def test_backends_agree(mode, wavelet):
    x = np.random.default_rng(3).standard_normal(5001)
    out = {}
    for b in ("numba", "numpy"):
        old = L._get_backend()
        L._set_backend(b)
        try:
            out[b] = (L.wavedec(x, wavelet, level=5, mode=mode), L.separate(x, wavelet, level=5, mode=mode))
        finally:
            L._set_backend(old)
    for p, q in zip(out["numba"][0], out["numpy"][0]):
        np.testing.assert_allclose(p, q, atol=1e-12, rtol=0)
    for p, q in zip(out["numba"][1], out["numpy"][1]):
        np.testing.assert_allclose(p, q, atol=1e-12, rtol=0)


def test_custom_scheme_periodization_round_trip(numpy_backend):
    x = np.random.default_rng(5).standard_normal(999)
    c = L.wavedec(x, CUSTOM, level=4)
    np.testing.assert_allclose(L.waverec(c, CUSTOM, length=999), x, atol=1e-12)


def test_backend_switch():
    old = L._get_backend()
    try:
        L._set_backend("numpy")
        assert L._get_backend() == "numpy"
        with pytest.raises(ConfigError, match="backend"):
            L._set_backend("cuda")
        assert L._get_backend() == "numpy"
    finally:
        L._set_backend(old)
