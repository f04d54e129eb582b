"""Honest accuracy metrics for drift predictions (method notes §5.4-5.5).

All metrics are computed **in the original (de-accumulated) domain**, in the physical unit of the
series (deg/h), on the test block, and always beside the one-step persistence baseline.

References
----------
.. [HK2006] R. J. Hyndman, A. B. Koehler, "Another look at measures of forecast accuracy",
   Int. J. Forecasting 22:679-688, 2006 (MASE, eq. in §3.4 there).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass

import numpy as np

from .errors import ConfigError, DataFormatError, FogdriftWarning, InsufficientDataError
from ._util import check_series

__all__ = [
    "OFFSET_CONVENTIONS",
    "MetricsResult",
    "rmse",
    "mae",
    "max_abs_error",
    "mase",
    "skill",
    "p0",
    "p0_weighted",
    "p0_ago",
    "evaluate",
]

#: Allowed offset conventions for relative-error metrics (method notes §5.5).
OFFSET_CONVENTIONS = ("as_measured", "earth_rate_removed", "demeaned_by_train_mean")

#: p0 guard: NaN when min|y| < P0_GUARD_RATIO · median|y| (method notes §5.5).
P0_GUARD_RATIO = 0.1


def _pair(y, yhat, names=("y", "yhat")) -> tuple[np.ndarray, np.ndarray]:
    """Two finite 1-D series of the same length, at least 1 sample (the package's one series validator)."""
    hint = " (drop warm-up NaN first, or use evaluate())"
    a = check_series(y, names[0], min_length=0, hint=hint)
    b = check_series(yhat, names[1], min_length=0, hint=hint)
    if a.size != b.size:
        raise DataFormatError(f"{names[0]} and {names[1]} must have the same length; got {a.size} and {b.size}")
    a = check_series(a, names[0], min_length=1)
    return a, b


def rmse(y, yhat) -> float:
    """Root-mean-square error sqrt(mean((y − ŷ)²)), in the unit of ``y`` (deg/h).

    Parameters
    ----------
    y, yhat : array_like, shape (n,)
        Reference and prediction, finite, same length.

    Returns
    -------
    float

    Raises
    ------
    DataFormatError
        Not 1-D, NaN/inf, or different lengths.
    InsufficientDataError
        Empty input.

    Examples
    --------
    >>> rmse([1.0, 2.0, 3.0], [1.0, 2.0, 5.0])
    1.1547005383792515
    """
    a, b = _pair(y, yhat)
    return float(np.sqrt(np.mean((a - b) ** 2)))


def mae(y, yhat) -> float:
    """Mean absolute error mean|y − ŷ| (unit of ``y``).

    Examples
    --------
    >>> mae([1.0, 2.0, 3.0], [1.0, 2.5, 5.0])
    0.8333333333333334
    """
    a, b = _pair(y, yhat)
    return float(np.mean(np.abs(a - b)))


def max_abs_error(y, yhat) -> float:
    """Largest absolute error max|y − ŷ| (unit of ``y``).

    Examples
    --------
    >>> max_abs_error([1.0, 2.0, 3.0], [1.0, 2.5, 1.0])
    2.0
    """
    a, b = _pair(y, yhat)
    return float(np.max(np.abs(a - b)))


def _ratio(num: float, den: float, what: str) -> float:
    if den == 0.0:
        warnings.warn(f"{what}: the denominator is 0; returning NaN", FogdriftWarning, stacklevel=3)
        return math.nan
    return num / den


def mase(y, yhat, y_train) -> float:
    """Mean absolute scaled error (dimensionless).

    Parameters
    ----------
    y, yhat : array_like, shape (n,)
        Test reference and prediction.
    y_train : array_like, shape (m,)
        Training block (m ≥ 2), same unit.

    Returns
    -------
    float
        MAE(y, ŷ) / mean_t |y_train[t] − y_train[t−1]|; NaN with a :class:`FogdriftWarning` when
        the training block is constant. Below 1: better than in-sample one-step persistence.

    Notes
    -----
    [HK2006]_: scaled by the in-sample MAE of the one-step naive (persistence) forecast.

    Examples
    --------
    >>> mase([1.0, 2.0], [1.5, 2.5], [0.0, 1.0, 3.0])
    0.3333333333333333
    """
    tr = np.asarray(y_train, dtype=np.float64)
    if tr.ndim != 1 or tr.size < 2 or not np.all(np.isfinite(tr)):
        raise DataFormatError(f"y_train must be a finite 1-D series of at least 2 samples; got shape {tr.shape}")
    return _ratio(mae(y, yhat), float(np.mean(np.abs(np.diff(tr)))), "mase")


def skill(y, yhat, yhat_persistence) -> float:
    """Skill vs persistence, 1 − RMSE(model)/RMSE(persistence) (dimensionless).

    Returns
    -------
    float
        1 for a perfect model, 0 for persistence-level accuracy, negative when worse; NaN with a
        warning when persistence is exact.

    Examples
    --------
    >>> skill([1.0, 2.0], [1.0, 2.0], [0.0, 1.0])
    1.0
    """
    _pair(y, yhat_persistence, ("y", "yhat_persistence"))
    return 1.0 - _ratio(rmse(y, yhat), rmse(y, yhat_persistence), "skill")


def _check_convention(offset_convention) -> str:
    if offset_convention not in OFFSET_CONVENTIONS:
        raise ConfigError(f"offset_convention must be one of {OFFSET_CONVENTIONS}; got {offset_convention!r}")
    return offset_convention


def _p0_core(a: np.ndarray, b: np.ndarray) -> tuple[float, str | None]:
    """p0 and the reason it was refused (None when computed). Private: clean input."""
    ay = np.abs(a)
    min_abs, med_abs = float(ay.min()), float(np.median(ay))
    if min_abs == 0.0 or min_abs < P0_GUARD_RATIO * med_abs:
        return math.nan, (
            f"p0 is unstable near zero: min|y| = {min_abs:.4g} < {P0_GUARD_RATIO} x median|y| = {med_abs:.4g}; "
            "returning NaN (report p0_weighted, RMSE and MASE instead)"
        )
    return float(100.0 * (1.0 - np.mean(np.abs(a - b) / ay))), None


def p0(y, yhat, *, offset_convention: str) -> float:
    """Mean-relative-error precision p0 [%], with a stated offset convention and a zero guard.

    Parameters
    ----------
    y : array_like, shape (n,)
        Reference drift in the original (de-accumulated) domain, physical units (deg/h).
    yhat : array_like, shape (n,)
        One-step predictions of the same samples (AGO models restored with the measured x¹(k−1)).
    offset_convention : {"as_measured", "earth_rate_removed", "demeaned_by_train_mean"}
        Which constant is contained in ``y`` (required; p0 depends strongly on it).

    Returns
    -------
    float
        p0 = 100·(1 − mean_k |y_k − ŷ_k|/|y_k|) [%]; NaN with a :class:`FogdriftWarning` when
        min|y| < 0.1·median|y| (or min|y| = 0).

    Raises
    ------
    ConfigError
        Unknown ``offset_convention``.
    DataFormatError, InsufficientDataError
        As :func:`rmse`.

    Notes
    -----
    Method notes §5.5. Pitfalls (§5.4): adding a constant to y and ŷ drives p0 of *any*
    predictor towards 100 %, so always compare with persistence's p0 computed the same way
    (:func:`evaluate` does), and never compute it on AGO values (see :func:`p0_ago`).

    Examples
    --------
    >>> p0([2.0, 4.0], [1.0, 5.0], offset_convention="as_measured")
    62.5
    """
    _check_convention(offset_convention)
    a, b = _pair(y, yhat)
    value, reason = _p0_core(a, b)
    if reason is not None:
        warnings.warn(reason, FogdriftWarning, stacklevel=2)
    return value


def p0_weighted(y, yhat) -> float:
    """Weighted precision p0_w = 100·(1 − Σ|y − ŷ|/Σ|y|) [%] (no per-sample division by y).

    Returns NaN with a warning when Σ|y| = 0.

    Notes
    -----
    Method notes §5.5; the fallback when :func:`p0`'s guard trips. It still depends on the
    offset contained in ``y``.

    Examples
    --------
    >>> p0_weighted([2.0, 4.0], [1.0, 5.0])
    66.66666666666667
    """
    a, b = _pair(y, yhat)
    r = _ratio(float(np.sum(np.abs(a - b))), float(np.sum(np.abs(a))), "p0_weighted")
    return 100.0 * (1.0 - r)


def p0_ago(x1, x1_hat) -> float:
    """p0 computed on **AGO** values — paper practice only, not a measure of skill.

    Parameters
    ----------
    x1, x1_hat : array_like, shape (n,)
        Accumulated series and its prediction.

    Returns
    -------
    float
        100·(1 − mean|x¹ − x̂¹|/|x¹|) [%]. Always emits a :class:`FogdriftWarning` saying so.

    Notes
    -----
    Method notes §5.4-5.5: x¹ grows like k·mean, so the same errors look tiny; persistence scored
    99.347 % in the original domain and 99.99949 % on AGO values there. Exists only to reproduce
    what a paper may have reported; flag it as such wherever it is shown.
    """
    a, b = _pair(x1, x1_hat, ("x1", "x1_hat"))
    warnings.warn("p0_ago is computed on AGO values (paper practice); it hides error and is not a measure "
                  "of skill; report p0 in the original domain", FogdriftWarning, stacklevel=2)
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(100.0 * (1.0 - np.mean(np.abs(a - b) / np.abs(a))))


@dataclass(frozen=True)
class MetricsResult:
    """Test-block metrics of one model beside persistence (original domain, deg/h).

    Attributes
    ----------
    rmse_dph, mae_dph, max_abs_dph : float
        Model errors [deg/h].
    mase : float
        MAE / in-sample persistence MAE of the training block.
    skill : float
        1 − RMSE/RMSE_persistence.
    p0_pct, p0_weighted_pct : float
        Model p0 and weighted p0 [%] (p0 NaN when the zero guard trips).
    n : int
        Test samples used (those where both the model and persistence have a prediction).
    p0_persistence_pct : float
        Persistence p0 [%], computed identically.
    rmse_persistence_dph : float
        Persistence RMSE [deg/h].
    offset_convention : str
        Constant contained in the reference (see :data:`OFFSET_CONVENTIONS`).
    domain : str
        Always ``"original"`` (de-accumulated).
    """

    rmse_dph: float
    mae_dph: float
    max_abs_dph: float
    mase: float
    skill: float
    p0_pct: float
    p0_weighted_pct: float
    n: int
    p0_persistence_pct: float
    rmse_persistence_dph: float
    offset_convention: str
    domain: str

    def to_dict(self) -> dict:
        """JSON-ready dict; NaN becomes None."""
        out = {}
        for k, v in asdict(self).items():
            if isinstance(v, float):
                out[k] = None if math.isnan(v) else float(v)
            else:
                out[k] = v
        return out


def evaluate(y_test, yhat, *, y_train, yhat_persistence, offset_convention="demeaned_by_train_mean") -> MetricsResult:
    """All metrics of one model's one-step predictions on the test block, beside persistence.

    Parameters
    ----------
    y_test : array_like, shape (n,)
        Reference drift of the test block, original domain [deg/h], finite.
    yhat : array_like, shape (n,)
        Model predictions; NaN marks warm-up samples without a prediction.
    y_train : array_like, shape (m,)
        Training block (MASE scale; with ``"demeaned_by_train_mean"`` its mean should be ≈ 0).
    yhat_persistence : array_like, shape (n,)
        Persistence predictions of the same samples (NaN allowed, as for ``yhat``).
    offset_convention : str, default "demeaned_by_train_mean"
        Label of the constant contained in ``y_test``; it is **recorded, not applied** (the
        caller prepares the series). A :class:`FogdriftWarning` is emitted when it says
        ``"demeaned_by_train_mean"`` but |mean(y_train)| > 0.01·std(y_train).

    Returns
    -------
    MetricsResult

    Raises
    ------
    ConfigError
        Unknown offset convention.
    DataFormatError
        Shapes differ, or ``y_test``/``y_train`` hold NaN/inf.
    InsufficientDataError
        No sample where both predictions are finite.

    Notes
    -----
    Samples where either prediction is NaN are dropped from **both** model and persistence
    metrics, so the two are always computed on the same ``n`` samples. At most one p0-guard
    warning is emitted per call.

    Examples
    --------
    >>> y = np.array([1.0, 1.2, 1.1, 1.3])
    >>> r = evaluate(y, np.array([np.nan, 1.15, 1.15, 1.2]), y_train=np.array([0.9, 1.0, 1.1]),
    ...              yhat_persistence=np.array([np.nan, 1.0, 1.2, 1.1]), offset_convention="as_measured")
    >>> r.n, round(r.skill, 4)
    (3, 0.5918)
    """
    convention = _check_convention(offset_convention)
    y = np.asarray(y_test, dtype=np.float64)
    yh = np.asarray(yhat, dtype=np.float64)
    yp = np.asarray(yhat_persistence, dtype=np.float64)
    tr = np.asarray(y_train, dtype=np.float64)
    if y.ndim != 1 or not np.all(np.isfinite(y)):
        raise DataFormatError("y_test must be a finite 1-D series")
    if yh.shape != y.shape or yp.shape != y.shape:
        raise DataFormatError(f"y_test, yhat and yhat_persistence must have the same length; got {y.size}, "
                              f"{yh.size} and {yp.size}")
    if tr.ndim != 1 or tr.size < 2 or not np.all(np.isfinite(tr)):
        raise DataFormatError(f"y_train must be a finite 1-D series of at least 2 samples; got shape {tr.shape}")
    if np.isinf(yh).any() or np.isinf(yp).any():
        raise DataFormatError("yhat and yhat_persistence may hold NaN (warm-up) but not inf")
    if convention == "demeaned_by_train_mean" and abs(float(np.mean(tr))) > 0.01 * float(np.std(tr)):
        warnings.warn(f"offset_convention='demeaned_by_train_mean' but mean(y_train) = {np.mean(tr):.4g} "
                      f"(std {np.std(tr):.4g}); was the series demeaned?", FogdriftWarning, stacklevel=2)
    ok = np.isfinite(yh) & np.isfinite(yp)
    n = int(ok.sum())
    if n == 0:
        raise InsufficientDataError("no test sample has both a model and a persistence prediction", needed=1, got=0)
    y, yh, yp = y[ok], yh[ok], yp[ok]
    p0_model, reason = _p0_core(y, yh)
    p0_pers, _ = _p0_core(y, yp)
    if reason is not None:
        warnings.warn(reason, FogdriftWarning, stacklevel=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FogdriftWarning)  # degenerate denominators -> NaN, reported once below
        mase_v = mase(y, yh, tr)
        skill_v = skill(y, yh, yp)
        p0w = p0_weighted(y, yh)
    for name, v in (("mase", mase_v), ("skill", skill_v), ("p0_weighted", p0w)):
        if math.isnan(v):
            warnings.warn(f"{name} is undefined (zero denominator); reported as NaN", FogdriftWarning, stacklevel=2)
    return MetricsResult(
        rmse_dph=rmse(y, yh),
        mae_dph=mae(y, yh),
        max_abs_dph=max_abs_error(y, yh),
        mase=mase_v,
        skill=skill_v,
        p0_pct=p0_model,
        p0_weighted_pct=p0w,
        n=n,
        p0_persistence_pct=p0_pers,
        rmse_persistence_dph=rmse(y, yp),
        offset_convention=convention,
        domain="original",
    )
