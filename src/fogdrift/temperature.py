"""Temperature carried with a gyro log: its range and drift over the log.

A reader can carry one temperature column (deg C) into the record
(:attr:`fogdrift.io.GyroRecord.temperature_c`, ``load(..., temperature=NAME)``).  Gyro bias and
scale factor depend on temperature (IEEE Std 952-1997 §§ 8.2.1 and C.5 ask for the temperature
during a drift test to be recorded with it), so a characterisation states how much the
temperature moved while the log was taken.  This module only summarises; the figure is
:func:`fogdrift.report.temperature.plot_rate_and_temperature`.  Temperature as a model covariate
comes later.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from .errors import ConfigError
from .units import S_PER_H

__all__ = ["TemperatureSummary", "temperature_summary", "summary_line", "EDGE_FRACTION"]

#: Share of the log averaged at each end for the start and end temperature (at least one sample).
EDGE_FRACTION = 0.01


@dataclass(frozen=True)
class TemperatureSummary:
    """Range and drift of the temperature over one log.

    Attributes
    ----------
    n_samples : int
        Temperature samples summarised.
    duration_s : float
        Length of the log in s (``n_samples * dt_s``).
    min_c, max_c, mean_c : float
        Extremes and mean in deg C.
    range_c : float
        ``max_c - min_c`` in deg C.
    start_c, end_c : float
        Mean of the first and of the last :data:`EDGE_FRACTION` of the samples (at least one) in
        deg C: the temperature at the start and at the end, robust to one noisy sample.
    change_c : float
        ``end_c - start_c``: the drift over the log in deg C.
    slope_c_per_h : float
        Least-squares slope of temperature against time over the whole log in deg C/h (0 for one
        sample).
    """

    n_samples: int
    duration_s: float
    min_c: float
    max_c: float
    mean_c: float
    range_c: float
    start_c: float
    end_c: float
    change_c: float
    slope_c_per_h: float

    def to_dict(self) -> dict:
        """JSON-serialisable dict (units in the keys)."""
        return asdict(self)


def temperature_summary(temperature_c, dt_s: float) -> TemperatureSummary:
    """Range and drift of a temperature series sampled every ``dt_s`` seconds.

    Parameters
    ----------
    temperature_c : array_like, shape (n_samples,)
        Temperature in deg C, finite.
    dt_s : float
        Sample interval in s (> 0).

    Returns
    -------
    TemperatureSummary

    Raises
    ------
    ConfigError
        Empty or non-finite series, or ``dt_s`` not > 0.

    Examples
    --------
    >>> s = temperature_summary([20.0, 20.5, 21.0, 21.5, 22.0], dt_s=900.0)   # 15-min samples
    >>> s.range_c, s.change_c, s.slope_c_per_h, s.duration_s
    (2.0, 2.0, 2.0, 4500.0)
    """
    x = np.asarray(temperature_c, dtype=np.float64).reshape(-1)
    dt = float(dt_s)
    if x.size == 0 or not np.all(np.isfinite(x)):
        raise ConfigError("temperature_c must be a non-empty series of finite deg C values")
    if not (math.isfinite(dt) and dt > 0):
        raise ConfigError(f"dt_s must be a finite number of seconds > 0; got {dt_s!r}")
    n = x.size
    k = max(1, int(round(EDGE_FRACTION * n)))
    start, end = float(np.mean(x[:k])), float(np.mean(x[-k:]))
    if n > 1:
        t_h = (np.arange(n) - (n - 1) / 2.0) * (dt / S_PER_H)     # centred: no cancellation
        slope = float(np.dot(t_h, x - x.mean()) / np.dot(t_h, t_h))
    else:
        slope = 0.0
    lo, hi = float(x.min()), float(x.max())
    return TemperatureSummary(n_samples=int(n), duration_s=n * dt, min_c=lo, max_c=hi, mean_c=float(x.mean()),
                              range_c=hi - lo, start_c=start, end_c=end, change_c=end - start,
                              slope_c_per_h=slope)


def summary_line(summary: TemperatureSummary | dict) -> str:
    """One line for a console: range, drift over the log and the least-squares slope.

    Examples
    --------
    >>> summary_line(temperature_summary([20.0, 20.5, 21.0, 21.5, 22.0], dt_s=900.0))
    'temperature 20.00 to 22.00 deg C (range 2.00), drift +2.00 deg C over 1.25 h (slope +2.000 deg C/h)'
    """
    s = summary.to_dict() if isinstance(summary, TemperatureSummary) else dict(summary)
    return (f"temperature {s['min_c']:.2f} to {s['max_c']:.2f} deg C (range {s['range_c']:.2f}), "
            f"drift {s['change_c']:+.2f} deg C over {s['duration_s'] / S_PER_H:.3g} h "
            f"(slope {s['slope_c_per_h']:+.3f} deg C/h)")
