"""The whole method on one recording: characterise, separate, model, compensate, evaluate.

``run_allan``, ``run_separation``, ``run_models`` and ``run_analysis`` are the library entry points behind
``fogdrift allan``, ``separate``, ``model`` and ``analyze``. They return dataclasses; they never print or plot
(:mod:`fogdrift.report` renders them).

Order of operations in :func:`run_analysis`, per axis (method notes §5–6):

1. optional Earth-rate removal for a latitude and axis orientation;
2. the constant bias is the mean of the **training block** only, and is subtracted;
3. Allan analysis of the original output at its native rate (whole record: Allan is invariant to constants);
4. block-average to the modelling rate (default 1 Hz: drift lives below ~0.1 Hz, and a 4-level db2
   approximation of a 100 Hz log still passes ~3 Hz);
5. chronological train / validation / test split; lifting separation **inside each block** (never across the
   split, because the wavelet drift is non-causal);
6. drift models fitted on the training drift (validation block for early stopping);
7. two compensated signals on the test block, both labelled:
   *paper* = drift minus its one-step predicted drift (the drift residual, the paper's Table 2 / Fig. 9), and
   *practical* = gyro output minus the one-step prediction made from the **causal** drift (what a real-time
   compensator can do);
8. Allan analysis of every compensated signal; metrics on the test block beside persistence.
"""

from __future__ import annotations

import dataclasses
import importlib.metadata
import platform
import time
import warnings
from dataclasses import field
from pathlib import Path
from typing import Callable

import numpy as np

from ..allan import allan_variance
from ..allan.segments import allan_variance_segments
from ..segments import longest_segment
from ..allan.ci import periodic_alpha
from ..errors import ConfigError, FogdriftWarning, InsufficientDataError
from ..interrupt import checkpoint  # a stop point between stages/axes/models; reports the stage to listeners
from ..io import file_sha256, record as _record
from ..io.readers.command_memory import check_records_memory
from ..lifting import causal_drift, choose_level, get_wavelet, level_scan, separate
from ..metrics import evaluate, p0
from ..models import MODEL_NAMES, Persistence  # registry order = report order
from ..models import build_model as make_model  # make_model(name, cfg, progress=None)
from ..noise import express_quantity, fit_noise
from ..noise.periodic import null_taus, periodic_content
from ..noise.spectral import analyse_spectrum, welch_psd
from ..outliers import treat_outliers
from ..allan.sums import CHUNKED_MIN_SAMPLES, AllanSums  # noqa: F401 (re-exported)
from .config import AnalysisConfig, check_options
from .results import (
    AllanAxis,
    AnalysisAxis,
    AnalysisResult,
    AxisSpectrum,
    CompensatedSignal,
    ModelAxis,
    SeparationAxis,
    _plain,
)
from ..units import earth_rate_projection_dph

__all__ = [
    "AnalysisConfig",
    "AllanAxis",
    "SeparationAxis",
    "ModelAxis",
    "CompensatedSignal",
    "AxisSpectrum",
    "AnalysisAxis",
    "AnalysisResult",
    "MODEL_NAMES",
    "make_model",
    "run_allan",
    "run_separation",
    "run_models",
    "run_analysis",
    "drift_reach",
    "causal_window_samples",
    "model_factor",
    "check_options",
]


def library_versions() -> dict:
    out = {"python": platform.python_version(), "platform": platform.platform()}
    for pkg in ("fogdrift", "numpy", "scipy", "numba", "jax", "optax", "matplotlib"):
        try:
            out[pkg] = importlib.metadata.version(pkg)
        except importlib.metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def _spectrum_of(x, dt_s, known=None):
    """:func:`~fogdrift.noise.spectral.analyse_spectrum` of ``x``, or ``known``'s summary when ``known`` =
    ``(samples, dt_s, summary)`` was taken of these very samples (same dtype and interval, equal bit for bit):
    ``fogdrift noise`` hands its GMWM's spectra to the Allan check of the same axes."""
    if known is not None:
        seen, seen_dt, summary = known
        a = np.asarray(x)
        if (seen_dt == dt_s and a.dtype == seen.dtype and a.shape == seen.shape
                and np.array_equal(np.ascontiguousarray(a).view(np.uint8), np.ascontiguousarray(seen).view(np.uint8))):
            return summary
    return analyse_spectrum(x, dt_s)


