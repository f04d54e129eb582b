"""IEEE-952 noise identification: the term table, unit conversions (method notes 2.3/2.4,
reference R10), exact recovery from noise-free curves of every statistic (each term alone and
all together), the slope read-outs' values, units and labels, statistic dispatch, and ground
truth on seeded simulations.  Coverage, false claims, grid independence and the automatic fit
range are in ``test_noise_selection.py``; the covariance model in ``test_noise_covariance.py``.
(The per-statistic variance laws themselves are verified in ``test_noise_laws.py``.)

Exact single-term curves are built here from the laws written out again (coefficients in the
reported units converted by hand: Q[arcsec] = Q[urad]/4.848137, N*60, K/60, R/3600), so a
wrong constant or unit factor in the library fails the recovery at 1e-6.

Ground-truth protocol (tolerances fixed in advance from the spec, not tuned): 20 seeds of
2^20 samples each, Allan variance with the fast estimator on an octave grid, default fit
(model selection).  Each scenario is built so that every simulated term dominates sigma^2
over at least one decade of tau.  N within 5 % in every seed; a reported Q/K/R within 20 %,
B within 30 %, in >= 16 of 20 seeds; the 95 % interval holds the truth in >= 18 of 20.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from types import SimpleNamespace

import fogdrift.noise as noise_module
from fogdrift import simulate as simulate_module
from fogdrift import units
from fogdrift.allan import IEEE952_ALPHAS, STATISTICS, AllanResult, allan_variance, edf_simple
from fogdrift.errors import ConfigError, InsufficientDataError
from fogdrift.noise import (
    TERM_HEADERS,
    TERM_TABLE,
    TERM_UNITS,
    TERMS,
    VARIANCE_LAWS,
    coefficients_from_A,
    default_terms,
    fit_noise,
    paper_table1_from_A,
    term_spec,
)
from fogdrift.noise.context import flicker_shape
from fogdrift.simulate import simulate

R10_A = [1.27635511e-1, 9.0e-2, 4.412712e-5, 3.7037037e-8, 9.6450617e-11]


# --- conversions ------------------------------------------------------------------------
def test_r10_correct_conversions():
    c = coefficients_from_A(R10_A)
    assert c["Q"] == pytest.approx(1.0, rel=1e-6)
    assert c["Q_arcsec"] == pytest.approx(0.2062648, rel=1e-6)
    for k, v in dict(N=0.005, B=0.01, K=0.02, R=0.05).items():
        assert c[k] == pytest.approx(v, rel=1e-6)


def test_r10_paper_table1_q_is_3_3600sq_too_large():
    c, p = coefficients_from_A(R10_A), paper_table1_from_A(R10_A)
    assert p["Q"] / c["Q"] == pytest.approx(3 * 3600**2, rel=1e-12)
    assert p["Q"] == pytest.approx(3.888e7, rel=1e-3)
    assert p["B"] == pytest.approx(0.0099997, rel=1e-5)
    for k in "NKR":
        assert p[k] == pytest.approx(c[k], rel=1e-12)
    assert p["Q_is_wrong"] == 1.0


@pytest.mark.parametrize("bad", [[1, 2, 3], [1, 2, 3, 4, -1], [1, 2, np.nan, 4, 5]])
def test_conversion_rejects_bad_A(bad):
    with pytest.raises(ConfigError):
        coefficients_from_A(bad)


# --- the term table ---------------------------------------------------------------------
def test_term_table_is_the_one_home():
    assert TERMS == ("Q", "N", "B", "K", "R")
    assert TERM_UNITS == {"Q": "urad", "N": "deg/sqrt(h)", "B": "deg/h", "K": "deg/h^1.5", "R": "deg/h^2"}
    assert TERM_HEADERS == {"Q": "Q [µrad]", "N": "N [deg/√h]", "B": "B [deg/h]", "K": "K [deg/h^1.5]",
                            "R": "R [deg/h²]"}
    assert [TERM_TABLE[t].long_name for t in TERMS] == ["quantization", "angle random walk", "bias instability",
                                                        "rate random walk", "rate ramp"]
    assert [TERM_TABLE[t].avar_power for t in TERMS] == [-2, -1, 0, 1, 2]
    assert [TERM_TABLE[t].suffix for t in TERMS] == ["_urad", "_dprh", "_dph", "_dphrh", "_dph2"]
    assert tuple(TERM_TABLE[t].alpha for t in TERMS[:4]) == IEEE952_ALPHAS
    assert all("IEEE" in TERM_TABLE[t].source for t in TERMS)
    # R10 through the table's conversion, and back
    for t, a, value in zip(TERMS, R10_A, (1.0, 0.005, 0.01, 0.02, 0.05)):
        assert term_spec(t).from_A(a) == pytest.approx(value, rel=1e-6)
        assert term_spec(t).to_A(value) == pytest.approx(a, rel=1e-6)
    with pytest.raises(ConfigError):
        term_spec("X")


def test_shared_constants_live_once():
    assert units.URAD_PER_ARCSEC == pytest.approx(4.84813681109536, rel=1e-14)
    assert units.B_FACTOR == pytest.approx(0.664282, abs=5e-7)
    assert noise_module.B_FACTOR is units.B_FACTOR and simulate_module.B_FLAT_FACTOR is units.B_FACTOR
    assert simulate_module.URAD_PER_ARCSEC is units.URAD_PER_ARCSEC
    assert TERM_TABLE["Q"].to_unit is units.URAD_PER_ARCSEC


def test_every_statistic_has_laws():
    assert set(VARIANCE_LAWS) == set(STATISTICS)
    assert default_terms("adev") == TERMS and default_terms("mdev") == TERMS
    assert default_terms("hdev") == ("Q", "N", "B", "K")
    for stat, laws in VARIANCE_LAWS.items():
        assert all(law.source for law in laws.values()), stat


# --- exact curves -----------------------------------------------------------------------
def _curve(var, tau_s, edf=1e5, statistic="adev", dt_s=None):
    """An AllanResult holding a given (exact) variance curve."""
    tau_s = np.asarray(tau_s, float)
    dev = np.sqrt(var)
    e = np.broadcast_to(np.asarray(edf, float), tau_s.shape).copy()
    return AllanResult(
        tau_s=tau_s, m=np.arange(1, tau_s.size + 1), var=np.asarray(var, float), dev=dev,
        n_terms=np.full(tau_s.size, 10**6), edf=e, dev_lo68=dev, dev_hi68=dev,
        dev_lo95=dev, dev_hi95=dev, noise_alpha=np.zeros(tau_s.size, int),
        estimator="overlapping", edf_rule="test", dt_s=float(tau_s[0]) if dt_s is None else dt_s,
        n_samples=10**13, statistic=statistic,  # noise-free: a record long enough for EDFs of ~1e6 at every tau
    )


def _exact_allan(A, tau_s, edf=1e5):
    tau_s = np.asarray(tau_s, float)
    m = np.arange(1, tau_s.size + 1)  # _curve's averaging factors
    shape = [1, 1, flicker_shape(m), 1, 1]  # sampled flicker is not flat at small m (checked in test_noise_covariance)
    return _curve(sum(a * s * tau_s**p for a, s, p in zip(A, shape, range(-2, 3))), tau_s, edf)


def test_exact_curve_is_recovered():
    tau = np.logspace(-2, 5, 50)
    fit = fit_noise(_exact_allan(R10_A, tau))
    assert fit.selected == TERMS
    assert_allclose(fit.A, R10_A, rtol=1e-4)
    assert fit.terms["N"].value == pytest.approx(0.005, rel=1e-4)
    assert coefficients_from_A(fit.A)["Q_arcsec"] == pytest.approx(0.2062648, rel=1e-4)
    assert all(fit.terms[k].estimable for k in TERMS)
    # model and per-term curves are consistent
    t = np.array([0.1, 10.0, 1e4])
    total = sum(fit.term_adev_dph(k, t) ** 2 for k in TERMS)
    assert_allclose(fit.model_adev_dph(t) ** 2, total, rtol=1e-12)


# Each statistic's law of each term, written out again: sigma^2 for a coefficient X in the Allan-law
# units (rate deg/h, tau and dt in s).
def _law(stat, term, X, tau, dt):
    r2 = (dt / tau) ** 2
    ln2, ln3 = math.log(2), math.log(3)
    table = {
        ("adev", "Q"): 3 * X**2 / tau**2, ("adev", "N"): X**2 / tau,
        ("adev", "B"): 2 * ln2 / math.pi * X**2 + 0 * tau, ("adev", "K"): X**2 * tau / 3,
        ("adev", "R"): X**2 * tau**2 / 2,
        ("hdev", "Q"): 10 / 3 * X**2 / tau**2, ("hdev", "N"): X**2 / tau,
        ("hdev", "B"): (4 * ln2 - 1.5 * ln3) / math.pi * X**2 + 0 * tau, ("hdev", "K"): X**2 * tau / 6,
        ("mdev", "Q"): 3 * X**2 * dt / tau**3, ("mdev", "N"): X**2 / (2 * tau) * (1 + r2),
        ("mdev", "B"): (27 / 8 * ln3 - 4 * ln2) / math.pi * X**2 + 0 * tau,
        ("mdev", "K"): X**2 * tau * (11 / 40 + r2 / 24 + r2**2 / 60), ("mdev", "R"): X**2 * tau**2 / 2,
    }
    return table[(stat, term)]


# reported value, and the same coefficient in the Allan-law units converted by hand
_VALUES = {"Q": (1.0, 1.0 / 4.848136811), "N": (0.005, 0.005 * 60), "B": (0.01, 0.01),
           "K": (0.02, 0.02 / 60), "R": (0.05, 0.05 / 3600)}


@pytest.mark.parametrize("stat, term", [(s, t) for s in ("adev", "hdev", "mdev") for t in TERMS
                                        if (s, t) != ("hdev", "R")])
def test_single_term_curve_recovers_the_value(stat, term):
    dt = 0.05
    tau = dt * np.unique(np.rint(np.logspace(0, 6, 40)))
    value, X = _VALUES[term]
    var = _law(stat, term, X, tau, dt) * (flicker_shape(np.rint(tau / dt), stat) if term == "B" else 1.0)
    curve = _curve(var, tau, statistic=stat, dt_s=dt)
    curve = AllanResult(**{**curve.__dict__, "m": np.rint(tau / dt).astype(int)})
    fit = fit_noise(curve, terms=(term,))
    assert fit.statistic == stat
    assert fit.terms[term].value == pytest.approx(value, rel=1e-5)
    assert fit.terms[term].unit == TERM_UNITS[term]
    # and with all the statistic's terms free, the absent ones stay at zero
    full = fit_noise(curve)
    assert full.terms[term].value == pytest.approx(value, rel=1e-5)


def test_readouts_values_and_units_on_single_term_curves():
    """Q-only: the Q read-out is Q in urad (1.0), not in arcsec (0.206); N-only: N in deg/sqrt(h) (0.005), not
    (deg/h) sqrt(s) (0.3); K and R likewise; each read-out is labelled as lying where its term dominates.
    (The read-outs are IEEE-952's, defined on the Allan deviation.)"""
    dt = 0.01
    tau = dt * np.unique(np.rint(np.logspace(0, 7, 60)))
    for term in ("Q", "N", "K", "R"):
        value, X = _VALUES[term]
        fit = fit_noise(_curve(_law("adev", term, X, tau, dt), tau, dt_s=dt), terms=(term,))
        ro = fit.readouts[term]
        assert ro.value == pytest.approx(value, rel=1e-9), (term, ro)
        assert ro.unit == TERM_TABLE[term].unit and ro.dominated is True and ro.note == ""
        assert all(r.value is None for k, r in fit.readouts.items() if k != term)
    # B from the minimum of a curve with a flat flicker floor between small N and K branches
    value, X = _VALUES["B"]
    var = (_law("adev", "B", X, tau, dt) + _law("adev", "N", 1e-4 * 60, tau, dt) + _law("adev", "K", 1e-4 / 60, tau, dt))
    fit = fit_noise(_curve(var, tau, dt_s=dt), terms=("N", "B", "K"))
    assert fit.readouts["B"].value == pytest.approx(value, rel=0.02) and fit.readouts["B"].unit == "deg/h"
    assert fit.b_min["value"] == pytest.approx(value, rel=0.02) and not fit.b_min["bound_only"]


def test_readouts_on_pure_slopes():
    tau = np.logspace(-1, 5, 40)
    n_only = fit_noise(_exact_allan([0, 0.09, 0, 0, 0], tau), terms=("N", "K"))
    assert n_only.readouts["N"].value == pytest.approx(0.005, rel=1e-9)
    k_only = fit_noise(_exact_allan([0, 0, 0, (0.02 / 60) ** 2 / 3, 0], tau), terms=("N", "K"))
    assert k_only.readouts["K"].value == pytest.approx(0.02, rel=1e-9)
    assert k_only.readouts["B"].value is None  # monotone curve: no minimum to read
    nk = fit_noise(_exact_allan([0, 0.09, 0, (0.02 / 60) ** 2 / 3, 0], tau), terms=("N", "K"))
    assert nk.readouts["B"].value is not None


def test_readout_in_a_transition_says_so():
    """Q + N: a read-out of N taken where Q still dominates is a transition and is labelled as such."""
    tau = np.logspace(-2, 3, 60)
    fit = fit_noise(_exact_allan([3 * 40.0**2, 0.09, 0, 0, 0], tau), terms=("Q", "N"))
    for ro in fit.readouts.values():
        if ro.value is not None and ro.term in ("Q", "N"):
            parts = {t: float(fit.term_adev_dph(t, [ro.tau_s])[0]) ** 2 for t in ("Q", "N")}
            assert ro.dominated == (parts[ro.term] >= 0.5 * sum(parts.values()))


# --- ground truth on simulations --------------------------------------------------------
SCENARIOS = {
    # name: (dt_s, simulate kwargs, {term: (true value, relative tolerance)})
    "QNB": (0.01, dict(q_urad=0.5, arw_dprh=0.01, bias_instability_dph=0.3),
            dict(Q=(0.5, 0.2), N=(0.01, 0.05), B=(0.3, 0.3))),
    "NBK": (0.1, dict(arw_dprh=0.005, bias_instability_dph=0.26, rrw_dphrh=1.0),
            dict(N=(0.005, 0.05), B=(0.26, 0.3), K=(1.0, 0.2))),
    "NK": (0.1, dict(arw_dprh=0.005, rrw_dphrh=0.3), dict(N=(0.005, 0.05), K=(0.3, 0.2))),
    "NR": (0.1, dict(arw_dprh=0.005, ramp_dph2=2.0), dict(N=(0.005, 0.05), R=(2.0, 0.2))),
}


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_ground_truth_recovery_20_seeds(name):
    """Default fit (model selection), fast estimator: N within 5 % in every seed; every term's 95 % interval
    holds the truth in >= 18 of 20 seeds; a reported value is within its tolerance in >= 16 of 20."""
    dt, kw, truth = SCENARIOS[name]
    covered = {k: 0 for k in truth}
    close = {k: 0 for k in truth}
    for seed in range(20):
        y = simulate(2**20, dt, seed=seed, **kw)
        fit = fit_noise(allan_variance(y, dt, estimator="fast"))
        assert fit.terms["N"].value == pytest.approx(truth["N"][0], rel=0.05), seed
        for k, (true, tol) in truth.items():
            term = fit.terms[k]
            covered[k] += (term.lo95 or 0.0) <= true <= term.hi95
            close[k] += term.value is not None and abs(term.value / true - 1) <= tol
    assert all(c >= 18 for c in covered.values()), covered
    assert all(c >= 16 for c in close.values()), close


def test_short_record_flags_long_tau_terms():
    """A 30 s log cannot give B or K: no value, a reason naming the record length, an upper bound."""
    y = simulate(3000, 0.01, arw_dprh=0.005, bias_instability_dph=0.01, rrw_dphrh=0.02, seed=1)
    fit = fit_noise(allan_variance(y, 0.01))
    assert fit.terms["N"].resolved and fit.terms["N"].value == pytest.approx(0.005, rel=0.1)
    for k, true in (("B", 0.01), ("K", 0.02)):
        t = fit.terms[k]
        assert not t.estimable and t.value is None and t.status == "absent"
        assert t.reason.startswith("not in the model") and ("longer record" in t.reason or "no sign" in t.reason)
        assert t.hi95 is not None and t.hi95 > true


def test_selected_terms_and_serialisation():
    y = simulate(2**16, 0.1, arw_dprh=0.01, rrw_dphrh=0.5, seed=4)
    fit = fit_noise(allan_variance(y, 0.1), terms=("K", "N"))
    assert fit.fitted_terms == ("N", "K") and fit.candidates[0]["terms"] == ["N", "K"]
    assert fit.A[0] == 0 and fit.A[2] == 0 and fit.A[4] == 0
    for k in "QBR":
        assert fit.terms[k].value is None and "not fitted" in fit.terms[k].reason
    d = json.loads(json.dumps(fit.to_dict()))
    assert d["terms"]["N"]["unit"] == "deg/sqrt(h)" and d["fit"]["dof"] == fit.dof
    assert {"chi2_red", "p_value", "quality", "tau_min_s", "tau_max_s", "points"} <= set(d["fit"])
    assert fit.terms["Q"].unit == "urad"


def test_fit_validation():
    r = allan_variance(np.random.default_rng(0).normal(size=64), 1.0)  # 5 octave taus
    with pytest.raises(ConfigError):
        fit_noise(r, terms=("N", "X"))
    with pytest.raises((ConfigError, AttributeError)):
        fit_noise("not an allan result")
    with pytest.raises(InsufficientDataError, match="at least"):
        fit_noise(r, tau_range_s=(1.0, 2.0))
    assert math.isfinite(fit_noise(r, terms=("N",)).terms["N"].value)


def test_statistic_dispatch():
    y = simulate(2**16, 0.1, arw_dprh=0.01, rrw_dphrh=0.5, ramp_dph2=5.0, seed=6)
    h = allan_variance(y, 0.1, statistic="hdev")
    with pytest.raises(ConfigError, match="Hadamard variance cancels") as err:
        fit_noise(h, terms=("N", "K", "R"))
    assert "terms=" in str(err.value) and "--terms" in err.value.render({"terms": "--terms"})
    fit = fit_noise(h)
    assert set(fit.fitted_terms) <= {"Q", "N", "B", "K"} and fit.statistic == "hdev"
    assert fit.terms["R"].status == "not_estimable" and "Hadamard" in fit.terms["R"].reason
    assert fit.terms["N"].value == pytest.approx(0.01, rel=0.05)
    d = json.loads(json.dumps(fit.to_dict()))
    assert d["statistic"] == "hdev" and d["dt_s"] == 0.1
    # dispatch is on the statistic field, not on the class
    duck = SimpleNamespace(statistic="hdev", tau_s=h.tau_s, var=h.var, dev=h.dev,
                           dev_hi95=h.dev_hi95, m=h.m, n_samples=h.n_samples, dt_s=h.dt_s)
    assert fit_noise(duck).terms["N"].value == fit.terms["N"].value
    with pytest.raises(ConfigError, match="statistic"):
        fit_noise(SimpleNamespace(statistic="tdev", tau_s=h.tau_s, var=h.var, dev_hi95=h.dev_hi95,
                                  m=h.m, n_samples=h.n_samples, dt_s=0.1))


def test_model_curves_across_statistics():
    """A modified-Allan fit implies an Allan curve: the same coefficients through the AVAR laws."""
    dt = 0.1
    tau = dt * np.unique(np.rint(np.logspace(0, 6, 50)))
    X = {t: _VALUES[t][1] for t in TERMS}
    m = np.rint(tau / dt)
    var = sum(_law("mdev", t, X[t], tau, dt) * (flicker_shape(m, "mdev") if t == "B" else 1.0) for t in TERMS)
    curve = _curve(var, tau, statistic="mdev", dt_s=dt)
    fit = fit_noise(AllanResult(**{**curve.__dict__, "m": m.astype(int)}))
    flat = sum(_law("mdev", t, X[t], tau, dt) for t in TERMS)  # the model curve uses the asymptotic B law
    assert_allclose(fit.model_dev_dph(tau) ** 2, flat, rtol=1e-4)
    t = np.array([0.1, 30.0, 1e4])
    assert_allclose(fit.model_adev_dph(t) ** 2, sum(_law("adev", k, X[k], t, dt) for k in TERMS), rtol=1e-5)
    assert_allclose(fit.term_adev_dph("K", t) ** 2, _law("adev", "K", X["K"], t, dt), rtol=1e-5)
    # a term the target statistic cannot see contributes nothing to it
    assert_allclose(fit.term_dev_dph("R", t, "hdev"), 0.0)
    # an Allan fit's model is sum_n A_n tau^n, as before
    afit = fit_noise(_exact_allan(R10_A, tau))
    assert_allclose(afit.model_adev_dph(t) ** 2, sum(a * t**p for a, p in zip(R10_A, range(-2, 3))), rtol=1e-4)


def test_readouts_ignore_rising_pieces_left_of_the_minimum():
    """A vibration bump (3 Hz) makes the ADEV rise at tau ~ 0.1 s; that is not rate random walk or ramp,
    so the K and R read-outs stay empty, while N is still read off the -1/2 line."""
    dt = 0.01
    n = 2**18
    rng = np.random.default_rng(7)
    t = np.arange(n) * dt
    y = simulate(n, dt, arw_dprh=0.05, seed=3) + 200.0 * np.sin(2 * np.pi * 3.0 * t + rng.uniform(0, 6.28))
    fit = fit_noise(allan_variance(y, dt))
    assert fit.readouts["K"].value is None
    assert fit.readouts["R"].value is None
    assert fit.readouts["N"].value == pytest.approx(0.05, rel=0.15)
    # and the fit leaves the bump out, saying what it is
    assert fit.excluded and "bump" in fit.excluded[0]["reason"]
