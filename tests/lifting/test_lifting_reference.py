"""Published/hand-checked reference values of the lifting transform (method notes §7: R1-R7, R16).

Each value was computed by an independent script (PyWavelets or by hand) and printed to 10
digits; PyWavelets itself is the second oracle where it applies.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import pywt

from fogdrift import lifting as L

CA_R1 = [3.346065215, 2.3107890345, 5.1392161593, 9.0029194644]


def test_R1_dwt_arange8():
    x = np.arange(8.0)
    ca, cd = L.lift(x, "db2")
    np.testing.assert_allclose(ca, CA_R1, atol=1e-9)  # reference printed to 10 digits
    np.testing.assert_allclose(cd, [-1.0352761804, 0.0, 0.0, 3.8637033052], atol=1e-9)
    pa, pd = pywt.dwt(x, "db2", mode="periodization")
    np.testing.assert_allclose(ca, pa, atol=1e-12)
    np.testing.assert_allclose(cd, pd, atol=1e-12)


def test_R2_raw_ds98_lifting_on_delayed_input():
    x = np.arange(8.0)
    raw = dataclasses.replace(L.WAVELETS["db2"], input_shift=0, detail_shift=0, detail_sign=1.0)
    s, d = L.lift(np.roll(x, 1), raw)
    np.testing.assert_allclose(s, CA_R1, atol=1e-9)
    np.testing.assert_allclose(d, [-3.8637033052, 1.0352761804, 0.0, 0.0], atol=1e-9)
    _, cd = L.lift(x, "db2")
    np.testing.assert_allclose(cd, -np.roll(d, -1), atol=1e-12)


def test_R3_sine_plus_ramp():
    n = np.arange(100)
    x = np.sin(0.3 * n) + 0.05 * n
    c = L.wavedec(x, "db2", level=4)
    assert [len(b) for b in c] == [7, 7, 13, 25, 50]
    np.testing.assert_allclose(
        c[0],
        [15.0731324906, 1.4969865227, 5.688484797, 9.1745084451, 11.4330637278, 13.9710809533, 21.1575377371],
        atol=1e-9,
    )
    drift, noise = L.separate(x, "db2", level=4)
    np.testing.assert_allclose(drift[:5], [2.3640866724, 2.476566101, 2.379234079, 2.0720906065, 1.8211659427], atol=1e-9)
    assert drift[50] == pytest.approx(2.5859501526, abs=1e-9)
    assert noise[50] == pytest.approx(0.5643376875, abs=1e-9)
    p = pywt.wavedec(x, "db2", mode="periodization", level=4)
    assert max(np.abs(a - b).max() for a, b in zip(c, p)) <= 1e-12


@pytest.mark.parametrize("n", [100, 101, 255, 1001, 4097])
def test_R4_random_lengths(n):
    rng = np.random.default_rng(n)
    x = 3 * rng.standard_normal(n) + 0.5
    tol = 1e-12 * np.abs(x).max()
    c = L.wavedec(x, "db2", level=4)
    p = pywt.wavedec(x, "db2", mode="periodization", level=4)
    for a, b in zip(c, p):
        assert a.shape == b.shape
        np.testing.assert_allclose(a, b, atol=tol, rtol=0)
    np.testing.assert_allclose(L.waverec(c, "db2", length=n), x, atol=tol, rtol=0)
    full = pywt.waverec(p, "db2", mode="periodization")
    assert len(full) == n + (n % 2)  # odd n: pywt returns n+1 samples, trimmed to n
    drift, noise = L.separate(x, "db2", level=4)
    zero = [np.zeros_like(b) for b in p]
    np.testing.assert_allclose(drift, pywt.waverec([p[0]] + zero[1:], "db2", mode="periodization")[:n], atol=tol, rtol=0)
    np.testing.assert_allclose(noise, pywt.waverec([zero[0]] + p[1:], "db2", mode="periodization")[:n], atol=tol, rtol=0)


def test_R5_constant():
    x = np.full(64, 2.5)
    c = L.wavedec(x, "db2", level=4)
    for d in c[1:]:
        np.testing.assert_allclose(d, 0.0, atol=1e-12)
    np.testing.assert_allclose(c[0], 10.0, atol=1e-12)  # 2.5 * 2**(J/2)
    drift, noise = L.separate(x, "db2", level=4)
    np.testing.assert_allclose(drift, 2.5, atol=1e-12)
    np.testing.assert_allclose(noise, 0.0, atol=1e-12)


@pytest.mark.parametrize("mode", ["periodization", "symmetric"])
def test_R6_alternating_goes_to_noise(mode):
    x = (-1.0) ** np.arange(64)
    drift, noise = L.separate(x, "db2", level=4, mode=mode)
    np.testing.assert_allclose(drift, 0.0, atol=1e-12)
    np.testing.assert_allclose(noise, x, atol=1e-12)


def test_R7_haar():
    x = [1.0, 2.0, 3.0, 4.0]
    ca, cd = L.lift(x, "haar")
    np.testing.assert_allclose(ca, [2.1213203436, 4.9497474683], atol=1e-9)
    np.testing.assert_allclose(cd, [-0.7071067812, -0.7071067812], atol=1e-9)
    raw = dataclasses.replace(L.WAVELETS["haar"], detail_sign=1.0)
    _, d = L.lift(x, raw)
    np.testing.assert_allclose(d, [0.7071067812, 0.7071067812], atol=1e-9)
    pa, pd = pywt.dwt(x, "haar", mode="periodization")
    np.testing.assert_allclose(ca, pa, atol=1e-12)
    np.testing.assert_allclose(cd, pd, atol=1e-12)


def test_R16_white_noise_in_drift():
    # about 1/2**J of the white-noise variance stays in the drift (0.0592 measured, seed-dependent)
    x = np.random.default_rng(16).standard_normal(2**16)
    drift, _ = L.separate(x, "db2", level=4)
    assert abs(drift.var() - 1 / 16) <= 0.01