def analyse_allan(name, y, dt_s, cfg: AnalysisConfig, progress=None, *, check_outliers=False,
                  spectrum="auto", outliers=None, quantity="angular_rate", sums=None, segments=None,
                  screen=None, known_spectrum=None) -> AllanAxis:
    """Allan-family variance and noise identification of one 1-D series ``y`` in its internal unit (deg/h, m/s^2).

    The curve is computed on the configured grid (``cfg.taus``) for display; the noise fit always uses an octave
    grid of the same data, so its numbers do not depend on the display grid.  With ``check_outliers`` the rate is
    checked for samples beyond 6 robust sigma and, if ``cfg.outliers`` says so, clipped or replaced first.

    ``spectrum``: the :class:`~fogdrift.noise.spectral.SpectrumSummary` of this rate, ``"auto"`` (default:
    computed here, once, from the rate that is analysed) or None (no spectrum).  Its lines become the S term of
    the fit; the fit curve then also holds the taus at whole multiples of each period (a sinusoid vanishes there,
    so quantization and a periodic error are told apart), and no tau gets a phase-noise (white-PM) EDF
    (:func:`fogdrift.allan.ci.periodic_alpha`).

    ``quantity``: the channel's quantity (:attr:`fogdrift.signal.Channel.quantity`); an accelerometer's
    (``"specific_force"``, the series in m/s^2) fit is reported in the accelerometer term table
    (:func:`fogdrift.noise.quantity.express`: velocity random walk in m/s/sqrt(h), bias instability in ug ...).

    ``outliers``: the OutlierReport of a rate already treated by the caller (stored in the result as if
    ``check_outliers`` had found it); the results are complete when built, nothing is patched afterwards.

    ``sums``: an :class:`~fogdrift.allan.sums.AllanSums` another stage already took of this very array (the
    plausibility check's octave ADEV, :func:`fogdrift.plausibility.check_record`); its sums are reused and only the
    missing cluster sizes are computed.  Ignored unless it holds the same array (after outlier treatment), interval,
    statistic and estimator.

    ``known_spectrum``: ``(samples, dt_s, summary)``, a spectrum another stage took, used for ``spectrum="auto"``
    when it was taken of the very samples analysed here (:func:`_spectrum_of`).
    """
    if check_outliers:
        y, outliers = treat_outliers(y, cfg.outliers)
    if segments is not None:
        return _analyse_segments(name, y, dt_s, cfg, segments, spectrum=spectrum, outliers=outliers,
                                 quantity=quantity, screen=screen, progress=progress, known_spectrum=known_spectrum)
    if isinstance(spectrum, str) and spectrum == "auto":
        spectrum = _spectrum_of(y, dt_s, known_spectrum)
    content = periodic_content(spectrum)
    # Every grid this analysis may need (display, octave, octave + the null taus of the periodic content) is known
    # before the data are touched: one pass of operator sums serves them all, and each result is rebuilt from the
    # sums (result_from_sums, the function allan_variance ends in: identical field by field).
    if sums is None or not sums.holds(y, dt_s, cfg.statistic, cfg.estimator):
        sums = AllanSums(y, dt_s, cfg.statistic, cfg.estimator)
    m_disp = sums.grid(cfg.taus)
    m_oct = m_disp if cfg.taus == "octave" else sums.grid("octave")
    taus = m_fit = None
    if content is not None:  # the taus at whole multiples of each period, beside the octave grid
        tau_oct = (m_oct * sums.dt).astype(np.float64)
        extra = null_taus(content.periods_s, dt_s, float(tau_oct[0]), float(tau_oct[-1]))
        taus = np.union1d(tau_oct, extra)
        m_fit = sums.grid(taus)
    sums.compute((m_disp, m_oct) if m_fit is None else (m_disp, m_oct, m_fit), progress)
    res = sums.result(m_disp, "auto")
    if content is not None:
        alphas, _ = periodic_alpha(res.noise_alpha, True)
        if np.any(alphas != res.noise_alpha):
            res = sums.result(m_disp, alphas)
    fit_curve = res if cfg.taus == "octave" else sums.result(m_oct, "auto")
    if content is not None:
        if taus.size != fit_curve.tau_s.size or np.any(fit_curve.noise_alpha > 0):
            # each added tau takes the alpha of the nearest octave tau (one pass over the data, not two)
            near = np.abs(np.log(taus)[:, None] - np.log(fit_curve.tau_s)[None, :]).argmin(axis=1)
            alphas, _ = periodic_alpha(np.asarray(fit_curve.noise_alpha)[near], True)
            fit_curve = sums.result(m_fit, alphas)
    del sums
    lo, hi = cfg.fit_tau_s
    tau_range = None if lo is None and hi is None else (lo, hi)
    noise = fit_noise(fit_curve, terms=None if cfg.terms is None else tuple(cfg.terms), tau_range_s=tau_range,
                      spectrum=spectrum, markov=True)
    if quantity != "angular_rate":
        noise = express_quantity(noise, quantity)
    if outliers is not None:  # a new, complete NoiseFit carrying the report (the fit's own object is not edited)
        noise = dataclasses.replace(noise, outliers=outliers.to_dict())
    return AllanAxis(name=name, allan=res, noise=noise, outliers=outliers, screen=screen)


