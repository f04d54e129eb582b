"""Interval width of each term of the GMWM against record length, from the estimator's own covariance laws, and
its Monte-Carlo check through the GMWM path of ``fogdrift noise``.

The plan model's terms are the latent processes of :mod:`fogdrift.gmwm.processes` (:data:`LATENT`: Q -> QN,
N -> WN, B -> FLICKER, K -> RW, R -> DR), their natural parameters ``theta`` the inverse of the IEEE-952 reading
of :mod:`fogdrift.gmwm.ieee` (every reading is ``sqrt`` of a variance parameter, R linear in the drift slope:
``theta = (value / reading(1))^2`` or ``value / reading(1)``).  For a record of ``n`` samples the GMWM uses the
Haar scales ``tau = 2^j``, ``j = 1 .. floor(log2 n) - 1`` (:func:`fogdrift.gmwm.wvar.haar_wvar`) with
``n - tau + 1`` coefficients each; on the expected curve of the true model the short-scale scan of
:func:`~fogdrift.gmwm.selection.select_model` excludes none.  Its final step weights with ``Omega = V^-1``,
``V`` the model covariance with the discrepancy allowance (:func:`fogdrift.gmwm.estimator.fit_covariance`), so
(the "Asimov" record: the expected curve fitted)

* ``Cov(z) = (A' V^-1 A)^-1`` with ``A = d nu / d log theta`` (:func:`fogdrift.gmwm.estimator.sandwich`, the
  estimator's own function);
* the 95 % interval of each IEEE term is the one :func:`fogdrift.gmwm.ieee.to_ieee` forms from that ``Cov(z)``
  (log-normal, ``value exp(+-1.96 se)``), and the relative width is ``(hi - lo) / (2 value)``;
* a log-normal interval never reaches zero, so **resolved** is the selection's rule instead: the term's
  component passes the checks of :func:`~fogdrift.gmwm.selection.select_model` that depend on the length, at
  its default thresholds: it changes the WV by at least ``snr_min`` standard deviations at some scale, explains
  at least ``share_min`` of it, and the standard error of its log parameter is at most ``se_log_max``.

The default candidate set of the selection has no FLICKER model (:data:`fogdrift.gmwm.DEFAULT_CANDIDATES`), so
``model="auto"`` never gives B as a term; the plan's GMWM is the fit of the true latent model
(``fogdrift noise --method gmwm --gmwm-model WN+RW+FLICKER``, say), and the Monte-Carlo runs exactly that
(:func:`simulate_gmwm_fits`).
"""

from __future__ import annotations

import math
import warnings
from types import SimpleNamespace

import numpy as np

from ..errors import FogdriftWarning
from ..gmwm.analysis import analyse_gmwm
from ..gmwm.estimator import Whitener, fit_covariance, sandwich
from ..gmwm.ieee import to_ieee
from ..gmwm.processes import PROCESSES, parse_model
from ..gmwm.selection import select_model
from ..simulate import simulate
from .montecarlo import run_seeds

__all__ = ["LATENT", "latent_model", "gmwm_widths", "simulate_gmwm_fits", "SELECTION_CHECKS"]

#: Plan term -> (latent process, key of its IEEE reading in :attr:`fogdrift.gmwm.ieee.IEEEResult.terms`).
LATENT = {"Q": ("QN", "Q_urad"), "N": ("WN", "N_dprh"), "B": ("FLICKER", "B_dph"), "K": ("RW", "K_dphrh"),
          "R": ("DR", "R_dph2")}

#: The selection's length-dependent checks at their defaults (:func:`fogdrift.gmwm.selection.select_model`).
SELECTION_CHECKS = {k: select_model.__kwdefaults__[k] for k in ("snr_min", "share_min", "se_log_max")}


def latent_model(model):
    """``(LatentModel, theta)`` of a :class:`~fogdrift.plan.model.PlanModel`: its terms as latent processes at
    the natural parameters (per sample, rate in deg/h) whose IEEE reading (:mod:`fogdrift.gmwm.ieee`) is the
    model's value.

    Examples
    --------
    >>> from fogdrift.plan import parse_model
    >>> mdl, theta = latent_model(parse_model("N=0.3 deg/sqrt(h), K=20 deg/h^1.5", 0.1))
    >>> mdl.name, [round(float(v), 6) for v in theta]
    ('WN+RW', [3240.0, 0.011111])
    """
    dt = model.dt_s
    comps = {LATENT[t][0]: t for t in model.terms}
    mdl = parse_model("+".join(comps))
    theta = []
    for key in mdl.components:
        t = comps[key]
        one = float(PROCESSES[key].ieee(np.array([1.0]), dt)[LATENT[t][1]])
        power = 1.0 if key == "DR" else 2.0  # the drift reading is linear in its slope, the others sqrt(variance)
        theta.append((float(model.coefficients[t]) / one) ** power)
    return mdl, np.asarray(theta, dtype=np.float64)


