"""The report's settings table: every setting of the run and what the run derived from it.

Rows are ``[group, setting, value]`` strings: the run (version, date, input and its SHA-256), Earth rate,
training-block bias, split (sample indices and times), separation, Allan analysis, outliers, every drift
model's hyper-parameters and where its training stopped, and the evaluation settings.
"""

from __future__ import annotations

from ..signal import record_sampling, record_units
from .glossary import plain_name, plain_setting
from .tables import _fmt

__all__ = ["settings_rows", "unit_row"]

#: Parameters of a model that are plumbing, not settings (never shown).
_HIDDEN_PARAMS = {"progress"}


def _params_text(params: dict) -> str:
    return ", ".join(plain_setting(k, v) for k, v in params.items() if k not in _HIDDEN_PARAMS) or "no parameters"


def _fitted_text(model) -> str:
    """What training found/decided for one model (stopping epoch, order, components), or ''."""
    if getattr(model, "best_epoch_", None) is not None:
        cap = getattr(model, "epochs", None)
        how = (f"early stop after {model.n_epochs_} epochs (patience {getattr(model, 'patience', '?')})"
               if cap is not None and model.n_epochs_ < cap else f"all {model.n_epochs_} epochs run (no early stop)")
        return f"{how}; kept epoch {model.best_epoch_ + 1} (best validation loss)"
    if getattr(model, "order_", None) is not None:
        return f"order {model.order_}"
    if getattr(model, "components_", None) is not None:
        comps = []
        for c in model.components_:
            vals = ", ".join(plain_setting(k, v, lambda x: _fmt(x, 3)) for k, v in c.items() if k != "kind")
            kind = plain_name(str(c.get("kind")))[0]
            comps.append(f"{kind} ({vals})" if vals else kind)
        ident = getattr(model, "identification_", {}) or {}
        how = f" from the {plain_name(ident['method'])[0]} fit of the training block" if ident.get("method") else ""
        return "states: " + "; ".join(comps) + how
    if getattr(model, "grade_", None) is not None:
        return f"accuracy grade {model.grade_}, shift {_fmt(getattr(model, 'shift_', None), 4)} deg/h"
    return ""


def _split_text(ma, t0_s: float) -> str:
    parts = []
    for name in ("train", "val", "test"):
        a, b = ma.split[name]
        parts.append(f"{name} [{a}, {b}) = {_fmt(t0_s + a * ma.dt_s, 6)} – {_fmt(t0_s + b * ma.dt_s, 6)} s")
    return "; ".join(parts)


def unit_row(rec) -> tuple[str, str]:
    """``(setting, value)`` of the input unit of a record block: the unit as read times its factor = the internal
    unit, from the block's ``signal.channels`` (:func:`fogdrift.signal.record_units`)."""
    u = record_units(rec, "the record")
    if u is None:
        return "unit (as read)", "–"
    if u.scale_to_internal is not None and u.internal_unit is not None:
        return ("rate unit (as read)" if u.all_gyro else "unit (as read)",
                f"{u.input_unit} × {_fmt(u.scale_to_internal, 6)} = {u.internal_unit}")
    # a gyro and accelerometer record: each channel has its own factor and internal unit
    return "unit (as read)", ", ".join(f"{c.name} {c.unit_as_read} × {_fmt(c.scale_to_internal, 6)} = "
                                       f"{c.internal_unit}" for c in u.channels)


