"""Haar MODWT wavelet variance (fogdrift.gmwm.wvar).

References: GMWM method notes (shared/docs/gmwm-notes.md) §7 checks R1, R2, R4, R4', R5, R5'
(values produced by the notes' ref_checks.py, numpy default_rng/PCG64), PyWavelets ``swt`` as an
independent Haar transform, fogdrift.allan (maximal-overlap AVAR) for R5, and the published SMAC
curves in shared/data/smac_fog_reference_curves (README: units, origin).  Tolerances: exact
identities at 1e-12 (rounding of sums of 2^16 terms), published 6-7 digit values at their
rounding.
"""

from __future__ import annotations

import csv
import gzip
import json
from pathlib import Path

import numpy as np
import pytest
import pywt
from numpy.testing import assert_allclose

from fogdrift._util import json_default
from fogdrift.allan import allan_variance
from fogdrift.errors import ConfigError, DataFormatError, InsufficientDataError
from fogdrift.gmwm.wvar import (
    WvarResult, eta3, eta3_ci, from_curve, haar_coefficients, haar_wvar, huber_scale_constant,
)

SMAC = Path("/work/shared/data/smac_fog_reference_curves")
needs_smac = pytest.mark.skipif(not SMAC.exists(), reason="shared SMAC reference curves not available")


def _rows(name):
    with gzip.open(SMAC / name, "rt") as fh:
        return list(csv.DictReader(fh))


# --- reference checks R1, R2, R4, R5 ----------------------------------------------------
def test_r1_ramp():
    r = haar_wvar(np.arange(1024.0), 1.0, levels=5)
    assert_allclose(r.nu2_dph2, [0.25, 1, 4, 16, 64], rtol=1e-12)  # tau^2 / 16
    assert r.n_coef.tolist() == [1023, 1021, 1017, 1009, 993]


def test_r2_alternating():
    r = haar_wvar((-1.0) ** np.arange(1000), 1.0, levels=4)
    assert_allclose(r.nu2_dph2, [1, 0, 0, 0], atol=1e-14)


def test_r4_eta3_interval():
    eta = eta3(10**6 - 1024 + 1, 1024)
    assert_allclose(eta, 975.5634766, rtol=1e-9)
    lo, hi = eta3_ci(1.0, eta)
    assert_allclose([lo, hi], [0.9168686541, 1.095033373], rtol=1e-9)


def test_r5_wv_is_half_the_overlapping_allan_variance():
    x = np.random.default_rng(42).standard_normal(2**16)
    r = haar_wvar(x, 1.0, levels=10)
    assert_allclose(r.nu2_dph2[:3], [0.5023977671, 0.2524351615, 0.1253469221], rtol=1e-9)
    av = allan_variance(x, 1.0, taus=2.0 ** np.arange(10))
    assert_allclose(r.nu2_dph2, av.avar_dph2 / 2.0, rtol=1e-12)
    assert_allclose(r.allan_tau_s, av.tau_s)


def test_classical_wv_via_allan_equals_the_mean_square_of_the_pyramid_coefficients():
    """The classical path (AVAR/2 by fogdrift.allan) against the mean of W^2 of the pyramid (which the next test
    checks against PyWavelets); odd length, a random walk and a large offset, to exercise the phase summation."""
    rng = np.random.default_rng(11)
    x = 500.0 + rng.standard_normal(2**15 + 37) + np.cumsum(1e-2 * rng.standard_normal(2**15 + 37))
    r = haar_wvar(x, 0.1)
    ref = [float(np.mean(w * w)) for _, w in haar_coefficients(x - x.mean(), len(r))]
    assert_allclose(r.nu2_dph2, ref, rtol=1e-10)
    assert_allclose(haar_wvar(x, 0.1, nonparametric_var=True).nu2_dph2, ref, rtol=1e-12)


def test_pyramid_equals_pywavelets_swt_non_boundary_coefficients():
    x = np.random.default_rng(7).standard_normal(1024)
    swt = pywt.swt(x, "haar", level=6, trim_approx=False)  # [(cA6, cD6), ..., (cA1, cD1)]
    for j, w in haar_coefficients(x, 6):
        d = swt[6 - j][1] / 2.0 ** (j / 2.0)  # orthonormal -> MODWT scaling; periodic boundary
        assert_allclose(w, -d[: x.size - 2**j + 1], rtol=1e-12, atol=1e-14)


