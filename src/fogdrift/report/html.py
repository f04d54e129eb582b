"""The self-contained HTML report (figures embedded, nothing fetched, no script).

Reading order: the **summary** (recording, headline noise coefficients with intervals and fit quality, one
compensation verdict per axis coloured by outcome, what the record cannot support), the **settings** (all of
them), the recording's figures, then per axis its noise identification, separation and **compensation**
(heading-error table first, then the filtering-artefact check, the one-step skill against the causal drift,
and last the paper's measure: one-step metrics against the wavelet drift, Figs. 8-9 and Table 2 with the rows
whose improvement removes signal marked), the same for a second recording (``--apply-to``), and a glossary.
"""

from __future__ import annotations

import base64
import html
import struct
from datetime import datetime, timezone
from pathlib import Path

from ..evaluation.verdicts import CONSTANT_BIAS_LABEL, judge, one_step_lines, table2_marks
from ..models.registry import MODELS
from ..output import atomic_path
from ..temperature import summary_line
from .figures import (_safe, plot_allan, plot_dynamic_adev, plot_models, plot_residuals, plot_separation,
                      plot_separation_allan, plot_signal, plot_spectrum)
from .files import write_json
from .glossary import glossary_entries
from .settings import settings_rows
from .summary import (OUTCOME_LABELS, SPEC_LABELS, cannot_support, noise_headline, recording_rows, spec_summary,
                      summary_dict, verdict_items)
from .tables import (METRICS_HEADERS, NOISE_HEADERS, _fmt, causal_metrics_rows, fit_cell, metrics_rows, noise_notes, noise_row,
                     readout_text)
from .pdf import write_pdf
from .screen import screen_summary
from .sections import sections
from .temperature import plot_rate_and_temperature

__all__ = ["write_report", "render_report"]

#: Order of the compensators in the heading-error and artefact tables: the constant-bias baseline, then the
#: model registry's labels in its (report) order, persistence (the registry's last row) last; others follow the
#: registry's models.  ``"AR(p)"`` stands for every ``"AR(4)"``...
MODEL_ORDER = (CONSTANT_BIAS_LABEL,) + tuple(spec.label for spec in MODELS if spec.name != "persistence")

_CSS = """
*{box-sizing:border-box}
body{font-family:system-ui,-apple-system,"Segoe UI",sans-serif;max-width:1240px;margin:0 auto;padding:1em 20px;
 color:#1d1d1d;line-height:1.4}
h1{font-size:1.6em;margin:0.3em 0}h2{border-bottom:2px solid #ccc;padding-bottom:0.15em;margin-top:1.6em}
h3{margin-top:1.4em}h4{margin:1.2em 0 0.3em}
.meta{color:#555;margin:0 0 0.8em}
.tw{max-width:100%;overflow-x:auto}
table{border-collapse:collapse;margin:0.5em 0 0.8em;font-size:0.86em}
th,td{border:1px solid #c4c4c4;padding:3px 7px;text-align:right;vertical-align:top;overflow-wrap:normal;
 word-break:normal;hyphens:manual}
th{background:#eee}td:first-child,th:first-child{text-align:left}
table.kv td{text-align:left}table.screen td,table.intervals td:nth-child(2){text-align:left}table.limits td{text-align:left}table.heading td:nth-child(-n+2),table.heading th:nth-child(-n+2){white-space:nowrap;
 overflow-wrap:normal}table.heading td:nth-child(2){text-align:left}table.limits td:first-child{white-space:nowrap}table.kv td:first-child{white-space:nowrap;color:#444}
table.settings td{text-align:left}table.settings tr.group th{text-align:left;background:#dde6ef}
table.settings td:first-child{width:28%}
td.good{background:#d8f0dc}td.bad{background:#f9dcd9}td.flag{background:#fde7c2;font-weight:600}
tr.removes td{background:#fdf1dc}td.hz{white-space:nowrap}
figure{margin:0.8em 0 1.2em}figure img{display:block;width:100%;height:auto;border:1px solid #e3e3e3}
figcaption{color:#555;font-size:0.9em}
.note{color:#4a4a4a;font-size:0.92em}ul.note{padding-left:1.2em}
ul.verdicts{list-style:none;padding:0;margin:0.4em 0}
ul.verdicts li,.headline{margin:0.35em 0;padding:0.45em 0.8em;border-left:6px solid;border-radius:3px}
.badge{display:inline-block;min-width:7.5em;font-weight:700;font-size:0.8em;margin-right:0.6em;letter-spacing:0.03em}
.v-reduces{background:#e3f3e6;border-color:#2e7d32}.v-reduces .badge{color:#1b5e20}
.v-mixed{background:#fff3dc;border-color:#e69500}.v-mixed .badge{color:#8a5a00}
.v-none{background:#fbe4e2;border-color:#c62828}.v-none .badge{color:#a31515}
.v-undetermined{background:#eeeeee;border-color:#8a8a8a}.v-undetermined .badge{color:#555}
.measure{background:#f6f6f6;border-left:6px solid #aaa;padding:0.4em 0.8em;margin:0.5em 0}
.measure p{margin:0.2em 0}
section.summary{background:#fafbfd;border:1px solid #dfe4ea;border-radius:6px;padding:0.2em 1em 0.6em}
nav{font-size:0.92em;margin:0.6em 0}nav a{margin-right:1em}
dl.glossary dt{font-weight:600;margin-top:0.6em}dl.glossary dd{margin:0.1em 0 0 1.2em}
code{overflow-wrap:anywhere}
@media print{
 body{max-width:none;padding:0;font-size:10pt}
 .tw{overflow:visible}table{font-size:8pt}
 figure,table,ul.verdicts li,.headline{break-inside:avoid}h2,h3,h4{break-after:avoid}
 thead{display:table-header-group}nav{display:none}
 @page{size:A4;margin:12mm}
}
"""


