"""Causal one-step drift estimates of one fitted model on a stream of modelling-rate samples.

:class:`CausalPredictor` is the piece that turns a fitted :class:`~fogdrift.models.DriftModel` into a real-time
compensator.  It is fed the bias-removed rate ``z`` at the modelling rate, one segment at a time, and returns for
every sample ``z[j]`` of the segment the drift estimate made from ``z[:j]`` only:

* ``input_kind == "drift"`` (the paper's models and persistence): the causal drift
  ``c[j] = g @ z[j-W+1 .. j]`` (``g`` the last row of the wavelet drift operator of a ``W``-sample window,
  :func:`fogdrift.lifting.causal_drift`), and the model's one-step prediction of ``c[j]`` from ``c[:j]``;
  the model is called with a fixed-length history (the last :func:`history_length` causal-drift values);
* ``input_kind == "rate"`` (the Kalman filter): the filter's prediction H x_{j|j-1}, the filter state carried
  from segment to segment, with its 1-sigma.

Entries without enough past (the causal drift's first ``W - 1`` samples, the model's lags) are NaN.  Outputs
depend only on the segment boundaries the caller chooses, never on how the input was read: the stream engine
uses fixed segment boundaries, so chunked and whole-file runs are identical (a test checks it).
"""

from __future__ import annotations

import numpy as np

from ..errors import ConfigError
from ..lifting import causal_drift

__all__ = ["causal_weights", "history_length", "CausalPredictor"]

#: History [modelling samples] given to models whose prediction depends on a running state that
#: starts from zero at the start of the history (Elman context): enough for it to settle.
RECURRENT_HISTORY = 256


def causal_weights(window: int, wavelet: str, level: int, mode: str) -> np.ndarray:
    """``g`` with ``causal_drift(x, window)[k] == g @ x[k-window+1 : k+1]`` (the causal wavelet drift as an FIR).

    Examples
    --------
    >>> g = causal_weights(128, "db2", 4, "symmetric")
    >>> g.shape, round(float(g.sum()), 12)  # a constant passes unchanged
    ((128,), 1.0)
    """
    return np.ascontiguousarray(causal_drift(np.eye(int(window)), int(window), wavelet, level, mode)[-1])


def history_length(model) -> int:
    """Samples of past causal drift a drift-input model's one-step prediction uses.

    Persistence 1, AR its order, rolling GM(1,1) its window; recurrent models (Elman, grey-Elman)
    :data:`RECURRENT_HISTORY` (their context restarts at the start of the history).

    Raises
    ------
    ConfigError
        A GM(1,1) in ``"whole"`` mode (its prediction depends on the time since training started).
    """
    name = type(model).__name__
    if name == "Persistence":
        return 1
    if name == "AR":
        return int(model.order_)
    if name == "GM11":
        if model.mode != "rolling":
            raise ConfigError("a GM(1,1) in mode 'whole' cannot compensate a new log (its time response is "
                              "tied to the training record); use mode 'rolling'")
        return int(model.window)
    return RECURRENT_HISTORY


class CausalPredictor:
    """One-step causal drift estimates of ``model`` over consecutive segments of ``z`` [deg/h].

    Parameters
    ----------
    model : DriftModel
        Fitted model (its ``input_kind`` decides what it is fed).
    g : ndarray, shape (W,)
        Causal-drift weights (:func:`causal_weights`), used for drift-input models.

    Examples
    --------
    >>> from fogdrift.models import Persistence
    >>> p = CausalPredictor(Persistence().fit([0.0]), np.full(2, 0.5))
    >>> p.push(np.array([1.0, 3.0, 5.0])).tolist()  # c = [nan, 2, 4]; prediction of c[j] is c[j-1]
    [nan, nan, 2.0]
    >>> p.push(np.array([7.0]), extra=True).tolist()  # the sample after the log: predicted from c = 6
    [4.0, 6.0]
    """

    def __init__(self, model, g):
        self.model = model
        self.g = np.asarray(g, dtype=np.float64)
        self.rate_input = getattr(model, "input_kind", "drift") == "rate"
        self._z_tail = np.empty(0)
        self._c_tail = np.empty(0)
        self._hist = 0 if self.rate_input else history_length(model)
        self._state = None
        self.sigma = None  # 1-sigma of the last pushed estimates (rate-input models), else None

    def push(self, z, *, extra: bool = False) -> np.ndarray:
        """Drift estimates for every sample of ``z`` (and, with ``extra``, for the sample after it).

        Returns
        -------
        ndarray, shape (len(z) + extra,)
            NaN where the model has too little past.
        """
        z = np.asarray(z, dtype=np.float64)
        if self.rate_input:
            pred, sigma, self._state = self.model.filter(z, state=self._state)
            if extra:
                mean, s, _ = self.model.forecast_with_uncertainty(1, state=self._state)
                pred, sigma = np.append(pred, mean), np.append(sigma, s)
            self.sigma = sigma
            return pred
        W = self.g.size
        full = np.concatenate([self._z_tail, z])
        c = np.full(z.size, np.nan)
        first = min(z.size, max(0, (W - 1) - self._z_tail.size))  # index in z of the first full window
        if first < z.size:
            # c[k] = sum_i g[i] full[k0 + k + i], as W elementwise passes (a BLAS dot product's summation
            # order may depend on memory alignment; this one does not)
            k0 = self._z_tail.size + first - (W - 1)
            n_out = z.size - first
            acc = np.zeros(n_out)
            for i in range(W):
                acc += self.g[i] * full[k0 + i:k0 + i + n_out]
            c[first:] = acc
        self._z_tail = full[-(W - 1):] if W > 1 else np.empty(0)
        y = c[first:]
        if extra:
            y = np.append(y, 0.0)  # the target slot of the sample after the log; its prediction uses y[:-1] only
        out = np.full(z.size + int(extra), np.nan)
        # Elman.predict cannot take fewer samples than its lags in all (they would all be NaN anyway)
        if y.size and self._c_tail.size + y.size > int(getattr(self.model, "lags", 0)):
            out[first:] = self.model.predict(y, history=self._c_tail if self._c_tail.size else None)
        finite = c[first:]
        self._c_tail = np.concatenate([self._c_tail, finite])[-self._hist:]
        return out
