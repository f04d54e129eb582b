"""The fleet page: one self-contained HTML file with a control chart per coefficient across the files.

For every IEEE-952 coefficient that any file's selected noise model contains, one figure with a panel per axis name: each file's
estimate with its 95 % interval, the fleet mean and the mean +- 3 sigma lines (sigma: the sample standard
deviation across the files of that axis).  A file is named an outlier when its estimate lies more than
3 sigma from the mean of the *other* files (leave-one-out): with the point itself in the mean and sigma, no
point of a fleet of n <= 10 can ever lie beyond 3 sigma (the largest possible |z| is (n - 1)/sqrt(n)), so
the plain rule would never fire on a small fleet.  A file whose own 95 % interval contains the mean of the
others is not named, however tight the fleet: its difference is within its measurement uncertainty.
A coefficient that is not in a file's selected model (or not estimable from it) is drawn as an open
triangle at its 95 % upper bound and takes no part in the statistics.  Figures are embedded as base64 PNG: the page
fetches nothing.
"""

from __future__ import annotations

import base64
import html
import io
import math
from pathlib import Path

import numpy as np

from .._util import fmt_number
from ..output import atomic_path
from ..report.figures import literal
from .commands import TERMS
from .summary import ACCEL_TERMS, UNITS

__all__ = ["write_fleet_page", "control_limits", "outliers", "SIGMA"]

#: Control-limit width in standard deviations.
SIGMA = 3.0

_UNIT_TEXT = {"urad": "µrad", "dprh": "deg/√h", "dph": "deg/h", "dphrh": "deg/h^1.5", "dph2": "deg/h²",
              "mps": "m/s", "mps_rh": "m/s/√h", "ug": "µg", "mps2_rh": "m/s²/√h", "mps2_ph": "m/s²/h"}


def control_limits(values) -> tuple[float, float, float] | None:
    """(mean, lower, upper) = mean -+ 3 sample sd of the finite values; None with fewer than 2.

    Examples
    --------
    >>> control_limits([1.0, 2.0, 3.0])
    (2.0, -1.0, 5.0)
    """
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    if v.size < 2:
        return None
    m, s = float(v.mean()), float(v.std(ddof=1))
    return m, m - SIGMA * s, m + SIGMA * s


def outliers(values, lo95=None, hi95=None) -> list[int]:
    """Indices of values more than 3 sd from the mean of the others (leave-one-out; needs 3 finite values).

    With ``lo95``/``hi95`` (each value's 95 % interval) a value is an outlier only if its interval also
    excludes the others' mean: a file whose own uncertainty covers the fleet is not singled out, however
    tight the fleet.

    Examples
    --------
    >>> outliers([1.0, 1.1, 0.9, 1.05, 0.95, 5.0])
    [5]
    >>> outliers([1.0, 1.1, 0.9, 1.05, 0.95, 5.0], lo95=[0.5] * 6, hi95=[1.5] * 5 + [9.0])
    []
    >>> outliers([1.0, 1.1, 0.9])
    []
    """
    idx = [i for i, x in enumerate(values) if x is not None and math.isfinite(x)]
    out = []
    if len(idx) < 3:
        return out
    for i in idx:
        others = np.asarray([values[j] for j in idx if j != i], dtype=float)
        m, s = others.mean(), others.std(ddof=1)
        if not (abs(values[i] - m) > SIGMA * s if s > 0 else values[i] != m):
            continue
        a = None if lo95 is None else lo95[i]
        b = None if hi95 is None else hi95[i]
        if a is not None and b is not None and a <= m <= b:
            continue
        out.append(i)
    return out


