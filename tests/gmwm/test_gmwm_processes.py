"""Latent processes (fogdrift.gmwm.processes) and their simulator (fogdrift.gmwm.simulate).

Independent references: the GMWM notes' R3 table (§7, 10 significant digits), 50-digit
``decimal`` arithmetic of the textbook AR(1) formula (the "numerical trap" of §2), exact
filter-times-ACVS sums in the time domain, ``scipy.integrate.quad`` for the flicker integral, the
§4 worked example, and Monte Carlo with the simulators (tolerances from the replicate counts).
"""

from __future__ import annotations

import math
from decimal import Decimal, getcontext

import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy import integrate

from fogdrift.errors import ConfigError
from fogdrift.gmwm import haar_wvar, simulate_latent
from fogdrift.gmwm.processes import B_FLAT_WV, PROCESSES, ar1_wv, flicker_wv_factor, haar_gain2, parse_model
from fogdrift.simulate import simulate
from fogdrift.units import RATE_UNITS

TAU = np.array([2.0, 8.0, 64.0, 1024.0])


# --- R3 ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("key,theta,expected,rtol", [
    ("WN", [2.0], [1, 0.25, 0.03125, 0.001953125], 1e-12),
    ("QN", [0.5], [0.75, 0.046875, 7.32421875e-4, 2.86102295e-6], 1e-9),
    ("RW", [0.01], [0.0025, 0.006875, 0.053359375, 0.85333496], 1e-8),
    ("DR", [0.1], [0.0025, 0.04, 2.56, 655.36], 1e-12),
    ("GM", [-math.log(0.9), 1.0], [0.2631578947, 0.5680840625, 0.9001211711, 0.0949458072], 1e-9),
    ("GM", [-math.log(0.99999), 1e-6], [2.5000125001e-7, 6.8748687513e-7, 5.3347110317e-6, 8.5007446042e-5], 1e-8),
])
def test_r3_theoretical_wv(key, theta, expected, rtol):
    assert_allclose(PROCESSES[key].wv(np.array(theta), TAU), expected, rtol=rtol)


def _ar1_decimal(beta: float, m: int) -> float:
    getcontext().prec = 60
    phi = (-Decimal(repr(beta))).exp()
    md = Decimal(m)
    num = md * (1 - phi * phi) - 3 * phi + 4 * phi ** (m + 1) - phi ** (2 * m + 1)
    return float(num / (2 * md * md * (1 - phi) ** 2 * (1 - phi * phi)))


def test_ar1_stable_form_against_50_digit_reference():
    worst = 0.0
    for beta in [1e-7, 3e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 0.1, 1.0, 5.0, 30.0]:
        m = 2 ** np.arange(24)
        got = ar1_wv(beta, 1.0, 2.0 * m)
        ref = np.array([_ar1_decimal(beta, int(v)) for v in m])
        worst = max(worst, float(np.max(np.abs(got / ref - 1.0))))
    assert worst < 1e-9
    # the textbook form in double precision fails there (why the stable form exists)
    phi = math.exp(-1e-7)
    m = 4.0
    textbook = (m * (1 - phi**2) - 3 * phi + 4 * phi ** (m + 1) - phi ** (2 * m + 1)) / (2 * m * m * (1 - phi) ** 2 * (1 - phi**2))
    assert abs(textbook / _ar1_decimal(1e-7, int(m)) - 1.0) > 1e-2


def test_ar1_limits():
    phi = 0.7
    assert_allclose(ar1_wv(-math.log(phi), 2.0, 2.0), 2.0 / (2 * (1 + phi)), rtol=1e-13)  # tau = 2
    tau = 2.0 ** np.arange(1, 12)
    assert_allclose(ar1_wv(1e-12, 3.0, tau), PROCESSES["RW"].wv([3.0], tau), rtol=1e-8)  # phi -> 1: RW
    assert_allclose(ar1_wv(40.0, 3.0, tau), 3.0 / tau, rtol=1e-12)  # phi -> 0: WN
    # vectorised over beta equals the scalar path
    betas = np.array([1e-6, 1e-3, 0.5])
    assert_allclose(ar1_wv(betas, 1.0, 64.0), [ar1_wv(b, 1.0, 64.0) for b in betas], rtol=1e-14)