def _scales(n: int):
    J = max(1, int(math.floor(math.log2(n))) - 1)
    tau = np.left_shift(1, np.arange(1, J + 1)).astype(np.int64)
    return tau, n - tau + 1


def gmwm_widths(model, n: int) -> dict:
    """Per term of ``model``: ``rel_width`` (expected relative 95 % half-width of the GMWM, inf when not
    estimable), ``se_log`` (standard error of the log of the term), ``snr`` (largest WV of its component over the
    WV's standard deviation), ``share``, ``resolved`` (the length-dependent selection checks pass) and
    ``value``/``lo95``/``hi95`` [term unit]; ``"_fit"``: ``J``, ``tau_max_s`` [s] (the longest Allan time the
    scales cover, half the last scale) and ``model`` (the latent model).  ``n``: record length in samples.
    """
    mdl, theta = latent_model(model)
    dt = model.dt_s
    tau, n_coef = _scales(int(n))
    fit = {"J": int(tau.size), "tau_max_s": float(tau[-1]) * dt / 2.0, "model": mdl.name}
    out = {"_fit": fit}
    empty = {"rel_width": math.inf, "se_log": math.inf, "snr": 0.0, "share": 0.0, "resolved": False,
             "value": None, "lo95": None, "hi95": None}
    if tau.size < mdl.n_params + 2:  # too few scales for the selection to fit the model
        out.update({t: dict(empty) for t in model.terms})
        return out
    V = fit_covariance(mdl, theta, tau, n_coef)
    taus = tau.astype(np.float64)
    A = mdl.wv_jacobian(theta, taus)
    cov, _ = sandwich(A, Whitener(V=V), V)
    z = np.log(theta)
    ie = to_ieee(SimpleNamespace(model=mdl.name, z=z, cov_z=cov, dt_s=dt, n_samples=int(n), tau_samples=tau,
                                 scale_s=taus * dt))
    nu = mdl.wv(theta, taus)
    comp = mdl.wv_components(theta, taus)
    sd = np.sqrt(np.diag(V))
    se_par = np.sqrt(np.maximum(np.diag(cov), 0.0))
    for t in model.terms:
        key, name = LATENT[t]
        i = list(mdl.components).index(key)
        term = ie.terms[name]
        width = (term.hi95 - term.lo95) / (2.0 * term.value) if math.isfinite(term.hi95) else math.inf
        snr = float(np.max(comp[i] / sd))
        share = float(np.max(comp[i] / nu))
        se_p = float(se_par[mdl.slices[i]].max())
        ok = (math.isfinite(width) and snr >= SELECTION_CHECKS["snr_min"]
              and share >= SELECTION_CHECKS["share_min"] and se_p <= SELECTION_CHECKS["se_log_max"])
        out[t] = {"rel_width": float(width), "se_log": float(term.se_log), "snr": snr, "share": share,
                  "resolved": bool(ok), "value": float(term.value), "lo95": float(term.lo95),
                  "hi95": float(term.hi95)}
    return out


def _one(args):
    terms, dt, n, seed, kw, latent = args
    y = simulate(int(n), float(dt), seed=int(seed), **kw)
    with warnings.catch_warnings():  # a seed whose fit fails a check says so in its status, not on the screen
        warnings.simplefilter("ignore", FogdriftWarning)
        got = analyse_gmwm("mc", y, float(dt), model=latent).ieee_terms()
    return {t: (got[t].value, got[t].lo95, got[t].hi95, got[t].status) for t in terms}


def simulate_gmwm_fits(model, n_samples, seeds, workers: int = 1) -> list[dict]:
    """GMWM of ``len(seeds)`` simulated records of ``n_samples`` samples (:func:`fogdrift.simulate.simulate`, as the
    Allan Monte-Carlo): :func:`fogdrift.gmwm.analysis.analyse_gmwm` with the true latent model fixed (the path of
    ``fogdrift noise --method gmwm`` with that model, its spectrum included).  One
    ``{term: (value, lo95, hi95, status)}`` per seed, in seed order, for
    :func:`fogdrift.plan.montecarlo.summarise`.  ``workers > 1``: that many processes."""
    latent = latent_model(model)[0].name
    jobs = [(model.terms, model.dt_s, int(n_samples), int(s), model.simulate_kwargs(), latent) for s in seeds]
    return run_seeds(_one, jobs, workers)