def _analyse_segments(name, y, dt_s, cfg: AnalysisConfig, segments, *, spectrum, outliers, quantity,
                      screen, progress=None, known_spectrum=None) -> AllanAxis:
    """The Allan analysis of the quiet ``segments`` of a disturbed record (``(start, stop)`` samples): the overlapping
    Allan variance pooled over the segments without bridging a gap (:func:`fogdrift.allan.allan_variance_segments`;
    other statistics and estimators: the longest segment alone), the spectrum of the longest segment, the noise
    fit as for a whole record."""
    segs = sorted((int(a), int(b)) for a, b in segments)
    longest = max(segs, key=lambda s: s[1] - s[0])
    if isinstance(spectrum, str) and spectrum == "auto":
        spectrum = _spectrum_of(y[longest[0]:longest[1]], dt_s, known_spectrum)
    content = periodic_content(spectrum)
    if cfg.statistic == "adev" and cfg.estimator == "overlapping":
        res = allan_variance_segments(y, dt_s, segs, taus=cfg.taus)
        fit_curve = res if cfg.taus == "octave" else allan_variance_segments(y, dt_s, segs, taus="octave")
        if content is not None:
            t = np.asarray(fit_curve.tau_s, dtype=np.float64)
            extra = null_taus(content.periods_s, dt_s, float(t[0]), float(t[-1]))
            fit_curve = allan_variance_segments(y, dt_s, segs, taus=np.union1d(t, extra))
    else:
        part = np.asarray(y[longest[0]:longest[1]], dtype=np.float64)
        res = allan_variance(part, dt_s, taus=cfg.taus, estimator=cfg.estimator, statistic=cfg.statistic)
        fit_curve = res if cfg.taus == "octave" else allan_variance(part, dt_s, estimator=cfg.estimator,
                                                                    statistic=cfg.statistic)
    if progress is not None:  # the pooled sums are one step: its taus done at once
        progress(len(res.tau_s), len(res.tau_s))
    lo, hi = cfg.fit_tau_s
    noise = fit_noise(fit_curve, terms=None if cfg.terms is None else tuple(cfg.terms),
                      tau_range_s=None if lo is None and hi is None else (lo, hi), spectrum=spectrum, markov=True)
    if quantity != "angular_rate":
        noise = express_quantity(noise, quantity)
    if outliers is not None:
        noise = dataclasses.replace(noise, outliers=outliers.to_dict())
    # what the whole record gives (``--segments whole``), kept beside the segments' fit for the output and the report
    whole = analyse_allan(name, y, dt_s, cfg, outliers=outliers, quantity=quantity).noise
    return AllanAxis(name=name, allan=res, noise=noise, outliers=outliers, screen=screen, whole_noise=whole)


