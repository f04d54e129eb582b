"""GMWM statistics by their definitions (issue 24): the J-test p-value and the WIC.

* J test: ``p = P(chi2_{J - p} > Q)`` with J the number of scales USED and p the number of parameters; the
  reference is the regularised upper incomplete gamma function ``Q(k/2, q/2)`` (``scipy.special.gammaincc``),
  not ``scipy.stats.chi2``; ``Q`` itself is the quadratic form ``d^T V^-1 d`` of the residuals.  Over seeded
  simulations a well-specified fit gives p-values compatible with U(0, 1) (KS test), a misspecified one tiny p.
* WIC: ``WIC = Q + 2 tr(Omega A (A^T Omega A)^-1 A^T Omega V)``, computed here from a finite-difference Jacobian
  of the model's wavelet variance; ``2p`` when ``Omega = V^-1``.  In a selection every candidate is fitted under
  ONE common V, and a nested over-fitted candidate that passes every check and fits only slightly better (by less
  than its extra penalty) ranks below the true model.

Each test names the one-line bug it catches (``tests/deliberate_bugs.py``, block H-tests24).
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy import special, stats

from fogdrift.gmwm import gmwm_fit, haar_wvar, select_model, simulate_latent

N_PARAMS = {"WN": 1, "WN+RW": 2, "WN+GM": 3, "QN+WN+RW": 3}


def _chi2_sf(q, k):
    """P(chi2_k > q) = Q(k/2, q/2), the regularised upper incomplete gamma function."""
    return float(special.gammaincc(k / 2.0, q / 2.0))


@pytest.fixture(scope="module")
def wn_rw():
    return haar_wvar(simulate_latent("WN+RW", [1.0, 1e-5], 2**15, seed=3), 0.01)


@pytest.mark.parametrize("model, scales", [("WN", None), ("WN+RW", None), ("WN+RW", list(range(3, 12))),
                                           ("WN+GM", list(range(2, 13))), ("WN+RW", list(range(1, 9)))])
def test_j_pvalue_is_the_chi2_survival_function_of_q_with_used_scales_minus_params(wn_rw, model, scales):
    """df = (scales used) - (parameters), counted here by hand; p = Q(df/2, q/2).
    Catches: df from every scale of the WV instead of the used ones, df off by one, cdf for sf, q/2 for q."""
    fit = gmwm_fit(wn_rw, model, scales=scales)
    J = len(wn_rw.level) if scales is None else len(scales)
    df = J - N_PARAMS[model]
    assert fit.df == df
    assert_allclose(fit.j_pvalue, _chi2_sf(fit.j_stat, df), rtol=1e-10, atol=1e-300)
    # Q is the quadratic form of the residuals in the final Omega = V^-1 (V with the model-discrepancy allowance);
    # J the same form in the sampling covariance alone, which is V less the allowance at the fitted model
    d = fit.nu2_hat - fit.nu2_fit
    assert_allclose(fit.q, d @ np.linalg.solve(fit.V, d), rtol=1e-6)
    from fogdrift.gmwm.estimator import _model_V
    from fogdrift.gmwm.processes import parse_model
    idx = np.flatnonzero(np.isin(wn_rw.level, fit.level))
    Vs = _model_V(parse_model(model), fit.theta, wn_rw, idx, allowance=False)
    assert_allclose(fit.j_stat, d @ np.linalg.solve(Vs, d), rtol=1e-6)
    assert fit.j_stat >= fit.q * (1 - 1e-9)  # the allowance only ever adds variance


def test_j_pvalue_is_uniform_for_a_well_specified_model_and_tiny_for_a_misspecified_one():
    """80 seeded white-noise records (2^13 samples, 12 scales), model WN: the p-values pass a KS test against
    U(0, 1) (measured KS p = 0.6 at 60 seeds) and their mean is near 1/2; WN fitted to WN + a strong RW gives
    p < 1e-6 on every seed.  Catches a p-value that is not a p-value (cdf, wrong scale of q, wrong df by several)."""
    ps = []
    for s in range(80):
        x = np.random.default_rng(s).standard_normal(2**13)
        ps.append(gmwm_fit(haar_wvar(x, 1.0), "WN").j_pvalue)
    ps = np.array(ps)
    assert stats.kstest(ps, "uniform").pvalue > 0.01, np.sort(ps)
    assert 0.35 < ps.mean() < 0.65 and np.mean(ps < 0.05) < 0.15
    for s in range(5):
        x = simulate_latent("WN+RW", [1.0, 1e-3], 2**13, seed=100 + s)
        assert gmwm_fit(haar_wvar(x, 1.0), "WN").j_pvalue < 1e-6


def _jacobian_log(fit, h=1e-6):
    """d nu / d log(theta) by central differences of the model's wavelet variance."""
    mdl, th, tau = fit.latent_model, np.asarray(fit.theta, float), fit.tau_samples.astype(float)
    cols = []
    for k in range(th.size):
        up, dn = th.copy(), th.copy()
        up[k] *= np.exp(h)
        dn[k] *= np.exp(-h)
        cols.append((mdl.wv(up, tau) - mdl.wv(dn, tau)) / (2 * h))
    return np.column_stack(cols)