def test_scales_units_and_constant_invariance():
    x = np.random.default_rng(1).standard_normal(4096)
    r = haar_wvar(x, 0.01)
    assert r.level.tolist() == list(range(1, 12))  # floor(log2 N) - 1
    assert_allclose(r.scale_s, 0.01 * 2.0 ** r.level)
    assert_allclose(haar_wvar(x + 1e4, 0.01).nu2_dph2, r.nu2_dph2, rtol=1e-9)
    assert r.unit == "(deg/h)^2"
    json.dumps(r.to_dict(), default=json_default)


def test_multi_axis_is_column_wise():
    x = np.random.default_rng(3).standard_normal((2048, 3)) * [1.0, 2.0, 3.0]
    r = haar_wvar(x, 0.1, axis_names=["gx", "gy", "gz"])
    assert r.nu2_dph2.shape == (len(r), 3) and r.n_axes == 3
    for k, name in enumerate(["gx", "gy", "gz"]):
        one = haar_wvar(x[:, k], 0.1)
        assert_allclose(r.axis(name).nu2_dph2, one.nu2_dph2, rtol=1e-13)
        assert_allclose(r.axis(k).ci_hi95_dph2, one.ci_hi95_dph2, rtol=1e-13)
    with pytest.raises(ConfigError):
        r.axis("q")


# --- robust estimator ---------------------------------------------------------------------
def test_huber_constant_and_efficiency_by_monte_carlo():
    c, delta = huber_scale_constant(0.6)
    # consistency: E min(Z^2, c^2) = delta (numerical integration as an independent check)
    from scipy import integrate, stats

    val = integrate.quad(lambda z: min(z * z, c * c) * stats.norm.pdf(z), -np.inf, np.inf)[0]
    assert_allclose(val, delta, rtol=1e-8)
    # efficiency: variance ratio of mean(W^2) and the robust scale on 400 Gaussian samples of 2000;
    # the ratio of two variance estimates from 400 replicates has a relative SE of about 7 %
    from fogdrift.gmwm.wvar import _robust_level

    rng = np.random.default_rng(11)
    cls, rob = [], []
    for _ in range(400):
        z2 = rng.standard_normal(2000) ** 2
        cls.append(z2.mean())
        rob.append(_robust_level(z2, c, delta))
    ratio = np.var(cls) / np.var(rob)
    assert 0.6 * 0.8 < ratio < 0.6 * 1.2
    assert abs(np.mean(rob) - 1.0) < 0.01


def test_one_gross_outlier_moves_the_classical_wv_but_not_the_robust_one():
    x = np.random.default_rng(5).standard_normal(2**14)
    clean_c = haar_wvar(x, 1.0, levels=8)
    clean_r = haar_wvar(x, 1.0, levels=8, robust=True)
    y = x.copy()
    y[5000] += 1000.0  # one gross outlier (1000 sigma)
    bad_c = haar_wvar(y, 1.0, levels=8)
    bad_r = haar_wvar(y, 1.0, levels=8, robust=True)
    assert np.min(bad_c.nu2_dph2 / clean_c.nu2_dph2) > 10.0  # classical: inflated at every scale
    # robust: the outlier enters tau_j coefficients, each clipped at c^2 s, so the change is
    # bounded by a few times the contaminated fraction tau_j / M_j (0.01 % .. 1.6 % here)
    change = np.abs(bad_r.nu2_dph2 / clean_r.nu2_dph2 - 1.0)
    assert np.all(change < 5.0 * bad_r.tau_samples / bad_r.n_coef)
    assert np.max(change[:4]) < 0.002
    # and on clean Gaussian data the robust WV agrees with the classical one (its SD is
    # sqrt(1/0.6) times larger: at most ~7 % at level 8 here)
    assert np.max(np.abs(clean_r.nu2_dph2 / clean_c.nu2_dph2 - 1.0)) < 0.08
    assert clean_r.robust and clean_r.efficiency == 0.6


