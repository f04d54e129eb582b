"""Evidence in heading error: how much angle a compensator saves after a static calibration.

Protocol (method notes §5.2 free run, §6 bias), on a held-out rate series ``r`` [deg/h] at the
modelling interval ``dt``:

* rolling origins ``t0`` every ``step_s`` (default 300 s) from ``calib_s`` on;
* **calibration** on the preceding window ``[t0 - calib_s, t0)``: the constant bias is the window mean
  ``b = mean(r)``, as a navigation system does after static alignment;
* every compensator then gets that window only (bias-removed, ``r - b``) and **forecasts the drift free-running**
  ``f(t)`` for the horizon: drift models from the window's causal wavelet drift (their training framing), the
  Kalman filter from the window's rate, *constant bias* forecasts 0, *persistence* the last causal drift value;
* the **angle error** after horizon ``H`` is ``E = sum_{t0 <= t < t0 + H} (r(t) - b - f(t)) dt / 3600`` [deg]
  (rate in deg/h, dt in s).  For a static record every deviation of the rate from its calibrated value is
  error, so E is the heading error the compensator would leave.

Per model and horizon: RMS of E over origins, its ratio to constant-bias compensation, the median and 90th
percentile of |E|, the fraction of origins where the model's |E| is below constant bias's, and for the Kalman
model its predicted 1-sigma angle envelope (median over origins) and the fraction of origins with |E| inside it
(a calibrated noise model gives about 68 %).  Origins are ``step_s`` apart while horizons reach 3600 s, so
their errors overlap and are correlated: the number of origins overstates the independent evidence for long
horizons.  Each row therefore also counts, over the origins whose horizon windows do not overlap (every
``ceil(H / step)``-th origin from the first, :func:`~fogdrift.evaluation.verdicts.independent_subset`), how many
there are and at how many the model's |E| is below / above constant bias's; the verdicts use only these
(:func:`~fogdrift.evaluation.verdicts.judge`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError, FogdriftError, InsufficientDataError
from ..models.causal_predictor import causal_weights
from ..units import S_PER_H
from .verdicts import diverges, independent_subset

__all__ = ["HORIZONS_S", "CONSTANT_BIAS", "HeadingRow", "HeadingResult", "heading_errors", "heading_row",
           "angle_error_deg"]

#: Default forecast horizons [s].
HORIZONS_S = (60.0, 600.0, S_PER_H)
#: Label of the reference compensator (window-mean bias, no drift model).
CONSTANT_BIAS = "constant bias"


def angle_error_deg(rate_dph, bias_dph, forecast_dph, dt_s) -> np.ndarray:
    """Accumulated angle error [deg] after each sample: cumsum(rate - bias - forecast) dt / 3600.

    Examples
    --------
    A rate 2 deg/h above the calibrated bias for one hour, nothing forecast: 2 deg.

    >>> float(angle_error_deg(np.full(3600, 5.0), 3.0, np.zeros(3600), 1.0)[-1])
    2.0
    """
    resid = np.asarray(rate_dph, dtype=np.float64) - bias_dph - np.asarray(forecast_dph, dtype=np.float64)
    with np.errstate(over="ignore", invalid="ignore"):
        return np.cumsum(resid) * (dt_s / S_PER_H)


@dataclass(frozen=True)
class HeadingRow:
    """One model at one horizon (angles in deg)."""

    model: str
    horizon_s: float
    n_origins: int
    rms_deg: float
    ratio_to_bias: float
    median_abs_deg: float
    p90_abs_deg: float
    wins_vs_bias: float
    predicted_sigma_deg: float | None = None
    inside_sigma: float | None = None
    n_independent: int | None = None
    better_independent: int | None = None
    worse_independent: int | None = None

    def to_dict(self) -> dict:
        out = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in self.__dict__.items()}
        out["diverges"] = diverges(self.rms_deg, self.ratio_to_bias)
        return out


@dataclass
class HeadingResult:
    """Result of :func:`heading_errors` for one axis.

    ``errors[model]`` has shape (n_origins, n_horizons): the angle error [deg] at each origin and horizon, NaN
    where the horizon does not fit after that origin.  ``sigma[model]`` the same for predicted 1-sigma
    (models that predict one).
    """

    axis: str
    dt_s: float
    calib_s: float
    step_s: float
    horizons_s: tuple
    origins_s: np.ndarray
    errors: dict
    sigma: dict
    rows: list
    notes: list = field(default_factory=list)

    def row(self, model: str, horizon_s: float) -> HeadingRow:
        for r in self.rows:
            if r.model == model and r.horizon_s == horizon_s:
                return r
        raise KeyError((model, horizon_s))

    def to_dict(self) -> dict:
        return {"axis": self.axis, "dt_s": self.dt_s, "calibration_window_s": self.calib_s,
                "origin_step_s": self.step_s, "horizons_s": list(self.horizons_s),
                "n_origins": int(self.origins_s.size), "rows": [r.to_dict() for r in self.rows], "notes": self.notes,
                "protocol": "bias = mean of the calibration window before each origin; each model forecasts the "
                            "drift free-running from that window only; angle error = integral of (rate - bias - "
                            "forecast) over the horizon"}


def heading_row(model, errors_deg, bias_errors_deg, *, horizon_s, step_s, horizon_eff_s=None,
                sigma_deg=None) -> HeadingRow:
    """One model's row at one horizon from its angle errors and constant bias's at the same origins [deg].

    ``step_s`` is the origins' spacing; the counts ``better_independent`` / ``worse_independent`` are taken over
    the origins whose horizon windows do not overlap (:func:`~fogdrift.evaluation.verdicts.independent_subset`,
    with ``horizon_eff_s``, the horizon as sampled, default ``horizon_s``); a non-finite error counts as worse.

    Examples
    --------
    Six origins 300 s apart, 600-s horizon: origins 0, 2 and 4 do not overlap; the model wins at 1, 3, 4 and 5 (4 of
    6 = most of all origins) but at only 1 of the 3 non-overlapping ones.

    >>> e = np.array([2.0, 0.5, 2.0, 0.5, 0.5, 0.5]); eb = np.ones(6)
    >>> r = heading_row("m", e, eb, horizon_s=600.0, step_s=300.0)
    >>> r.wins_vs_bias, r.n_independent, r.better_independent, r.worse_independent
    (0.6666666666666666, 3, 1, 2)
    """
    e = np.asarray(errors_deg, dtype=np.float64)
    eb = np.asarray(bias_errors_deg, dtype=np.float64)
    with np.errstate(over="ignore", invalid="ignore"):
        rms = float(np.sqrt(np.mean(np.square(e)))) if e.size else math.nan
        rms_b = float(np.sqrt(np.mean(np.square(eb)))) if eb.size else math.nan
        ratio = rms / rms_b if rms_b > 0 else math.nan
    sub = independent_subset(e.size, step_s, horizon_s if horizon_eff_s is None else horizon_eff_s)
    ei, ebi = np.abs(e[sub]), np.abs(eb[sub])
    with np.errstate(invalid="ignore"):
        n_better, n_worse = int(np.sum(ei < ebi)), int(np.sum(~(ei <= ebi)))  # NaN/inf: worse
    pred = inside = None
    if sigma_deg is not None:
        s = np.asarray(sigma_deg, dtype=np.float64)
        pred = float(np.median(s))
        inside = float(np.mean(np.abs(e) <= s))
    with np.errstate(invalid="ignore"):
        return HeadingRow(
            model=model, horizon_s=float(horizon_s), n_origins=int(e.size), rms_deg=rms, ratio_to_bias=ratio,
            median_abs_deg=float(np.median(np.abs(e))) if e.size else math.nan,
            p90_abs_deg=float(np.percentile(np.abs(e), 90)) if e.size else math.nan,
            wins_vs_bias=float(np.mean(np.abs(e) < np.abs(eb))) if e.size else math.nan,
            predicted_sigma_deg=pred, inside_sigma=inside, n_independent=int(sub.size),
            better_independent=n_better, worse_independent=n_worse)


def _fir(x, g):
    W = g.size
    if x.size < W:
        return np.empty(0)
    return np.lib.stride_tricks.sliding_window_view(x, W) @ g


def _batch_forecaster(model):
    """The model's ``forecast_many(h, histories)`` when it stands for its ``forecast``, else None.

    Only drift-input models; and only when the class that defines ``forecast_many`` is (a subclass of) the one
    that defines ``forecast``, so a subclass that overrides ``forecast`` alone keeps its own per-origin forecasts.
    """
    if getattr(model, "input_kind", "drift") == "rate":
        return None
    method = getattr(model, "forecast_many", None)
    if not callable(method):
        return None
    owner = {}
    for cls in type(model).__mro__:
        for name in ("forecast", "forecast_many"):
            if name not in owner and name in vars(cls):
                owner[name] = cls
    if "forecast_many" not in owner:  # set on the instance: trust it
        return method
    if "forecast" in owner and not issubclass(owner["forecast_many"], owner["forecast"]):
        return None
    return method


def _batched_forecasts(models, calib) -> dict:
    """Label -> (n_origins, max h_max) free-run forecasts [deg/h] from one ``forecast_many`` call per model.

    ``calib`` holds (bias, bias-removed window, causal drift, h_max) per origin.  Models without the method, or
    whose call raises a :class:`~fogdrift.errors.FogdriftError` or returns the wrong shape, are left out (the
    per-origin loop handles them).
    """
    out = {}
    if not calib:
        return out
    histories = None
    h_top = max(item[3] for item in calib)
    for label, model in models.items():
        method = _batch_forecaster(model)
        if method is None:
            continue
        if histories is None:
            histories = np.stack([item[2] for item in calib])
        try:
            with warnings.catch_warnings(), np.errstate(all="ignore"):
                warnings.simplefilter("ignore")
                f = np.asarray(method(h_top, histories), dtype=np.float64)
        except FogdriftError:
            continue
        if f.shape == (len(calib), h_top):
            out[label] = f
    return out


def heading_errors(rate_dph, dt_s, models, *, causal_window: int, wavelet="db2", level=4, mode="symmetric",
                   calib_s=300.0, step_s=300.0, horizons_s=HORIZONS_S, axis="") -> HeadingResult:
    """Angle error of every compensator over rolling origins (see the module docstring).

    Parameters
    ----------
    rate_dph : array_like, shape (n,)
        Held-out rate [deg/h] at the modelling interval (any constant offset: each origin recalibrates).
    dt_s : float
        Its sample interval [s].
    models : dict
        Label -> fitted :class:`~fogdrift.models.DriftModel` (e.g. ``ModelAxis.fitted`` or a bundle axis's
        models); constant bias is always added as :data:`CONSTANT_BIAS`.
    causal_window : int
        Window [samples] of the causal drift fed to drift-input models (as in training).
    wavelet, level, mode
        The separation settings the models were trained with.
    calib_s, step_s : float
        Calibration window and origin spacing [s].
    horizons_s : sequence of float
        Forecast horizons [s]; those longer than the record after one calibration window are dropped
        (a note says so).
    axis : str
        Name, for the result.

    Returns
    -------
    HeadingResult

    Raises
    ------
    InsufficientDataError
        No origin with even the shortest horizon fits, or the calibration window is shorter than the
        causal-drift window.

    Examples
    --------
    White noise around a constant: no model can beat the window mean by much, and at 60 s constant bias
    leaves an RMS error of about N sqrt(60 s) (N = 6 (deg/h) sqrt(s) here: 46 arcsec = 0.013 deg).

    >>> from fogdrift.models import Persistence
    >>> r = 3.0 + np.random.default_rng(0).normal(0.0, 6.0, 20000)
    >>> res = heading_errors(r, 1.0, {"persistence": Persistence().fit(r[:10])}, causal_window=128,
    ...                      horizons_s=(60.0,))
    >>> row = res.row("constant bias", 60.0)
    >>> row.n_origins, 0.008 < row.rms_deg < 0.018
    (66, True)
    """

    r = np.asarray(rate_dph, dtype=np.float64)
    if r.ndim != 1 or not np.all(np.isfinite(r)):
        raise ConfigError("rate_dph must be a finite 1-D series")
    dt = float(dt_s)
    w_cal = int(round(calib_s / dt))
    step = max(1, int(round(step_s / dt)))
    W = int(causal_window)
    if w_cal < W + 1:
        raise InsufficientDataError(f"the calibration window ({calib_s:g} s = {w_cal} samples) must be longer than "
                                    f"the causal-drift window ({W} samples)", needed=W + 1, got=w_cal)
    notes = []
    horizons = []
    for h in horizons_s:
        H = int(round(h / dt))
        if H >= 1 and w_cal + H <= r.size:
            horizons.append((float(h), H))
        else:
            notes.append(f"horizon {h:g} s dropped: the record ({r.size * dt:g} s) does not hold a "
                         f"{calib_s:g}-s calibration plus {h:g} s")
    if not horizons:
        raise InsufficientDataError(f"no horizon fits: the record has {r.size * dt:g} s, a calibration of "
                                    f"{calib_s:g} s plus the shortest horizon does not", got=r.size)
    origins = np.arange(w_cal, r.size - horizons[0][1] + 1, step)
    g = causal_weights(W, wavelet, level, mode)
    labels = [CONSTANT_BIAS] + [k for k in models]
    errors = {k: np.full((origins.size, len(horizons)), np.nan) for k in labels}
    sigma = {}
    failed = {}
    # Calibration of every origin first (bias, bias-removed window, causal drift, longest horizon that fits) ...
    calib = []
    for t0 in origins:
        win = r[t0 - w_cal:t0]
        b = float(np.mean(win))
        zc = win - b
        calib.append((b, zc, _fir(zc, g), max(H for _, H in horizons if t0 + H <= r.size)))
    # ... so that a drift model with a batched free run forecasts all origins in one call (one forecast per origin
    # would be most of `compensate`'s time for the grey model); row i cut to its own h_max equals
    # forecast(h_max, history=c_i) (same per-row operations; a free run is causal).  On a FogdriftError the
    # per-origin loop below runs instead and decides whether the model fails.
    batched = _batched_forecasts(models, calib)
    for i, t0 in enumerate(origins):
        b, zc, c, h_max = calib[i]
        future = r[t0:t0 + h_max]
        forecasts = {CONSTANT_BIAS: (np.zeros(h_max), None)}
        for label, model in models.items():
            if label in failed:
                continue
            if label in batched:
                forecasts[label] = (batched[label][i, :h_max], None)
                continue
            try:
                with warnings.catch_warnings(), np.errstate(all="ignore"):
                    warnings.simplefilter("ignore")
                    if getattr(model, "input_kind", "drift") == "rate":
                        mean, _, ang = model.forecast_with_uncertainty(h_max, history=zc)
                        forecasts[label] = (mean, ang)
                    else:
                        forecasts[label] = (model.forecast(h_max, history=c), None)
            except FogdriftError as exc:
                failed[label] = str(exc)
        for label, (f, ang) in forecasts.items():
            e = angle_error_deg(future, b, f, dt)
            for j, (_, H) in enumerate(horizons):
                if t0 + H <= r.size:
                    errors[label][i, j] = e[H - 1]
                    if ang is not None:
                        sigma.setdefault(label, np.full((origins.size, len(horizons)), np.nan))[i, j] = ang[H - 1]
    for label, msg in failed.items():
        notes.append(f"{label}: no forecast ({msg})")
        errors.pop(label, None)
    rows = []
    base = errors[CONSTANT_BIAS]
    for label, err in errors.items():
        for j, (h, H) in enumerate(horizons):
            ok = ~np.isnan(base[:, j])
            rows.append(heading_row(label, err[ok, j], base[ok, j], horizon_s=h, step_s=step * dt,
                                    horizon_eff_s=H * dt, sigma_deg=sigma[label][ok, j] if label in sigma else None))
    return HeadingResult(axis=axis, dt_s=dt, calib_s=float(calib_s), step_s=float(step_s),
                         horizons_s=tuple(h for h, _ in horizons), origins_s=origins * dt, errors=errors,
                         sigma=sigma, rows=rows, notes=notes)