def _haar(m):
    return np.concatenate([np.full(m, 0.5 / m), np.full(m, -0.5 / m)])


@pytest.mark.parametrize("key,theta", [("WN", [1.3]), ("QN", [0.7]), ("RW", [0.2]), ("DR", [0.05]),
                                       ("GM", [-math.log(0.9), 1.0]), ("GM", [-math.log(0.999), 0.01])])
def test_wv_equals_exact_time_domain_filter_sums(key, theta):
    """nu2_j = Var(sum_l h_l x_{t-l}) from the process ACVS (or its increments), j = 1..10."""
    for j in range(1, 11):
        m = 2 ** (j - 1)
        h = _haar(m)
        if key == "WN":
            ref = theta[0] * np.sum(h * h)
        elif key == "QN":  # x = q (e_t - e_{t-1}) sqrt(12 Var U) -> filter (h * [1, -1]) on white q2
            g = np.convolve(h, [1.0, -1.0])
            ref = theta[0] * np.sum(g * g)
        elif key == "RW":  # W = sum_l c_l e_{t-l}, c = cumulative sum of h (finite: sum h = 0)
            c = np.cumsum(h)
            ref = theta[0] * np.sum(c * c)
        elif key == "DR":
            ref = (theta[0] * np.sum(np.arange(2 * m) * h)) ** 2
        else:
            phi = math.exp(-theta[0])
            lag = np.arange(-(2 * m - 1), 2 * m)
            r_h = np.correlate(h, h, mode="full")  # sum_l h_l h_{l+k}
            ref = float(np.sum(r_h * theta[1] / (1 - phi * phi) * phi ** np.abs(lag)))
        assert_allclose(PROCESSES[key].wv(np.array(theta), [2.0 * m]), ref, rtol=1e-9)


def test_haar_gain_integrates_to_the_wv():
    f = np.linspace(0, 0.5, 200001)[1:]
    for m in (1, 3, 16):
        for key, th in (("WN", [1.0]), ("GM", [0.05, 1.0])):
            val = 2.0 * integrate.trapezoid(haar_gain2(f, m) * PROCESSES[key].sdf(np.array(th), f), f)
            assert_allclose(val, PROCESSES[key].wv(np.array(th), [2.0 * m]), rtol=1e-6)


# --- flicker ----------------------------------------------------------------------------------
def test_flicker_factor_against_adaptive_quadrature():
    for m in (1, 2, 3, 8, 100, 128, 129, 256, 1024, 4096):
        f = lambda x, m=m: np.sin(np.pi * x * m) ** 4 / (m * m * np.sin(np.pi * x) ** 2 * x) / np.pi  # noqa: E731
        edges = np.linspace(0, 0.5, 4 * m + 1)
        ref = sum(integrate.quad(f, a, b, epsabs=0, epsrel=1e-13, limit=200)[0] for a, b in zip(edges[:-1], edges[1:]))
        assert_allclose(flicker_wv_factor([2 * m]), ref, rtol=1e-9)
    assert_allclose(flicker_wv_factor([2.0**31]), B_FLAT_WV, rtol=1e-9)
    with pytest.raises(ConfigError):
        flicker_wv_factor([3.0])


def test_flicker_wv_matches_fogdrift_simulate_bias_instability():
    """fogdrift.simulate shapes 1/f noise with one-sided PSD B^2/(pi f) (its own method): the mean
    WV over 40 records must match B^2 c(m) (relative SD of the mean < 3 % at every level used)."""
    B, n, dt = 2.0, 2**14, 0.01
    nus = np.array([haar_wvar(simulate(n, dt, bias_instability_dph=B, seed=s), dt, levels=9).nu2_dph2
                    for s in range(40)])
    theory = PROCESSES["FLICKER"].wv(np.array([B * B]), 2.0 ** np.arange(1, 10))
    se = nus.std(axis=0, ddof=1) / math.sqrt(nus.shape[0])
    assert np.all(np.abs(nus.mean(axis=0) - theory) < 4.0 * se + 0.01 * theory)


