"""Issue 25 (S2): the GMWM selection's speed-ups give the same results by construction.

* :class:`fogdrift.gmwm.processes.WvEvaluator` (the optimiser's WV and Jacobian at fixed scales) makes the same kernel
  call with the same operations as ``LatentModel.wv`` / ``wv_jacobian``: equal bit for bit in the same process (both
  sides computed here, on this CPU, by the same kernel: no stored float is compared), and equal to the closed forms
  of the registry table (hand formulas, independent of the kernel).
* ``_Problem._fun`` / ``_jac`` (what ``least_squares`` calls) equal ``resid`` / ``jac`` bit for bit, for diagonal
  weights and a full V, including the non-finite branches, and return fresh arrays (the optimiser keeps them).
* ``_best_solution`` runs a start equal (once clipped into the bounds) to an earlier one only once, and returns the
  same list as running every start.
* ``allan_checks(sums=)`` hands the plausibility check's Allan sums to the Allan fit (no second octave pass)
  with the same comparison lines, and ``fogdrift noise`` hands them on.
"""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.gmwm import estimator as est
from fogdrift.gmwm.estimator import Whitener, _best_solution, _Problem
from fogdrift.gmwm.processes import WvEvaluator, parse_model

MODELS = ["WN", "WN+RW", "QN+WN+RW+GM", "WN+2GM", "WN+RW+DR+3GM", "QN+WN+RW+DR+FLICKER+2GM"]
TAU = 2.0 ** np.arange(1, 19)


def _thetas(mdl, n, seed):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        th = np.exp(rng.uniform(-16, 2, mdl.n_params))
        for j, name in enumerate(mdl.param_names):
            if name.endswith(".beta"):  # both the small-(m beta) series and the closed form
                th[j] = 10 ** rng.uniform(-8, 1.5)
        yield th


@pytest.mark.parametrize("model", MODELS)
def test_evaluator_equals_the_model_bit_for_bit(model):
    mdl = parse_model(model)
    ev = mdl.evaluator(TAU)
    for th in _thetas(mdl, 60, 7):
        assert np.array_equal(ev.wv(th), mdl.wv(th, TAU))
        assert np.array_equal(ev.jac(th), mdl.wv_jacobian(th, TAU))


def test_evaluator_reproduces_the_closed_forms():
    """WN + RW + DR: sigma2 / tau + gamma2 (tau^2 + 2) / (12 tau) + omega^2 tau^2 / 16 (module table); Jacobian in
    log theta: each variance column its component, the drift column twice its component."""
    mdl = parse_model("WN+RW+DR")
    s2, g2, om = 2.0, 3e-5, 4e-4
    wn, rw, dr = s2 / TAU, g2 * (TAU**2 + 2.0) / (12.0 * TAU), om**2 * TAU**2 / 16.0
    ev = mdl.evaluator(TAU)
    np.testing.assert_allclose(ev.wv(np.array([s2, g2, om])), wn + rw + dr, rtol=1e-14)
    np.testing.assert_allclose(ev.jac(np.array([s2, g2, om])), np.column_stack([wn, rw, 2.0 * dr]), rtol=1e-14)
    # a GM at beta -> WV of an AR(1) (phi = 0.9, unit innovation: module docstring of ar1_wv)
    gm = parse_model("GM").evaluator([2.0, 8.0, 64.0, 1024.0])
    np.testing.assert_allclose(gm.wv(np.array([-np.log(0.9), 1.0])),
                               [0.2631578947, 0.5680840625, 0.9001211711, 0.0949458072], atol=1e-10)


def test_evaluator_needs_one_dimensional_scales():
    from fogdrift.errors import ConfigError

    with pytest.raises(ConfigError, match="1-D"):
        WvEvaluator(parse_model("WN"), np.ones((2, 2)))


def _problems(model):
    mdl = parse_model(model)
    th0 = next(_thetas(mdl, 1, 3))
    nu = mdl.wv(th0, TAU) * np.exp(np.random.default_rng(4).normal(0, 0.05, TAU.size))
    V = np.diag((0.1 * nu) ** 2) + 0.3 * np.outer(0.1 * nu, 0.1 * nu)
    return mdl, [_Problem(mdl, nu, TAU, Whitener(weights=1.0 / nu**2)), _Problem(mdl, nu, TAU, Whitener(V=V))]


@pytest.mark.parametrize("model", MODELS)
def test_optimiser_residuals_and_jacobian_equal_resid_and_jac(model):
    mdl, probs = _problems(model)
    for prob in probs:
        for th in _thetas(mdl, 30, 11):
            z = np.log(th)
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
                assert np.array_equal(prob._fun(z), prob.resid(z))
                assert np.array_equal(prob._jac(z), prob.jac(z))
        # fresh arrays: least_squares keeps the residuals and Jacobian of the current point while it tries others
        z1, z2 = np.log(next(_thetas(mdl, 1, 1))), np.log(next(_thetas(mdl, 1, 2)))
        r1, j1 = prob._fun(z1), prob._jac(z1)
        prob._fun(z2), prob._jac(z2)
        assert np.array_equal(r1, prob.resid(z1)) and np.array_equal(j1, prob.jac(z1))


