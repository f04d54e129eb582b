"""Covariance of WV estimates (fogdrift.gmwm.covariance), and of AVAR estimates (fogdrift.noise.covariance, its one home).

Independent references: (1) exact time-domain sums ``int |H_a H_b|^2 S^2 = sum_k c_k^2`` with ``c``
the convolution of the two filters (and of the RW/AR(1) impulse responses); (2) the exact
finite-sample covariance of the sums of squares of Gaussian white noise filtered by explicit
matrices; (3) Monte Carlo with 200 seeded replicates of the notes' §1(b) design (WN sigma2 = 1, RW
gamma2 = 1e-6, AR(1) phi = 0.995, sigma2 = 2.5e-4, N = 2^16), using fogdrift.allan for the Allan
variances (about 10 s).  Tolerances for (3) follow from the replicate count: the relative SE of a
sample SD from R = 200 replicates is about 1/sqrt(2R) = 5 % (6-7 % with the excess kurtosis of
the long scales), that of a correlation about (1 - rho^2)/sqrt(R) = 0.05; per-scale bounds are
about 4 SE, the bounds on averages over scales about 3 SE of the average.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.signal import lfilter

from fogdrift.allan import allan_variance
from fogdrift.errors import ConfigError
from fogdrift.gmwm import haar_wvar, parse_model, simulate_latent
from fogdrift.gmwm.covariance import (
    filter_gram, model_wvar_covariance, wvar_covariance,
)
from fogdrift.gmwm.processes import PROCESSES
from fogdrift.noise.covariance import estimator_covariance

MC_MODEL = "WN+RW+GM"
MC_THETA = [1.0, 1e-6, -math.log(0.995), 2.5e-4]
MC_N = 2**16
MC_R = 200


def _haar(m):
    return np.concatenate([np.full(m, 0.5 / m), np.full(m, -0.5 / m)])


def _exact_gram(ms, kind, par):
    n = len(ms)
    out = np.zeros((n, n))
    for a in range(n):
        for b in range(n):
            ha, hb = _haar(ms[a]), _haar(ms[b])
            if kind == "WN":
                c = np.convolve(ha, hb) * par
            elif kind == "RW":
                c = np.convolve(np.cumsum(ha), np.cumsum(hb)) * par
            else:  # AR(1) twice: c = (ha * hb) filtered by 1/(1 - phi z)^2, `extra` lags of decay kept
                phi, s2, extra = par
                c0 = np.zeros(ha.size + hb.size - 1 + extra)
                hh = np.convolve(ha, hb)
                c0[: hh.size] = hh
                c = lfilter([1.0], [1.0, -phi], lfilter([1.0], [1.0, -phi], c0)) * s2
            out[a, b] = 0.5 * np.sum(c * c)
    return out


@pytest.mark.parametrize("kind,par,sdf", [
    ("WN", 1.0, lambda f: np.ones_like(f)),
    ("RW", 1.0, lambda f: PROCESSES["RW"].sdf(np.array([1.0]), f)),
    ("AR", (0.9, 1.0, 400), lambda f: PROCESSES["GM"].sdf(np.array([-math.log(0.9), 1.0]), f)),
    ("AR", (0.999, 1.0, 40000), lambda f: PROCESSES["GM"].sdf(np.array([-math.log(0.999), 1.0]), f)),
])
def test_gram_against_exact_time_domain_sums(kind, par, sdf):
    ms = [1, 2, 3, 4, 8, 10, 16, 30, 64, 100]  # octave and non-octave half-widths
    exact = _exact_gram(ms, kind, par)
    assert_allclose(filter_gram(ms, sdf), exact, rtol=1e-5)
    assert_allclose(filter_gram(ms, sdf, ratio=1.01), exact, rtol=2e-7)


def test_finite_sample_covariance_uses_the_larger_count():
    """Exact Cov(nu2_a, nu2_b) for Gaussian WN with N = 1024: 2 ||F_a F_b^T||_F^2 / (M_a M_b).
    The large-M formula with max(M_a, M_b) is within 4 % up to level 7, the geometric mean of
    the notes overstates the cross-covariances of the long scales by up to 33 %."""
    n, J = 1024, 9
    F = []
    for j in range(1, J + 1):
        tau = 2**j
        h = _haar(tau // 2)
        m = n - tau + 1
        Fj = np.zeros((m, n))
        for i in range(m):
            Fj[i, i:i + tau] = h[::-1]
        F.append(Fj)
    exact = np.array([[2.0 * np.sum((F[a] @ F[b].T) ** 2) / (F[a].shape[0] * F[b].shape[0])
                       for b in range(J)] for a in range(J)])
    tau = 2 ** np.arange(1, J + 1)
    V = wvar_covariance(tau, n - tau + 1, lambda f: np.ones_like(f))
    ratio = V / exact
    assert np.all(np.abs(ratio[:7, :7] - 1.0) < 0.04)
    M = (n - tau + 1).astype(float)
    geo = V * np.maximum.outer(M, M) / np.sqrt(np.outer(M, M))
    assert np.abs(np.diag(geo / exact, 1)[-1] - 1.0) > 0.3 > np.abs(np.diag(ratio, 1)[-1] - 1.0)


@pytest.fixture(scope="module")
def monte_carlo():
    levels = 13
    m_allan = [1, 3, 10, 30, 100]
    nus, avs, vnp = [], [], []
    for s in range(MC_R):
        x = simulate_latent(MC_MODEL, MC_THETA, MC_N, seed=20_000 + s)
        r = haar_wvar(x, 1.0, levels=levels, nonparametric_var=s < 40)
        nus.append(r.nu2_dph2)
        if s < 40:
            vnp.append(r.var_nonparam_dph4)
        avs.append(allan_variance(x, 1.0, taus=m_allan).avar_dph2)
    return np.array(nus), np.array(avs), np.array(vnp), levels, m_allan


def _corr(c):
    d = np.sqrt(np.diag(c))
    return c / np.outer(d, d)


def test_wv_covariance_against_monte_carlo(monte_carlo):
    nus, _, _, levels, _ = monte_carlo
    tau = 2 ** np.arange(1, levels + 1)
    V = model_wvar_covariance(MC_MODEL, MC_THETA, tau, MC_N - tau + 1)
    nu = parse_model(MC_MODEL).wv(MC_THETA, tau)
    assert_allclose(nus.mean(axis=0), nu, rtol=0.1)  # unbiased (SE of the mean < 2 %)
    ratio = nus.std(axis=0, ddof=1) / np.sqrt(np.diag(V))
    assert np.all(np.abs(ratio - 1.0) < 0.25)
    assert abs(np.mean(np.log(ratio))) < 0.06
    c_mc, c_model = np.corrcoef(nus.T), _corr(V)
    for k in (1, 2):
        diff = np.diag(c_mc, k) - np.diag(c_model, k)
        assert np.all(np.abs(diff) < 0.18) and abs(diff.mean()) < 0.05
    # eta3 is conservative: it overstates the SD from level 5 on (notes: 1.15-1.7x)
    eta_sd = nu * np.sqrt(2.0 / np.maximum((MC_N - tau + 1) / tau, 1.0))
    assert np.all(eta_sd[4:] > 1.1 * nus.std(axis=0, ddof=1)[4:])


def test_allan_covariance_of_fogdrift_noise_at_non_octave_m_against_monte_carlo(monte_carlo):
    """The AVAR covariance has one home, fogdrift.noise.covariance; checked here on a latent model it never sees
    (WN+RW+GM) at non-octave m."""
    _, avs, _, _, m = monte_carlo
    sdf = parse_model(MC_MODEL).sdf(MC_THETA)
    V = estimator_covariance(m, MC_N, sdf)
    assert_allclose(avs.mean(axis=0), parse_model(MC_MODEL).avar(MC_THETA, m), rtol=0.05)
    ratio = avs.std(axis=0, ddof=1) / np.sqrt(np.diag(V))
    assert np.all(np.abs(ratio - 1.0) < 0.25)
    assert abs(np.mean(np.log(ratio))) < 0.08
    diff = np.diag(np.corrcoef(avs.T), 1) - np.diag(_corr(V), 1)  # neighbouring m: 1-3, 3-10, 10-30, 30-100
    assert np.all(np.abs(diff) < 0.18)


def test_nonparametric_variance_is_unbiased_on_average(monte_carlo):
    nus, _, vnp, _, _ = monte_carlo
    # mean of 40 nonparametric estimates against the MC variance of 200 replicates (SE ~ 10 %)
    ratio = vnp.mean(axis=0) / nus.var(axis=0, ddof=1)
    assert np.all(np.abs(ratio[:10] - 1.0) < 0.35)
    assert abs(np.mean(np.log(ratio[:10]))) < 0.15


def test_filter_gram_refuses_m_below_one():
    with pytest.raises(ConfigError):
        filter_gram([0, 1], lambda f: np.ones_like(f))


def test_psd_and_cache_reuse():
    tau = 2 ** np.arange(1, 18)
    M = 2**18 - tau + 1
    mdl = parse_model("WN+RW+2GM")
    V1 = model_wvar_covariance(mdl, [1.0, 1e-7, 0.01, 1e-4, 1e-4, 1e-7], tau, M)
    V2 = model_wvar_covariance(mdl, [2.0, 1e-7, 0.01, 1e-4, 1e-4, 1e-7], tau, M)  # cached plan
    assert np.linalg.eigvalsh(_corr(V1)).min() > 0
    assert not np.allclose(V1, V2)
    assert_allclose(np.diag(wvar_covariance(tau, M, mdl.sdf([1.0, 1e-7, 0.01, 1e-4, 1e-4, 1e-7]), diagonal=True)),
                    np.diag(V1), rtol=1e-12)


def test_fourth_cumulant_term_for_uniform_quantization_noise():
    """QN from uniform rounding (excess kurtosis -1.2): 400 replicates, N = 2^14.  The Gaussian
    formula overstates the SD by about 20 % and the adjacent correlation (0.40 vs about 0.13);
    the model covariance with the fourth-cumulant term matches (SE of an SD ratio 3.5 %, of a
    correlation 0.05)."""
    n, levels = 2**14, 6
    nus = np.array([haar_wvar(simulate_latent("QN", [1.0], n, seed=30_000 + s), 1.0, levels=levels).nu2_dph2
                    for s in range(400)])
    tau = 2 ** np.arange(1, levels + 1)
    M = n - tau + 1
    V = model_wvar_covariance("QN", [1.0], tau, M)
    V_gauss = wvar_covariance(tau, M, parse_model("QN").sdf([1.0]))
    sd = nus.std(axis=0, ddof=1)
    assert np.all(np.abs(sd / np.sqrt(np.diag(V)) - 1.0) < 0.12)
    assert np.all(sd / np.sqrt(np.diag(V_gauss)) < 0.92)
    adj = np.diag(np.corrcoef(nus.T), 1)
    assert np.all(np.abs(adj - np.diag(_corr(V), 1)) < 0.15)
    assert np.all(adj < np.diag(_corr(V_gauss), 1) - 0.1)