def _treated_record(record, cfg: AnalysisConfig):
    """The record with outliers clipped or replaced per ``cfg.outliers`` (unchanged for "warn"), and the reports.

    The float64 copy of the table is made only when an axis was treated (8 bytes per sample and axis)."""
    reports, treated = {}, {}
    for k, name in enumerate(record.axis_names):
        y, reports[name] = treat_outliers(record.data_internal[:, k], cfg.outliers)
        if cfg.outliers != "warn" and reports[name].count:
            treated[k] = y
    if not treated:
        return record, reports
    data = np.array(record.data_internal, dtype=np.float64)
    for k, y in treated.items():
        data[:, k] = y
    note = f"outliers {cfg.outliers}: " + ", ".join(f"{n} {r.count}" for n, r in reports.items())
    return dataclasses.replace(record, data_internal=data, notes=tuple(record.notes) + (note,)), reports


def model_factor(record, cfg: AnalysisConfig) -> int:
    """The block-average factor that takes ``record`` to the modelling rate ``cfg.model_rate_hz`` (1 for None).

    The one place the factor is decided (:func:`fogdrift.io.decimation_factor`): the CLI calls it before
    any work, to refuse a rate that does not divide the native rate by an integer (the message names the
    nearest valid rates), and hands the result to :func:`run_analysis` / :func:`run_models` /
    :func:`run_separation` (``factor=``), which then do not decide it again.  It is stored on every
    :class:`ModelAxis`, in the bundle, and in the modelling record's signal description.
    """
    return 1 if cfg.model_rate_hz is None else _record.decimation_factor(record.dt_s, cfg.model_rate_hz)


def _model_record(record, cfg: AnalysisConfig, factor: int | None = None):
    """Block-average a record to the modelling rate by the integer factor (decided once), or keep it."""
    return record.average_by(model_factor(record, cfg) if factor is None else factor)


def drift_reach(wavelet: str, level: int) -> int:
    """Support [samples] of the level-``level`` drift filter of ``wavelet``: ``(filter_length - 1) 2^level``."""
    return (get_wavelet(wavelet).filter_length - 1) * 2**int(level)


def causal_window_samples(causal_window_s: float, dt_s: float, wavelet: str, level: int, train_stop: int) -> int:
    """Window [samples] of the causal drift: ``causal_window_s`` at ``dt_s``, at least the filter's reach,
    at most the training block (its warm-up must end inside it).  Decided once per axis by the pipeline and
    stored as :attr:`ModelAxis.causal_window`; read that, do not call this again on a result."""
    return int(min(max(int(round(causal_window_s / dt_s)), drift_reach(wavelet, level)), train_stop))


def _separate(x, cfg: AnalysisConfig, dt_s):
    return separate(x, wavelet=cfg.wavelet, level=cfg.level, mode=cfg.mode)


def _resolved_level(x, cfg: AnalysisConfig, dt_s) -> tuple[int, list | None]:
    if cfg.level != "auto":
        return int(cfg.level), None

    scan = level_scan(x, dt_s, wavelet=cfg.wavelet, mode=cfg.mode)
    return int(choose_level(scan)), scan


def _split_indices(n: int, cfg: AnalysisConfig) -> dict:
    n_train = int(round(n * cfg.train_fraction))
    n_val = int(round(n * cfg.val_fraction))
    split = {"train": [0, n_train], "val": [n_train, n_train + n_val], "test": [n_train + n_val, n]}
    return split


def _earth_rate(name: str, cfg: AnalysisConfig) -> float:
    if cfg.latitude_deg is None or name not in cfg.earth_axes:
        return 0.0

    return float(earth_rate_projection_dph(cfg.latitude_deg, cfg.earth_axes[name]))


def _check_earth_axes(record, cfg: AnalysisConfig) -> None:
    unknown = [k for k in cfg.earth_axes if k not in record.axis_names]
    if unknown:
        raise ConfigError(f"Earth-rate axis {unknown} not in the record; its axes are {list(record.axis_names)}")