def _png(fig) -> str:
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _chart(rows, name, unit, axes_names):
    """(PNG base64, [(axis, file, value)] outliers) of one coefficient, or None if no file resolves it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    col, lo, hi = f"{name}_{unit}", f"{name}_lo95_{unit}", f"{name}_hi95_{unit}"
    if not any(r.get(col) is not None for r in rows):
        return None
    fig, axs = plt.subplots(1, len(axes_names), figsize=(max(5.0, 4.2 * len(axes_names)), 3.6), squeeze=False)
    flagged = []
    for ax, axis in zip(axs[0], axes_names):
        sel = [r for r in rows if r.get("axis") == axis]
        files = [r["file"] for r in sel]
        x = np.arange(len(sel))
        vals = [r.get(col) for r in sel]
        for k, r in enumerate(sel):
            v = r.get(col)
            if v is not None:
                # a value at its data bound can sit an ulp above its hi95 (rounding): no negative bar
                yerr = [[max(0.0, v - (r.get(lo) if r.get(lo) is not None else v))], [max(0.0, (r.get(hi) or v) - v)]]
                ax.errorbar([k], [v], yerr=yerr, fmt="o", ms=4, color="k", lw=0.8, capsize=2)
            elif r.get(hi) is not None:
                ax.plot([k], [r[hi]], "v", mfc="none", color="0.4", ms=6)
        lim = control_limits(vals)
        if lim is not None:
            m, a, b = lim
            ax.axhline(m, color="C0", lw=1.0)
            ax.axhline(a, color="C3", lw=0.8, ls="--")
            ax.axhline(b, color="C3", lw=0.8, ls="--")
        for k in outliers(vals, [r.get(lo) for r in sel], [r.get(hi) for r in sel]):
            ax.plot([k], [vals[k]], "o", ms=9, mfc="none", color="C3", mew=1.5)
            right = k >= len(sel) / 2          # label towards the middle, inside the panel
            ax.annotate(literal(files[k]), (k, vals[k]), textcoords="offset points", xytext=(-7 if right else 7, 5),
                        ha="right" if right else "left", fontsize=7, color="C3")
            flagged.append((axis, files[k], vals[k]))
        ax.set_xticks(x)
        ax.set_xticklabels([literal(f if len(f) <= 18 else "…" + f[-17:]) for f in files], rotation=60, ha="right",
                           fontsize=7)
        ax.set_title(literal(f"{name}, axis {axis}"), fontsize=9)
        ax.set_ylabel(f"{name} [{_UNIT_TEXT[unit]}]")
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return _png(fig), flagged


def _fmt(x) -> str:
    """A summary cell: floats by :func:`fogdrift._util.fmt_number` (whole numbers up to 1e9 without decimals),
    anything else as text."""
    if x is None or isinstance(x, float):
        return fmt_number(x, 4, nonfinite=None, whole_below=1e9)
    return str(x)


def _table(headers, rows) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(_fmt(c))}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


_CSS = """
body{font-family:system-ui,sans-serif;max-width:1250px;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:1em 0;font-size:0.8em}th,td{border:1px solid #bbb;padding:2px 6px}
th{background:#eee}td{text-align:right}td:first-child,td:nth-child(2){text-align:left}
img{max-width:100%}.note{color:#555;font-size:0.9em}.bad{color:#a00}
"""


def write_fleet_page(rows: list[dict], path, *, command: str = "", settings: dict | None = None) -> Path:
    """Write the fleet HTML page (control charts, outliers, the summary and the errors) to ``path``.

    Parameters
    ----------
    rows : list of dict
        Summary rows (:data:`fogdrift.fleet.summary.COLUMNS`).
    path : str or Path
        Output HTML file.
    command : str
        Batch command, for the title.
    settings : dict, optional
        Shown on the page.
    """
    good = [r for r in rows if r.get("status") in ("ok", "cached") and r.get("axis") is not None]
    bad = [r for r in rows if r.get("status") == "error"]
    axes_names = list(dict.fromkeys(r["axis"] for r in good))
    files = list(dict.fromkeys(r["file"] for r in rows))
    parts = [f"<h1>fogdrift fleet: {html.escape(command)} over {len(files)} files</h1>",
             f'<p class="note">{len(good)} file x axis results ({sum(r["status"] == "cached" for r in good)} '
             f"cached), {len(bad)} files failed. Rates in deg/h, τ in s; brackets and bars are 95 % intervals. "
             f"Control limits: fleet mean ± {SIGMA:g}σ per axis (σ = sample s.d. across files); a file is named an "
             f"outlier when it lies more than {SIGMA:g}σ from the mean of the other files (leave-one-out) and its own "
             "95 % interval excludes that mean. "
             "Open triangles: not in that file's selected noise model (or not estimable), drawn at the 95 % upper "
             "bound.</p>"]
    flagged_all = []
    for name, unit in TERMS + ACCEL_TERMS:  # gyro axes' charts, then accelerometer axes' (their own columns)
        chart = _chart(good, name, unit, axes_names) if axes_names else None
        if chart is None:
            continue
        png, flagged = chart
        flagged_all += [(name, *f) for f in flagged]
        parts.append(f"<h2>{name} [{html.escape(_UNIT_TEXT[unit])}]: {html.escape(UNITS[f'{name}_{unit}'])}</h2>")
        parts.append(f'<img alt="control chart {name}" src="data:image/png;base64,{png}">')
    parts.append("<h2>Outliers</h2>")
    parts.append(_table(["coefficient", "axis", "file", "value"], flagged_all) if flagged_all
                 else '<p class="note">None.</p>')
    parts.append("<h2>Summary</h2>")
    cols = ["file", "axis", "status", "duration_s", "rate_hz"] + [f"{n}_{u}" for n, u in TERMS] + \
           ["noise_model", "fit_quality", "fit_chi2_red"]
    if any(r.get("verdict") for r in good):
        cols.append("verdict")
    if any(r.get("temperature_range_c") is not None for r in good):
        cols += ["temperature_range_c", "temperature_change_c"]
    parts.append(_table(cols, [[r.get(c) for c in cols] for r in good]))
    if bad:
        parts.append('<h2 class="bad">Errors</h2>')
        parts.append(_table(["file", "error"], [[r["file"], r.get("error")] for r in bad]))
    if settings:
        parts.append(f'<p class="note">Settings: {html.escape(str(settings))}</p>')
    doc = (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>fogdrift fleet</title>"
           f"<style>{_CSS}</style></head><body>{''.join(parts)}</body></html>")
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(doc, encoding="utf-8")
    return path
