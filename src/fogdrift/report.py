"""Render fogdrift results: tables (rows of strings with units), figures (matplotlib PNG), JSON/CSV files and
one self-contained HTML report.

This module only reads results produced by the library (:mod:`fogdrift.pipeline`); the library never imports it.
Figures follow the reference paper's numbering (Tang et al. 2012): 1 signal, 2 spectrum, 3 Allan, 5 drift and
white noise, 6 Allan of the drift, 8 model against drift, 9 residual, 10–11 the same on a second recording.
"""

from __future__ import annotations

import base64
import html
import json
import math
import re
from pathlib import Path

import numpy as np

from ._util import json_default
from .output import atomic_path

__all__ = [
    "NOISE_HEADERS",
    "noise_row",
    "metrics_rows",
    "METRICS_HEADERS",
    "write_json",
    "write_allan_outputs",
    "write_separation_outputs",
    "write_model_outputs",
    "write_report",
    "verdict",
]

#: Column headers of a Q, N, B, K, R table, units included.
NOISE_HEADERS = ("Q [µrad]", "N [deg/√h]", "B [deg/h]", "K [deg/h^1.5]", "R [deg/h²]")

METRICS_HEADERS = (
    "model",
    "RMSE [deg/h]",
    "MAE [deg/h]",
    "max|e| [deg/h]",
    "MASE",
    "skill vs persistence",
    "p0 [%]",
    "p0_w [%]",
    "p0 as measured [%] (persistence)",
)


def _fmt(x, digits=4) -> str:
    if x is None:
        return "–"
    x = float(x)
    if not math.isfinite(x):
        return "NaN"
    if x == 0:
        return "0"
    if abs(x) >= 1e4 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def term_text(term) -> str:
    """``value [lo95, hi95]`` for a term in the model; ``- (< hi95)`` for one that is not; ``n/e`` when the data
    cannot support a number (the reason is in the notes)."""
    if term.value is None:
        if term.status == "not_estimable":
            return "n/e" if term.hi95 is None else f"n/e (< {_fmt(term.hi95, 3)})"
        return "–" if term.hi95 is None else f"– (< {_fmt(term.hi95, 3)})"
    text = _fmt(term.value)
    if term.lo95 is not None and term.hi95 is not None:
        text += f" [{_fmt(term.lo95, 3)}, {_fmt(term.hi95, 3)}]"
    return text


def noise_row(noise) -> list[str]:
    """Five cells Q, N, B, K, R of a NoiseFit (95 % intervals in brackets; – = not in the model, with its upper
    bound; n/e = not estimable)."""
    return [term_text(noise.terms[name]) for name in ("Q", "N", "B", "K", "R")]


def fit_summary(noise) -> str:
    """One line: the selected model, the fit statistic and p-value, the fitted tau range."""
    return (f"model {'+'.join(noise.selected) or '(none)'} selected from {len(noise.candidates)} candidates; "
            f"chi2_red {_fmt(noise.chi2_red, 3)} on {noise.dof} dof (p = {noise.p_value:.2g}, fit {noise.quality}); "
            f"fitted tau {_fmt(noise.tau_min_s, 3)} .. {_fmt(noise.tau_max_s, 3)} s")


def readout_text(noise) -> str:
    """The classic IEEE-952 slope read-outs, labelled as a cross-check (with where each was read)."""
    parts = [ro.text() for ro in noise.readouts.values() if ro.value is not None]
    return "; ".join(parts) if parts else "no term's slope is visible in the curve"


