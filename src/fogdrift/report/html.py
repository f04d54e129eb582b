"""The self-contained HTML report (figures embedded, nothing fetched)."""

from __future__ import annotations

import base64
import html
from pathlib import Path

from ..output import atomic_path
from .figures import (_safe, plot_allan, plot_models, plot_residuals, plot_separation, plot_separation_allan,
                      plot_signal, plot_spectrum)
from .files import write_json
from .tables import (METRICS_HEADERS, NOISE_HEADERS, _fmt, causal_metrics_rows, metrics_rows, noise_notes, noise_row,
                     readout_text, verdict)

def _img(path) -> str:
    data = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return f'<figure><img alt="{html.escape(Path(path).stem)}" src="data:image/png;base64,{data}"></figure>'


def _table(headers, rows, cls="") -> str:
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>" for row in rows)
    return f'<table class="{cls}"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>'


_CSS = """
body{font-family:system-ui,sans-serif;max-width:1150px;margin:2em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:1em 0;font-size:0.85em}
th,td{border:1px solid #bbb;padding:3px 7px;text-align:right}th{background:#eee}
td:first-child,th:first-child{text-align:left}
figure{margin:1em 0}img{max-width:100%}
.note{color:#555;font-size:0.9em}.verdict{background:#f4f8ee;border-left:4px solid #7a5;padding:0.5em 1em}
"""


def _effective_rate(result) -> str:
    """The modelling rate actually used: the averaged record's rate and its block-average factor."""
    m = getattr(result, "model_record", None) or {}
    fs, k = m.get("fs_hz"), m.get("block_average_factor") or 1
    if fs is None:
        return "native rate"
    native = m.get("native_fs_hz") or fs
    return f"{fs:.6g} Hz (native {native:.6g} Hz averaged in blocks of {k})" if k > 1 else f"{fs:.6g} Hz (native)"


def _analysis_section(result, fig_dir, title, fig_offset=0) -> str:
    parts = [f"<h2>{html.escape(title)}</h2>"]
    rec = result.record
    parts.append(_table(["item", "value"], [
        ["source", result.source],
        ["SHA-256", result.sha256],
        ["samples", rec.get("n_samples")],
        ["sample interval [s]", rec.get("dt_s")],
        ["duration [s]", _fmt(rec.get("duration_s"))],
        ["axes", ", ".join(rec.get("axis_names", []))],
        ["input unit (converted to deg/h)", rec.get("input_unit")],
        ["modelling rate (effective)", _effective_rate(result)],
        ["wavelet / level / mode", f"{result.config.wavelet} / {result.config.level} / {result.config.mode}"],
        ["split train / val / test", f"{result.config.train_fraction} / {result.config.val_fraction} / "
                                     f"{1 - result.config.train_fraction - result.config.val_fraction:.2g}"],
    ], "summary"))
    for ax in result.axes:
        parts.append(f"<h3>Axis {html.escape(ax.name)}</h3>")
        parts.append("<h4>Noise coefficients of the original output (whole record, native rate)</h4>")
        parts.append(_table(("signal",) + NOISE_HEADERS, [["original"] + noise_row(ax.original.noise)], "allan"))
        notes = noise_notes(ax.original.noise)
        parts.append('<ul class="note">' + "".join(f"<li>{html.escape(n)}</li>" for n in notes) + "</ul>")
        parts.append('<p class="note">In the table: value [95 % interval]; “– (&lt; x)”: the term is not in the '
                     "selected model and x is its 95 % upper bound; “n/e”: not estimable (reason above).</p>")
        parts.append('<p class="note">Slope read-outs (cross-check): '
                     + html.escape(readout_text(ax.original.noise)) + "</p>")
        parts.append("<h4>Table 2: noise coefficients before and after compensation (test block, modelling rate)</h4>")
        parts.append(_table(("signal",) + NOISE_HEADERS, [[r.label] + noise_row(r.analysis.noise) for r in ax.table2],
                            "table2"))
        parts.append('<p class="note">“drift residual (paper)” is the wavelet drift minus its one-step '
                     "prediction, what the paper's Table 2 and Fig. 9 show; “practical” is the gyro output minus the "
                     "one-step prediction made from the causal (real-time) drift. Brackets: 95 % intervals.</p>")
        ma = ax.models
        parts.append("<h4>Metrics on the test block (target: wavelet drift of the test block)</h4>")
        parts.append(_table(METRICS_HEADERS, metrics_rows(ma), "metrics"))
        parts.append("<h4>Metrics on the test block (target: causal drift)</h4>")
        parts.append(_table(METRICS_HEADERS, causal_metrics_rows(ma), "metrics"))
        parts.append('<div class="verdict"><p>' + "</p><p>".join(html.escape(v) for v in verdict(ma)) + "</p></div>")
        # deterministic names: the figure number and the axis; the applied section's files start "apply_to_"
        pre, name = ("apply_to_" if fig_offset else ""), _safe(ax.name)
        figs = [
            plot_allan([ax.original], fig_dir / f"{pre}fig3_allan_{name}.png", "Allan deviation (Fig. 3)"),
            plot_separation(ax.separation, fig_dir / f"{pre}fig5_drift_noise_{name}.png"),
            plot_separation_allan(ax.separation, fig_dir / f"{pre}fig6_allan_{name}.png"),
            plot_models(ma, fig_dir / f"{pre}fig{8 + fig_offset}_models_{name}.png", 8 + fig_offset),
            plot_residuals(ma, fig_dir / f"{pre}fig{9 + fig_offset}_residual_{name}.png", 9 + fig_offset),
        ]
        parts += [_img(p) for p in figs]
    return "\n".join(parts)


def write_report(result, record, out_dir, apply_record=None) -> Path:
    """Write ``report.html`` (figures embedded as base64, nothing fetched) plus ``analysis.json``."""
    out = Path(out_dir)
    fig_dir = out / "figures"
    write_json(result.to_dict(), out / "analysis.json")
    body = [f"<h1>fogdrift analysis of {html.escape(Path(result.source).name)}</h1>",
            '<p class="note">Rates in deg/h, τ in s. Method: Tang et al., Chinese J. Lasers 39(10) 2012, with the '
            "corrected IEEE-952 quantization relation (the paper's Table 1 Q formula is 3·3600² too large). "
            "The drift is separated inside each block, so no test information leaks into training.</p>"]
    body.append(_img(plot_signal(record, fig_dir / "fig1_signal.png")))
    body.append(_img(plot_spectrum(record, fig_dir / "fig2_spectrum.png")))
    body.append(_analysis_section(result, fig_dir, "Analysis"))
    if result.apply_to is not None:
        body.append(_analysis_section(result.apply_to, fig_dir,
                                      "Generalisation: fitted models applied unchanged to a second recording", 2))
    doc = (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>fogdrift report</title>"
           f"<style>{_CSS}</style></head><body>{''.join(body)}</body></html>")
    path = out / "report.html"
    with atomic_path(path) as tmp:
        tmp.write_text(doc, encoding="utf-8")
    return path
