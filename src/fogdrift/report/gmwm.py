"""Files and report table of a GMWM noise analysis (:class:`fogdrift.gmwm.analysis.GmwmAxis`).

* :func:`write_gmwm_outputs` - ``noise.json``, ``wvar.csv``, ``noise.png`` (every file through
  :func:`fogdrift.output.atomic_path`, so inside a run's :class:`~fogdrift.output.OutputDir`).
* :func:`gmwm_noise_html` - the HTML noise table of the analysis report (``analyze --noise-method gmwm``).

It uses only public names of :mod:`fogdrift.report` (``write_json``).
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np

from .._util import fmt_number
from ..gmwm.analysis import J_CAVEAT, GmwmAxis, b_detail_lines, ieee_rows
from ..output import atomic_path
from ..units import INTERNAL_UNITS, KEY_SUFFIXES
from .figures import _place, literal, save_figure, subplots
from .files import write_json

__all__ = ["write_gmwm_outputs", "plot_gmwm", "gmwm_noise_html", "fmt"]


def fmt(x, digits=4) -> str:
    """A number with ``digits`` significant digits ('–' for None/NaN; a text cell such as a bound as it is):
    :func:`fogdrift._util.fmt_number`."""
    return fmt_number(x, digits)


def plot_gmwm(axes: list[GmwmAxis], path) -> Path:
    """Per axis: the WV with its 95 % interval (excluded scales hollow), the fitted model and each component."""
    n = len(axes)
    fig, axs = subplots(1, n, figsize=(5.6 * n, 4.6), squeeze=False)  # on the Agg canvas, without pyplot
    for ax, a in zip(axs[0], axes):
        wv, sel = a.wvar, a.selection
        used = np.isin(wv.level, sel.levels_used)
        yerr = np.vstack([wv.nu2_dph2 - wv.ci_lo95_dph2, wv.ci_hi95_dph2 - wv.nu2_dph2])
        ax.errorbar(wv.scale_s, wv.nu2_dph2, yerr=yerr, fmt="none", ecolor="0.4", lw=0.8, label="WV (95 % CI)")
        ax.plot(wv.scale_s[used], wv.nu2_dph2[used], "o", ms=4, color="k", label="used")
        if np.any(~used):
            ax.plot(wv.scale_s[~used], wv.nu2_dph2[~used], "o", ms=4, mfc="white", color="k", label="excluded")
        tau, scale = wv.tau_samples[used], wv.scale_s[used]  # the model over the scales it was fitted to
        fit = sel.fit
        ax.loglog(scale, fit.latent_model.wv(fit.theta, tau), "r-", lw=1.6, label=literal(f"GMWM {sel.selected}"))
        for label, comp in zip(fit.latent_model.labels, fit.component_wv(tau)):
            ok = comp > np.nanmin(wv.nu2_dph2) * 1e-3
            ax.loglog(scale[ok], comp[ok], "--", lw=0.9, label=literal(label))
        ax.set_ylim(np.nanmin(wv.ci_lo95_dph2[wv.ci_lo95_dph2 > 0]) / 5, np.nanmax(wv.ci_hi95_dph2) * 3)
        ax.set_xlabel("scale [s]")
        ax.set_ylabel(f"wavelet variance [({INTERNAL_UNITS[a.quantity]})²]")
        ax.set_title(literal(f"{a.name}: {sel.selected}{'' if sel.passed_checks else ' (no candidate passed the checks)'}\n"
                             f"J = {fit.j_stat:.3g}, df {fit.df}, p = {fit.j_pvalue:.2g}"), fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    _place(fig)  # margins measured once (bbox_inches="tight" drew the figure twice)
    return save_figure(fig, path, dpi=110)


def _quantity(axes: list[GmwmAxis]) -> str | None:
    """The axes' one quantity, or None for gyro and accelerometer axes together."""
    found = {a.quantity for a in axes}
    return found.pop() if len(found) == 1 else None


def _units(axes: list[GmwmAxis]) -> dict:
    """``noise.json``'s units: the internal unit of the axes' quantity (per axis when they differ)."""
    q = _quantity(axes)
    if q is not None:
        return {"rate": INTERNAL_UNITS[q], "wvar": f"({INTERNAL_UNITS[q]})^2", "scale": "s"}
    return {"rate": {a.name: INTERNAL_UNITS[a.quantity] for a in axes},
            "wvar": {a.name: f"({INTERNAL_UNITS[a.quantity]})^2" for a in axes}, "scale": "s"}