# ---------------------------------------------------------------------------------------------------------
# entry points


def run_allan(record, cfg: AnalysisConfig | None = None, progress: Callable | None = None, *,
              own_units: bool = True, sums: dict | None = None, segments: dict | None = None,
              screens: dict | None = None, spectra: dict | None = None) -> list[AllanAxis]:
    """Allan variance and noise identification of every axis of a record at its native rate.

    ``own_units`` (default True): each axis's fit in its quantity's term table (an accelerometer's velocity random
    walk in m/s/sqrt(h), B in ug, :func:`fogdrift.noise.quantity.express`); False keeps every fit in the gyro
    table's units of the internal unit (for a comparison with a reading made the same way, the GMWM's).

    ``sums``: axis name -> :class:`~fogdrift.allan.sums.AllanSums` already taken of that axis (the plausibility
    check's, :func:`fogdrift.plausibility.check_record` ``sums=``), reused where they hold the analysed array.

    ``segments``: axis name -> ``[(start, stop), ...]`` quiet segments to fit instead of the whole record (None or a
    missing name: the whole record); ``screens``: axis name -> the record screen's dict, kept on the result.
    ``spectra``: axis name -> ``(samples, dt_s, SpectrumSummary)`` another stage took (``analyse_allan``'s
    ``known_spectrum``), reused where they are the samples analysed.
    The memory need is held to the budget first (:func:`fogdrift.io.readers.command_memory.check_records_memory`).
    """
    check_records_memory("allan", record)
    cfg = (cfg or AnalysisConfig()).validate()
    out = []
    for name in record.axis_names:
        checkpoint("Allan variance", axis=name)
        out.append(analyse_allan(name, record.axis(name), record.dt_s, cfg, progress, check_outliers=True,
                                 quantity=record.signal.channel(name).quantity if own_units else "angular_rate",
                                 sums=(sums or {}).get(name), segments=(segments or {}).get(name),
                                 screen=(screens or {}).get(name), known_spectrum=(spectra or {}).get(name)))
    return out


def run_separation(record, cfg: AnalysisConfig | None = None, *, factor: int | None = None) -> list[SeparationAxis]:
    """Lifting separation of every axis (whole record, at the modelling rate) with Allan tables.

    ``factor``: the block-average factor to the modelling rate when already decided (:func:`model_factor`).
    The memory need is held to the budget first (:func:`fogdrift.io.readers.command_memory.check_records_memory`).
    """
    check_records_memory("separate", record)
    cfg = (cfg or AnalysisConfig()).validate()
    rec = _model_record(record, cfg, factor)
    out = []
    for name in rec.axis_names:
        checkpoint("separation", axis=name)
        x = np.asarray(rec.axis(name), dtype=np.float64)
        # A constant goes wholly into the drift; remove it so the drift shows the variation only.
        sep = _separation_axis(name, x - x.mean(), rec.dt_s, cfg, mean_removed_dph=float(x.mean()))
        out.append(sep)
    return out


def _separation_axis(name, x, dt_s, cfg: AnalysisConfig, mean_removed_dph: float | None = None) -> SeparationAxis:
    """Separate one whole series and analyse original, drift and noise (``mean_removed_dph``: the mean the caller
    subtracted from ``x``, stored in the result)."""
    level, scan = _resolved_level(x, cfg, dt_s)
    drift, noise = _separate(x, _with_level(cfg, level), dt_s)
    rows = [(label, analyse_allan(label, sig, dt_s, cfg)) for label, sig in
            (("original", x), ("drift", drift), ("noise", noise))]
    return SeparationAxis(name, dt_s, level, x, drift, noise, rows, scan, mean_removed_dph)


def _with_level(cfg: AnalysisConfig, level: int) -> AnalysisConfig:
    return AnalysisConfig(**{**cfg.to_dict(), "level": int(level)})


