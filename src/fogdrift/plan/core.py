"""The plan: for each target term, the record length at which the Allan fit resolves it and at which its 95 %
interval reaches the requested relative half-width (analytic, :mod:`.analytic`), checked by Monte-Carlo
(:mod:`.montecarlo`), the same for the GMWM (:mod:`.gmwm`); and what a record of a stated length supports."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError
from ..noise.terms import TERM_TABLE
from .analytic import analytic_widths
from .gmwm import gmwm_widths, simulate_gmwm_fits
from .model import fmt_length
from .montecarlo import MC_MAX_SAMPLES, simulate_fits, summarise
from .spread import SPREAD_DRAWS, share_ratio

__all__ = ["Plan", "make_plan", "MAX_LENGTH_S", "RECORD_SHARE", "SHARE_ALLOWANCE", "crossing", "ESTIMATORS"]

#: The estimators a plan is made for: the Allan fit (:mod:`.analytic`) and the GMWM (:mod:`.gmwm`).
ESTIMATORS = ("allan", "gmwm")

#: Longest record the planner looks at [s] (30 days).
MAX_LENGTH_S = 30 * 86400.0
_MIN_SAMPLES = 64
_STEP = 2.0**0.5  # grid of record lengths: half an octave

#: Share of records that must reach the target width at ``share_s`` (the median record reaches it at ``target_s``).
RECORD_SHARE = 0.8
#: Allowance on the 80 % width for what the linearised records (:mod:`.spread`) do not hold: ``share_s`` is the
#: length at which ``w_share * share_ratio * (1 + SHARE_ALLOWANCE)`` reaches the target.  Without it, simulated
#: records of the MEMS class of docs/plan.md reached its B target at ``share_s`` in 928 of 1 200 seeds (77.3 %): the
#: records' own 80 % width is about 2.5 % above the plan's there (docs/plan.md, "The allowance").
SHARE_ALLOWANCE = 0.03
_SHARE_ITER = 6  # secant steps at most for share_s, to a relative change of the length below _SHARE_TOL
_SHARE_TOL = 0.005


def crossing(x, y, level):
    """First ``x`` where ``y`` (sampled at increasing ``x``) falls to ``level`` or below, log-log interpolated
    between the grid points around it; None if it never does; ``x[0]`` if it starts there.

    Examples
    --------
    >>> crossing([1.0, 4.0], [2.0, 1.0], 1.5) == 2 ** (2 * __import__("math").log2(2 / 1.5))
    True
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = np.flatnonzero(y <= level)
    if ok.size == 0:
        return None
    i = int(ok[0])
    if i == 0:
        return float(x[0])
    y0, y1 = y[i - 1], y[i]
    if not math.isfinite(y0):
        return float(x[i])
    f = (math.log(y0) - math.log(level)) / (math.log(y0) - math.log(y1))
    return float(math.exp(math.log(x[i - 1]) + f * (math.log(x[i]) - math.log(x[i - 1]))))