def noise_notes(noise) -> list[str]:
    """Everything a reader needs beside the table, in words: fit quality, what was left out and why, the
    classical bias instability, each term that is not resolved and why, outliers."""
    out = [fit_summary(noise)]
    for e in noise.excluded:
        out.append(f"left out tau {_fmt(e['tau_min_s'], 3)} .. {_fmt(e['tau_max_s'], 3)} s: {e['reason']}")
    out += list(noise.notes)
    b = noise.b_min or {}
    if b.get("value") is not None:
        if b.get("bound_only"):
            why = ("the fitted flat floor lies above the measured curve, so the measured minimum bounds it"
                   if "measured curve" in b.get("rule", "") else "the curve still falls at the longest tau")
            out.append(f"bias instability (IEEE reading at the ADEV minimum): B_min < {_fmt(b['value'], 3)} deg/h "
                       f"(min at tau = {_fmt(b['tau_s'], 3)} s; {why})")
        else:
            which = "measured" if "measured ADEV" in b.get("rule", "") else "fitted"
            out.append(f"bias instability (IEEE reading, min of the {which} ADEV / 0.664): B_min = {_fmt(b['value'], 3)} "
                       f"deg/h at tau = {_fmt(b['tau_s'], 3)} s")
    for t in noise.terms.values():
        if t.reason and t.status != "resolved":
            out.append(f"{t.name}: {t.reason}")
    if noise.outliers and noise.outliers.get("count"):
        o = noise.outliers
        out.append(f"outliers: {o['count']} samples ({100 * o['fraction']:.3g} %) beyond {o['threshold_sigma']:g} "
                   f"robust sigma, action: {o['action']}")
    return out


def not_estimable_notes(noise) -> list[str]:
    """Kept for callers of the earlier API: the notes of :func:`noise_notes`."""
    return noise_notes(noise)


def metrics_rows(model_axis) -> list[list[str]]:
    """One row per model of the test-block metrics (paper target: the wavelet drift of the test block)."""
    rows = []
    for label, m in model_axis.metrics.items():
        p0m, p0p = model_axis.p0_as_measured.get(label, (float("nan"), float("nan")))
        rows.append([
            label, _fmt(m.rmse_dph), _fmt(m.mae_dph), _fmt(m.max_abs_dph), _fmt(m.mase), _fmt(m.skill),
            _fmt(m.p0_pct), _fmt(m.p0_weighted_pct), f"{_fmt(p0m, 5)} ({_fmt(p0p, 5)})",
        ])
    return rows


def causal_metrics_rows(model_axis) -> list[list[str]]:
    rows = []
    for label, m in model_axis.causal_metrics.items():
        rows.append([label, _fmt(m.rmse_dph), _fmt(m.mae_dph), _fmt(m.max_abs_dph), _fmt(m.mase), _fmt(m.skill),
                     _fmt(m.p0_pct), _fmt(m.p0_weighted_pct), "–"])
    return rows


def verdict(model_axis) -> list[str]:
    """Plain-language sentences: which model beat persistence on the test block, judged on RMSE and MAE.

    A model "beat" persistence only if both its RMSE and its MAE are lower; if one is lower and the other
    higher the verdict says "mixed" (RMSE is dominated by a few large errors, MAE by typical ones).
    """
    learned = {k: v for k, v in model_axis.metrics.items() if k != "persistence"}
    if not learned:
        return ["Only the persistence baseline was run."]
    any_m = next(iter(model_axis.metrics.values()))
    p_rmse = any_m.rmse_persistence_dph
    p_mae = model_axis.metrics["persistence"].mae_dph if "persistence" in model_axis.metrics else None
    lines = []
    for label, m in learned.items():
        d_rmse = 100.0 * (m.rmse_dph / p_rmse - 1.0)
        text = f"RMSE {_fmt(m.rmse_dph)} vs {_fmt(p_rmse)} deg/h ({d_rmse:+.1f} %)"
        if p_mae is None:
            better = d_rmse < 0
            word = "beat" if better else "did NOT beat"
        else:
            d_mae = 100.0 * (m.mae_dph / p_mae - 1.0)
            text += f", MAE {_fmt(m.mae_dph)} vs {_fmt(p_mae)} deg/h ({d_mae:+.1f} %)"
            if d_rmse < 0 and d_mae < 0:
                word = "beat"
            elif d_rmse >= 0 and d_mae >= 0:
                word = "did NOT beat"
            else:
                word = "gave a MIXED result against"
        lines.append(f"{label} {word} persistence one step ahead: {text}.")
    best = min(learned, key=lambda k: learned[k].rmse_dph)
    lines.append(f"Lowest RMSE among learned models on the test block: {best}.")
    return lines


# -------------------------------------------------------------------------------------------------------------
# files