def _fit_axis_models(name, rate, dt_s, cfg: AnalysisConfig, bias, earth, progress=None, fitted=None,
                     factor: int = 1) -> ModelAxis:
    """Split, separate inside each block, fit (unless ``fitted`` models are given) and evaluate one axis."""
    level = int(cfg.level)
    split = _split_indices(rate.size, cfg)
    reach = drift_reach(cfg.wavelet, level)  # support of the level-J drift filter
    need = max(reach, cfg.lags + 2)
    for block, (lo, hi) in split.items():
        if hi - lo < need:
            raise InsufficientDataError(
                f"axis {name}: the {block} block has {hi - lo} samples at {1 / dt_s:.4g} Hz; needs at least {need} "
                f"for level-{level} separation and {cfg.lags} lags (use a longer record, a higher --model-rate "
                "or a lower --level)",
                needed=need,
                got=hi - lo,
            )
    (a, b), (c, d), (e, f) = split["train"], split["val"], split["test"]
    blocks = {"train": rate[a:b], "val": rate[c:d], "test": rate[e:f]}
    drift = {k: _separate(v, cfg, dt_s)[0] for k, v in blocks.items()}
    history = np.concatenate([drift["train"], drift["val"]])

    # The causal drift's warm-up (one window) must end inside the training block.
    window = causal_window_samples(cfg.causal_window_s, dt_s, cfg.wavelet, level, b)
    causal = causal_drift(rate, window, wavelet=cfg.wavelet, level=level, mode=cfg.mode)
    causal_hist = causal[:e][np.isfinite(causal[:e])]
    causal_test = causal[e:f]

    persistence = Persistence().fit(drift["train"])
    persist_pred = persistence.predict(drift["test"], history=history)
    persist_causal = persistence.predict(causal_test, history=causal_hist)
    offset = bias + earth

    models, fit_s = {}, {}
    if fitted is None:
        for model_name in cfg.models:
            checkpoint("fitting", axis=name, model=model_name)
            model = make_model(model_name, cfg, progress, inputs={"dt_s": dt_s})  # the rows declare what they take
            t0 = time.perf_counter()
            fit_on = blocks if model.input_kind == "rate" else drift  # a Kalman filter sees the rate itself
            model.fit(fit_on["train"], fit_on["val"])
            fit_s[model.label] = time.perf_counter() - t0
            models[model.label] = model
    else:
        models = dict(fitted)

    checkpoint("evaluating", axis=name)
    predictions, causal_predictions, metrics, causal_metrics, p0_meas = {}, {}, {}, {}, {}
    # Score only predictions whose inputs lie inside the test block: the first `lags` use history from the
    # validation block, whose drift was separated on its own and carries that block's end effect.
    skip = cfg.lags
    # The p0 guard warns for every model; the tables show NaN, so keep each distinct message once.
    with warnings.catch_warnings(record=True) as log:
        warnings.simplefilter("always", FogdriftWarning)
        for label, model in models.items():
            if model.input_kind == "rate":  # causal by construction: the same estimate for both targets
                yhat = yhat_c = model.predict(blocks["test"], history=rate[:e])
            else:
                yhat = model.predict(drift["test"], history=history)
                yhat_c = model.predict(causal_test, history=causal_hist)
            predictions[label], causal_predictions[label] = yhat, yhat_c
            y, p, pp = drift["test"][skip:], yhat[skip:], persist_pred[skip:]
            metrics[label] = evaluate(y, p, y_train=drift["train"], yhat_persistence=pp,
                                      offset_convention="demeaned_by_train_mean")
            causal_metrics[label] = evaluate(causal_test[skip:], yhat_c[skip:], y_train=drift["train"],
                                             yhat_persistence=persist_causal[skip:],
                                             offset_convention="demeaned_by_train_mean")
            # Paper-compatible p0: bias and Earth rate added back ("as measured"), persistence beside it.
            ok = np.isfinite(p) & np.isfinite(pp)
            p0_meas[label] = (
                p0(y[ok] + offset, p[ok] + offset, offset_convention="as_measured"),
                p0(y[ok] + offset, pp[ok] + offset, offset_convention="as_measured"),
            )
    notes = sorted({str(w.message).split(":")[0] for w in log if issubclass(w.category, FogdriftWarning)})
    return ModelAxis(
        name=name, dt_s=dt_s, split=split, bias_dph=bias, earth_rate_dph=earth, rate_dph=rate,
        drift_blocks=drift, causal_drift_dph=causal, predictions=predictions,
        causal_predictions=causal_predictions, metrics=metrics, causal_metrics=causal_metrics,
        p0_as_measured=p0_meas, fitted=models, fit_seconds=fit_s, level=level, causal_window=window, notes=notes,
        score_from=skip, block_average_factor=int(factor),
    )