def write_gmwm_outputs(axes: list[GmwmAxis], out_dir, *, source: str, record: dict | None = None) -> dict:
    """``noise.json`` (every axis: selection, candidates, IEEE table, J with its caveat), ``wvar.csv`` and
    ``noise.png`` in ``out_dir``; returns ``{"json", "csv", "png"}`` paths."""
    out = Path(out_dir)
    doc = {"fogdrift_result": "noise", "method": "gmwm", "source": str(source), "record": record,
           "units": _units(axes),
           "axes": [a.to_dict() for a in axes]}
    paths = {"json": out / "noise.json", "csv": out / "wvar.csv", "png": out / "noise.png"}
    write_json(doc, paths["json"])
    with atomic_path(paths["csv"]) as tmp, open(tmp, "w", encoding="utf-8") as fh:
        two = KEY_SUFFIXES[_quantity(axes)][1] if _quantity(axes) else "internal2"  # the WV's unit in the names
        fh.write(f"axis,level,scale_s,wvar_{two},ci_lo95_{two},ci_hi95_{two},used,model_wvar_{two}\n")
        for a in axes:
            wv, fit = a.wvar, a.selection.fit
            model = fit.latent_model.wv(fit.theta, wv.tau_samples)
            used = np.isin(wv.level, a.selection.levels_used)
            for i in range(len(wv)):
                fh.write(f"{a.name},{int(wv.level[i])},{float(wv.scale_s[i])!r},{float(wv.nu2_dph2[i])!r},"
                         f"{float(wv.ci_lo95_dph2[i])!r},{float(wv.ci_hi95_dph2[i])!r},{int(used[i])},"
                         f"{float(model[i])!r}\n")
    plot_gmwm(axes, paths["png"])
    return paths


def gmwm_noise_html(axis: GmwmAxis) -> str:
    """HTML of the GMWM noise table of one axis (selected model, IEEE quantities with 95 % intervals, candidates,
    excluded scales, the J statistic and its caveat)."""
    sel = axis.selection
    e = html.escape
    head = "".join(f"<th>{h}</th>" for h in ("quantity", "value", "95 % interval", "unit", "from"))
    body = "".join(f"<tr><td>{e(str(r[0]))}</td><td>{e(fmt(r[1]))}</td>"
                   f"<td>{'–' if r[2] is None or r[3] is None else f'[{fmt(r[2])}, {fmt(r[3])}]'}</td>"
                   f"<td>{e(str(r[4]))}</td><td>{e(str(r[5]))}</td></tr>" for r in ieee_rows(axis))
    details = "".join(f"<li>{e(line)}</li>" for line in b_detail_lines(axis))
    check = "" if axis.allan_check is None else "".join(f"<li>GMWM vs Allan fit: {e(line)}</li>"
                                                        for line in axis.allan_check["lines"])
    cands = "".join(f"<tr><td>{e(c.model)}</td><td>{fmt(c.wic)}</td><td>{'yes' if c.passed else 'no'}</td>"
                    f"<td>{e('; '.join(c.reasons))}</td></tr>" for c in sel.candidates)
    excl = "".join(f"<li>scale {fmt(x.scale_s)} s: {e(x.reason)}</li>" for x in sel.excluded)
    fit = sel.fit
    return (f"<h4>Noise model by GMWM (wavelet variance): {e(sel.selected)}"
            f"{'' if sel.passed_checks else ' (no candidate passed every check)'}</h4>"
            f"<table class='gmwm'><tr>{head}</tr>{body}</table>"
            + (f"<ul class='note'>{details}{check}</ul>" if details or check else "")
            + f"<p class='note'>J = {fmt(fit.j_stat)} with {fit.df} degrees of freedom, p = {fmt(fit.j_pvalue, 2)}: "
            f"{e(J_CAVEAT)}.</p>"
            + (f"<ul class='note'>{excl}</ul>" if excl else "")
            + "<table class='gmwm-candidates'><tr><th>candidate</th><th>WIC</th><th>passed</th><th>why rejected</th>"
              f"</tr>{cands}</table>")


def gmwm_axis_block(ax, result, fig_dir, pre, fig_offset, evaluated) -> str:
    """Report section ``gmwm`` (:mod:`fogdrift.report.sections`): the GMWM noise table of an axis analysed with
    ``--noise-method gmwm``, first in the axis's noise identification; ``""`` for an Allan-only axis."""
    gm = getattr(ax, "gmwm", None)
    return "" if gm is None else gmwm_noise_html(gm)
