"""Figures of ``fogdrift plan``: expected relative 95 % half-width of each term against record length (log-log),
each target marked, the Monte-Carlo medians as points; the GMWM's curves (when planned) dash-dotted in the term's
colour, its Monte-Carlo medians as plus signs.  With ``--fleet``: each term's spread and type-mean widths against the
number of units."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..units import S_PER_H
from .figures import pyplot, save_figure

__all__ = ["plot_plan", "plot_fleet_plan"]


def plot_plan(plan, path) -> Path:
    """Write the plan figure (PNG) of :class:`fogdrift.plan.Plan` to ``path``."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    L = np.asarray(plan.grid["length_s"], dtype=float) / S_PER_H
    allan = "allan" in getattr(plan, "estimators", ("allan",))
    for i, (t, w) in enumerate(plan.grid["width"].items()):
        w = 100.0 * np.asarray(w, dtype=float)
        color = f"C{i}"
        if allan:
            ax.loglog(L, np.where(np.isfinite(w), w, np.nan), color=color, label=f"{t} (Allan fit, expected)")
        _gmwm_curve(ax, plan, t, L, color)
        r = plan.terms.get(t)
        if r is None or not allan:
            continue
        w80 = 100.0 * np.asarray(plan.grid.get("width_share", {}).get(t, []), dtype=float)
        if w80.size == L.size:  # the width four records in five stay within (drawn for the target terms)
            ax.loglog(L, np.where(np.isfinite(w80), w80, np.nan), color=color, ls="--", lw=0.8,
                      label=f"{t}, 80 % of records")
        ax.axhline(100.0 * r["target"], color=color, ls=":", lw=0.9)
        if r["target_s"] is not None:  # the median record's length (open) and the 80 % one (filled)
            ax.plot([r["target_s"] / S_PER_H], [100.0 * r["target"]], "o", color=color, mfc="none")
        if r.get("share_s") is not None:
            ax.plot([r["share_s"] / S_PER_H], [100.0 * r["target"]], "o", color=color)
        mc = r.get("mc")
        if mc and mc.get("median_width") is not None and math.isfinite(mc["median_width"]):
            ax.plot([mc["n_samples"] * plan.model.dt_s / S_PER_H], [100.0 * mc["median_width"]], "x", color=color,
                    label=f"{t} Monte-Carlo median ({len(plan.seeds)} seeds)")
    if plan.at_length:
        ax.axvline(plan.at_length["length_s"] / S_PER_H, color="0.5", ls="--", lw=0.9, label="--length")
    ax.set_xlabel("record length [h]")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylabel("95 % half-width [% of value]")
    ax.set_title(f"fogdrift plan: {plan.model.text()} at {1 / plan.model.dt_s:g} Hz", fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    return save_figure(fig, path)


def _gmwm_curve(ax, plan, t, L, color) -> None:
    """The GMWM's expected width of ``t`` (dash-dotted), its target length and Monte-Carlo median."""
    gw = plan.grid.get("gmwm_width", {}).get(t)
    if gw is None:
        return
    gw = 100.0 * np.asarray(gw, dtype=float)
    # a log-normal interval's width grows without bound as a term fades: drawn up to +-1000 % (the Allan
    # fit's curve ends where its term is not estimable)
    ax.loglog(L, np.where(np.isfinite(gw) & (gw <= 1000.0), gw, np.nan), color=color, ls="-.", lw=1.1, label=f"{t} (GMWM, expected)")
    g = (plan.terms.get(t) or {}).get("gmwm")
    if not g:
        return
    ax.axhline(100.0 * plan.terms[t]["target"], color=color, ls=":", lw=0.9)
    if g["target_s"] is not None:
        ax.plot([g["target_s"] / S_PER_H], [100.0 * plan.terms[t]["target"]], "s", color=color, mfc="none")
    mc = g.get("mc")
    if mc and mc.get("median_width") is not None and math.isfinite(mc["median_width"]):
        ax.plot([mc["n_samples"] * plan.model.dt_s / S_PER_H], [100.0 * mc["median_width"]], "+", color=color,
                ms=9, label=f"{t} GMWM Monte-Carlo median ({mc['n_seeds']} seeds)")


def plot_fleet_plan(plan, path) -> Path:
    """Write the fleet figure (PNG) of :class:`fogdrift.plan.fleet.FleetPlan` to ``path``: per term the expected
    95 % half-width of the between-unit SD (solid) and of the type's mean (dashed) against the number of units
    (log-log), each target dotted, the units needed as circles, ``--units`` as a vertical line."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.0, 4.6))
    for i, (t, r) in enumerate(plan.terms.items()):
        color, c = f"C{i}", r["curve"]
        m = np.asarray(c["units"], dtype=float)
        sw = 100.0 * np.asarray(c["spread_width"], dtype=float)
        if np.any(np.isfinite(sw)):
            ax.loglog(m, np.where(np.isfinite(sw), sw, np.nan), color=color, label=f"{t} spread (between-unit SD)")
        ax.loglog(m, 100.0 * np.asarray(c["mean_width"], dtype=float), color=color, ls="--", lw=0.9,
                  label=f"{t} type mean")
        for target, needed in ((r["spread_target"], r["spread_units"]), (r["mean_target"], r["mean_units"])):
            if target is None:
                continue
            ax.axhline(100.0 * target, color=color, ls=":", lw=0.9)
            if needed is not None:
                ax.plot([needed], [100.0 * target], "o", color=color, mfc="none")
    if plan.units is not None:
        ax.axvline(plan.units, color="0.5", ls="--", lw=0.9, label="--units")
    ax.set_xlabel("units recorded")
    ax.set_ylabel("95 % half-width [% of value]")
    ax.set_title(f"fogdrift plan --fleet: {plan.pilot.n_rows} pilot units ({plan.pilot.source})", fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    return save_figure(fig, path)