# --- simulator ------------------------------------------------------------------------------
@pytest.mark.parametrize("model,theta", [
    ("WN+QN", [1.0, 0.5]),
    ("WN+RW", [1.0, 1e-4]),
    ("GM", [0.01, 1e-2]),
    ("WN+FLICKER", [0.1, 1.0]),
    ("WN+DR", [1.0, 1e-3]),
])
def test_simulator_wv_matches_theory(model, theta):
    mdl = parse_model(model)
    reps = np.array([haar_wvar(simulate_latent(mdl, theta, 2**13, seed=s), 1.0, levels=9).nu2_dph2
                     for s in range(60)])
    theory = mdl.wv(theta, 2.0 ** np.arange(1, 10))
    se = reps.std(axis=0, ddof=1) / math.sqrt(reps.shape[0])
    z = (reps.mean(axis=0) - theory) / np.maximum(se, 1e-12 * theory)
    assert np.max(np.abs(z)) < 4.5, z


def test_simulator_is_seeded_and_components_independent():
    a = simulate_latent("WN+RW", [1.0, 1e-4], 1000, seed=3)
    assert_allclose(a, simulate_latent("WN+RW", [1.0, 1e-4], 1000, seed=3))
    assert not np.allclose(a, simulate_latent("WN+RW", [1.0, 1e-4], 1000, seed=4))
    with pytest.raises(ConfigError):
        simulate_latent("WN", [-1.0], 100, seed=0)


# --- models ---------------------------------------------------------------------------------
def test_parse_model_canonical_names_and_errors():
    assert parse_model("gm+WN+rw").name == "WN+RW+GM"
    assert parse_model("WN+AR1").name == "WN+GM"
    assert parse_model("QN+WN+RW+2GM").n_params == 7
    assert parse_model("arw+bi").name == "WN+FLICKER"
    for bad in ("", "WN+XX", "WN+WN", "7GM", 3):
        with pytest.raises(ConfigError):
            parse_model(bad)


def test_wv_jacobian_against_central_differences():
    mdl = parse_model("QN+WN+RW+DR+FLICKER+2GM")
    th = np.array([0.5, 1.0, 1e-6, 1e-4, 0.01, 0.01, 1e-4, 1e-4, 1e-6])
    tau = 2.0 ** np.arange(1, 15)
    a = mdl.wv_jacobian(th, tau)
    z = np.log(th)
    h = 1e-4
    comp_of = np.concatenate([[k] * (s.stop - s.start) for k, s in enumerate(mdl.slices)])
    num = np.column_stack([
        (mdl.wv_components(np.exp(z + e), tau)[comp_of[i]] - mdl.wv_components(np.exp(z - e), tau)[comp_of[i]]) / (2 * h)
        for i, e in enumerate(np.eye(z.size) * h)])
    beta_cols = [i for i, n in enumerate(mdl.param_names) if n.endswith(".beta")]
    other = [i for i in range(z.size) if i not in beta_cols]
    assert_allclose(a[:, other], num[:, other], rtol=1e-6)
    assert_allclose(a[:, beta_cols], num[:, beta_cols], rtol=1e-3)  # see LatentModel.wv_jacobian


def test_sort_gm_by_decreasing_beta():
    mdl = parse_model("WN+2GM")
    th = np.array([1.0, 1e-4, 2e-6, 0.1, 1e-3])
    cov = np.diag(np.arange(1.0, 6.0))
    th2, cov2 = mdl.sort_gm(th, cov)
    assert th2.tolist() == [1.0, 0.1, 1e-3, 1e-4, 2e-6]
    assert np.diag(cov2).tolist() == [1.0, 4.0, 5.0, 2.0, 3.0]