def test_nonparametric_variance_is_returned_and_positive():
    x = np.random.default_rng(2).standard_normal(2**12)
    r = haar_wvar(x, 1.0, levels=6, nonparametric_var=True)
    # white noise: Var(nu2_1) = 3 / (4 M) (sum of squared ACVS of W_1 = 1/4 + 2/16)
    assert_allclose(r.var_nonparam_dph4[0] * r.n_coef[0], 0.75, rtol=0.1)
    assert np.all(r.var_nonparam_dph4 > 0)


# --- published curves ----------------------------------------------------------------------
@needs_smac
def test_r4_prime_published_ci_is_the_eta3_ci_for_every_gyro_row():
    rows = _rows("smac_wvar_gyro_reference.csv.gz")
    assert len(rows) == 297
    for r in rows:
        n = int(r["n_samples"])
        tau = round(float(r["scale_s"]) * float(r["sample_rate_hz"]))
        eta = eta3(n - tau + 1, tau)
        lo, hi = eta3_ci(float(r["wvar"]), eta)
        assert_allclose([lo, hi], [float(r["wvar_ci_low"]), float(r["wvar_ci_high"])], rtol=1e-12)


@needs_smac
def test_r5_prime_published_wv_is_half_the_published_avar_at_half_the_scale():
    wv = {(r["sensor_key"], r["axis"], float(r["scale_s"])): float(r["wvar"])
          for r in _rows("smac_wvar_gyro_reference.csv.gz")}
    pairs = 0
    for r in _rows("smac_avar_gyro_reference.csv.gz"):
        key = (r["sensor_key"], r["axis"], 2.0 * float(r["tau_s"]))
        if key in wv:
            assert_allclose(wv[key], float(r["avar"]) / 2.0, rtol=1e-4)
            pairs += 1
    assert pairs == 282


@needs_smac
def test_from_curve_wraps_a_published_table_in_deg_per_hour():
    rows = [r for r in _rows("smac_wvar_gyro_reference.csv.gz") if r["sensor_key"] == "kvh1750" and r["axis"] == "x"]
    r = WvarResult.from_table(
        [float(v["scale_s"]) for v in rows], [float(v["wvar"]) for v in rows],
        n_samples=int(rows[0]["n_samples"]), dt_s=1.0 / float(rows[0]["sample_rate_hz"]),
        ci_low=[float(v["wvar_ci_low"]) for v in rows], ci_high=[float(v["wvar_ci_high"]) for v in rows],
        unit="deg/s",
    )
    assert r.level.tolist() == list(range(1, 19)) and r.source == "table"
    assert_allclose(r.nu2_dph2[0], float(rows[0]["wvar"]) * 3600.0**2)
    lo, hi = eta3_ci(r.nu2_dph2, r.eta3)
    assert_allclose(r.ci_lo95_dph2, lo, rtol=1e-12)
    assert_allclose(r.ci_hi95_dph2, hi, rtol=1e-12)


# --- errors ----------------------------------------------------------------------------------
def test_errors():
    with pytest.raises(DataFormatError):
        haar_wvar([1.0, np.nan, 2.0, 3.0], 1.0)
    with pytest.raises(DataFormatError):
        haar_wvar(np.zeros((2, 2, 2)), 1.0)
    with pytest.raises(InsufficientDataError, match="levels="):
        haar_wvar(np.ones(100), 1.0, levels=7)
    with pytest.raises(InsufficientDataError):
        haar_wvar([1.0], 1.0)
    with pytest.raises(ConfigError):
        haar_wvar(np.ones(100), 0.0)
    with pytest.raises(ConfigError):
        haar_wvar(np.ones(100), 1.0, robust=True, efficiency=1.5)
    with pytest.raises(DataFormatError, match="power-of-two"):
        from_curve([0.003], [1.0], n_samples=1000, dt_s=0.001)
    with pytest.raises(ConfigError):
        from_curve([0.002], [1.0], n_samples=1000, dt_s=0.001, ci_low=[0.5])


def test_compiled_pyramid_equals_numpy_pyramid():
    x = np.random.default_rng(4).standard_normal((70_001, 2)) + [5.0, -3.0]  # > one parallel block
    r = haar_wvar(x, 0.01)
    for k in range(2):
        xm = x[:, k] - x[:, k].mean()
        ref = [float(np.mean(w * w)) for _, w in haar_coefficients(xm, len(r))]
        assert_allclose(r.nu2_dph2[:, k], ref, rtol=1e-12)
