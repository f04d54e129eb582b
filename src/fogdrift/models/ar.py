"""Linear baseline for drift models: least-squares AR(p) with intercept (:func:`ar_fit`, :func:`ar_aic`, :class:`AR`).

Persistence lives in :mod:`fogdrift.models.persistence`. Series are 1-D float arrays of drift rate
in deg/h at a fixed sample interval.

References
----------
.. [Akaike1974] H. Akaike, "A new look at the statistical model identification", IEEE Trans.
   Automatic Control 19(6):716-723, 1974.
.. [BoxJenkins] G. E. P. Box, G. M. Jenkins, G. C. Reinsel, *Time Series Analysis: Forecasting and
   Control*, conditional least squares for AR models.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._util import check_series
from ..errors import ConfigError, InsufficientDataError
from .base import DriftModel

__all__ = ["ARFit", "ar_fit", "ar_aic", "AR"]


@dataclass(frozen=True)
class ARFit:
    """Least-squares AR(p) fit y[t] = intercept + Σ_i coef[i]·y[t−1−i] + e[t].

    Attributes
    ----------
    coef : tuple of float, length p
        coef[i] multiplies y[t−1−i] (lag i + 1).
    intercept : float
        In the unit of y (deg/h).
    sigma : float
        Residual standard deviation, divisor m − p − 1 (m = n − p equations) [deg/h].
    n : int
        Training length.
    rss : float
        Residual sum of squares [(deg/h)²].
    """

    coef: tuple
    intercept: float
    sigma: float
    n: int
    rss: float

    def to_dict(self) -> dict:
        return {"coef": [float(c) for c in self.coef], "intercept": float(self.intercept),
                "sigma": float(self.sigma), "n": int(self.n), "rss": float(self.rss)}


def _lagged(y: np.ndarray, p: int, start: int):
    """Design rows for t = start..n−1: columns y[t−1], …, y[t−p]; target y[t]. Needs start ≥ p."""
    n = y.size
    cols = [y[start - 1 - i : n - 1 - i] for i in range(p)]
    x = np.column_stack(cols) if p else np.empty((n - start, 0))
    return x, y[start:]


def _ls(y: np.ndarray, p: int, start: int):
    """Least squares on the centred series (better conditioned with a large offset); returns coef, c, rss, m."""
    mu = float(np.mean(y))
    yc = y - mu
    x, t = _lagged(yc, p, start)
    design = np.column_stack([np.ones(t.size), x])
    sol, _, _, _ = np.linalg.lstsq(design, t, rcond=None)
    resid = t - design @ sol
    coef = sol[1:]
    intercept = float(sol[0] + mu * (1.0 - coef.sum()))
    return coef, intercept, float(resid @ resid), t.size


def _check_order(p, name="order") -> int:
    if isinstance(p, (bool, np.bool_)) or not isinstance(p, (int, np.integer)) or p < 1:
        raise ConfigError(f"{name} must be an integer >= 1 or 'aic'; got {p!r}")
    return int(p)


def ar_fit(y, order: int) -> ARFit:
    """Fit AR(p) with intercept by conditional least squares.

    Parameters
    ----------
    y : array_like, shape (n,)
        Training series [deg/h]; n ≥ 2p + 2.
    order : int
        p ≥ 1.

    Returns
    -------
    ARFit

    Raises
    ------
    ConfigError
        ``order`` is not an integer ≥ 1.
    DataFormatError
        ``y`` not 1-D or not finite.
    InsufficientDataError
        n < 2p + 2 (fewer equations than needed for p + 1 parameters and a residual variance).

    Notes
    -----
    Minimises Σ_{t=p}^{n−1} (y[t] − c − Σ_i φ_i y[t−1−i])² over (c, φ) ([BoxJenkins]_, conditional
    LS). Solved on y − mean(y) with an SVD and mapped back, c = c' + ȳ(1 − Σφ); identical to the
    raw lagged-design solution in exact arithmetic, better conditioned when the drift carries a
    large constant.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> e = rng.normal(size=5000)
    >>> y = np.zeros(5000)
    >>> for t in range(1, 5000):
    ...     y[t] = 0.2 + 0.7 * y[t - 1] + e[t]
    >>> fit = ar_fit(y, 1)
    >>> abs(fit.coef[0] - 0.7) < 0.04, abs(fit.intercept - 0.2) < 0.05
    (True, True)
    """
    arr = check_series(y, "y")
    p = _check_order(order)
    need = 2 * p + 2
    if arr.size < need:
        raise InsufficientDataError(f"AR({p}) needs at least {need} samples; got {arr.size}", needed=need,
                                    got=int(arr.size))
    coef, intercept, rss, m = _ls(arr, p, p)
    sigma = math.sqrt(rss / (m - p - 1))
    return ARFit(coef=tuple(float(c) for c in coef), intercept=intercept, sigma=sigma, n=int(arr.size), rss=rss)


def ar_aic(y, max_order: int) -> np.ndarray:
    """AIC of AR(p), p = 1..max_order, all on the same equations t = max_order..n−1.

    Parameters
    ----------
    y : array_like, shape (n,)
        Training series; n ≥ 2·max_order + 2.
    max_order : int
        Largest order tried.

    Returns
    -------
    ndarray, shape (max_order,)
        aic[p − 1] = m·ln(RSS_p/m) + 2(p + 1), m = n − max_order (Gaussian conditional likelihood
        up to a constant; [Akaike1974]_). The same m for every p makes the values comparable.

    Raises
    ------
    ConfigError, DataFormatError, InsufficientDataError
        As :func:`ar_fit`.
    """
    arr = check_series(y, "y")
    pmax = _check_order(max_order, "max_order")
    need = 2 * pmax + 2
    if arr.size < need:
        raise InsufficientDataError(f"AIC up to AR({pmax}) needs at least {need} samples; got {arr.size}",
                                    needed=need, got=int(arr.size))
    out = np.empty(pmax)
    for p in range(1, pmax + 1):
        _, _, rss, m = _ls(arr, p, pmax)
        out[p - 1] = m * math.log(max(rss, np.finfo(float).tiny) / m) + 2 * (p + 1)
    return out


class AR(DriftModel):
    """Least-squares AR(p) with intercept: the linear one-step baseline.

    Parameters
    ----------
    order : int or "aic", default 4
        p ≥ 1, or ``"aic"``: choose p in 1..``max_order`` minimising :func:`ar_aic` on the training
        block (all orders scored on the same equations), then refit p on the whole block.
    max_order : int, default 12
        Largest order tried by ``order="aic"`` (ignored otherwise).

    Attributes
    ----------
    order_ : int
        Order used.
    coef_ : ndarray, shape (order_,)
        coef_[i] multiplies y[t−1−i].
    intercept_ : float
        [deg/h].
    sigma_ : float
        Residual standard deviation on the training block [deg/h].
    n_train_ : int
    aic_ : ndarray, shape (max_order,)
        AIC per order when ``order="aic"``; empty otherwise.
    last_ : ndarray, shape (order_,)
        Last training samples, start of free-run forecasts.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> y = np.sin(0.05 * np.arange(400)) + rng.normal(0, 0.01, 400)
    >>> model = AR(order=2).fit(y[:300])
    >>> model.predict(y[300:], history=y[:300]).shape
    (100,)
    """

    label = "AR(p)"

    def __init__(self, *, order=4, max_order=12):
        self.order = order
        self.max_order = max_order

    def fit(self, y_train, y_val=None):
        """Fit on the training block only (``y_val`` is ignored; it is part of the common interface)."""
        y = check_series(y_train, "y_train")
        if isinstance(self.order, str):
            if self.order != "aic":
                raise ConfigError(f"AR order must be an integer >= 1 or 'aic'; got {self.order!r}")
            aic = ar_aic(y, self.max_order)
            p = int(np.argmin(aic)) + 1
        else:
            p = _check_order(self.order)
            aic = np.empty(0)
        fit = ar_fit(y, p)
        self.order_ = p
        self.coef_ = np.asarray(fit.coef, dtype=np.float64)
        self.intercept_ = float(fit.intercept)
        self.sigma_ = float(fit.sigma)
        self.n_train_ = int(y.size)
        self.aic_ = aic
        self.last_ = y[-p:].copy()
        return self

    def predict(self, y, *, history=None):
        """One-step predictions: out[k] = c + Σ_i coef_[i]·z[k−1−i] on z = history ⧺ y [deg/h].

        NaN where fewer than ``order_`` measured samples precede ``y[k]``.
        """
        self._check_fitted()
        y = check_series(y, "y")
        hist = np.empty(0) if history is None else check_series(history, "history")
        p = self.order_
        full = np.concatenate([hist, y])
        out = np.full(y.size, np.nan)
        first = max(0, p - hist.size)
        if first >= y.size:
            return out
        # windows full[j-p:j] (oldest first) for j = hist.size+first .. full.size-1
        view = np.lib.stride_tricks.sliding_window_view(full[:-1], p)
        start = hist.size + first - p
        out[first:] = self.intercept_ + view[start:] @ self.coef_[::-1]
        return out

    def forecast(self, h: int, *, history=None):
        """Free-run forecast of ``h`` samples after ``history`` (default: after the training block)."""
        self._check_fitted()
        if isinstance(h, (bool, np.bool_)) or not isinstance(h, (int, np.integer)) or h < 0:
            raise ConfigError(f"h must be a non-negative integer; got {h!r}")
        p = self.order_
        if history is None:
            buf = list(self.last_)
        else:
            hist = check_series(history, "history")
            if hist.size < p:
                raise InsufficientDataError(f"AR({p}) forecast needs a history of at least {p} samples; got "
                                            f"{hist.size}", needed=p, got=int(hist.size))
            buf = list(hist[-p:])
        out = np.empty(int(h))
        rev = self.coef_[::-1]
        for i in range(int(h)):
            nxt = self.intercept_ + float(np.dot(rev, buf[-p:]))
            out[i] = nxt
            buf.append(nxt)
        return out

    def _get_state(self):
        meta = {"order_": self.order_, "intercept_": self.intercept_, "sigma_": self.sigma_,
                "n_train_": self.n_train_}
        return meta, {"coef_": self.coef_, "aic_": self.aic_, "last_": self.last_}

    def _set_state(self, meta, arrays):
        self.order_ = int(meta["order_"])
        self.intercept_ = float(meta["intercept_"])
        self.sigma_ = float(meta["sigma_"])
        self.n_train_ = int(meta["n_train_"])
        self.coef_ = np.asarray(arrays["coef_"], dtype=np.float64)
        self.aic_ = np.asarray(arrays["aic_"], dtype=np.float64)
        self.last_ = np.asarray(arrays["last_"], dtype=np.float64)
