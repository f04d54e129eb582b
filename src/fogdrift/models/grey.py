"""Grey theory: AGO/IAGO, the GM(1,1) model, its precision tests, and the ``GM11`` drift model.

The maths lives in plain functions on arrays (:func:`ago`, :func:`iago`, :func:`gm11_fit`,
:func:`gm11_predict`, :func:`class_ratio_check`, :func:`posterior_variance_ratio`,
:func:`small_error_probability`, :func:`grade`); :class:`GM11` is a thin estimator over them that
follows the :mod:`fogdrift.models` contract.

Series are 1-D float arrays; for drift they are rates in deg/h at a fixed sample interval, and
every returned series is in the same unit as the input.

References
----------
.. [Deng1982] J. Deng, "Control problems of grey systems", Systems & Control Letters 1(5):288-294, 1982.
.. [LiuLin2010] S. Liu, Y. Lin, *Grey Systems: Theory and Applications*, Springer, 2010 (GM(1,1),
   class-ratio test and posterior-error tests; the chapter on GM models).  The class-ratio
   interval and the grading table are quoted via the method notes §3.3-3.4, which did not
   re-check the page; some texts use e^{2/(n+2)} as the upper limit.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass

import numpy as np

from .._util import check_series
from ..errors import ConfigError, DataFormatError, FogdriftWarning, InsufficientDataError
from ._grey_batch import _expm1_over, _gm11_next_batch
from .settings import GM11_MIN_LENGTH
from .base import DriftModel

__all__ = [
    "ago",
    "iago",
    "GM11Fit",
    "gm11_fit",
    "gm11_predict",
    "class_ratio_check",
    "posterior_variance_ratio",
    "small_error_probability",
    "mean_relative_error_pct",
    "grade",
    "auto_shift",
    "GM11",
]



# ----------------------------------------------------------------------------------------------
# AGO / IAGO
# ----------------------------------------------------------------------------------------------
def ago(x) -> np.ndarray:
    """First-order accumulated generating operation (AGO).

    Parameters
    ----------
    x : array_like, shape (n,)
        Original series x⁰ (any unit, e.g. deg/h).

    Returns
    -------
    ndarray, shape (n,)
        x¹(k) = Σ_{i=1..k} x⁰(i), same unit as ``x``.

    Raises
    ------
    DataFormatError
        If ``x`` is not 1-D or holds NaN/inf.

    Notes
    -----
    [Deng1982]_; method notes §3.1. AGO is ``np.cumsum``; :func:`iago` inverts it exactly.

    Examples
    --------
    >>> ago([0.5, -0.2, 0.1, 0.3]).tolist()
    [0.5, 0.3, 0.4, 0.7]
    """
    return np.cumsum(check_series(x, "x"))


def iago(x1) -> np.ndarray:
    """Inverse AGO (IAGO): x⁰(1) = x¹(1), x⁰(k) = x¹(k) − x¹(k−1).

    Parameters
    ----------
    x1 : array_like, shape (n,)
        Accumulated series.

    Returns
    -------
    ndarray, shape (n,)
        The de-accumulated series, same unit.

    Raises
    ------
    DataFormatError
        If ``x1`` is not 1-D or holds NaN/inf.

    Notes
    -----
    Method notes §3.1: ``np.diff(np.r_[0, x1])``. For a one-step prediction x̂¹(k+1) made from
    measured history, restore with the **measured** x¹(k): x̂⁰(k+1) = x̂¹(k+1) − x¹(k)
    (method notes §4.1); that is a subtraction, not a call of this function.

    Examples
    --------
    >>> np.round(iago([0.5, 0.3, 0.4, 0.7]), 12).tolist()
    [0.5, -0.2, 0.1, 0.3]
    """
    arr = check_series(x1, "x1")
    return np.diff(arr, prepend=0.0)


# ----------------------------------------------------------------------------------------------
# GM(1,1)
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class GM11Fit:
    """Parameters of one GM(1,1) fit.

    Attributes
    ----------
    a : float
        Development coefficient (dimensionless, per sample).
    b : float
        Grey input, in the unit of the (shifted) series.
    x0_first : float
        First value of the **shifted** series x̃⁰(1) = x⁰(1) + shift, the initial condition of
        the time response.
    n : int
        Number of samples the model was fitted to.
    shift : float
        Constant c added to the series before fitting (0 when none); :func:`gm11_predict`
        subtracts it again.
    """

    a: float
    b: float
    x0_first: float
    n: int
    shift: float

    def to_dict(self) -> dict:
        return {k: (float(v) if isinstance(v, float) else v) for k, v in asdict(self).items()}


def _gm11_restored(a, b, x0_first, k):
    """x̂⁰(k+1) = (1 − eᵃ)(x⁰(1) − b/a) e^{−ak}, written as (b·φ(a) − expm1(a)·x⁰(1))·e^{−ak}.

    ``φ(a) = expm1(a)/a`` makes the a → 0 limit (x̂⁰ = b, a constant) exact. Valid for k ≥ 1.
    """
    amp = b * _expm1_over(a) - np.expm1(a) * x0_first
    return amp * np.exp(-a * np.asarray(k, dtype=np.float64))


def gm11_fit(x0, *, shift: float = 0.0) -> GM11Fit:
    """Fit GM(1,1) by exact least squares.

    Parameters
    ----------
    x0 : array_like, shape (n,)
        Original series, n ≥ 4. GM(1,1) assumes x⁰ + shift > 0 (see :func:`class_ratio_check`).
    shift : float, optional
        Constant c added before fitting (method notes §3.3); recorded in the result and
        subtracted again by :func:`gm11_predict`. Default 0.

    Returns
    -------
    GM11Fit

    Raises
    ------
    DataFormatError
        If ``x0`` is not 1-D, holds NaN/inf, or its background values are all equal (e.g.
        x⁰(2..n) all zero), so that a and b are not identifiable.
    InsufficientDataError
        If n < 4.
    ConfigError
        If ``shift`` is not finite.

    Notes
    -----
    [Deng1982]_, [LiuLin2010]_, method notes §3.2: with x¹ = AGO(x̃⁰) and background values
    z¹(k) = ½(x¹(k) + x¹(k−1)), k = 2..n, solve x̃⁰(k) + a z¹(k) = b in the least-squares sense,
    [a, b]ᵀ = (BᵀB)⁻¹BᵀY with rows of B = [−z¹(k), 1] and Y = x̃⁰(2..n). Solved with an SVD
    (``np.linalg.lstsq``), which equals the normal-equation solution to rounding.

    Examples
    --------
    >>> fit = gm11_fit([2.874, 3.278, 3.337, 3.390, 3.679])
    >>> round(fit.a, 6), round(fit.b, 6)
    (-0.037204, 3.065363)
    """
    arr = check_series(x0, "x0")
    if arr.size < GM11_MIN_LENGTH:
        raise InsufficientDataError(
            f"GM(1,1) needs at least {GM11_MIN_LENGTH} samples; got {arr.size}",
            needed=GM11_MIN_LENGTH,
            got=int(arr.size),
        )
    c = float(shift)
    if not math.isfinite(c):
        raise ConfigError(f"shift must be finite; got {shift!r}")
    xs = arr + c
    x1 = np.cumsum(xs)
    z = 0.5 * (x1[1:] + x1[:-1])
    design = np.column_stack([-z, np.ones_like(z)])
    sol, _, rank, _ = np.linalg.lstsq(design, xs[1:], rcond=None)
    if rank < 2:
        raise DataFormatError(
            "GM(1,1) is not identifiable: the background values z(k) are all equal "
            f"(x0[1:] + shift is {xs[1]!r} everywhere); expected a series that is not identically zero"
        )
    return GM11Fit(a=float(sol[0]), b=float(sol[1]), x0_first=float(xs[0]), n=int(arr.size), shift=c)


def gm11_predict(fit: GM11Fit, n_total: int) -> np.ndarray:
    """Restored GM(1,1) values x̂⁰[0:n_total], continuing past the fitted block as forecasts.

    Parameters
    ----------
    fit : GM11Fit
        Result of :func:`gm11_fit`.
    n_total : int
        Number of values; indices ≥ ``fit.n`` are forecasts (index ``fit.n`` is the next one).

    Returns
    -------
    ndarray, shape (n_total,)
        x̂⁰ in the unit of the original series (the shift is subtracted again).

    Raises
    ------
    ConfigError
        If ``n_total`` is not a non-negative integer.

    Warns
    -----
    FogdriftWarning
        If e^{−ak} overflows (long horizons with a < 0); those values are ±inf.

    Notes
    -----
    Method notes §3.2: x̂⁰(1) = x̃⁰(1) and, for k ≥ 1,
    x̂⁰(k+1) = x̂¹(k+1) − x̂¹(k) = (1 − eᵃ)(x̃⁰(1) − b/a) e^{−ak}, evaluated as
    (b·(eᵃ − 1)/a − (eᵃ − 1)·x̃⁰(1))·e^{−ak}, whose a → 0 limit is b (a constant series is
    forecast as that constant; no division by zero).

    Examples
    --------
    >>> fit = gm11_fit([2.874, 3.278, 3.337, 3.390, 3.679])
    >>> np.round(gm11_predict(fit, 6), 4).tolist()
    [2.874, 3.232, 3.3545, 3.4817, 3.6137, 3.7507]
    """
    n = _check_count(n_total, "n_total")
    out = np.empty(n)
    if n == 0:
        return out
    out[0] = fit.x0_first
    if n > 1:
        with np.errstate(over="ignore", invalid="ignore"):
            out[1:] = _gm11_restored(fit.a, fit.b, fit.x0_first, np.arange(1, n))
    if not np.all(np.isfinite(out)):
        warnings.warn(
            f"GM(1,1) time response overflows (a = {fit.a:.4g} over {n} samples); non-finite values returned",
            FogdriftWarning,
            stacklevel=2,
        )
    return out - fit.shift


def _check_count(value, name: str) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ConfigError(f"{name} must be a non-negative integer; got {value!r}")
    return int(value)


# ----------------------------------------------------------------------------------------------
# Admissibility and precision tests
# ----------------------------------------------------------------------------------------------
def class_ratio_check(x0) -> tuple[bool, np.ndarray, tuple[float, float]]:
    """Class-ratio (level-ratio) admissibility test of a series for GM(1,1).

    Parameters
    ----------
    x0 : array_like, shape (n,)
        Series (already shifted, if a shift is used), n ≥ 2.

    Returns
    -------
    passes : bool
        True when every x⁰(k) > 0 and every σ(k) lies strictly inside the interval.
    sigma : ndarray, shape (n − 1,)
        σ(k) = x⁰(k−1)/x⁰(k), k = 2..n (inf where x⁰(k) = 0).
    interval : tuple of float
        (e^{−2/(n+1)}, e^{2/(n+1)}).

    Raises
    ------
    DataFormatError
        If ``x0`` is not 1-D or holds NaN/inf.
    InsufficientDataError
        If n < 2.

    Notes
    -----
    Interval e^{±2/(n+1)} as in [LiuLin2010]_ (method notes §3.3; some texts use e^{2/(n+2)} for
    the upper limit). For n = 5 it is (0.7165, 1.3956).

    Examples
    --------
    >>> ok, sigma, (lo, hi) = class_ratio_check([2.874, 3.278, 3.337, 3.390, 3.679])
    >>> ok, round(lo, 4), round(hi, 4)
    (True, 0.7165, 1.3956)
    """
    arr = check_series(x0, "x0")
    n = arr.size
    if n < 2:
        raise InsufficientDataError(f"class-ratio test needs at least 2 samples; got {n}", needed=2, got=int(n))
    with np.errstate(divide="ignore", invalid="ignore"):
        sigma = arr[:-1] / arr[1:]
    sigma = np.where(arr[1:] == 0.0, np.inf, sigma)
    lo, hi = math.exp(-2.0 / (n + 1)), math.exp(2.0 / (n + 1))
    passes = bool(np.all(arr > 0.0) and np.all((sigma > lo) & (sigma < hi)))
    return passes, sigma, (lo, hi)


def _residual_pair(x0, x0_hat):
    x = check_series(x0, "x0")
    xh = check_series(x0_hat, "x0_hat")
    if x.shape != xh.shape:
        raise DataFormatError(f"x0 and x0_hat must have the same length; got {x.size} and {xh.size}")
    if x.size < 2:
        raise InsufficientDataError(f"precision tests need at least 2 samples; got {x.size}", needed=2, got=x.size)
    return x, x - xh


def posterior_variance_ratio(x0, x0_hat) -> float:
    """Posterior variance ratio C = S₂/S₁ (dimensionless).

    Parameters
    ----------
    x0, x0_hat : array_like, shape (n,)
        Series and its GM(1,1) restored values (in-sample), same unit.

    Returns
    -------
    float
        C; NaN when S₁ = 0 (constant series).

    Notes
    -----
    [LiuLin2010]_, method notes §3.4: S₁ = std of x⁰, S₂ = std of ε(k) = x⁰(k) − x̂⁰(k) over
    k = 1..n (ε(1) = 0 by construction), both with divisor n (``ddof=0``). With this
    convention the §3.2 example gives C = 0.2125.

    Examples
    --------
    >>> x = [2.874, 3.278, 3.337, 3.390, 3.679]
    >>> round(posterior_variance_ratio(x, gm11_predict(gm11_fit(x), 5)), 4)
    0.2125
    """
    x, eps = _residual_pair(x0, x0_hat)
    s1 = float(np.std(x))
    if s1 == 0.0:
        return math.nan
    return float(np.std(eps)) / s1


def small_error_probability(x0, x0_hat) -> float:
    """Small-error probability P = fraction of k with |ε(k) − ε̄| < 0.6745·S₁.

    Parameters
    ----------
    x0, x0_hat : array_like, shape (n,)
        Series and its restored values.

    Returns
    -------
    float
        P in [0, 1] (0 for a constant series, since S₁ = 0).

    Notes
    -----
    [LiuLin2010]_, method notes §3.4; S₁ with divisor n, ε over k = 1..n.

    Examples
    --------
    >>> x = [2.874, 3.278, 3.337, 3.390, 3.679]
    >>> small_error_probability(x, gm11_predict(gm11_fit(x), 5))
    1.0
    """
    x, eps = _residual_pair(x0, x0_hat)
    s1 = float(np.std(x))
    return float(np.mean(np.abs(eps - eps.mean()) < 0.6745 * s1))


def mean_relative_error_pct(x0, x0_hat, *, skip_first: bool = True) -> float:
    """Mean relative error Δ̄ = mean_k |ε(k)|/|x⁰(k)|, in percent (in-sample grey precision).

    Parameters
    ----------
    x0, x0_hat : array_like, shape (n,)
    skip_first : bool, optional
        Average over k = 2..n (default; x̂⁰(1) = x⁰(1) by construction).

    Returns
    -------
    float
        100·Δ̄ [%]. The grey "model precision" is 100 − this value. For forecast evaluation use
        :func:`fogdrift.metrics.p0` instead (offset convention, zero guard, persistence beside it).

    Notes
    -----
    Method notes §3.4. The §3.2 example gives 1.602 %.
    """
    x, eps = _residual_pair(x0, x0_hat)
    sl = slice(1, None) if skip_first else slice(None)
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(100.0 * np.mean(np.abs(eps[sl]) / np.abs(x[sl])))


def grade(C: float, P: float) -> str:
    """Grey precision grade from C and P.

    Parameters
    ----------
    C : float
        Posterior variance ratio.
    P : float
        Small-error probability.

    Returns
    -------
    str
        ``"good"`` (P > 0.95 and C < 0.35), ``"qualified"`` (P > 0.80 and C < 0.50),
        ``"barely"`` (P > 0.70 and C < 0.65) or ``"unqualified"`` (otherwise, including NaN).

    Notes
    -----
    Common grading table, method notes §3.4 (quoted from the standard texts, [LiuLin2010]_).

    Examples
    --------
    >>> grade(0.2125, 1.0), grade(0.45, 0.9), grade(0.6, 0.75), grade(0.7, 1.0)
    ('good', 'qualified', 'barely', 'unqualified')
    """
    for name, p_min, c_max in (("good", 0.95, 0.35), ("qualified", 0.80, 0.50), ("barely", 0.70, 0.65)):
        if P > p_min and C < c_max:
            return name
    return "unqualified"


def auto_shift(y_train, *, margin: float = 1.0) -> float:
    """Shift c that makes a signed training series positive for GM(1,1), from training data only.

    Parameters
    ----------
    y_train : array_like, shape (n,)
        Training block [deg/h].
    margin : float, optional
        Minimum of the shifted series, in units of the training range (max − min; when the
        range is 0, of |mean|, or 1 when the mean is 0 too). Default 1.0.

    Returns
    -------
    float
        c = max(0, margin·scale − min(y_train)) [deg/h], so min(y_train + c) ≥ margin·scale.
        A series already that far above zero is not shifted.

    Notes
    -----
    Method notes §3.3: the GM(1,1) forecast depends on c (toy series there: 0.0347, 0.0332,
    0.0330 for c = 0.1, 1, 10; a → 0 as c grows, and GM(1,1) tends to a straight line through
    x¹, i.e. a locally constant-mean model of x⁰). Test data must never influence c.

    Examples
    --------
    >>> auto_shift([-0.02, 0.01, 0.03, -0.01, 0.02, 0.04])
    0.08
    """
    y = check_series(y_train, "y_train", min_length=1)
    m = float(margin)
    if not (math.isfinite(m) and m >= 0.0):
        raise ConfigError(f"shift_margin must be a finite number >= 0; got {margin!r}")
    span = float(np.ptp(y))
    scale = span if span > 0 else (abs(float(np.mean(y))) or 1.0)
    return max(0.0, m * scale - float(np.min(y)))


# ----------------------------------------------------------------------------------------------
# Estimator
# ----------------------------------------------------------------------------------------------
_MODES = ("rolling", "whole")


class GM11(DriftModel):
    """GM(1,1) drift model with a recorded, training-only shift.

    Parameters
    ----------
    mode : {"rolling", "whole"}, default "rolling"
        ``"rolling"``: a genuine one-step predictor. ``out[k]`` is the next-value forecast of a
        GM(1,1) fitted to the last ``window`` **measured** samples before ``y[k]`` (shifted by
        ``shift_``). ``"whole"``: the paper's usage. One GM(1,1) is fitted to the whole shifted
        training block, and ``predict`` evaluates its time response continued past the training
        block; it **ignores the measured values** of ``y`` (it is a curve extrapolation in time,
        not a one-step predictor; label it so in reports).
    window : int, default 8
        Samples per rolling fit (≥ 4); used by ``mode="rolling"`` only.
    shift : "auto" or float, default "auto"
        Constant c [deg/h] added before fitting and subtracted from predictions (method notes
        §3.3). ``"auto"`` uses :func:`auto_shift` on the **training block only**.
    shift_margin : float, default 1.0
        ``margin`` of :func:`auto_shift` (in units of the training range).

    Attributes
    ----------
    shift_ : float
        Shift actually used [deg/h].
    a_, b_ : float
        GM(1,1) of the whole shifted training block (the grey diagnostics in both modes; the
        predictor in ``"whole"`` mode). ``b_`` in deg/h (shifted scale).
    x0_first_ : float
        First shifted training sample (initial condition of the whole-block time response).
    n_train_ : int
        Training length.
    C_, P_ : float
        Posterior variance ratio and small-error probability of the whole-block fit (in-sample).
    grade_ : str
        :func:`grade` of (C_, P_).
    mre_pct_ : float
        In-sample mean relative error of the whole-block fit, k ≥ 2 [%] (on the shifted series).
    class_ratio_pass_ : bool
        :func:`class_ratio_check` of the shifted training block.
    last_window_ : ndarray, shape (window,)
        Last training samples [deg/h, unshifted]; start of rolling free-run forecasts.

    Notes
    -----
    ``predict(y, history)`` in ``"whole"`` mode places ``y[0]`` at time index ``n_train_`` (right
    after training) when ``history`` is None, and at index ``len(history)`` otherwise, i.e.
    ``history`` is then taken to start at the first training sample.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> y = np.cumsum(rng.normal(0, 0.01, 200))
    >>> model = GM11(window=8).fit(y[:150])
    >>> pred = model.predict(y[150:], history=y[:150])
    >>> pred.shape, bool(np.isfinite(pred).all())
    ((50,), True)
    """

    label = "GM(1,1)"

    def __init__(self, *, mode="rolling", window=8, shift="auto", shift_margin=1.0):
        self.mode = mode
        self.window = window
        self.shift = shift
        self.shift_margin = shift_margin

    # -- validation --------------------------------------------------------------------------
    def _validate(self):
        if self.mode not in _MODES:
            raise ConfigError(f"GM11 mode must be one of {_MODES}; got {self.mode!r}")
        if (
            isinstance(self.window, (bool, np.bool_))
            or not isinstance(self.window, (int, np.integer))
            or self.window < GM11_MIN_LENGTH
        ):
            raise ConfigError(f"GM11 window must be an integer >= {GM11_MIN_LENGTH}; got {self.window!r}")
        if isinstance(self.shift, str):
            if self.shift != "auto":
                raise ConfigError(f"GM11 shift must be 'auto' or a finite number; got {self.shift!r}")
        else:
            try:
                ok = math.isfinite(float(self.shift))
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise ConfigError(f"GM11 shift must be 'auto' or a finite number; got {self.shift!r}")
        try:
            ok = math.isfinite(float(self.shift_margin)) and float(self.shift_margin) >= 0
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise ConfigError(f"GM11 shift_margin must be a finite number >= 0; got {self.shift_margin!r}")

    # -- fit / predict -----------------------------------------------------------------------
    def fit(self, y_train, y_val=None):
        """Fit on the training block only (``y_val`` is accepted for the common interface and ignored).

        Raises
        ------
        ConfigError
            Invalid hyper-parameter.
        DataFormatError
            ``y_train`` not 1-D or not finite.
        InsufficientDataError
            Fewer than ``window`` (rolling) or 4 (whole) training samples.
        """
        self._validate()
        y = check_series(y_train, "y_train")
        need = int(self.window) if self.mode == "rolling" else GM11_MIN_LENGTH
        need = max(need, GM11_MIN_LENGTH)
        if y.size < need:
            raise InsufficientDataError(
                f"GM11(mode={self.mode!r}) needs at least {need} training samples; got {y.size}",
                needed=need,
                got=int(y.size),
            )
        c = auto_shift(y, margin=float(self.shift_margin)) if self.shift == "auto" else float(self.shift)
        fit = gm11_fit(y, shift=c)
        shifted = y + c
        fitted = gm11_predict(fit, y.size) + c
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            C = posterior_variance_ratio(shifted, fitted)
            P = small_error_probability(shifted, fitted)
            mre = mean_relative_error_pct(shifted, fitted)
        self.shift_ = float(c)
        self.a_ = fit.a
        self.b_ = fit.b
        self.x0_first_ = fit.x0_first
        self.n_train_ = int(y.size)
        self.C_ = float(C)
        self.P_ = float(P)
        self.grade_ = grade(C, P)
        self.mre_pct_ = float(mre)
        self.class_ratio_pass_ = class_ratio_check(shifted)[0]
        self.last_window_ = y[-int(self.window):].copy() if self.mode == "rolling" else y[-GM11_MIN_LENGTH:].copy()
        return self

    def _whole_fit(self) -> GM11Fit:
        return GM11Fit(a=self.a_, b=self.b_, x0_first=self.x0_first_, n=self.n_train_, shift=self.shift_)

    def _whole_at(self, start: int, count: int) -> np.ndarray:
        return gm11_predict(self._whole_fit(), start + count)[start:]

    def predict(self, y, *, history=None):
        """One-step predictions (rolling) or the continued time response (whole) for ``y`` [deg/h].

        Returns
        -------
        ndarray, shape (len(y),)
            Rolling: NaN where fewer than ``window`` measured samples precede ``y[k]``.
        """
        self._check_fitted()
        y = check_series(y, "y")
        hist = np.empty(0) if history is None else check_series(history, "history")
        if self.mode == "whole":
            start = self.n_train_ if history is None else hist.size
            return self._whole_at(start, y.size)
        w = int(self.window)
        full = np.concatenate([hist, y]) + self.shift_
        out = np.full(y.size, np.nan)
        first = max(0, w - hist.size)  # first index of y with a full window before it
        if first >= y.size:
            return out
        # windows ending right before y[k], k = first .. len(y)-1; processed in chunks (memory bound)
        view = np.lib.stride_tricks.sliding_window_view(full, w)
        start_row = hist.size + first - w
        rows = y.size - first
        chunk = 1 << 16
        for lo in range(0, rows, chunk):
            hi = min(rows, lo + chunk)
            out[first + lo : first + hi] = _gm11_next_batch(view[start_row + lo : start_row + hi])
        return out - self.shift_

    def forecast(self, h: int, *, history=None):
        """Free-run forecast of ``h`` samples after ``history`` (default: after the training block) [deg/h].

        Rolling mode feeds each forecast back into the window; whole mode continues the time
        response (``history``, if given, is taken to start at the first training sample).
        """
        self._check_fitted()
        h = _check_count(h, "h")
        if self.mode == "whole":
            start = self.n_train_ if history is None else check_series(history, "history").size
            return self._whole_at(start, h)
        w = int(self.window)
        if history is None:
            buf = self.last_window_.copy()
        else:
            hist = check_series(history, "history")
            if hist.size < w:
                raise InsufficientDataError(
                    f"GM11 forecast needs a history of at least window={w} samples; got {hist.size}",
                    needed=w,
                    got=int(hist.size),
                )
            buf = hist[-w:].copy()
        return self._free_run(buf[None, :], h)[0]

    def forecast_many(self, h: int, histories):
        """Free-run forecasts of ``h`` samples after each row of ``histories`` [deg/h], all origins at once.

        Row ``i`` of the result equals ``forecast(h, history=histories[i])`` (same operations on each row, so the
        same values: tested), but each forecast step is one NumPy call over every origin instead of one per
        origin: the heading evaluation's rolling origins in one call.

        Parameters
        ----------
        h : int
            Forecast length [samples].
        histories : array_like, shape (n_origins, n_hist)
            One history per row [deg/h, unshifted], ``n_hist >= window`` in rolling mode; in whole mode only
            its length matters (as in :meth:`forecast`).

        Returns
        -------
        ndarray, shape (n_origins, h)
        """
        self._check_fitted()
        h = _check_count(h, "h")
        hist = np.asarray(histories, dtype=np.float64)
        if hist.ndim != 2 or not np.all(np.isfinite(hist)):
            raise DataFormatError(f"histories must be a finite 2-D array (origins x samples); got shape {hist.shape}")
        if self.mode == "whole":
            return np.tile(self._whole_at(hist.shape[1], h), (hist.shape[0], 1))
        w = int(self.window)
        if hist.shape[1] < w:
            raise InsufficientDataError(
                f"GM11 forecast needs a history of at least window={w} samples; got {hist.shape[1]}",
                needed=w,
                got=int(hist.shape[1]),
            )
        return self._free_run(hist[:, -w:], h)

    def _free_run(self, last, h: int) -> np.ndarray:
        """Rolling free run from the windows ``last`` (rows, unshifted): each forecast is fed back."""
        w = last.shape[1]
        buf = np.empty((last.shape[0], w + h))
        buf[:, :w] = last + self.shift_
        for i in range(h):
            buf[:, w + i] = _gm11_next_batch(buf[:, i:i + w])
        return buf[:, w:] - self.shift_

    # -- fitted state as data ------------------------------------------------------------------
    def _get_state(self):
        meta = {
            k: getattr(self, k)
            for k in ("shift_", "a_", "b_", "x0_first_", "n_train_", "C_", "P_", "grade_", "mre_pct_")
        }
        meta["class_ratio_pass_"] = bool(self.class_ratio_pass_)
        return meta, {"last_window_": self.last_window_}

    def _set_state(self, meta, arrays):
        for k in ("shift_", "a_", "b_", "x0_first_", "C_", "P_", "mre_pct_"):
            setattr(self, k, float(meta[k]))
        self.n_train_ = int(meta["n_train_"])
        self.grade_ = str(meta["grade_"])
        self.class_ratio_pass_ = bool(meta["class_ratio_pass_"])
        self.last_window_ = np.asarray(arrays["last_window_"], dtype=np.float64)

    def sensitivity_to_shift(self, y_train, shifts, *, h: int = 1) -> np.ndarray:
        """Free-run forecasts of ``h`` steps for several shifts, refitted on ``y_train`` (method notes §3.3).

        Parameters
        ----------
        y_train : array_like
            Training block [deg/h].
        shifts : array_like, shape (m,)
            Shift values c [deg/h].
        h : int
            Horizon.

        Returns
        -------
        ndarray, shape (m, h)
            Row i: forecast with shift ``shifts[i]`` (same mode/window as ``self``); ``self`` is
            not changed.
        """
        params = self.get_params()
        rows = []
        for c in np.asarray(shifts, dtype=np.float64).ravel():
            params["shift"] = float(c)
            rows.append(type(self)(**params).fit(y_train).forecast(h))
        return np.array(rows).reshape(-1, _check_count(h, "h"))