def _clean(obj):
    """Replace NaN/inf by None so the JSON is strict."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    return obj


def write_json(obj, path) -> Path:
    path = Path(path)
    data = json.loads(json.dumps(obj, default=json_default))
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(_clean(data), indent=2, allow_nan=False))
    return path


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path) -> Path:
    path = Path(path)
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=110, bbox_inches="tight")
    finally:
        _plt().close(fig)
    return path


def _safe(name) -> str:
    """An axis or model name as a file-name part (deterministic; no path separators)."""
    return re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._") or "axis"


# -------------------------------------------------------------------------------------------------------------
# figures


def plot_allan(axes_list, path, title=None) -> Path:
    """Fig. 3: log-log deviation with 68 % error bars, the fitted curve over the fitted range (points used marked,
    left-out taus shaded), each selected term's asymptote, and the fit statistic."""
    plt = _plt()
    n = len(axes_list)
    fig, axs = plt.subplots(1, n, figsize=(5.6 * n, 4.6), squeeze=False)
    for ax, aa in zip(axs[0], axes_list):
        r, fit = aa.allan, aa.noise
        label = {"adev": "ADEV", "hdev": "HDEV", "mdev": "MDEV"}.get(getattr(r, "statistic", "adev"), "deviation")
        yerr = np.vstack([r.dev_dph - r.dev_lo68_dph, r.dev_hi68_dph - r.dev_dph])
        ax.errorbar(r.tau_s, r.dev_dph, yerr=yerr, fmt="o", ms=3, color="k", lw=0.8, mfc="white",
                    label=f"{label} (68 % CI)")
        used = np.isin(np.round(r.tau_s, 12), np.round(fit.fit_tau_s, 12))
        ax.plot(r.tau_s[used], r.dev_dph[used], "o", ms=4.5, color="k", zorder=4, label="fitted points")
        for e in fit.excluded:
            ax.axvspan(e["tau_min_s"] / 1.2, e["tau_max_s"] * 1.2, color="0.85", zorder=0, label="left out")
        tau = np.logspace(np.log10(fit.tau_min_s), np.log10(fit.tau_max_s), 200)
        ax.loglog(tau, fit.model_dev_dph(tau), "r-", lw=1.6, label=f"fit {'+'.join(fit.selected)}")
        for name, style in zip(("Q", "N", "B", "K", "R"), ("--", "-.", ":", "--", "-.")):
            if name in fit.selected and fit.terms[name].value:
                ax.loglog(tau, fit.term_dev_dph(name, tau), style, lw=0.9, label=name)
        pos = r.dev_lo68_dph > 0
        lo = np.nanmin(r.dev_lo68_dph[pos]) if np.any(pos) else np.nanmin(r.dev_dph)
        ax.set_ylim(lo / 3, np.nanmax(r.dev_hi68_dph) * 3)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("τ [s]")
        ax.set_ylabel(f"{label} σ(τ) [deg/h]")
        ax.set_title(f"{title or label}: {aa.name}\nχ²_red {fit.chi2_red:.3g}, p = {fit.p_value:.2g} ({fit.quality})",
                     fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    return _save(fig, path)


def plot_signal(record, path) -> Path:
    """Fig. 1: the rate signal of every axis over time."""
    plt = _plt()
    fig, axs = plt.subplots(record.n_axes, 1, figsize=(9, 2.2 * record.n_axes), squeeze=False, sharex=True)
    t = record.t0_s + np.arange(record.n_samples) * record.dt_s
    step = max(1, record.n_samples // 20000)  # plot at most ~20k points per axis
    for ax, name in zip(axs[:, 0], record.axis_names):
        ax.plot(t[::step], np.asarray(record.axis(name))[::step], lw=0.4)
        ax.set_ylabel(f"{name} [deg/h]")
        ax.grid(alpha=0.3)
    axs[-1, 0].set_xlabel("t [s]")
    fig.suptitle("Gyro output (Fig. 1)")
    return _save(fig, path)


def plot_spectrum(record, path) -> Path:
    """Fig. 2: Welch power spectral density of every axis."""
    from scipy.signal import welch

    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4))
    for name in record.axis_names:
        x = np.asarray(record.axis(name), dtype=float)
        f, p = welch(x - x.mean(), fs=record.fs_hz, nperseg=min(len(x), 4096))
        ax.loglog(f[1:], p[1:], lw=0.8, label=name)
    ax.set_xlabel("f [Hz]")
    ax.set_ylabel("PSD [(deg/h)²/Hz]")
    ax.set_title("Spectrum of the output (Fig. 2)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return _save(fig, path)


def plot_separation(sep, path) -> Path:
    """Fig. 5: drift and white noise over time."""
    plt = _plt()
    t = np.arange(sep.rate_dph.size) * sep.dt_s
    fig, axs = plt.subplots(2, 1, figsize=(9, 4.5), sharex=True)
    axs[0].plot(t, sep.rate_dph, lw=0.4, color="0.7", label="input")
    axs[0].plot(t, sep.drift_dph, lw=1.0, color="C3", label=f"drift (approximation, level {sep.level})")
    axs[0].set_ylabel("[deg/h]")
    axs[0].legend(fontsize=7)
    axs[1].plot(t, sep.noise_dph, lw=0.4, color="C0", label="white noise (details)")
    axs[1].set_ylabel("[deg/h]")
    axs[1].set_xlabel("t [s]")
    axs[1].legend(fontsize=7)
    for ax in axs:
        ax.grid(alpha=0.3)
    fig.suptitle(f"Drift and white noise, axis {sep.name}, dt = {sep.dt_s:g} s (Fig. 5)")
    return _save(fig, path)


def plot_separation_allan(sep, path) -> Path:
    """Fig. 6: ADEV of original, drift and noise."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for (label, aa), color in zip(sep.rows, ("k", "C3", "C0")):
        r = aa.allan
        yerr = np.vstack([r.dev_dph - r.dev_lo68_dph, r.dev_hi68_dph - r.dev_dph])
        ax.errorbar(r.tau_s, r.dev_dph, yerr=yerr, fmt="o-", ms=3, lw=0.8, color=color, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("τ [s]")
    ax.set_ylabel("σ(τ) [deg/h]")
    ax.set_title(f"Allan deviation of drift and noise, axis {sep.name} (Fig. 6)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return _save(fig, path)


def plot_models(model_axis, path, fig_no=8, *, residual=False) -> Path:
    """Fig. 8: one-step predictions against the test-block drift; with ``residual``, Fig. 9: drift minus
    each one-step prediction (the residual drift after compensation)."""
    plt = _plt()
    e, _ = model_axis.split["test"]
    y = model_axis.drift_blocks["test"]
    t = (e + np.arange(y.size)) * model_axis.dt_s
    fig, ax = plt.subplots(figsize=(9, 4))
    if not residual:
        ax.plot(t, y, "k-", lw=1.6, label="wavelet drift (test block)")
    for label, yhat in model_axis.predictions.items():
        ax.plot(t, y - yhat if residual else yhat, lw=0.8 if residual else 0.9, label=label)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("residual [deg/h]" if residual else "drift [deg/h]")
    what = "Residual after drift compensation" if residual else "One-step drift models"
    ax.set_title(f"{what}, axis {model_axis.name} (Fig. {fig_no})")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return _save(fig, path)


def plot_residuals(model_axis, path, fig_no=9) -> Path:
    """Fig. 9: residual drift after compensation (drift minus one-step model) on the test block."""
    return plot_models(model_axis, path, fig_no, residual=True)


# -------------------------------------------------------------------------------------------------------------
# per-command outputs


def _noise_csv_rows(label, aa):
    cells = []
    for name in ("Q", "N", "B", "K", "R"):
        t = aa.noise.terms[name]
        cells += [t.value, t.lo95, t.hi95]
    return [label] + ["" if c is None else repr(float(c)) for c in cells]


def _noise_csv_header():
    from .noise import TERM_TABLE

    head = ["signal"]
    for name, spec in TERM_TABLE.items():
        head += [f"{name}{spec.suffix}", f"{name}_lo95{spec.suffix}", f"{name}_hi95{spec.suffix}"]
    return head


def _write_rows_csv(path, header, rows) -> Path:
    path = Path(path)
    with atomic_path(path) as tmp, open(tmp, "w") as fh:
        fh.write(",".join(header) + "\n")
        for row in rows:
            fh.write(",".join(str(c) for c in row) + "\n")
    return path


def write_allan_outputs(allan_axes, record, out_dir) -> dict:
    """``allan.json``, ``allan.csv`` (curve of every axis, with units) and ``allan.png``."""
    out = Path(out_dir)
    write_json({"source": record.source, "record": record.metadata(),
                "axes": [a.to_dict() for a in allan_axes]}, out / "allan.json")
    rows = []
    for a in allan_axes:
        r = a.allan
        for i in range(r.tau_s.size):
            rows.append([a.name, repr(float(r.tau_s[i])), int(r.m[i]), repr(float(r.dev_dph[i])),
                         repr(float(r.var_dph2[i])), int(r.n_terms[i]), repr(float(r.edf[i])),
                         repr(float(r.dev_lo68_dph[i])), repr(float(r.dev_hi68_dph[i])),
                         repr(float(r.dev_lo95_dph[i])), repr(float(r.dev_hi95_dph[i]))])
    dev = {"adev": "adev", "hdev": "hdev", "mdev": "mdev"}.get(getattr(allan_axes[0].allan, "statistic", "adev"), "dev")
    var = {"adev": "avar", "hdev": "hvar", "mdev": "mvar"}.get(dev, "var")
    _write_rows_csv(out / "allan.csv",
                    ["axis", "tau_s", "m", f"{dev}_dph", f"{var}_dph2", "n_terms", "edf", f"{dev}_lo68_dph",
                     f"{dev}_hi68_dph", f"{dev}_lo95_dph", f"{dev}_hi95_dph"], rows)
    plot_allan(allan_axes, out / "allan.png")
    return {"json": out / "allan.json", "csv": out / "allan.csv", "png": out / "allan.png"}


def write_separation_outputs(seps, out_dir) -> dict:
    """Drift and noise series (CSV and NPZ), Fig. 5 and 6 per axis, the Q..R table (JSON and CSV)."""
    out = Path(out_dir)
    arrays = {}
    for s in seps:
        arrays[f"{s.name}_input_dph"] = s.rate_dph
        arrays[f"{s.name}_drift_dph"] = s.drift_dph
        arrays[f"{s.name}_noise_dph"] = s.noise_dph
    with atomic_path(out / "separation.npz") as tmp:
        np.savez(tmp, dt_s=np.array(seps[0].dt_s), **arrays)
    n = seps[0].rate_dph.size
    cols = ["t_s"] + list(arrays)
    data = np.column_stack([np.arange(n) * seps[0].dt_s] + [arrays[c] for c in cols[1:]])
    with atomic_path(out / "separation.csv") as tmp:
        np.savetxt(tmp, data, delimiter=",", header=",".join(cols), comments="", fmt="%.10g")
    rows = [_noise_csv_rows(f"{s.name}:{label}", aa) for s in seps for label, aa in s.rows]
    _write_rows_csv(out / "separation_table.csv", _noise_csv_header(), rows)
    write_json({"axes": [s.to_dict() for s in seps]}, out / "separation.json")
    files = {}
    for s in seps:
        files[f"fig5_{s.name}"] = plot_separation(s, out / f"fig5_drift_noise_{_safe(s.name)}.png")
        files[f"fig6_{s.name}"] = plot_separation_allan(s, out / f"fig6_allan_{_safe(s.name)}.png")
    return files


def write_model_outputs(model_axes, out_dir) -> dict:
    """Saved models (JSON + NPZ), metrics JSON, Fig. 8 and 9 per axis."""
    out = Path(out_dir)
    for ma in model_axes:
        for label, model in ma.fitted.items():
            safe = label.replace("(", "").replace(")", "").replace(",", "").replace(" ", "_").lower()
            model.save(out / "models" / f"{_safe(ma.name)}_{_safe(safe)}")
        plot_models(ma, out / f"fig8_models_{_safe(ma.name)}.png")
        plot_residuals(ma, out / f"fig9_residual_{_safe(ma.name)}.png")
    write_json({"axes": [ma.to_dict() for ma in model_axes]}, out / "metrics.json")
    return {"dir": out}


# -------------------------------------------------------------------------------------------------------------
# HTML report


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