def settings_rows(result, *, generated: str, title: str = "") -> list:
    """``[group, setting, value]`` rows of every setting of ``result`` (an AnalysisResult).

    ``generated`` is the report's date; ``title`` prefixes the rows of a second recording (``--apply-to``).
    """
    cfg, rec = result.config, result.record
    axes = list(result.axes)
    t0 = float(rec.get("t0_s") or 0.0)
    rows = []

    def add(group, setting, value):
        rows.append([f"{title}{group}", setting, str(value)])

    v = result.versions
    add("run", "fogdrift version", v.get("fogdrift", "?"))
    add("run", "report date", generated)
    add("run", "analysis wall time", f"{result.wall_s:.1f} s")
    add("run", "libraries", ", ".join(f"{k} {v[k]}" for k in ("python", "numpy", "scipy", "numba", "jax", "optax",
                                                                 "matplotlib") if k in v))
    add("input", "file", result.source)
    add("input", "SHA-256", result.sha256 or "–")
    add("input", *unit_row(rec))
    add("input", "reader notes", "; ".join(rec.get("notes", [])) or "–")
    if result.applied:
        add("input", "models", "applied unchanged from the fitted recording (not refitted)")
    # Earth rate and bias
    if cfg.latitude_deg is None:
        add("Earth rate", "latitude / axes", "not removed (no --latitude); it stays in the training-block bias")
    else:
        add("Earth rate", "latitude", f"{cfg.latitude_deg:g} deg")
        add("Earth rate", "axes", ", ".join(f"{k}={o}" for k, o in cfg.earth_axes.items()))
    add("Earth rate", "removed per axis [deg/h]", ", ".join(f"{ax.name} {_fmt(ax.models.earth_rate_dph, 5)}"
                                                            for ax in axes))
    add("bias", "training-block bias per axis [deg/h]", ", ".join(f"{ax.name} {ax.models.bias_dph:+.6g}" for ax in axes))
    add("bias", "how estimated", "mean of the training block at the modelling rate, after Earth-rate removal; "
                                 "subtracted from the whole record before separation and modelling")
    # split
    ma0 = axes[0].models
    add("split", "fractions train / validation / test",
        f"{cfg.train_fraction:g} / {cfg.val_fraction:g} / {1 - cfg.train_fraction - cfg.val_fraction:.3g} "
        "(chronological)")
    add("split", f"sample indices at the modelling rate (dt {ma0.dt_s:g} s) and times", _split_text(ma0, t0))
    add("split", "not scored", f"the first {ma0.score_from} test samples (their inputs reach into the validation "
                               "block); shaded in Figs. 8 and 9")
    # rates and separation
    m = record_sampling(result.model_record, "the model_record")
    add("modelling", "modelling rate (effective)",
        f"{_fmt(m.rate_hz, 6)} Hz, block average ×{m.block_average_factor} of the native "
        f"{_fmt(m.native_rate_hz, 6)} Hz" if m else "native rate")
    add("separation", "wavelet / level / mode",
        f"{cfg.wavelet} / {cfg.level} (used: " + ", ".join(f"{ax.name} {ax.separation.level}" for ax in axes)
        + f") / {cfg.mode}")
    add("separation", "where", "inside each block (train, validation, test separately: no test information "
                               "reaches training); Figs. 5-6 show the whole record")
    add("separation", "causal drift window", f"{cfg.causal_window_s:g} s (practical compensation, heading and "
                                             "artefact evaluations)")
    # Allan / noise
    add("Allan", "statistic / estimator / τ grid", f"{cfg.statistic} / {cfg.estimator} / {cfg.taus}")
    add("Allan", "noise terms", "selected from the data (all Q, N, B, K, R candidates)" if cfg.terms is None
        else "fixed: " + "+".join(cfg.terms))
    lo, hi = cfg.fit_tau_s
    add("Allan", "fitted τ range asked", "whole curve" if lo is None and hi is None
        else f"{'–' if lo is None else f'{lo:g}'} .. {'–' if hi is None else f'{hi:g}'} s")
    out_counts = []
    for ax in axes:
        o = getattr(ax.original, "outliers", None)
        out_counts.append(f"{ax.name} {o.count if o is not None else '?'}")
    add("outliers", "handling / samples beyond 6 robust σ", f"{cfg.outliers} / " + ", ".join(out_counts))
    # models
    add("models", "run (report order)", ", ".join(ma0.fitted) or "–")
    add("models", "seed", cfg.seed)
    for label, model in ma0.fitted.items():
        params = model.get_params() if hasattr(model, "get_params") else {}
        add("models", f"{label}: hyper-parameters", _params_text(params))
        fitted = [f"{ax.name}: {t}" for ax in axes if label in ax.models.fitted
                  for t in [_fitted_text(ax.models.fitted[label])] if t]
        if fitted:
            add("models", f"{label}: fitted", "; ".join(fitted))
        secs = [f"{ax.name} {ax.models.fit_seconds[label]:.2g} s" for ax in axes
                if label in ax.models.fit_seconds]
        if secs:
            add("models", f"{label}: fit time", ", ".join(secs))
    # evaluation
    evs = [ax.evaluation for ax in axes if getattr(ax, "evaluation", None) is not None]
    if not evs:
        add("evaluation", "heading error and artefact check", "not run (analyze --no-heading)")
    else:
        s = evs[0].settings
        add("evaluation", "calibration window / origin step",
            f"{s['calibration_window_s']:g} s / {s['origin_step_s']:g} s (rolling origins on the test block)")
        add("evaluation", "horizons asked", ", ".join(f"{h:g}" for h in s["horizons_s"]) + " s")
        amps = [f"{ev.axis} {_fmt(ev.artefacts.amplitude_dph, 4)}" for ev in evs if ev.artefacts is not None]
        add("evaluation", "artefact check", ("injected amplitude [deg/h] (3 × std of the test block): "
                                             + ", ".join(amps)) if amps else "not run (see the notes)")
        add("evaluation", "wall time", ", ".join(f"{ev.axis} {ev.wall_s:.2g} s" for ev in evs))
    return rows