def test_ieee_mapping_worked_example_of_the_notes():
    """§4 example at fs = 100 Hz with rates in rad/s, converted to deg/h first."""
    f2 = RATE_UNITS["rad/s"] ** 2
    dt = 0.01
    assert_allclose(PROCESSES["WN"].ieee(np.array([1e-6 * f2]), dt)["N_dprh"], 0.3438, rtol=1e-4)
    assert_allclose(PROCESSES["RW"].ieee(np.array([1e-14 * f2]), dt)["K_dphrh"], 12.38, rtol=1e-3)
    assert_allclose(PROCESSES["QN"].ieee(np.array([1e-8 * f2]), dt)["Q_arcsec"], 0.206, rtol=2e-3)
    assert_allclose(PROCESSES["DR"].ieee(np.array([1e-9 * RATE_UNITS["rad/s"]]), dt)["R_dph2"], 74.26, rtol=1e-3)
    gm = PROCESSES["GM"].ieee(np.array([-math.log(0.9999), 1e-12 * f2]), dt)
    assert_allclose(gm["tc_s"], 99.995, rtol=1e-5)
    assert_allclose(gm["sigma_gm_dph"], 14.59, rtol=1e-3)


def _reference_wv_and_jacobian(mdl, th, tau):
    """The model WV and Jacobian composed from the registry's NumPy ``wv`` and :func:`ar1_wv` (the compiled
    kernel of LatentModel must give the same values)."""
    comps, cols = [], []
    for key, sl in zip(mdl.components, mdl.slices):
        p = th[sl]
        comps.append(PROCESSES[key].wv(p, tau))
        if key == "GM":
            h = 1e-3
            cols += [(ar1_wv(p[0] * math.exp(h), p[1], tau) - ar1_wv(p[0] * math.exp(-h), p[1], tau)) / (2 * h),
                     ar1_wv(p[0], p[1], tau)]
        else:
            cols.append((2.0 if key == "DR" else 1.0) * PROCESSES[key].wv(p, tau))
    comps = np.array(comps)
    return comps, comps.sum(axis=0), np.column_stack(cols)


@pytest.mark.parametrize("model", ["WN+RW+GM", "QN+WN+RW+2GM", "WN+DR+3GM", "QN+WN+RW+DR+FLICKER+2GM", "WN+GM"])
def test_compiled_wv_and_jacobian_equal_the_numpy_composition(model):
    """Issue 25: LatentModel.wv / wv_components / wv_jacobian run one compiled kernel (the GMWM optimiser's inner
    loop); same values as the NumPy path, with GMs of different beta (a row mix-up between GMs would show), the
    small-(m beta) series and the closed form both exercised, and a drift (factor 2 in its Jacobian column)."""
    mdl = parse_model(model)
    rng = np.random.default_rng(25)
    tau = 2.0 ** np.arange(1, 22)
    for _ in range(40):
        th = np.exp(rng.uniform(-16, 2, mdl.n_params))
        for j, name in enumerate(mdl.param_names):
            if name.endswith(".beta"):
                th[j] = 10 ** rng.uniform(-8, 1.5)
        comps, total, jac = _reference_wv_and_jacobian(mdl, th, tau)
        assert_allclose(mdl.wv_components(th, tau), comps, rtol=1e-14, atol=0)
        assert_allclose(mdl.wv(th, tau), total, rtol=1e-14, atol=0)
        assert_allclose(mdl.wv_jacobian(th, tau), jac, rtol=1e-12, atol=1e-14 * np.abs(jac).max())
    # one scale, a 0-d tau and a GM whose m beta straddles the 1e-3 series switch
    th = np.array([1.0, 2e-4, 0.5])[: mdl.n_params] if model == "WN+GM" else None
    if th is not None:
        for t in (np.array([8.0]), 8.0):
            assert_allclose(mdl.wv(th, t), _reference_wv_and_jacobian(mdl, th, np.atleast_1d(t))[1].reshape(np.shape(t)),
                            rtol=1e-14)
        t = np.array([8.0, 10.0, 12.0])  # m beta = 8e-4, 1.0e-3, 1.2e-3
        assert_allclose(mdl.wv(th, t), _reference_wv_and_jacobian(mdl, th, t)[1], rtol=1e-14)
