"""``compensate_file``: a bundle applied to a new log, end to end (read, match, stream, write, evaluate)."""

from __future__ import annotations

import contextlib
import math
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..allan import allan_variance
from ..bundle import Bundle, load_bundle
from ..errors import ConfigError, FogdriftError, FogdriftWarning, render_options
from ..evaluation.artefacts import artefact_check
from ..evaluation.heading import heading_errors
from ..evaluation.verdicts import adev_caveat, artefact_verdict, heading_verdict, headline_verdict
from ..interrupt import checkpoint
from ..units import S_PER_H
from ..models import model_spec
from ..output import OutputDir, active, atomic_path
from ..report.files import write_json
from .engine import BIAS_ONLY, AxisPlan, StreamCompensator
from .outputs import AllanAccumulator, CsvWriter, NpzWriter, plot_before_after
from .sources import DEFAULT_CHUNK, match_log, open_log

__all__ = ["CompensationResult", "compensate_file", "parse_bias", "default_model"]

FORMATS = ("csv", "npz")


def parse_bias(value):
    """``"keep"`` -> ``"keep"``; ``"re-estimate:300"`` (or a number) -> 300.0 seconds.

    Examples
    --------
    >>> parse_bias("keep"), parse_bias("re-estimate:120"), parse_bias(60)
    ('keep', 120.0, 60.0)
    """
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        seconds = float(value)
    elif isinstance(value, str) and value.strip().lower() == "keep":
        return "keep"
    elif isinstance(value, str) and value.strip().lower().startswith("re-estimate:"):
        try:
            seconds = float(value.split(":", 1)[1])
        except ValueError:
            seconds = math.nan
    else:
        seconds = math.nan
    if not (math.isfinite(seconds) and seconds > 0):
        raise ConfigError(f"bias must be 'keep' or 're-estimate:SECONDS' with SECONDS > 0; got {value!r}; "
                          "pass {opt:bias}")
    return seconds


def default_model(bundle) -> str:
    """The model used when none is named: the Kalman filter if the bundle has one, else constant bias only."""
    return "kalman" if "kalman" in bundle.model_names else BIAS_ONLY


def _model_name(bundle, model) -> str:
    if model is None:
        return default_model(bundle)
    key = str(model).strip().lower()
    if key in (BIAS_ONLY, "constant-bias", "none"):
        return BIAS_ONLY
    try:
        name = model_spec(key).name
    except ConfigError:
        name = None
    if name not in bundle.model_names:
        raise ConfigError(f"model {model!r} is not in the bundle; pass {{opt:model}} as one of "
                          f"{', '.join(bundle.model_names + (BIAS_ONLY,))}")
    return name


@dataclass
class CompensationResult:
    """What :func:`compensate_file` did: ``summary`` (the JSON), the files, messages and evaluations."""

    summary: dict
    files: dict
    messages: list
    heading: list = field(default_factory=list)  # HeadingResult per axis
    artefacts: list = field(default_factory=list)  # ArtefactResult per axis
    verdicts: list = field(default_factory=list)  # Verdict objects, reading order


def _allan_rows(before, after, dt):
    a = allan_variance(before, dt, taus="octave")
    b = allan_variance(after, dt, taus="octave")
    return a, b, [{"tau_s": float(t), "adev_before_dph": float(x), "adev_after_dph": float(y),
                   "ratio": float(y / x) if x > 0 else None}
                  for t, x, y in zip(a.tau_s, a.adev_dph, b.adev_dph)]