def _penalty(A, omega, V):
    return 2.0 * np.trace(omega @ A @ np.linalg.inv(A.T @ omega @ A) @ A.T @ omega @ V)


def test_wic_penalty_by_its_general_formula_with_diagonal_weights(wn_rw):
    """steps=1: Omega = diag(eta3 / (2 nu_hat^2)) (times the efficiency), V the model covariance: the penalty is
    2 tr(Omega A (A^T Omega A)^-1 A^T Omega V), not 2p; WIC = Q + penalty.
    Catches: the penalty taken as 2p (or tr without V), a factor 1 for 2, WIC = Q - penalty or Q alone."""
    for model in ("WN+RW", "WN+GM"):  # measured: penalty 4.22 and 5.42 (WN alone: 2.0006, eta3 ~ V^-1 there)
        fit = gmwm_fit(wn_rw, model, steps=1)
        omega = np.diag(wn_rw.eta3 * wn_rw.efficiency / (2.0 * wn_rw.nu2_dph2**2))
        want = _penalty(_jacobian_log(fit), omega, fit.V)
        assert_allclose(fit.penalty, want, rtol=1e-4)
        assert abs(want - 2 * N_PARAMS[model]) > 0.1  # the case where the general formula matters
        assert_allclose(fit.wic, fit.q + fit.penalty, rtol=1e-12)


def test_wic_penalty_is_2p_under_omega_v_inverse(wn_rw):
    for model in ("WN", "WN+RW", "WN+GM"):
        fit = gmwm_fit(wn_rw, model)
        A = _jacobian_log(fit)
        assert_allclose(fit.penalty, _penalty(A, np.linalg.inv(fit.V), fit.V), rtol=1e-4)
        assert_allclose(fit.penalty, 2 * N_PARAMS[model], rtol=1e-6)
        assert_allclose(fit.wic, fit.q + 2 * N_PARAMS[model], rtol=1e-9)


def test_nested_over_fitted_model_that_fits_slightly_better_ranks_below_the_true_one():
    """WN+RW record (seed 3): QN+WN+RW passes every check and fits better (Q 6.35 vs 7.74: nested, so Q can
    only drop), but by less than its extra penalty 2: its WIC is higher and WN+RW is selected.  Every candidate
    is scored under the same V (the common Omega that makes WIC values comparable).
    Catches: WIC without the penalty, half the penalty, the sign of the penalty, per-candidate V."""
    wv = haar_wvar(simulate_latent("WN+RW", [1.0, 1e-5], 2**15, seed=3), 0.01)
    sel = select_model(wv, ["WN", "WN+RW", "QN+WN+RW"])
    true, over = sel.candidate("WN+RW"), sel.candidate("QN+WN+RW")
    assert true.passed  # (with the model-discrepancy allowance the collapsed QN also fails a check now)
    assert over.q < true.q < over.q + 2.0  # better fit, by less than one extra parameter's penalty
    for c in (true, over):
        assert_allclose(c.penalty, 2 * c.n_params, rtol=1e-6)
        assert_allclose(c.wic, c.q + c.penalty, rtol=1e-12)
        assert_allclose(c.fit.V, sel.fit.V, rtol=0, atol=0)  # one common V for every candidate
    assert over.wic > true.wic and sel.selected == "WN+RW"