def _prepared_axis(record_m, name, cfg):
    """Rate at the modelling rate with Earth rate and training-block bias removed."""
    x = np.asarray(record_m.axis(name), dtype=np.float64)
    earth = _earth_rate(name, cfg)
    n_train = _split_indices(x.size, cfg)["train"][1]
    bias = float(np.mean(x[:n_train]) - earth)
    return x - earth - bias, bias, earth


def run_models(record, cfg: AnalysisConfig | None = None, progress=None, *, factor: int | None = None) -> list[ModelAxis]:
    """Fit every configured drift model on every axis (training block) and evaluate on the test block.

    ``factor``: the block-average factor to the modelling rate when already decided (:func:`model_factor`).
    The memory need is held to the budget first (:func:`fogdrift.io.readers.command_memory.check_records_memory`).
    """
    check_records_memory("model", record)
    cfg = (cfg or AnalysisConfig()).validate()
    _check_earth_axes(record, cfg)
    factor = model_factor(record, cfg) if factor is None else int(factor)
    rec = _model_record(record, cfg, factor)
    out = []
    for name in rec.axis_names:
        checkpoint("separation", axis=name)
        rate, bias, earth = _prepared_axis(rec, name, cfg)
        lvl_cfg = _with_level(cfg, _resolved_level(rate, cfg, rec.dt_s)[0])
        out.append(_fit_axis_models(name, rate, rec.dt_s, lvl_cfg, bias, earth, progress, factor=factor))
    return out


def _table2(ma: ModelAxis, cfg: AnalysisConfig) -> list[CompensatedSignal]:
    """Allan analysis of original, drift and every compensated signal on the test block."""
    checkpoint("Table 2", axis=ma.name)
    e, f = ma.split["test"]
    k = ma.score_from
    raw = ma.rate_dph[e + k:f]
    drift = ma.drift_blocks["test"][k:]
    rows = [
        CompensatedSignal("original (test block)", "reference", None, raw, analyse_allan("original", raw, ma.dt_s, cfg)),
        CompensatedSignal("drift signal (test block)", "reference", None, drift, analyse_allan("drift", drift, ma.dt_s, cfg)),
    ]
    compensations = (
        ("drift residual (paper)", "paper", ma.predictions, drift),
        ("output - causal prediction (practical)", "practical", ma.causal_predictions, raw),
    )
    for suffix, kind, predictions, target in compensations:
        for label, yhat in predictions.items():
            ok = np.isfinite(yhat[k:])  # NaN only during the models' warm-up
            signal = target[ok] - yhat[k:][ok]
            rows.append(CompensatedSignal(f"{label}: {suffix}", kind, label, signal,
                                          analyse_allan(label, signal, ma.dt_s, cfg)))
    return rows


