"""The time base of a log, checked, not assumed: strictly increasing stamps, one sample interval between gaps,
a uniform grid (no step too short, no scatter, a span that matches, no drift off the straight line), gaps found.

:func:`check_time` returns the sample interval, the gap-free segments and the gap sizes, or refuses the log at
the line of the first stamp that breaks a rule (the thresholds below are the rules' one home).
"""

from __future__ import annotations

import numpy as np

from .readers.base import Table

__all__ = ["check_time", "GAP_FACTOR", "DT_TOLERANCE", "SHORT_STEP_FACTOR", "JITTER_TOLERANCE",
           "GRID_DRIFT_INTERVALS", "GRID_DRIFT_FRACTION"]

#: A time step larger than ``GAP_FACTOR`` sample intervals is a gap.
GAP_FACTOR = 1.5
#: Largest relative disagreement allowed between the time column and ``dt_s``/``rate_hz``.
DT_TOLERANCE = 0.01
#: A time step shorter than ``SHORT_STEP_FACTOR`` sample intervals means the rate changed (or the steps alternate).
SHORT_STEP_FACTOR = 0.7
#: Largest spread of the time steps (median absolute deviation / sample interval) of a uniform grid.
JITTER_TOLERANCE = 0.05
#: Largest departure of the time stamps of a gap-free stretch from the straight line through its first and last
#: stamp: the larger of ``GRID_DRIFT_INTERVALS`` sample intervals (delivery jitter of a logger that stamps on
#: receipt) and ``GRID_DRIFT_FRACTION`` of the stretch (an oscillator's drift with temperature, ~100 ppm).  Blocks
#: at other sample rates whose steps pass the spread and span checks (10 s at 125 Hz, 10 s at 80 Hz between
#: 100 Hz stretches) run seconds off that line.
GRID_DRIFT_INTERVALS = 20.0
GRID_DRIFT_FRACTION = 1e-3

_UNIFORM_HINT = ("the analysis needs one sample interval; split the log where the rate changes, or, if the samples "
                 "are uniform and only the time stamps are not, pass {opt:time_column} none with {opt:rate_hz}")


def _check_uniform(table: Table, t: np.ndarray, steps: np.ndarray, dt: float, t_idx, gap_rows) -> None:
    """The time base is checked, not assumed: between gaps the steps must be one sample interval.

    Refused, naming the line: a step shorter than :data:`SHORT_STEP_FACTOR` intervals (the rate changed, or the
    steps alternate short/long, which the median hides); steps that scatter by more than
    :data:`JITTER_TOLERANCE` (median absolute deviation relative to ``dt``); a gap-free stretch whose time span
    differs from ``(n - 1) dt`` by more than :data:`DT_TOLERANCE`.
    """
    short = np.flatnonzero(steps < SHORT_STEP_FACTOR * dt)
    if short.size:
        i = int(short[0]) + 1
        s = float(steps[i - 1])
        raise table.error(
            f"time step of {s:.6g} s{table.at(i)} (after t={float(t[i - 1])!r} s on {table.row_ref(i - 1)}) is "
            f"{s / dt:.3g} sample intervals; expected {dt:.10g} s (the median step, {1 / dt:.10g} Hz): the sample "
            f"rate changes or the steps alternate ({short.size} step(s) shorter than {SHORT_STEP_FACTOR} intervals); "
            + _UNIFORM_HINT, row=i, col=t_idx)
    inner = np.ones(steps.size, dtype=bool)
    inner[gap_rows - 1] = False
    if inner.sum() >= 8:
        spread = float(np.median(np.abs(steps[inner] - dt))) / dt
        if spread > JITTER_TOLERANCE:
            worst = int(np.argmax(np.where(inner, np.abs(steps - dt), -1.0))) + 1
            raise table.error(
                f"time steps scatter by {100 * spread:.3g} % of the sample interval {dt:.10g} s (median absolute "
                f"deviation; largest {float(steps[worst - 1]):.6g} s{table.at(worst)}); expected a uniform grid "
                f"within {100 * JITTER_TOLERANCE:g} %; " + _UNIFORM_HINT, row=worst, col=t_idx)
    bounds = [0, *np.asarray(gap_rows).tolist(), t.shape[0]]
    for a, b in zip(bounds[:-1], bounds[1:]):
        if b - a < 3:
            continue
        span, grid = float(t[b - 1] - t[a]), (b - 1 - a) * dt
        if abs(span - grid) > DT_TOLERANCE * grid:
            raise table.error(
                f"time column spans {span:.6g} s from {table.row_ref(a)} to {table.row_ref(b - 1)}, but its "
                f"{b - a} samples at {dt:.10g} s span {grid:.6g} s ({100 * (span / grid - 1):+.3g} %); expected "
                f"agreement within {100 * DT_TOLERANCE:g} %; " + _UNIFORM_HINT, row=b - 1, col=t_idx)
        k, dev = _grid_departure(t[a:b])
        limit = max(GRID_DRIFT_INTERVALS * dt, GRID_DRIFT_FRACTION * span)
        if abs(dev) > limit:
            i = a + k
            raise table.error(
                f"time stamps run {abs(dev):.6g} s ({abs(dev) / dt:.3g} sample intervals) {'ahead of' if dev > 0 else 'behind'} "
                f"a uniform grid{table.at(i)} (the straight line from {table.row_ref(a)} to {table.row_ref(b - 1)}); "
                f"expected within {limit:.3g} s: the sample rate changes within the log (blocks at other rates "
                "whose steps each look regular); " + _UNIFORM_HINT, row=i, col=t_idx)


