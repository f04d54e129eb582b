"""The compiled GMWM solver (:mod:`fogdrift.gmwm.solver`) against ``scipy.optimize.least_squares``.

``_Problem.solve`` runs :func:`~fogdrift.gmwm.solver.trf_solve`, a port of ``least_squares(method="trf",
x_scale="jac")`` with the model kernel inside; ``_Problem.solve_scipy`` is the SciPy run.  On seeded problems (white
noise, random walk, Gauss-Markov; diagonal weights and a full V; bounds inactive and active):

* the converged optima agree: the objective to 1e-10 relative, the parameters to 1e-6 where the problem identifies
  them, an active bound at the bound;
* on well-conditioned problems the iteration is SciPy's step for step: the same number of residual evaluations and
  the same objective to 1e-13 (NumPy's vectorised ``exp`` may differ from libm's in the last bit, so not bit for
  bit).  A one-line slip in the port (a dropped Levenberg-Marquardt update, a wrong bound projection, the Jacobian
  scale not kept at its running maximum, a reflection not taken) changes the evaluation count or the optimum;
* where the compiled run hands back undecided (:data:`~fogdrift.gmwm.solver.FALLBACK`), ``solve`` returns SciPy's
  answer.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import optimize

from fogdrift.gmwm import solver
from fogdrift.gmwm.estimator import Whitener, _Problem
from fogdrift.gmwm.processes import parse_model
from fogdrift.gmwm.starts import starts as heuristic_starts

TAU = 2.0 ** np.arange(1, 19)

# (model, true natural parameters): WN, RW, GM (beta per sample, innovation variance)
CASES = [
    ("WN+RW", [1.0, 1e-6]),
    ("WN+GM", [1.0, 1e-3, 1e-4]),
    ("WN+RW+GM", [1.0, 1e-7, 1e-3, 1e-5]),
    ("WN+2GM", [1.0, 2e-2, 1e-3, 1e-4, 1e-6]),
    ("QN+WN+RW+DR+GM", [1e-2, 1.0, 1e-7, 1e-6, 1e-3, 1e-5]),
]


def _problem(model, theta, seed, full_v):
    mdl = parse_model(model)
    rng = np.random.default_rng(seed)
    nu = mdl.wv(np.asarray(theta, dtype=float), TAU) * np.exp(rng.normal(0.0, 0.05, TAU.size))
    if full_v:
        sd = 0.05 * nu
        W = Whitener(V=np.diag(sd**2) + 0.4 * np.outer(sd, sd) * np.exp(-np.abs(np.subtract.outer(
            np.arange(TAU.size), np.arange(TAU.size)))))
    else:
        W = Whitener(weights=1.0 / (0.05 * nu) ** 2)
    return _Problem(mdl, nu, TAU, W)


def _starts(prob, k=3):
    w = prob.W.w**2 if prob.W.C is None else 1.0 / np.diag(prob.W.V)
    return [np.log(s) for s in heuristic_starts(prob.model, prob.nu_hat, prob.tau, w)[:k]]


def _scipy(prob, z0, max_nfev):
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        return optimize.least_squares(prob._fun, prob.clipped(z0), jac=prob._jac, bounds=(prob.lo, prob.hi),
                                      method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=max_nfev,
                                      x_scale="jac")


def _compiled(prob, z0, max_nfev):
    return solver.trf_solve(prob._ev, prob._w, prob._cinv, prob.nu_hat, prob.lo, prob.hi, prob.clipped(z0), max_nfev)


@pytest.mark.parametrize("full_v", [False, True])
@pytest.mark.parametrize("model,theta", CASES)
def test_optima_agree_with_least_squares(model, theta, full_v):
    for seed in (1, 2):
        prob = _problem(model, theta, seed, full_v)
        for z0 in _starts(prob):
            z, q, ok = prob.solve(z0, max_nfev=2000)
            zs, qs, oks = prob.solve_scipy(z0, max_nfev=2000)
            assert ok == oks
            np.testing.assert_allclose(q, qs, rtol=1e-10)
            assert np.all(z >= prob.lo) and np.all(z <= prob.hi)
            if ok:  # the objective is flat along a weakly identified parameter: compare where it is curved
                J = prob.jac(zs)
                curv = np.sqrt(np.sum(J**2, axis=0))
                firm = curv > 1e-3 * curv.max()
                np.testing.assert_allclose(z[firm], zs[firm], rtol=0, atol=1e-5)


# well-conditioned problems: before convergence a rounding difference does not change the path (at convergence the
# ftol test compares reductions of ~1e-16 and may stop one evaluation earlier or later: the optimum is the same).
# Starts far off (every log-parameter shifted by 4) make the first steps trust-region bound, where the Levenberg-
# Marquardt parameter and its update between tries matter.
FAR = (4.0, -4.0)
STEP_CASES = [("WN+RW", [1.0, 1e-6], False, FAR), ("WN+RW+GM", [1.0, 1e-7, 1e-3, 1e-5], False, FAR),
              ("WN+RW+GM", [1.0, 1e-7, 1e-3, 1e-5], True, FAR), ("WN+GM", [1.0, 1e-3, 1e-4], True, FAR),
              ("WN+2GM", [1.0, 2e-2, 1e-3, 1e-4, 1e-6], False, ())]


@pytest.mark.parametrize("model,theta,full_v,shifts", STEP_CASES)
def test_iterations_follow_least_squares_step_for_step(model, theta, full_v, shifts):
    prob = _problem(model, theta, 3, full_v)
    heur = _starts(prob, 2)
    for z0 in heur + [heur[0] + sh for sh in shifts]:
        res = _scipy(prob, z0, 2000)
        x, cost, status, nfev = _compiled(prob, z0, 2000)
        assert (status > 0) == (res.status > 0)
        np.testing.assert_allclose(cost, res.cost, rtol=1e-12)
        # a budget that stops both on the way: the same point after the same evaluations
        for budget in range(2, min(nfev, res.nfev) - 1):
            rb = _scipy(prob, z0, budget)
            xb, cb, sb, nb = _compiled(prob, z0, budget)
            assert (nb, sb) == (rb.nfev, rb.status) == (budget, 0)
            np.testing.assert_allclose(cb, rb.cost, rtol=1e-8)
            np.testing.assert_allclose(xb, rb.x, rtol=0, atol=1e-7)


def _tightened(model, theta, seed, full_v, which, side, by):
    """A problem whose bound ``side`` of parameter ``which`` is moved ``by`` past its unconstrained optimum."""
    prob = _problem(model, theta, seed, full_v)
    z_opt = prob.solve_scipy(_starts(prob, 1)[0])[0]
    lo, hi = prob.lo.copy(), prob.hi.copy()
    if side == "hi":
        hi[which] = z_opt[which] - by
    else:
        lo[which] = z_opt[which] + by
    prob.lo, prob.hi = lo, hi
    return prob


@pytest.mark.parametrize("full_v", [False, True])
@pytest.mark.parametrize("model,theta,which,side", [
    ("WN+RW", [1.0, 1e-6], 0, "hi"), ("WN+RW", [1.0, 1e-6], 1, "lo"),
    ("WN+RW+GM", [1.0, 1e-7, 1e-3, 1e-5], 2, "lo"), ("WN+RW+GM", [1.0, 1e-7, 1e-3, 1e-5], 3, "hi")])
def test_an_active_bound_is_held_as_least_squares_holds_it(model, theta, which, side, full_v):
    """A bound moved past the optimum: both stop on it (the projected and reflected steps of ``select_step``), from
    a start inside and from a start on the opposite bound."""
    prob = _tightened(model, theta, 5, full_v, which, side, 0.5)
    inside = _starts(prob, 1)[0]
    across = inside.copy()
    across[which] = prob.lo[which] if side == "hi" else prob.hi[which]
    bound = prob.hi[which] if side == "hi" else prob.lo[which]
    for z0 in (inside, across):
        res = _scipy(prob, z0, 2000)
        x, cost, status, nfev = _compiled(prob, z0, 2000)
        assert abs(x[which] - bound) < 1e-6 and abs(res.x[which] - bound) < 1e-6
        assert np.all(x >= prob.lo) and np.all(x <= prob.hi)
        np.testing.assert_allclose(cost, res.cost, rtol=1e-10)
        np.testing.assert_allclose(x, res.x, atol=1e-5)
        for budget in range(2, min(nfev, res.nfev) - 1):  # the path to it: the same steps off and along the bound
            rb = _scipy(prob, z0, budget)
            xb, cb, sb, nb = _compiled(prob, z0, budget)
            np.testing.assert_allclose(xb, rb.x, rtol=0, atol=1e-7)


def test_a_run_handed_back_undecided_is_solved_by_least_squares(monkeypatch):
    prob = _problem("WN+RW+GM", [1.0, 1e-7, 1e-3, 1e-5], 6, True)
    z0 = _starts(prob, 1)[0]
    want = prob.solve_scipy(z0, 150)
    import fogdrift.gmwm.estimator as est

    monkeypatch.setattr(est, "trf_solve", lambda *a, **k: (z0, 0.0, solver.FALLBACK, 1))
    z, q, ok = prob.solve(z0, 150)
    assert q == want[1] and ok == want[2] and np.array_equal(z, want[0])


def test_a_non_finite_start_is_handed_back():
    """Residuals that overflow at the start (SciPy raises there): the compiled run does not decide."""
    prob = _problem("WN+RW", [1.0, 1e-6], 7, False)
    z0 = prob.hi.copy()
    prob.nu_hat = prob.nu_hat * 1e300  # W (nu_hat - nu) overflows
    _, _, status, _ = _compiled(prob, z0, 100)
    assert status == solver.FALLBACK