@dataclass
class Plan:
    """Result of :func:`make_plan` (lengths in s; widths are relative 95 % half-widths, 0.1 = +-10 %).

    ``terms``: term -> ``target`` (width asked), ``resolved_s`` (length from which the median record resolves it),
    ``target_s`` (length at which its expected width reaches the target; None: not within
    :data:`MAX_LENGTH_S`), ``share_s`` (length at which :data:`RECORD_SHARE` of the records reach it: the share
    union's width times ``share_ratio``, the ratio of the share's quantile to the median over linearised records,
    :func:`~fogdrift.plan.spread.share_ratio`, and ``1 +`` :data:`SHARE_ALLOWANCE`; both None in a plan of the GMWM
    alone), ``floor_width``
    (width at :data:`MAX_LENGTH_S`), ``mc`` (Monte-Carlo at ``target_s``: median width, fractions, coverage, seeds,
    and ``length_s``, the length the measured width implies) and ``mc_share`` (Monte-Carlo at ``share_s``).
    ``grid``: the analytic curve (``length_s`` and each term's width). ``at_length``: what ``length_s`` supports.
    With the GMWM among ``estimators``, each term also holds ``gmwm``: ``target_s``, ``resolved_s``,
    ``floor_width`` and ``mc`` as above for the GMWM (:mod:`.gmwm`; no ``share_s``), and ``grid["gmwm_width"]``
    its curve.
    """

    model: object
    targets: dict
    terms: dict
    grid: dict
    at_length: dict | None = None
    seeds: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    estimators: tuple = ESTIMATORS

    def _mc_text(self, mc) -> str:
        s = (f"Monte-Carlo {mc['n_seeds']} seeds at that length: median ±{100 * mc['median_width']:.3g} %"
             if math.isfinite(mc["median_width"]) else
             f"Monte-Carlo {mc['n_seeds']} seeds at that length: resolved in fewer than half")
        s += f", coverage {100 * mc['coverage']:.0f} %"
        if mc.get("length_s"):
            s += f" (implies {fmt_length(mc['length_s'])})"
        return s

    def _gmwm_text(self, t, g, w, head: bool) -> str:
        """The GMWM's part of a term's line (``head``: the line starts with it)."""
        name = f"GMWM {g['model']}" if head else "GMWM"
        if g["target_s"] is not None:
            s = f"{fmt_length(g['target_s'])} ({name})"
        elif math.isfinite(g["floor_width"]):
            s = f"not within {fmt_length(MAX_LENGTH_S)} ({name}: ±{100 * g['floor_width']:.3g} % or wider)"
        else:
            s = f"not resolved within {fmt_length(MAX_LENGTH_S)} ({name})"
        return s

    def _gmwm_tail(self, t, g) -> str:
        s = ""
        if g.get("mc"):
            s += f"; GMWM {self._mc_text(g['mc'])}"
        if g["resolved_s"] is not None:
            s += f"; {t} resolved from {fmt_length(g['resolved_s'])} (GMWM)"
        return s

    def lines(self) -> list[str]:
        """The first-screen lines: one per target term, then the stated length's."""
        out = []
        for t, r in self.terms.items():
            w = f"±{100 * r['target']:.3g} %"
            g = r.get("gmwm")
            if "allan" not in self.estimators:
                out.append(f"{t} to {w}: {self._gmwm_text(t, g, w, True)}" + self._gmwm_tail(t, g))
                continue
            share = r["target_s"] is not None  # the length to record first: four records in five reach the width
            if share:
                most = f"{100 * RECORD_SHARE:.0f} % of records"
                if r.get("share_s") is not None:
                    s = f"{t} to {w}: {fmt_length(r['share_s'])} for {most} (Allan fit"
                    ms = r.get("mc_share")
                    if ms:
                        s += f"; {round(ms['met_fraction'] * ms['n_seeds'])} of {ms['n_seeds']} seeds reach {w} there"
                elif math.isfinite(r.get("share_ratio") or math.inf):
                    s = f"{t} to {w}: not within {fmt_length(MAX_LENGTH_S)} for {most} (Allan fit"
                else:
                    s = (f"{t} to {w}: not found for {most} (Allan fit; fewer than {most} resolve {t} at the median "
                         "length")
                s += f"); the median record: {fmt_length(r['target_s'])} (Allan fit)"
            else:
                s = f"{t} to {w}: "
            if r["target_s"] is not None:
                s += "" if share else f"{fmt_length(r['target_s'])} (Allan fit)"
                if g:
                    s += ", " + self._gmwm_text(t, g, w, False)
                mc = r.get("mc")
                if mc:
                    s += f"; Allan {self._mc_text(mc)}" if g or share else f", {self._mc_text(mc)}"
            else:
                s += (f"not within {fmt_length(MAX_LENGTH_S)} (Allan fit; the model-discrepancy "
                      f"allowance keeps it at ±{100 * r['floor_width']:.3g} % or wider)"
                      if math.isfinite(r["floor_width"]) else f"not resolved within {fmt_length(MAX_LENGTH_S)}")
                if g:
                    s += ", " + self._gmwm_text(t, g, w, False)
            if r["resolved_s"] is not None:
                s += f"; {t} resolved from {fmt_length(r['resolved_s'])}" + (" (Allan fit)" if g else "")
            if g:
                s += self._gmwm_tail(t, g)
            out.append(s)
        if self.at_length:
            L = self.at_length
            parts = []
            for name, terms in ((("Allan fit", L["terms"]),) if "allan" in self.estimators else ()) + \
                    ((("GMWM", L["gmwm"]["terms"]),) if "gmwm" in L else ()):
                good = [f"{t} to ±{100 * v['rel_width']:.2g} %" for t, v in terms.items() if v["resolved"]]
                bound = [t for t, v in terms.items() if not v["resolved"]]
                s = f"resolves {', '.join(good)}" if good else "resolves no term"
                parts.append(s + (f" and gives {', '.join(bound)} only as a bound" if bound else "") + f" ({name})")
            out.append(f"a {fmt_length(L['length_s'])} record " + "; ".join(parts))
        return out

    def to_dict(self) -> dict:
        def clean(x):
            if isinstance(x, dict):
                return {k: clean(v) for k, v in x.items()}
            if isinstance(x, (list, tuple)):
                return [clean(v) for v in x]
            if isinstance(x, float) and not math.isfinite(x):
                return None
            if isinstance(x, np.generic):
                return clean(x.item())
            return x

        est = {"allan": "allan fit (fogdrift allan)", "gmwm": "GMWM of the true latent model (fogdrift noise "
               "--method gmwm --model ...)"}
        return clean({"fogdrift_result": "plan", "estimator": " and ".join(est[e] for e in self.estimators),
                      "estimators": list(self.estimators),
                      "width": "relative 95 % half-width, (hi95 - lo95) / (2 value)",
                      "model": self.model.to_dict(),
                      "targets": self.targets, "terms": self.terms, "at_length": self.at_length,
                      "monte_carlo_seeds": self.seeds, "grid": self.grid, "notes": self.notes,
                      "lines": self.lines()})


