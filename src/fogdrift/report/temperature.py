"""Figure of the rate beside the temperature carried with the log (for the report; matplotlib, PNG).

The report (:func:`fogdrift.report.render_report`, section "Recording") calls :func:`plot_rate_and_temperature`
when ``record.temperature_c`` is not None.
This module only draws; the numbers come from :mod:`fogdrift.temperature`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ConfigError
from ..temperature import summary_line, temperature_summary
from .figures import save_figure, literal

__all__ = ["plot_rate_and_temperature", "MAX_POINTS"]

#: Points drawn per curve at most (block means of the record; the figure stays small for long logs).
MAX_POINTS = 20_000


def _decimated(x: np.ndarray, n_out: int) -> np.ndarray:
    """Block means of ``x`` (axis 0) in ``n_out`` blocks at most (the tail that does not fill a block is dropped)."""
    k = max(1, x.shape[0] // n_out)
    nb = x.shape[0] // k
    return x[: nb * k].reshape((nb, k) + x.shape[1:]).mean(axis=1)


def plot_rate_and_temperature(record, path, *, summary=None) -> Path:
    """Rate of every axis (top panels) and the temperature (bottom panel) against time, written as PNG.

    Parameters
    ----------
    record : GyroRecord
        A record with ``temperature_c`` (deg C); rates in deg/h.
    path : str or Path
        Output PNG.
    summary : TemperatureSummary or dict, optional
        The temperature's range and drift as already summarised (the report passes the result's
        ``record["temperature"]``); None: summarised here from ``record.temperature_c``.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ConfigError
        If the record carries no temperature.

    Notes
    -----
    Curves longer than :data:`MAX_POINTS` are drawn as block means (a plot cannot show more points
    than pixels; the means keep slow trends exact).  The title of the temperature panel is
    :func:`fogdrift.temperature.summary_line`.
    """
    temp = getattr(record, "temperature_c", None)
    if temp is None:
        raise ConfigError(f"{record.source}: the record carries no temperature; load it with {{opt:temperature}}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = record.n_samples
    k = max(1, n // MAX_POINTS)
    t = record.t0_s + (np.arange(n // k) * k + (k - 1) / 2.0) * record.dt_s
    rate = _decimated(np.asarray(record.data_internal), n // k)
    temp_d = _decimated(np.asarray(temp), n // k)
    fig, axs = plt.subplots(record.n_axes + 1, 1, figsize=(9, 2.0 * (record.n_axes + 1)), sharex=True,
                            squeeze=False)
    for j, name in enumerate(record.axis_names):
        axs[j, 0].plot(t, rate[:, j], lw=0.5)
        axs[j, 0].set_ylabel(literal(f"{name} [deg/h]"))
        axs[j, 0].grid(alpha=0.3)
    ax = axs[-1, 0]
    ax.plot(t, temp_d, color="C3", lw=1.0)
    ax.set_ylabel("T [°C]")
    ax.set_xlabel("t [s]")
    ax.grid(alpha=0.3)
    ax.set_title(summary_line(temperature_summary(temp, record.dt_s) if summary is None else summary), fontsize=8)
    if k > 1:
        fig.suptitle(f"Rate and temperature (block means of {k} samples)", fontsize=9)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(fig, path, dpi=110, bbox_inches="tight", format="png")  # complete or absent (fogdrift.output)
