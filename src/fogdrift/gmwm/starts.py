"""Starting points and parameter bounds of a GMWM fit: deterministic heuristics per latent process.

Each built-in process has its own reference magnitude and start (the value at which it alone reaches the observed
WV at a characteristic scale); a process registered in :mod:`fogdrift.noise.processes` without heuristics of its
own gets the generic rule of :func:`_unit_scale`.  The GMs' starts are placed at each scale's residual peak.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from .processes import PROCESSES, LatentModel, parse_model

__all__ = ["bounds", "starts"]

_GM_PEAK_TAU = 3.785  # WV peak of a GM at tau ~ 3.785 / beta (samples)
_GM_PEAK_HEIGHT = 0.1906  # times the process variance


def _refs(model: LatentModel, nu_hat, tau):
    """Reference magnitude of each natural parameter: the value at which the component alone
    reaches the largest observed WV at some scale (bounds are placed around it)."""
    t = tau
    ref_wn = np.max(t * nu_hat)
    ref_rw = np.max(12.0 * nu_hat * t / (t * t + 2.0))
    refs = []
    for key in model.components:
        if key == "WN":
            refs.append([ref_wn])
        elif key == "QN":
            refs.append([np.max(t * t * nu_hat / 6.0)])
        elif key == "RW":
            refs.append([ref_rw])
        elif key == "DR":
            refs.append([np.max(4.0 * np.sqrt(nu_hat) / t)])
        elif key == "FLICKER":
            refs.append([np.max(nu_hat) / 0.22])
        elif key == "GM":
            refs.append([1.0, max(ref_wn, ref_rw)])
        else:  # a registered process: the value of its first parameter at which it alone reaches the WV somewhere
            refs.append(_unit_scale(model, key, nu_hat, t, np.max))
    return np.concatenate(refs)


def _unit_scale(model: LatentModel, key, nu_hat, tau, pick):
    """Parameters of a registered process (no heuristics of its own): the first parameter scaled so that the process
    alone matches ``pick(nu_hat / its WV at unit parameters)``, the others 1."""
    n = len(PROCESSES[key].params)
    unit = np.asarray(PROCESSES[key].wv(np.ones(n), tau), dtype=np.float64)
    return [float(pick(nu_hat / unit))] + [1.0] * (n - 1)


def bounds(model: LatentModel, nu_hat, tau):
    """Lower and upper bounds of the free parameters (log theta) around each parameter's reference magnitude."""
    ref = np.log(_refs(model, nu_hat, tau))
    lo = ref - 45.0
    hi = ref + 5.0
    for key, sl in zip(model.components, model.slices):
        if key == "GM":
            lo[sl.start] = math.log(1e-3 / tau.max())  # T_c up to 1000 x the largest scale
            hi[sl.start] = math.log(30.0)  # phi = e^-30: white
    return lo, hi


def starts(model: LatentModel, nu_hat, tau, weights) -> list[np.ndarray]:
    """Deterministic heuristic starting points (natural parameters), best first by step-1 Q."""
    J = tau.size
    base = {}
    if model.has("QN"):
        low = slice(0, max(1, J // 2))
        base["WN"] = float(np.min(tau[low] * nu_hat[low]))
        q2 = (nu_hat[0] - base["WN"] / tau[0]) * tau[0] ** 2 / 6.0
        base["QN"] = q2 if q2 > 0 else 0.1 * nu_hat[0] * tau[0] ** 2 / 6.0
    else:
        base["WN"] = float(tau[0] * nu_hat[0])
    if model.has("RW"):
        base["RW"] = float(12.0 * nu_hat[-1] / tau[-1])
    if model.has("DR"):
        base["DR"] = float(2.0 * math.sqrt(nu_hat[-1]) / tau[-1])
    if model.has("FLICKER"):
        base["FLICKER"] = float(np.min(nu_hat) / 0.22 * 0.5)
    for key in model.components:  # a registered process: half the level at which it alone meets the WV
        if key not in base and key != "GM":
            first, *rest = _unit_scale(model, key, nu_hat, tau, np.min)
            base[key] = [0.5 * first, *rest] if rest else 0.5 * first
    fixed_keys = [k for k in model.components if k != "GM"]
    k_gm = model.n_gm

    def assemble(vals: dict, gms):
        th = []
        it = iter(gms)
        for key in model.components:
            v = next(it) if key == "GM" else vals[key]
            th.extend(v if isinstance(v, list) else [v])
        return np.asarray(th, dtype=np.float64)

    def partial(vals):
        tmp = parse_model("+".join(fixed_keys)) if fixed_keys else None
        if tmp is None:
            return np.zeros(J)
        flat = [x for k in tmp.components for x in (vals[k] if isinstance(vals[k], list) else [vals[k]])]
        return tmp.wv(flat, tau)

    variants = [base]
    if model.has("RW") or model.has("QN") or model.has("FLICKER"):
        shrunk = dict(base)
        for k in ("RW", "QN", "FLICKER"):
            if k in shrunk:
                shrunk[k] *= 0.3
        variants.append(shrunk)
    cands = []
    for vals in variants:
        if k_gm == 0:
            cands.append(assemble(vals, []))
            continue
        resid = nu_hat - partial(vals)
        for placement in itertools.combinations(range(J), k_gm):
            gms = []
            for j in placement:
                beta = _GM_PEAK_TAU / tau[j]
                h = resid[j] if resid[j] > 0 else 0.1 * nu_hat[j]
                sp2 = h / (_GM_PEAK_HEIGHT * k_gm)
                u = -math.expm1(-beta)
                gms.append([beta, sp2 * u * (2.0 - u)])
            cands.append(assemble(vals, gms))
    w = np.sqrt(weights)
    scored = []
    ev = model.evaluator(tau)  # the values of model.wv(th, tau), without its per-call overhead (hundreds of starts)
    with np.errstate(over="ignore", invalid="ignore"):
        for th in cands:
            r = w * (nu_hat - ev.wv(th))
            scored.append((float(r @ r), th))
    scored.sort(key=lambda s: s[0])
    return [th for _, th in scored]