def test_non_finite_model_values_take_the_same_branches():
    mdl, probs = _problems("WN+GM")
    for prob in probs:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            z = np.array([800.0, 0.0, 0.0])  # sigma2 = inf: the WV is not finite -> residuals 1e10
            assert np.array_equal(prob._fun(z), np.full(TAU.size, 1e10))
            assert np.array_equal(prob._fun(z), prob.resid(z))
            assert np.array_equal(prob._jac(z), prob.jac(z))  # the inf column set to 0 in both
            assert np.all(np.isfinite(prob._jac(z)))


def test_equal_starts_are_run_once_with_the_same_result(monkeypatch):
    mdl, (prob, _) = _problems("WN+RW+GM")
    starts = [np.log(s) for s in est._starts(mdl, prob.nu_hat, prob.tau, prob.W.w**2)[:2]]
    above = prob.hi + 5.0  # clipped to hi - 1e-6 like prob.hi + 1.0: the same run
    runs = [starts[0], starts[1], starts[0].copy(), above, prob.hi + 1.0]
    want = [(q, z, ok) for z, q, ok in (prob.solve(s, max_nfev=150) for s in runs)]
    want.sort(key=lambda s: s[0])
    calls = []
    real = _Problem.solve
    monkeypatch.setattr(_Problem, "solve", lambda self, z0, max_nfev=2000: calls.append(z0) or real(self, z0, max_nfev))
    (q, z, ok), sols = _best_solution(prob, runs, len(runs))
    assert len(calls) == 3 + (0 if want[0][2] else 1)  # three distinct starts (+ the polish of a screened best)
    assert len(sols) == len(runs)
    for (qa, za, oka), (qb, zb, okb) in zip(sols[1:], want[1:]):
        assert qa == qb and oka == okb and np.array_equal(za, zb)
    if want[0][2]:
        assert sols[0][0] == want[0][0] and np.array_equal(sols[0][1], want[0][1])


def _record(n=2**14, seed=5):
    from fogdrift.io import from_array

    rng = np.random.default_rng(seed)
    x = 0.1 * rng.standard_normal((n, 1)) + 1e-3 * np.cumsum(rng.standard_normal((n, 1)), axis=0)
    return from_array(x, dt_s=0.01, unit="deg/h", axis_names=["gx"])


def test_allan_check_reuses_the_plausibility_sums(monkeypatch):
    from fogdrift.allan import _kernels
    from fogdrift.gmwm.analysis import analyse_gmwm
    from fogdrift.workflows.noise import allan_checks
    from fogdrift.plausibility import check_record

    rec = _record()
    axes = [analyse_gmwm("gx", rec.axis("gx"), rec.dt_s, model="WN+RW")]
    want = allan_checks(rec, axes)
    sums = {}
    check_record(rec, sums=sums)
    assert sorted(sums) == ["gx"]
    calls = []
    real = _kernels.operator_sums
    monkeypatch.setattr(_kernels, "operator_sums", lambda p, m, *a: calls.append(m.tolist()) or real(p, m, *a))
    got = allan_checks(rec, axes, sums=sums)
    octave = [2**k for k in range(13)]  # m <= 2^14 / 4
    assert not any(set(c) & set(octave) for c in calls)  # no octave pass again
    assert got == want
    calls.clear()
    allan_checks(rec, axes)  # without sums the octave pass is made
    assert any(set(c) >= set(octave) for c in calls)


def test_noise_command_hands_the_plausibility_sums_to_the_allan_check(monkeypatch, tmp_path):
    from fogdrift.cli import app
    from fogdrift.workflows import noise as compare
    from fogdrift.allan.sums import AllanSums

    rec = _record(2**13)
    path = tmp_path / "log.csv"
    t = np.arange(rec.n_samples) * rec.dt_s
    np.savetxt(path, np.column_stack([t, rec.axis("gx")]), delimiter=",", header="t_s,gx", comments="")
    seen = []
    real = compare.run_allan
    monkeypatch.setattr(compare, "run_allan", lambda record, cfg, **kw: seen.append(kw) or real(record, cfg, **kw))
    res = CliRunner().invoke(app, ["noise", str(path), "--unit", "deg/h", "--model", "WN+RW", "--out",
                                   str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    (kw,) = seen
    assert sorted(kw["sums"]) == ["gx"] and isinstance(kw["sums"]["gx"], AllanSums)