def compensate_file(bundle, path, out_dir, *, model=None, bias="keep", unit=None, axis_map=None,
                    accept_rate=False, columns=None, time_column="auto", rate_hz=None, time_unit=None, format=None,
                    reader_options=None, temperature=None, gaps="error", apply_unit=None, chunk_samples=DEFAULT_CHUNK,
                    formats=FORMATS, figures=True, heading=True, artefacts=True,
                    calib_s=300.0, step_s=300.0, horizons_s=(60.0, 600.0, S_PER_H), max_model_rate_samples=1 << 23,
                    segment=None, progress=None, flags=None) -> CompensationResult:
    """Compensate the log ``path`` with ``bundle`` and write the results to ``out_dir``.

    Parameters
    ----------
    bundle : Bundle or path
        A bundle or its directory (:func:`fogdrift.bundle.load_bundle`).
    path : str or Path
        The log to compensate (any format :func:`fogdrift.io.load` reads; ``.npy`` is streamed).
    out_dir : str or Path
        Output directory: ``compensated.csv``, ``compensated.npz``, ``compensation.json``,
        ``compensation_allan.png``, each written atomically (:func:`fogdrift.output.atomic_path`) and listed in
        the folder's manifest; without an active :class:`fogdrift.output.OutputDir` for it (the CLI's), one is
        opened here.
    model : str, optional
        Registry name of a model of the bundle, or ``"bias"`` (constant bias only); default
        :func:`default_model`.
    bias : "keep" or "re-estimate:SECONDS" or float
        Keep the bundle's bias, or re-estimate it on the first SECONDS of the log (see
        :mod:`fogdrift.compensate.engine`).
    unit : str, optional
        Unit of the log's numbers (as :func:`fogdrift.io.load`: it takes precedence over a declared unit).  A
        log that declares none needs it (refused otherwise, suggesting the bundle's unit).
    axis_map, accept_rate
        How to map a log that does not match the bundle (:func:`~fogdrift.compensate.sources.match_log`).
    columns, time_column, rate_hz, time_unit, format, reader_options, temperature, gaps
        How to read the log (as :func:`fogdrift.io.load`).
    apply_unit : str, optional
        Deprecated spelling of ``unit`` (a :class:`~fogdrift.errors.FogdriftWarning` says so).
    chunk_samples : int
        Rows read at a time; the outputs do not depend on it.
    formats : sequence of {"csv", "npz"}
    figures : bool
        Write the before/after Allan figure (:func:`fogdrift.compensate.outputs.plot_before_after`: column and
        model names drawn as written through :func:`fogdrift.report.figures.literal`, never as mathtext, and
        saved by :func:`fogdrift.report.figures.save_figure` like every figure of the package).
    heading, artefacts : bool
        Run the heading-error evaluation (every model of the bundle plus constant bias, on the whole log) /
        the filtering-artefact check (both by default; the before/after figure and the messages carry the
        check's caveat, :func:`~fogdrift.evaluation.verdicts.adev_caveat`); skipped with a note when the log has
        more than ``max_model_rate_samples`` samples at the modelling rate.
    calib_s, step_s, horizons_s
        Heading-error protocol (:func:`fogdrift.evaluation.heading.heading_errors`).
    segment : int, optional
        Processing segment in modelling intervals (default fixed by the block-average factor; see
        :class:`~fogdrift.compensate.engine.StreamCompensator`).  Tests use short segments.
    progress : callable, optional
        ``progress(done_samples, total_samples)``.
    flags : dict, optional
        Setting name -> how the caller names it (the CLI's ``--unit``); ``{opt:NAME}`` markers in the
        messages are rendered with it before they are stored (default: ``NAME=``, the keyword of this function).

    Returns
    -------
    CompensationResult
    """
    if apply_unit is not None:
        if unit is not None and unit.strip() != apply_unit.strip():
            raise ConfigError(f"unit {unit!r} and its deprecated spelling apply_unit {apply_unit!r} disagree; pass "
                              "{opt:unit} only")
        warnings.warn("{opt:apply_unit} is deprecated; pass {opt:unit} (the same meaning)", FogdriftWarning,
                      stacklevel=2)
        unit = apply_unit
    edge = contextlib.nullcontext() if active(Path(out_dir) / "compensation.json") is not None else \
        OutputDir(out_dir, command="compensate", create_parents=True, protect=[path])  # parents: as mkdir -p before
    with edge:
        return _compensate(bundle, path, out_dir, model=model, bias=bias,
                           unit=unit, axis_map=axis_map, accept_rate=accept_rate,
                           load_kwargs=dict(columns=columns, time_column=time_column, rate_hz=rate_hz,
                                            time_unit=time_unit, format=format, reader_options=reader_options,
                                            temperature=temperature, gaps=gaps),
                           chunk_samples=chunk_samples, formats=formats, figures=figures, heading=heading,
                           artefacts=artefacts, calib_s=calib_s, step_s=step_s, horizons_s=horizons_s,
                           max_model_rate_samples=max_model_rate_samples, segment=segment, progress=progress,
                           flags=flags)