# -------------------------------------------------------------------------------------------------------------
# HTML helpers


def _e(x) -> str:
    return html.escape(str(x))


def _png_size(data: bytes) -> tuple:
    """(width, height) from a PNG's IHDR chunk."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return None, None
    return struct.unpack(">II", data[16:24])


def _img(path, caption: str = "") -> str:
    data = Path(path).read_bytes()
    w, h = _png_size(data)
    size = f' width="{w}" height="{h}"' if w else ""
    src = base64.b64encode(data).decode("ascii")
    cap = f"<figcaption>{_e(caption)}</figcaption>" if caption else ""
    return f'<figure><img alt="{_e(Path(path).stem)}"{size} src="data:image/png;base64,{src}">{cap}</figure>'


def _cell(c, tag="td") -> str:
    """A cell: plain value (escaped) or ``(text, css_class)``."""
    if isinstance(c, tuple):
        text, cls = c
        return f'<{tag} class="{cls}">{_e(text)}</{tag}>' if cls else f"<{tag}>{_e(text)}</{tag}>"
    return f"<{tag}>{_e(c)}</{tag}>"


def _table(headers, rows, cls="", row_classes=None) -> str:
    head = "".join(_cell(h, "th") for h in headers)
    body = []
    for i, row in enumerate(rows):
        rc = (row_classes or {}).get(i)
        body.append((f'<tr class="{rc}">' if rc else "<tr>") + "".join(_cell(c) for c in row) + "</tr>")
    return f'<div class="tw"><table class="{cls}"><thead><tr>{head}</tr></thead><tbody>{"".join(body)}</tbody></table></div>'


def _ul(items, cls="note") -> str:
    return f'<ul class="{cls}">' + "".join(f"<li>{_e(i)}</li>" for i in items) + "</ul>" if items else ""


def _verdict_li(item, tag="li") -> str:
    o = item["outcome"]
    return (f'<{tag} class="v-{o}"><span class="badge">{OUTCOME_LABELS.get(o, o)}</span>'
            f"{_e(item['sentence'])}</{tag}>")


def _order(labels) -> list:
    def key(label):
        if label == "persistence":
            return (len(MODEL_ORDER) + 1, label)
        for i, name in enumerate(MODEL_ORDER):
            if label == name or (name.endswith("(p)") and label.startswith(name[:-2])):  # "AR(p)": "AR(4)"
                return (i, label)
        return (len(MODEL_ORDER), label)

    return sorted(dict.fromkeys(labels), key=key)


# -------------------------------------------------------------------------------------------------------------
# summary and settings


def _spec_block(spec: dict) -> str:
    """The datasheet comparison (``analyze --spec``, :func:`fogdrift.report.summary.spec_summary`): one verdict line
    per channel and item, badged pass / fail / cannot tell, and which B reading was compared."""
    parts = [f"<h3>Does it meet the datasheet? {_e(spec['title'])}: every limit an upper limit, judged with the "
             "95 % interval</h3>"]
    if spec["items"]:
        parts.append('<ul class="verdicts spec">' + "".join(
            f'<li class="v-{i["outcome"]}"><span class="badge">{SPEC_LABELS[i["verdict"]]}</span>{_e(i["line"])}</li>'
            for i in spec["items"]) + "</ul>")
    else:
        parts.append(f'<p class="note">{_e(spec["note"])}</p>')
    parts.append(f'<p class="note">{_e(spec["b_compared"])}.</p>')
    return "\n".join(parts)


def _screen_block(result, fig_dir) -> str:
    """The record screen on the first screen (:func:`fogdrift.report.screen.screen_summary`): per axis what disturbs
    it and what the noise fit used against the whole record, the disturbed intervals, and the dynamic ADEV figure
    of the disturbed axes (the values the screen holds; nothing recomputed)."""
    scr = screen_summary(result)
    if scr is None:
        return ""
    parts = ["<h3>Is the record stationary? The screen before the noise fit</h3>"]
    if not scr["disturbed"]:
        parts.append(f'<p class="note">No disturbed interval on any axis (false-alarm rate {scr["false_alarm"]:g} per '
                     "axis): the noise fit uses the whole record.</p>")
        return "\n".join(parts)
    parts.append(_table(scr["axes"]["headers"], scr["axes"]["rows"], "screen"))
    parts.append("<h4>Disturbed intervals (times from the first sample)</h4>")
    parts.append(_table(scr["intervals"]["headers"], scr["intervals"]["rows"], "intervals"))
    parts.append('<p class="note">A disturbance only adds to the sensor\'s own noise: the figures of the fit used '
                 "are the gyro's under the quiet part; the whole record's include the disturbance. Method and "
                 "characters (transient, level step, shock, vibration burst, warm-up): docs/disturbed-records.md.</p>")
    fig = plot_dynamic_adev([ax.original for ax in result.axes], Path(fig_dir) / "fig_dynamic_adev.png")
    if fig is not None:
        parts.append(_img(fig, "Dynamic Allan deviation of each disturbed axis: ADEV over sliding windows (1/8 of "
                               "the record, quarter-window steps) against time and τ; red above: the disturbed "
                               "intervals."))
    return "\n".join(parts)


def _summary_section(result, sensor, evaluated, spec=None, fig_dir=None) -> str:
    parts = ['<section class="summary" id="summary"><h2>Summary</h2>']
    parts.append(_table(["recording", ""], recording_rows(result, sensor), "kv"))
    headers, rows = noise_headline(result)
    parts.append("<h3>How noisy is this gyro? (native rate; value [95 % interval])</h3>")
    parts.append(_table(headers, rows, "noise"))
    parts.append('<p class="note">“– (&lt; x)”: not in the selected model, x = 95 % upper bound; “n/e”: not '
                 'estimable (why: below). Definitions in the <a href="#glossary">glossary</a>.</p>')
    if fig_dir is not None:
        parts.append(_screen_block(result, fig_dir))
    if spec is not None:
        parts.append(_spec_block(spec))
    parts.append("<h3>Did drift compensation help? Heading error after a static calibration, against "
                 "constant-bias compensation (held-out test block)</h3>")
    parts.append('<ul class="verdicts">' + "".join(_verdict_li(v) for v in verdict_items(result, evaluated=evaluated))
                 + "</ul>")
    if result.apply_to is not None:
        parts.append(f"<p>Models applied unchanged to {_e(Path(str(result.apply_to.source)).name)}:</p>")
        parts.append('<ul class="verdicts">' + "".join(_verdict_li(v) for v in
                                                       verdict_items(result.apply_to, evaluated=evaluated)) + "</ul>")
    cs = cannot_support(result)
    parts.append("<h3>What this record cannot support</h3>")
    if cs["terms"]:
        parts.append(_table(cs["term_headers"], cs["terms"], "limits"))
    parts.append(_ul(cs["items"]))
    parts.append("</section>")
    return "\n".join(parts)


def _settings_section(result, generated) -> str:
    rows = settings_rows(result, generated=generated)
    if result.apply_to is not None:
        rows += settings_rows(result.apply_to, generated=generated, title="applied recording: ")
    body, group = [], None
    for g, setting, value in rows:
        if g != group:
            body.append(f'<tr class="group"><th colspan="2">{_e(g)}</th></tr>')
            group = g
        body.append(f"<tr><td>{_e(setting)}</td><td>{_e(value)}</td></tr>")
    return ('<section id="settings"><h2>Settings</h2><div class="tw"><table class="settings"><tbody>'
            + "".join(body) + "</tbody></table></div></section>")


# -------------------------------------------------------------------------------------------------------------
# compensation tables


def _heading_table(h) -> str:

    headers = ["horizon", "compensator", "origins (independent)", "RMS angle error [deg]", "ratio to constant bias",
               "median |E| [deg]", "90th pct |E| [deg]", "better than constant bias at", "Kalman 1σ [deg] / inside"]
    rows = []
    for hz in h.horizons_s:
        by = {r.model: r for r in h.rows if r.horizon_s == hz}
        for label in _order(by):
            r = by[label]
            j = judge(r, step_s=h.step_s)  # the one rule: colour = what the verdict says
            k = j.n
            cls = ""
            if label != "constant bias":
                cls = "good" if j.reduces else ("bad" if j.worsens else "")
            div = j.outcome == "diverges"
            env = "–" if r.predicted_sigma_deg is None or div else \
                f"{_fmt(r.predicted_sigma_deg, 3)} / {100 * r.inside_sigma:.0f} %"
            wins = "–" if label == "constant bias" else (
                f"{'?' if j.better is None else j.better} of {k} non-overlapping ({100 * r.wins_vs_bias:.0f} % of all "
                f"{r.n_origins})")
            rows.append([f"{hz:g} s", label, f"{r.n_origins} ({k})", "diverges" if div else _fmt(r.rms_deg, 3),
                         ("1" if label == "constant bias" else ("diverges" if div else _fmt(r.ratio_to_bias, 3)), cls),
                         "diverges" if div else _fmt(r.median_abs_deg, 3), "diverges" if div else _fmt(r.p90_abs_deg, 3),
                         wins, env])
    return _table(headers, rows, "heading")


def _artefact_table(a) -> str:
    models = _order(r.model for r in a.rows if r.model != "constant bias")
    by = {r.model: r for r in a.rows}
    headers = [f"injected signal (amplitude {_fmt(a.amplitude_dph, 4)} deg/h)"] + models
    rows = []
    for f in a.frequencies_hz:
        cells = [(f"sinusoid {f:g} Hz: gain", "hz")]
        for m in models:
            g = by[m].gains.get(f)
            cls = "flag" if f in by[m].flagged_hz else ("bad" if g is not None and g < 0.9 else "")
            cells.append((_fmt(g, 2) + (" ⚑" if cls == "flag" else ""), cls))
        rows.append(cells)
    for d in a.step_delays_s:
        rows.append([f"step: surviving after {d:g} s"] + [_fmt(by[m].step_survival.get(d), 2) for m in models])
    rows.append(["ramp: surviving slope"] + [_fmt(by[m].ramp_survival, 2) for m in models])
    rows.append(["flagged [Hz]"] + [(", ".join(f"{f:g}" for f in by[m].flagged_hz) or "–",
                                     "flag" if by[m].flagged_hz else "") for m in models])
    return _table(headers, rows, "artefacts")


def _measure(title, lines) -> str:
    return (f'<div class="measure"><p><strong>{_e(title)}</strong></p>'
            + "".join(f"<p>{_e(line)}</p>" for line in lines) + "</div>")


def _compensation_section(ax, fig_dir, pre, fig_offset, evaluated) -> str:

    ma, ev = ax.models, getattr(ax, "evaluation", None)
    name = _safe(ax.name)
    parts = [f'<h3 id="{_e(pre)}comp-{_e(name)}">Compensation, axis {_e(ax.name)}</h3>']
    verdicts = {}
    if ev is None:
        item = {"outcome": "undetermined", "sentence": f"{ax.name}: heading error and artefact check not run"
                + (" (analyze --no-heading)." if not evaluated else ".")}
        parts.append(_verdict_li(item, "div").replace('class="v-', 'class="headline v-', 1))
    else:
        verdicts = {v.kind: v for v in ev.verdicts}
        parts.append(_verdict_li({"outcome": ev.outcome, "sentence": ev.headline.lines[0]}, "div")
                     .replace('class="v-', 'class="headline v-', 1))
        h = ev.heading
        title = (f"1. Heading error after a {h.calib_s:g}-s static calibration (test block, origins every "
                 f"{h.step_s:g} s)" if h is not None else "1. Heading error")
        parts.append(f"<h4>{_e(title)}</h4>")
        if h is not None:
            parts.append(_table_note_heading() + _heading_table(h))
            parts.append(_ul(verdicts["heading"].lines + h.notes if "heading" in verdicts else h.notes))
        parts.append(_ul([n for n in ev.notes if "heading" in n]))
        parts.append("<h4>2. Filtering-artefact check: how much injected real rate survives each compensator</h4>")
        if ev.artefacts is not None:
            parts.append(_artefact_table(ev.artefacts))
            parts.append(_ul(verdicts["artefacts"].lines if "artefacts" in verdicts else []))
            parts.append('<p class="note">Gain 1 = the signal passes untouched; ⚑ = flagged: more than 10 % of a '
                         "real signal removed where the compensator's Allan curve “improves”.</p>")
        parts.append(_ul([n for n in ev.notes if "artefact" in n]))
    parts.append("<h4>3. One-step skill against the causal drift (what a real-time compensator sees)</h4>")
    parts.append(_table(METRICS_HEADERS, causal_metrics_rows(ma), "metrics"))
    if "causal" in verdicts:
        parts.append(_ul(verdicts["causal"].lines))
    parts.append("<h4>4. Paper's measure: one-step metrics against the non-causal wavelet drift (not a "
                 "compensation result)</h4>")
    parts.append(_table(METRICS_HEADERS, metrics_rows(ma), "metrics"))
    parts.append(_measure("Paper's measure (one step ahead; target = wavelet drift of the test block, which uses "
                          "future samples):", one_step_lines(ma)))
    parts.append('<p class="note">p0 is NaN where the drift crosses zero (see <a href="#g-p0">p0</a>); the first '
                 f"{ma.score_from} test samples are not scored.</p>")
    parts.append(_img(plot_models(ma, fig_dir / f"{pre}fig{8 + fig_offset}_models_{name}.png", 8 + fig_offset)))
    parts.append(_img(plot_residuals(ma, fig_dir / f"{pre}fig{9 + fig_offset}_residual_{name}.png", 9 + fig_offset)))
    parts.append("<h4>5. Paper's measure: Table 2, noise coefficients before and after compensation (test block, "
                 "modelling rate)</h4>")
    marks = table2_marks(ax.table2, ev.artefacts) if ev is not None and ev.artefacts is not None else {}
    rows, rc = [], {}
    for i, r in enumerate(ax.table2):
        mark = marks.get(r.label, "")
        rows.append([r.label] + noise_row(r.analysis.noise) + [fit_cell(r.analysis.noise), mark or "–"])
        if mark:
            rc[i] = "removes"
    parts.append(_table(("signal",) + NOISE_HEADERS + ("fit", "artefact check"), rows, "table2", rc))
    parts.append('<p class="note">“drift residual (paper)”: wavelet drift minus its one-step prediction (the '
                 "paper's Table 2 and Fig. 9); “practical”: gyro output minus the one-step prediction from the "
                 "causal drift. A marked row “improves” a coefficient by removing real rate (artefact check).</p>")
    return "\n".join(parts)


def _table_note_heading() -> str:
    return ('<p class="note">Angle error of each compensator after each horizon (RMS over rolling origins); ratio '
            "to constant bias at or below 0.95 AND better at more than half of the origins whose horizons do not "
            "overlap (green) reduces the error; at or above 1.05 AND worse at more than half of them, or a diverged "
            "forecast (red), worsens it; only horizons with 10 non-overlapping origins are judged (uncoloured "
            'otherwise). See <a href="#g-heading">heading error</a>.'
            "</p>")


# -------------------------------------------------------------------------------------------------------------
# sections


def _axis_section(ax, result, fig_dir, pre, fig_offset, evaluated) -> str:
    """One axis: its heading, then every ``axis`` row of :data:`fogdrift.report.sections.SECTIONS` in order."""
    name = _safe(ax.name)
    parts = [f'<section id="{_e(pre)}axis-{_e(name)}"><h2>{"Applied: " if pre else ""}Axis {_e(ax.name)}</h2>',
             "<h3>Noise identification (whole record, native rate)</h3>"]
    parts += [s.render(ax, result, fig_dir, pre, fig_offset, evaluated) for s in sections("axis")]
    return "\n".join([p for p in parts if p] + ["</section>"])


def noise_block(ax, result, fig_dir, pre, fig_offset, evaluated) -> str:
    """Section ``noise``: the Allan-fit noise table of the whole record, its notes, slope read-outs, Fig. 3."""
    name = _safe(ax.name)
    return "\n".join([
        _table(("signal",) + NOISE_HEADERS, [["original"] + noise_row(ax.original.noise)], "allan"),
        _ul(noise_notes(ax.original.noise)),
        '<p class="note">Slope read-outs (cross-check): ' + _e(readout_text(ax.original.noise)) + "</p>",
        _img(plot_allan([ax.original], fig_dir / f"{pre}fig3_allan_{name}.png", "Allan deviation (Fig. 3)"))])


def separation_block(ax, result, fig_dir, pre, fig_offset, evaluated) -> str:
    """Section ``separation``: drift and white noise of the whole record (Fig. 5) and their ADEV (Fig. 6)."""
    name = _safe(ax.name)
    return "\n".join([
        "<h3>Drift / noise separation</h3>",
        _img(plot_separation(ax.separation, fig_dir / f"{pre}fig5_drift_noise_{name}.png", ax.models.split),
             "The models separate inside each block (no test information reaches training); this figure "
             "separates the whole record for display."),
        _img(plot_separation_allan(ax.separation, fig_dir / f"{pre}fig6_allan_{name}.png"))])


def compensation_block(ax, result, fig_dir, pre, fig_offset, evaluated) -> str:
    """Section ``compensation`` (:func:`_compensation_section`)."""
    return _compensation_section(ax, fig_dir, pre, fig_offset, evaluated)


def _split_seconds(result) -> dict | None:
    if not result.axes:
        return None
    ma = result.axes[0].models
    t0 = float(result.record.get("t0_s") or 0.0)
    return {k: (t0 + a * ma.dt_s, t0 + b * ma.dt_s) for k, (a, b) in ma.split.items()}


def _glossary_section() -> str:
    items = "".join(f'<dt id="g-{_e(a)}">{_e(t)}</dt><dd>{_e(x)}</dd>' for t, a, x in glossary_entries())
    return f'<section id="glossary"><h2>Glossary</h2><dl class="glossary">{items}</dl></section>'


def signal_block(result, record, fig_dir) -> str:
    """Section ``signal``: Fig. 1, the output of every axis with the chronological split."""
    return _img(plot_signal(record, fig_dir / "fig1_signal.png", _split_seconds(result)))


def spectrum_block(result, record, fig_dir) -> str:
    """Section ``spectrum``: Fig. 2, the output's spectrum as the workflow computed it (each axis's ``spectrum``;
    ``""`` when the result holds none)."""
    shown = [ax for ax in result.axes if getattr(ax, "spectrum", None) is not None]
    return _img(plot_spectrum(shown, fig_dir / "fig2_spectrum.png")) if shown else ""


def temperature_block(result, record, fig_dir) -> str:
    """Section ``temperature``: rate and temperature against time, with the temperature's range and drift (the
    result's ``record["temperature"]``, summarised when the record was read), when the log carries one (``""``
    otherwise)."""
    summary = (result.record or {}).get("temperature")
    if getattr(record, "temperature_c", None) is None or summary is None:
        return ""
    line = summary_line(summary)
    return (f'<h3>Temperature</h3><p class="note">{_e(line)}. The noise fit and the drift models use the '
            "rate only, not the temperature: a drift that follows this temperature history need not repeat "
            "under another.</p>"
            + _img(plot_rate_and_temperature(record, fig_dir / "fig_temperature.png", summary=summary)))


def render_report(result, record, fig_dir, *, sensor=None, evaluated=True, generated=None, spec=None) -> str:
    """The report's HTML text (figures written to ``fig_dir`` and embedded); ``spec``: the datasheet comparison
    for the first screen (:func:`fogdrift.report.summary.spec_summary`), none when None."""
    fig_dir = Path(fig_dir)
    generated = generated or datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    src = Path(str(result.source)).name
    nav = ['<a href="#summary">Summary</a>', '<a href="#settings">Settings</a>', '<a href="#recording">Recording</a>']
    nav += [f'<a href="#axis-{_e(_safe(a.name))}">Axis {_e(a.name)}</a>' for a in result.axes]
    if result.apply_to is not None:
        nav.append('<a href="#applied">Applied recording</a>')
    nav.append('<a href="#glossary">Glossary</a>')
    body = [f"<h1>fogdrift report: {_e(src)}</h1>",
            f'<p class="meta">{_e(generated)} · fogdrift {_e(result.versions.get("fogdrift", "?"))} · rates in '
            "deg/h, τ in s</p>",
            _summary_section(result, sensor, evaluated, spec, fig_dir), f"<nav>{''.join(nav)}</nav>",
            _settings_section(result, generated),
            '<section id="recording"><h2>Recording</h2>',
            '<p class="note">Method: Tang et al., Chinese J. Lasers 39(10) 2012, with the corrected IEEE-952 '
            "quantization relation (the paper's Table 1 Q formula is 3·3600² too large). The drift is separated "
            "inside each block, so no test information leaks into training.</p>",
            *[s.render(result, record, fig_dir) for s in sections("recording")], "</section>"]
    body += [_axis_section(ax, result, fig_dir, "", 0, evaluated) for ax in result.axes]
    if result.apply_to is not None:
        body.append(f'<section id="applied"><h2>Generalisation: fitted models applied unchanged to '
                    f"{_e(Path(str(result.apply_to.source)).name)}</h2></section>")
        body += [_axis_section(ax, result.apply_to, fig_dir, "apply_to_", 2, evaluated) for ax in result.apply_to.axes]
    body.append(_glossary_section())
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>fogdrift report: {_e(src)}</title><style>{_CSS}</style></head><body>{''.join(body)}</body></html>")


def write_report(result, record, out_dir, apply_record=None, *, sensor=None, evaluated=True, pdf=False,
                 spec=None) -> Path:
    """Write ``report.html`` (figures embedded as base64, nothing fetched) and ``analysis.json`` (the result,
    with the first screen as data under ``report_summary``); with ``pdf``, also ``report.pdf`` (headless
    Chromium, :mod:`fogdrift.report.pdf`).

    ``evaluated`` False says in the report that the heading-error evaluation was skipped on purpose
    (``analyze --no-heading``); ``sensor`` names the sensor on the first screen; ``spec`` (``analyze --spec``:
    ``{"limits": parsed spec, "judgements": [Judgement, ...], "source": file name}``, the judgements the caller
    made, :func:`fogdrift.spec.analysis_judgements`) puts the datasheet verdicts on the first screen and
    under ``report_summary.spec`` (:func:`fogdrift.report.summary.spec_summary`).
    """
    out = Path(out_dir)
    if spec is not None:
        spec = spec_summary(spec["limits"], spec["judgements"], spec.get("source", ""))
    doc = result.to_dict()
    doc["report_summary"] = summary_dict(result, sensor, evaluated=evaluated, spec=spec)
    write_json(doc, out / "analysis.json")
    page = render_report(result, record, out / "figures", sensor=sensor, evaluated=evaluated, spec=spec)
    path = out / "report.html"
    with atomic_path(path) as tmp:
        tmp.write_text(page, encoding="utf-8")
    if pdf:

        write_pdf(path, out / "report.pdf")
    return path