def _grid_n(dt_s):
    n_max = int(MAX_LENGTH_S / dt_s)
    out, n = [], float(_MIN_SAMPLES)
    while n <= n_max:
        out.append(int(round(n)))
        n *= _STEP
    if out and out[-1] < n_max:  # the last point at MAX_LENGTH_S itself: "not within 30 d" means 30 d
        out.append(n_max)
    return out


def _width80(w_share, ratio) -> list:
    """The width :data:`RECORD_SHARE` of the records stay within, per length: the share union's ``w_share`` times
    the records' spread ``ratio`` and the allowance :data:`SHARE_ALLOWANCE` (inf where ``w_share`` is)."""
    f = ratio * (1.0 + SHARE_ALLOWANCE)
    return [x * f if math.isfinite(x) else math.inf for x in w_share]


def _share_length(model, term, target, lengths, w_share):
    """``(length, ratio)``: the fixed point ``L = crossing(w_share * share_ratio(L) * (1 + SHARE_ALLOWANCE))`` (the
    length at which the 80 % width, :func:`_width80` with the spread at that length, reaches ``target``; None if it
    never does).

    The ratio falls with length, so plain substitution oscillates about the fixed point (MEMS B: 57 906 ->
    106 415 -> 85 541 -> 92 502 -> ... samples); a secant step on ``log L`` finds it in 3-4 evaluations of
    ``SPREAD_DRAWS // 4`` records, then the ratio is taken there with ``SPREAD_DRAWS`` and the length read again.
    """
    dt = model.dt_s
    end = math.log(lengths[-1])

    def step(x, draws):
        """``(log crossing, ratio, beyond)``: where the 80 % width with the spread at ``exp(x)`` reaches the target;
        a crossing beyond the grid is clamped to its end (``beyond``: the spread of a shorter record is wider, so a
        later step may still find one); None when too few records resolve the term."""
        r = share_ratio(model, max(int(round(math.exp(x) / dt)), _MIN_SAMPLES), term, RECORD_SHARE, draws=draws)
        if not math.isfinite(r):
            return None, r, False
        at = crossing(lengths, _width80(w_share, r), target)
        return (end, r, True) if at is None else (math.log(at), r, False)

    x0 = math.log(crossing(lengths, w_share, target))
    g0, r, _ = step(x0, SPREAD_DRAWS // 4)
    if g0 is None:
        return None, r
    x1 = g0
    for _ in range(_SHARE_ITER):
        g1, r, _ = step(x1, SPREAD_DRAWS // 4)
        if g1 is None:  # too few records resolve the term there: back to the last length that gave one
            x1 = g0
            break
        h0, h1 = g0 - x0, g1 - x1
        x2 = x1 - h1 * (x1 - x0) / (h1 - h0) if h1 != h0 else g1
        x2 = min(max(x2, math.log(lengths[0])), end)
        x0, g0, x1 = x1, g1, x2
        if abs(x1 - x0) < _SHARE_TOL:
            break
    g, r, beyond = step(x1, SPREAD_DRAWS)
    return (None if g is None or beyond else math.exp(g)), r


def _mc_length(L, w_mc, target, grid_len, grid_w):
    """Length the measured median width implies, with the analytic curve's local log-log slope at ``L``."""
    gl, gw = np.asarray(grid_len), np.asarray(grid_w)
    ok = np.isfinite(gw)
    if not (math.isfinite(w_mc) and ok.sum() >= 2):
        return None
    lg, lw = np.log(gl[ok]), np.log(gw[ok])
    i = int(np.clip(np.searchsorted(lg, math.log(L)), 1, lg.size - 1))
    s = (lw[i] - lw[i - 1]) / (lg[i] - lg[i - 1])
    if s > -0.05:  # the width no longer falls with length (at its floor): no length to read
        return None
    return float(L * (target / w_mc) ** (1.0 / s))


def _gmwm_terms(model, targets, ns, lengths, seeds, workers, notes) -> tuple[dict, dict]:
    """The GMWM's curve (term -> width per grid length) and, per target term, its ``target_s``,
    ``resolved_s``, ``floor_width`` and Monte-Carlo (:mod:`.gmwm`)."""
    dt = model.dt_s
    curves = [gmwm_widths(model, n) for n in ns]
    width = {t: [c[t]["rel_width"] for c in curves] for t in model.terms}
    out = {}
    for t, target in targets.items():
        w = width[t]
        resolved_s = crossing(lengths, [0.0 if c[t]["resolved"] else math.inf for c in curves], 0.0)
        g = {"model": curves[0]["_fit"]["model"], "target_s": crossing(lengths, w, target),
             "resolved_s": resolved_s, "floor_width": w[-1]}
        if g["target_s"] is not None and seeds:
            n = int(round(g["target_s"] / dt))
            if n > MC_MAX_SAMPLES:
                notes.append(f"GMWM Monte-Carlo of {t} skipped: {fmt_length(g['target_s'])} is {n} samples, beyond "
                             f"the simulation limit of {MC_MAX_SAMPLES}")
            else:
                mc = summarise(model, simulate_gmwm_fits(model, n, seeds, workers=workers), {t: target})[t]
                mc["length_s"] = _mc_length(g["target_s"], mc["median_width"], target, lengths, w)
                mc["n_samples"] = n
                g["mc"] = mc
        out[t] = g
    return width, out


def make_plan(model, targets, *, length_s=None, monte_carlo=0, seed0=1, workers=1, estimators=ESTIMATORS) -> Plan:
    """Plan the record for ``model`` (:class:`~fogdrift.plan.model.PlanModel`) and ``targets`` (term -> relative
    half-width).  ``monte_carlo``: seeds per checked length (0: analytic only); ``workers``: processes;
    ``estimators``: the ones planned for, of :data:`ESTIMATORS` (the Allan fit's analytic curve is always made:
    the plan's grid and the stated length's reading use it; without ``"allan"`` its 80 % length, Monte-Carlo and
    lines are left out)."""
    estimators = tuple(e for e in ESTIMATORS if e in estimators)
    if not estimators:
        raise ConfigError(f"{{opt:estimator}} names no estimator; expected {', '.join(ESTIMATORS)} or both")
    for t in targets:
        if t not in model.terms:
            raise ConfigError(f"{{opt:target}}: the model has no {t} term to plan for")
    if monte_carlo < 0:
        raise ConfigError(f"{{opt:monte_carlo}} must be >= 0 seeds; got {monte_carlo}")
    dt = model.dt_s
    ns = _grid_n(dt)
    if len(ns) < 2:
        raise ConfigError(f"sample interval {dt:g} s leaves fewer than {_MIN_SAMPLES} samples in "
                          f"{fmt_length(MAX_LENGTH_S)}")
    curves = [analytic_widths(model, n) for n in ns]
    lengths = [n * dt for n in ns]
    grid = {"length_s": lengths, "n_samples": ns,
            "tau_max_s": [c["_fit"]["tau_max_s"] for c in curves],
            "width": {t: [c[t]["rel_width"] for c in curves] for t in model.terms},
            "z": {t: [c[t]["z"] for c in curves] for t in model.terms}}
    # the width RECORD_SHARE of the records stay within: the union of the models that share of the records may
    # find plausible, times the spread of the fit's rules on linearised records (plan.spread), evaluated at the
    # length it gives (a fixed point, _share_length); a length of the Allan fit's, so not made for the GMWM alone
    allan = "allan" in estimators
    shared = [analytic_widths(model, n, share=RECORD_SHARE) for n in ns] if targets and allan else curves
    grid["width_share"], spread = {}, {t: None for t in targets}
    for t, target in (targets.items() if allan else ()):
        w = [c[t]["rel_width"] for c in shared]
        ratio = _share_length(model, t, target, lengths, w)[1] if crossing(lengths, w, target) else math.inf
        spread[t] = ratio
        grid["width_share"][t] = _width80(w, ratio)
    terms = {}
    seeds = list(range(seed0, seed0 + int(monte_carlo)))
    notes = []
    for t, target in targets.items():
        w = grid["width"][t]
        res = [0.0 if c[t]["resolved"] else math.inf for c in curves]
        resolved_s = crossing(lengths, res, 0.0)
        if resolved_s is not None:  # interpolate the resolving threshold in A/sd between the grid points
            i = lengths.index(resolved_s)
            if i > 0:
                z = grid["z"][t]
                need = max(math.sqrt(2.0 + 6.0), 2.0)
                zz = [need / max(v, 1e-300) for v in z]
                resolved_s = crossing(lengths[i - 1:i + 1], zz[i - 1:i + 1], 1.0) or resolved_s
        target_s = crossing(lengths, w, target)
        r = {"target": target, "unit": TERM_TABLE[t].unit, "value": model.coefficients[t],
             "resolved_s": resolved_s, "target_s": target_s, "share": RECORD_SHARE,
             "share_s": crossing(lengths, grid["width_share"][t], target) if allan else None,
             "share_ratio": spread[t],
             "floor_width": w[-1]}
        if target_s is not None:
            j = min(range(len(lengths)), key=lambda k: abs(math.log(lengths[k] / target_s)))
            r["tau_range_s"] = [curves[j]["_fit"]["tau_min_s"], curves[j]["_fit"]["tau_max_s"]]
        if target_s is not None and seeds and "allan" in estimators:
            n = int(round(target_s / dt))
            if n > MC_MAX_SAMPLES:
                notes.append(f"Monte-Carlo of {t} skipped: {fmt_length(target_s)} is {n} samples, beyond the "
                             f"simulation limit of {MC_MAX_SAMPLES}")
            else:
                fits = simulate_fits(model, n, seeds, workers=workers)
                mc = summarise(model, fits, {t: target})[t]
                mc["length_s"] = _mc_length(target_s, mc["median_width"], target, lengths, w)
                mc["n_samples"] = n
                r["mc"] = mc
            n = None if r["share_s"] is None else int(round(r["share_s"] / dt))
            if n is not None and n <= MC_MAX_SAMPLES:
                fits = simulate_fits(model, n, seeds, workers=workers)
                r["mc_share"] = dict(summarise(model, fits, {t: target})[t], n_samples=n)
        terms[t] = r
    if "gmwm" in estimators:
        grid["gmwm_width"], g = _gmwm_terms(model, targets, ns, lengths, seeds, workers, notes)
        for t in targets:
            terms[t]["gmwm"] = g[t]
    at = None
    if length_s is not None:
        n = int(round(float(length_s) / dt))
        if n < _MIN_SAMPLES:
            raise ConfigError(f"{{opt:length}} {fmt_length(length_s)} is fewer than {_MIN_SAMPLES} samples at "
                              f"{1 / dt:g} Hz")
        c = analytic_widths(model, n)
        at = {"length_s": float(length_s), "n_samples": n, "tau_max_s": c["_fit"]["tau_max_s"],
              "terms": {t: {"resolved": c[t]["resolved"], "rel_width": c[t]["rel_width"],
                            "rel_hi": c[t]["rel_hi"], "z": c[t]["z"]} for t in model.terms}}
        if seeds and n <= MC_MAX_SAMPLES and "allan" in estimators:
            fits = simulate_fits(model, n, seeds, workers=workers)
            at["mc"] = summarise(model, fits, {})
        if "gmwm" in estimators:  # the same question for the GMWM, from its own covariance law
            g = gmwm_widths(model, n)
            at["gmwm"] = {"tau_max_s": g["_fit"]["tau_max_s"],
                          "terms": {t: {"resolved": g[t]["resolved"], "rel_width": g[t]["rel_width"]}
                                    for t in model.terms}}
    return Plan(model, dict(targets), terms, grid, at, seeds, notes + list(model.notes), estimators)