def _compensate(bundle, path, out_dir, *, model, bias, unit, axis_map, accept_rate, load_kwargs,
                chunk_samples, formats, figures, heading, artefacts, calib_s, step_s, horizons_s,
                max_model_rate_samples, segment, progress, flags) -> CompensationResult:
    t_start = time.perf_counter()
    b = bundle if isinstance(bundle, Bundle) else load_bundle(bundle)
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise ConfigError(f"formats must be a non-empty subset of {list(FORMATS)}; got {list(formats)!r}")
    bias_mode = parse_bias(bias)
    name = _model_name(b, model)
    if isinstance(chunk_samples, bool) or not isinstance(chunk_samples, (int, np.integer)) or chunk_samples < 1:
        raise ConfigError(f"{{opt:chunk_samples}} must be an integer >= 1 (rows read at a time); got "
                          f"{chunk_samples!r}")
    source = open_log(path, unit=unit, bundle_unit=b.input_unit, **load_kwargs)
    match = match_log(source, b, axis_map=axis_map, accept_rate=accept_rate)
    plans = [AxisPlan(log_ax, b.axis(b_ax), name) for log_ax, b_ax in match.axes]
    engine = StreamCompensator(plans, factor=match.factor, model_dt_s=b.model_dt_s, wavelet=b.wavelet, mode=b.mode,
                               bias=bias_mode, segment=segment,
                               keep_model_rate=(heading or artefacts)
                               and source.n_samples // match.factor <= max_model_rate_samples)
    out = Path(out_dir)  # as the caller named it (the paths in the summary and the result)
    out_abs = out.absolute()  # written through: an OutputDir takes a relative path as one inside its folder
    names = [a for a, _ in match.axes]
    scale = match.scale_to_dph  # the reader's own factor (file unit -> deg/h), carried: outputs divide by it once
    writers, files = [], {}
    acc = AllanAccumulator(source.n_samples, len(names))

    def emit(blocks):
        for blk in blocks:
            for w in writers:
                w.write(blk.t_s, blk.compensated_dph / scale, blk.drift_dph / scale,
                        None if blk.sigma_dph is None else blk.sigma_dph / scale)
            acc.add(blk.rate_dph, blk.compensated_dph)

    checkpoint("compensating")
    with contextlib.ExitStack() as stack:  # the final names appear (renamed) only when every row is written
        if "csv" in formats:
            files["csv"] = out / "compensated.csv"
            writers.append(CsvWriter(stack.enter_context(atomic_path(out_abs / "compensated.csv")), names, match.unit,
                                     engine.has_sigma))
        if "npz" in formats:
            files["npz"] = out / "compensated.npz"
            writers.append(NpzWriter(stack.enter_context(atomic_path(out_abs / "compensated.npz")), source.n_samples,
                                     names, match.unit, scale, engine.has_sigma))
        try:
            for t, x in source.chunks(chunk_samples):
                emit(engine.push(t, x))
                if progress is not None:
                    progress(engine.n_in, source.n_samples)
            emit(engine.finish())
        except BaseException:
            for w in writers:
                w.abort()
            raise
        for w in writers:
            w.close()

    messages = list(match.notes)
    biases = engine.biases()
    if bias_mode == "keep":
        messages.append("bias: kept from the bundle (" + ", ".join(
            f"{p.log_name} {p.bundle_axis.bias_dph:.6g} deg/h" for p in plans) + ")")
    else:
        messages.append(f"bias: RE-ESTIMATED on the first {engine.n_cal * b.model_dt_s:g} s of the log "
                        f"({engine.n_cal} samples at {1 / b.model_dt_s:g} Hz), minus the Earth rate: " + ", ".join(
                            f"{p.log_name} {bo:.6g} deg/h (bundle {p.bundle_axis.bias_dph:.6g})"
                            for p, (bo, _) in zip(plans, biases))
                        + "; before that the bundle's bias and no drift model were used")
    first = engine.first_active()
    axes_doc = []
    curves = []
    for k, (p, (bias_out, bias_total)) in enumerate(zip(plans, biases)):
        start = first[k] if first[k] is not None else source.n_samples
        before, after = acc.series(start)
        doc = {"axis": p.log_name, "bundle_axis": p.bundle_axis.name, "bias_dph": bias_out,
               "bias_plus_earth_dph": bias_total, "bundle_bias_dph": p.bundle_axis.bias_dph,
               "earth_rate_dph": p.bundle_axis.earth_rate_dph,
               "model_active_from_s": None if first[k] is None else first[k] * source.dt_s,
               "causal_window_s": p.bundle_axis.causal_window * b.model_dt_s}
        if before.shape[0] >= 8:
            a_res, b_res, rows = _allan_rows(before[:, k], after[:, k], source.dt_s * acc.f)
            doc["allan_before_after"] = rows
            curves.append((p.log_name, a_res, b_res, name))
        axes_doc.append(doc)
    training_sha = b.training.get("sha256")
    held_out = not (training_sha and source.sha256 and training_sha == source.sha256)
    if not held_out:
        messages.insert(0, "WARNING: this log is the bundle's own training log (same SHA-256): the heading-error "
                           "verdict is NOT held-out evidence")

    result = CompensationResult(summary={}, files=files, messages=messages)
    z_all = engine.model_rate_series() if engine.keep_model_rate else None
    why_not = "" if artefacts else "--no-artefacts"
    if (heading or artefacts) and z_all is None:
        why_not = f"more than {max_model_rate_samples} samples at the modelling rate"
        messages.append(f"evaluation skipped: {why_not}")
    if z_all is not None and z_all.shape[0]:
        _evaluate(result, b, plans, biases, z_all, heading=heading, artefacts=artefacts, calib_s=calib_s,
                  step_s=step_s, horizons_s=horizons_s)
    caveats = _caveats(result, name, plans, curves, why_not)
    messages.extend(caveats.values())
    if figures and curves:
        files["figure"] = out / "compensation_allan.png"
        plot_before_after(curves, out_abs / "compensation_allan.png", "ADEV before / after", caveats=caveats)
    messages[:] = [render_options(m, flags) for m in messages]
    result.summary = {
        "fogdrift_result": "compensation",
        "bundle": str(b.path) if b.path else None, "bundle_training_sha256": b.training.get("sha256"),
        "log": str(source.path), "log_sha256": source.sha256, "held_out": held_out, "model": name,
        "model_label": "constant bias" if name == BIAS_ONLY else plans[0].model.label,
        "bias_mode": "keep" if bias_mode == "keep" else {"re_estimate_s": bias_mode},
        # the log's unit and its factor to deg/h are its signal description's channels' (unit_as_read,
        # scale_to_internal), written once there
        "signal": source.signal.to_dict(), "model_dt_s": b.model_dt_s,
        "block_average_factor": match.factor, "n_samples": source.n_samples, "chunk_samples": int(chunk_samples),
        "design": "drift estimate of modelling interval j = the model's one-step prediction from modelling samples "
                  "< j, held over the interval's native samples (zero-order hold); compensated = rate - bias - "
                  "drift estimate (the Earth-rate projection stays in the output)",
        "messages": messages, "axes": axes_doc, "files": {k: str(v) for k, v in files.items()},
        "heading": [h.to_dict() for h in result.heading], "artefacts": [a.to_dict() for a in result.artefacts],
        "verdicts": [v.to_dict() for v in result.verdicts], "wall_s": time.perf_counter() - t_start,
    }
    files["json"] = out / "compensation.json"
    _write_json(result.summary, out_abs / "compensation.json")
    result.summary["files"]["json"] = str(files["json"])
    return result


def _caveats(result, name, plans, curves, why_not) -> list:
    """Axis -> the artefact check's caveat on the before/after ADEV, per plotted axis (none for 'bias')."""
    if name == BIAS_ONLY or not curves:
        return {}
    label = plans[0].model.label
    arte = {a.axis: a for a in result.artefacts}
    head = {h.axis: h for h in result.heading}
    why = why_not or "skipped; see above"
    return {axis: adev_caveat(label, arte.get(axis), axis=axis, heading=head.get(axis), why_not=why)
            for axis, *_ in curves}


def _write_json(obj, path) -> Path:
    """The summary as strict JSON (NaN/inf as null), atomically: the one strict-JSON writer
    (:func:`fogdrift._util.write_json`, imported through ``report.files`` until the structure test's table of the
    compensate <-> evaluation cycle follows)."""
    return write_json(obj, path)


def _evaluate(result, b, plans, biases, z_all, *, heading, artefacts, calib_s, step_s, horizons_s):
    for k, (p, (_, bias_total)) in enumerate(zip(plans, biases)):
        h = a = None
        ax = p.bundle_axis
        z = z_all[:, k] - bias_total
        models = {m.label: m for m in ax.models.values()}
        opts = dict(causal_window=ax.causal_window, wavelet=b.wavelet, level=ax.level, mode=b.mode, axis=p.log_name)
        if heading:
            try:
                h = heading_errors(z, b.model_dt_s, models, calib_s=calib_s, step_s=step_s, horizons_s=horizons_s,
                                   **opts)
            except FogdriftError as exc:
                result.messages.append(f"{p.log_name}: heading evaluation skipped ({exc})")
            else:
                result.heading.append(h)
                result.verdicts.append(heading_verdict(h))
        if artefacts:
            try:
                a = artefact_check(z, b.model_dt_s, models, **opts)
            except FogdriftError as exc:
                result.messages.append(f"{p.log_name}: artefact check skipped ({exc})")
            else:
                result.artefacts.append(a)
                result.verdicts.append(artefact_verdict(a))
        if h is not None:  # the one-sentence verdict of the axis, by the same rule (evaluation.verdicts.judge)
            result.verdicts.append(headline_verdict(h, a, axis=p.log_name))
