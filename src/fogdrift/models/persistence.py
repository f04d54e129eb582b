"""Persistence ("repeat the last value"): the baseline every drift-model table shows."""

from __future__ import annotations

import numpy as np

from .._util import check_series
from .base import DriftModel

__all__ = ["Persistence"]


class Persistence(DriftModel):
    """Persistence ("repeat the last value") baseline: predicts y[k] = y[k-1].

    For a smoothed drift target this is hard to beat one step ahead (method notes §5.2);
    every metric table shows it beside the learned models.

    Attributes
    ----------
    last_ : float
        Last training sample [deg/h], start of free-run forecasts.

    Examples
    --------
    >>> model = Persistence().fit([0.1, 0.2, 0.4])
    >>> model.predict([0.5, 0.7], history=[0.3, 0.4]).tolist(), model.forecast(2).tolist()
    ([0.4, 0.5], [0.4, 0.4])
    """

    label = "persistence"

    def __init__(self):
        pass

    def fit(self, y_train, y_val=None):
        """Remember the last training sample (``y_val`` is accepted for the common interface and ignored)."""
        y = check_series(y_train, "y_train", min_length=1)
        self.last_ = float(y[-1])
        return self

    def predict(self, y, *, history=None):
        """One-step predictions [deg/h]: ``out = [history[-1], y[0], ..., y[-2]]`` (NaN first without history)."""
        self._check_fitted()
        y = check_series(y, "y")
        out = np.empty_like(y)
        out[1:] = y[:-1]
        if history is not None and len(history):
            out[0] = check_series(history, "history")[-1]
        else:
            out[0] = np.nan
        return out

    def forecast(self, h: int, *, history=None):
        """``h`` copies of the last sample of ``history`` (default: of the training block) [deg/h]."""
        self._check_fitted()
        start = self.last_ if history is None else float(check_series(history, "history", min_length=1)[-1])
        return np.full(int(h), start)

    def _get_state(self):
        return {"last_": self.last_}, {}

    def _set_state(self, meta, arrays):
        self.last_ = float(meta["last_"])