def run_analysis(record, cfg: AnalysisConfig | None = None, *, source: str | None = None, sha256: str | None = None,
                 apply_to=None, progress=None, fitted_from: "AnalysisResult | list | None" = None,
                 factor: int | None = None, apply_to_factor: int | None = None,
                 sums: dict | None = None, segments: dict | None = None,
                 screens: dict | None = None) -> AnalysisResult:
    """The whole method on one record (see the module docstring); ``apply_to`` is a second GyroRecord.

    ``progress(epoch, n_epochs, train_loss, val_loss)`` is passed to the neural models.
    With ``fitted_from`` (used for ``apply_to``), no model is fitted: the models of that analysis are applied
    unchanged to the axes of the same name.  ``factor`` / ``apply_to_factor``: the block-average factors to
    the modelling rate of ``record`` / ``apply_to`` when already decided (:func:`model_factor`); decided here
    otherwise, once.  ``sums``: axis name -> :class:`~fogdrift.allan.sums.AllanSums` of ``record``'s axes
    already taken (the plausibility check's, :func:`fogdrift.plausibility.check_record` ``sums=``), reused by the
    native-rate Allan analysis where they hold the analysed array (not after outliers were clipped or replaced).
    ``segments`` / ``screens``: axis name -> the quiet segments the native-rate noise fit uses and the record screen
    (:func:`fogdrift.screen.plan_segments`; None: the whole record, no screen), as for :func:`run_allan`.
    """
    t_start = time.perf_counter()
    if fitted_from is None:  # the memory need of both records, before any work (apply_to runs inside this call)
        check_records_memory("analyze", record, apply_to)
    cfg = (cfg or AnalysisConfig()).validate()
    _check_earth_axes(record, cfg)
    factor = model_factor(record, cfg) if factor is None else int(factor)
    record, outlier_reports = _treated_record(record, cfg)
    rec_m = _model_record(record, cfg, factor)
    axes = []
    for name in record.axis_names:
        checkpoint("Allan variance (native rate)", axis=name)
        seg = (segments or {}).get(name)
        original = analyse_allan(name, np.asarray(record.axis(name), dtype=np.float64), record.dt_s, cfg,
                                 outliers=outlier_reports[name], sums=(sums or {}).get(name), segments=seg,
                                 screen=(screens or {}).get(name))
        gmwm = None
        if cfg.noise_method == "gmwm":
            checkpoint("GMWM noise model (native rate)", axis=name)
            from ..gmwm.analysis import analyse_gmwm  # deferred: allan/separate/model never load GMWM (scipy.optimize)

            from ..evaluation.gmwm_vs_allan import compare_with_allan

            gmwm = analyse_gmwm(name, longest_segment(np.asarray(record.axis(name), dtype=np.float64), seg),
                                record.dt_s)
            gmwm = dataclasses.replace(gmwm, allan_check=compare_with_allan(gmwm, original.noise))  # N, B vs Allan
        checkpoint("separation", axis=name)
        rate, bias, earth = _prepared_axis(rec_m, name, cfg)
        sep = _separation_axis(name, rate, rec_m.dt_s, cfg)
        lvl_cfg = _with_level(cfg, sep.level)
        ma = _fit_axis_models(name, rate, rec_m.dt_s, lvl_cfg, bias, earth, progress,
                              fitted=None if fitted_from is None else _fitted_models_for(name, fitted_from),
                              factor=factor)
        spectrum = AxisSpectrum(*welch_psd(record.axis(name), record.dt_s), record.signal.channel(name).internal_unit)
        axes.append(AnalysisAxis(name, original, sep, ma, _table2(ma, lvl_cfg), gmwm=gmwm, spectrum=spectrum))
    applied = None
    if apply_to is not None:
        applied = run_analysis(apply_to, cfg, progress=progress, fitted_from=axes, factor=apply_to_factor)
    return AnalysisResult(
        config=cfg,
        source=source or record.source,
        sha256=sha256 or record.sha256 or (file_sha256(record.source) if Path(str(record.source)).is_file() else ""),
        record=record.metadata(),
        model_record=rec_m.metadata(),
        axes=axes,
        versions=library_versions(),
        wall_s=time.perf_counter() - t_start,
        apply_to=applied,
        applied=fitted_from is not None,
    )


def _fitted_models_for(name: str, fitted_from) -> dict:
    """The fitted models of axis ``name`` in an AnalysisResult or a list of AnalysisAxis."""
    source_axes = {a.name: a for a in getattr(fitted_from, "axes", fitted_from)}
    if name not in source_axes:
        raise ConfigError(
            f"--apply-to: axis {name!r} has no fitted models; the fitted recording has axes {list(source_axes)}"
        )
    return source_axes[name].models.fitted