def _grid_departure(t: np.ndarray, chunk: int = 1 << 20) -> tuple[int, float]:
    """``(k, d)``: the sample whose stamp lies farthest from the straight line through the first and last stamp,
    and its signed distance [s] (computed in chunks: no second array the size of the record)."""
    n = t.shape[0]
    slope = float(t[-1] - t[0]) / (n - 1)
    best_k, best = 0, 0.0
    for a in range(0, n, chunk):
        seg = t[a:a + chunk] - (t[0] + slope * np.arange(a, min(a + chunk, n), dtype=np.float64))
        j = int(np.argmax(np.abs(seg)))
        if abs(seg[j]) > abs(best):
            best_k, best = a + j, float(seg[j])
    return best_k, best


def check_time(table: Table, t: np.ndarray, t_idx, dt_user, split: bool):
    """Validate the time vector; return (dt_s, [(start, stop) segments], [gap sizes in s])."""
    n = t.shape[0]
    if n < 2:
        return dt_user, [(0, n)], []
    with np.errstate(over="ignore", invalid="ignore"):
        steps = np.diff(t)
    nonpos = ~(steps > 0)
    if nonpos.any():
        i = int(np.argmax(nonpos)) + 1
        if steps[i - 1] == 0:
            msg = (f"duplicate timestamp{table.at(i)}; expected strictly increasing time, "
                   f"got {float(t[i])!r} s again (as on {table.row_ref(i - 1)})")
        else:
            msg = (f"time goes backwards{table.at(i)}; expected strictly increasing time, "
                   f"got {float(t[i])!r} s after {float(t[i - 1])!r} s on {table.row_ref(i - 1)}")
        raise table.error(msg, row=i, col=t_idx)
    dt_time = float(f"{float(np.median(steps)):.10g}")
    if not (np.isfinite(dt_time) and dt_time > 0):
        raise table.error(
            f"time steps overflow; expected a finite median step between time stamps, got {dt_time!r} s", col=t_idx
        )
    if dt_user is None:
        dt = dt_time
    else:
        rel = abs(dt_time - dt_user) / dt_user
        if rel > DT_TOLERANCE:
            raise table.error(
                f"time column disagrees with the given sample interval (omit {{opt:rate_hz}} to take it from the "
                f"time column); expected a median step within 1 % of {dt_user:.10g} s ({1 / dt_user:.10g} Hz), "
                f"got {dt_time:.10g} s ({rel:.1%} off)", col=t_idx,
            )
        dt = dt_user
    gap_rows = np.flatnonzero(steps > GAP_FACTOR * dt) + 1
    _check_uniform(table, t, steps, dt, t_idx, gap_rows)
    if gap_rows.size == 0:
        return dt, [(0, n)], []
    if not split:
        i = int(gap_rows[0])
        g = float(steps[i - 1])
        raise table.error(
            f"gap in time{table.at(i)} of {g:.6g} s ({g / dt:.4g} sample intervals) between t={float(t[i - 1])!r} s "
            f"and t={float(t[i])!r} s ({gap_rows.size} gap(s) in total; set {{opt:gaps}} to use the gap-free "
            f"segments); expected steps of at most {GAP_FACTOR} x {dt:.10g} s, got {g:.6g} s",
            row=i, col=t_idx,
        )
    starts = [0, *gap_rows.tolist()]
    stops = [*gap_rows.tolist(), n]
    return dt, list(zip(starts, stops)), [float(steps[i - 1]) for i in gap_rows]
