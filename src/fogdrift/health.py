"""Sensor health: is this a working gyro at all?  Checks made before any fit, beside the plausibility rules.

A noise fit takes every sample as the sensor's output.  A sensor (or its logger) that froze, a rate clipped at
the range limit, one axis in another unit than the others, an accelerometer read as a gyro or a time column
that counts samples or milliseconds all give a curve that looks fine and a number that is wrong (half the log
frozen: N 0.70x the truth; 20 % clipped: N 0.84x; rad/s beside deg/s: that axis 57x low; ms read as s: N 31.6x).
:func:`health_findings` names each, located (the axis, the samples, the time), with its likely cause and the
flag that fixes it; :func:`fogdrift.plausibility.check_record` adds them to its findings, so every command
prints them where it prints the plausibility findings (and the workflows' ``screen()`` before every fit).

Rules (each a tuple ``(rule, axes, message, likely_units)``; settings as ``{opt:NAME}``):

``frozen``
    The longest run of identical consecutive samples of an axis, L samples, against the repeats elsewhere in
    the axis: with p the fraction of consecutive equal pairs outside the run (or, when larger, the fraction of
    pairs starting at the run's value that repeat it, from at least 20 such pairs: a quantised sensor repeats
    its commonest level most), a run of L is expected less than once when ``n p^(L-1) < FROZEN_P``
    (independent samples; p = 0 for unquantised data).  Flagged when
    ``L >= FROZEN_MIN_RUN`` and that holds.  A constant axis is said as such.
``saturated``
    Samples exactly at the axis's largest (smallest) value: at least :data:`CLIP_MIN_COUNT` and
    :data:`CLIP_MIN_FRACTION` of the samples, and more than :data:`CLIP_PILE` times the samples at the next
    value inwards (a quantised Gaussian has fewer samples at its extreme level than next to it; a clipped
    rate piles up there).
``unit-mix``
    Two or more angular-rate axes whose noise (the robust deviation of the first differences) differ by a
    unit factor: 57.3 (rad vs deg), 60 (per min vs per s), 1000 (m... vs ...), 3600 (per h vs per s), within
    :data:`UNIT_MIX_RTOL` -- the odd axis named (the one away from the others' median).
``gravity``
    Angular-rate axes whose steady means (``|mean| > GRAVITY_STEADY`` times their noise) make a vector of
    1 g: 9.80665 (m/s^2) from one or more axes, or 1 (g) from two or more (a tilted triad 0.8/0.6), within
    :data:`GRAVITY_RTOL`: likely an accelerometer read as a gyro.
``time-step``
    A time column read as s whose step is an exact integer of 1 to 9 s from an integer start: a sample index,
    or a time in ms (a 1 kHz log read as 1 Hz); steps of 10 s and more are the plausibility ``sample-rate``
    rule's.

The rules warn; they never change the data (but ``--segments auto`` fits around a frozen stretch:
:func:`fogdrift.segments.plan_segments`).

Measured false alarms: 0 findings on 520 clean simulated logs (white noise; white + random walk + bias
instability; quantised counts with many repeats; triads whose axes' noise differ up to 10x, with the Earth rate;
``tests/test_health.py`` keeps 120 of them), and none on 12 of the 13 real logs in the shared data (ADIS16405 gyros
and accelerometers, MTi-G, the PSINS RLG).  The 13th, the ROMY ring laser sampled at 1 Hz with whole-second
stamps from 0, gets the ``time-step`` note: a genuine 1 Hz log with integer stamps cannot be told from a sample
index or from ms read as s, so the note says that such a log needs nothing.
"""

from __future__ import annotations

import math

import numpy as np

from .units import DEG_PER_RAD, S_PER_H, S_PER_MIN

__all__ = ["health_findings", "frozen_stretch", "FROZEN_MIN_RUN", "FROZEN_P", "CLIP_MIN_COUNT", "CLIP_MIN_FRACTION", "CLIP_PILE",
           "UNIT_FACTORS", "UNIT_MIX_RTOL", "GRAVITY_RTOL", "GRAVITY_STEADY"]

#: A frozen stretch is at least this many identical consecutive samples ...
FROZEN_MIN_RUN = 50
#: ... and less likely than this under the axis's own rate of repeats.
FROZEN_P = 1e-6
#: Samples at the extreme value: at least this many, this fraction of the axis, and this many times the
#: samples at the next value inwards.
CLIP_MIN_COUNT = 20
CLIP_MIN_FRACTION = 1e-3
CLIP_PILE = 3.0
#: Unit factors between axes: (factor, what it suggests).
UNIT_FACTORS = ((DEG_PER_RAD, "rad/s beside deg/s (or rad/h beside deg/h)"),
                (S_PER_MIN, "per minute beside per second"),
                (1000.0, "milli-units beside units (e.g. mrad/s beside rad/s)"), (S_PER_H, "deg/h beside deg/s"))
#: Relative tolerance of a unit factor between axes' noise.
UNIT_MIX_RTOL = 0.15
#: Relative tolerance of "the mean vector is 1 g".
GRAVITY_RTOL = 0.03
#: A mean counts as steady when it is this many times the axis's noise deviation.
GRAVITY_STEADY = 20.0
#: Samples used per axis (the first ones): the checks stay cheap on 10^8-sample logs.
MAX_SAMPLES = 1 << 24


def health_findings(record) -> list[tuple]:
    """The health rules (module docstring) on a :class:`~fogdrift.io.GyroRecord`; a list of
    ``(rule, axes, message, likely_units)``, empty for a healthy record."""
    out = []
    dt = float(record.dt_s)
    quantities = list(getattr(record, "quantities", ["angular_rate"] * record.n_axes))
    noise = {}
    for k, axis in enumerate(record.axis_names):
        x = np.asarray(record.axis(axis), dtype=np.float64)[:MAX_SAMPLES]
        if x.size < 2:
            continue
        unit = _unit(record, k)
        scale = _scale(record, k)
        out += _frozen(axis, x, dt, unit, scale)
        out += _saturated(axis, x, unit, scale)
        noise[axis] = _noise(x)
    gyro = [a for a, q in zip(record.axis_names, quantities) if q == "angular_rate" and a in noise]
    out += _unit_mix(gyro, noise)
    out += _gravity(record, gyro, noise)
    out += _time_step(record)
    return out


def _unit(record, k) -> str:
    chans = getattr(getattr(record, "signal", None), "channels", None)
    u = chans[k].unit if chans and k < len(chans) else record.input_unit
    return str(getattr(u, "text", u))


def _scale(record, k) -> float:
    chans = getattr(getattr(record, "signal", None), "channels", None)
    return float(chans[k].scale_to_internal) if chans and k < len(chans) else float(record.scale_to_internal)


def _noise(x: np.ndarray) -> float:
    """Robust deviation of the first differences / sqrt(2) (the white-noise deviation of the samples).

    The medians select in place, in the one array of differences: an order statistic does not depend on the order
    of the values, so no copy is needed (the standard deviation, whose sum does, takes the differences afresh)."""
    d = np.diff(x)
    med = np.median(d, overwrite_input=True)
    np.abs(np.subtract(d, med, out=d), out=d)
    mad = float(np.median(d, overwrite_input=True)) * 1.4826
    if mad == 0.0:
        mad = float(np.std(np.diff(x)))
    return mad / math.sqrt(2.0)


def _longest_run(x: np.ndarray) -> tuple[int, int, int]:
    """(start, length, number of equal consecutive pairs) of the longest run of identical samples."""
    same = x[1:] == x[:-1]
    n_same = int(np.count_nonzero(same))
    if n_same == 0:
        return 0, 1, 0
    edges = np.flatnonzero(np.diff(np.concatenate(([0], same.view(np.int8), [0]))))
    starts, ends = edges[::2], edges[1::2]  # runs of equal pairs [s, e): samples s .. e
    j = int(np.argmax(ends - starts))
    return int(starts[j]), int(ends[j] - starts[j] + 1), n_same


def _t(i: int, dt: float) -> str:
    return f"{i * dt:.6g}"


def frozen_stretch(x) -> tuple[int, int] | None:
    """``(start, stop)`` (samples, stop exclusive) of the frozen stretch of one axis (rule ``frozen``), else None."""
    x = np.asarray(x, dtype=np.float64)[:MAX_SAMPLES]
    n = x.size
    if n < 2:
        return None
    start, length, n_same = _longest_run(x)
    if length < FROZEN_MIN_RUN:
        return None
    pairs_out = (n - 1) - (length - 1)
    p = (n_same - (length - 1)) / pairs_out if pairs_out > 0 else 0.0
    v = x[start]
    at_v = np.flatnonzero(x[:-1] == v)
    at_v = at_v[(at_v < start) | (at_v >= start + length - 1)]  # pairs that start at the value, outside the run
    if at_v.size >= 20:  # a quantised sensor repeats its most common level more often than the others
        p = max(p, float(np.mean(x[at_v + 1] == v)))
    if p > 0 and math.log(n) + (length - 1) * math.log(p) >= math.log(FROZEN_P):
        return None
    return start, start + length


def _frozen(axis, x, dt, unit, scale) -> list[tuple]:
    n = x.size
    found = frozen_stretch(x)
    if found is None:
        return []
    start, end = found
    length = end - start
    value = x[start] / scale
    if length == n:
        return [("frozen", (axis,), f"{axis}: all {n} samples read {value:.6g} {unit}: the sensor or its logger is "
                                    "stuck (or the column is a constant, not a rate); nothing to analyse here -- "
                                    "check the file and {opt:columns}", ())]
    where = "to the end of the log" if end == n else f"to sample {end - 1}"
    cut = (f"{{opt:segments}} 0:{_t(start, dt)}" if end == n else
           f"{{opt:segments}} {_t(end, dt)}:" if start == 0 else
           f"{{opt:segments}} 0:{_t(start, dt)},{_t(end, dt)}:")
    return [("frozen", (axis,),
             f"{axis}: samples {start} {where} ({length} samples, {100 * length / n:.3g} % of the log, t = "
             f"{_t(start, dt)}-{_t(end, dt)} s) all read {value:.6g} {unit}: a frozen (stuck) sensor or logger "
             f"repeating its last value; the fit takes them as a perfectly quiet gyro (N and the other terms come out "
             f"low); with {{opt:segments}} auto (the default) the noise fit leaves them out; else fit the healthy part "
             f"with {cut}", ())]


def _saturated(axis, x, unit, scale) -> list[tuple]:
    n = x.size
    lo, hi = float(np.min(x)), float(np.max(x))
    if lo == hi:
        return []
    found = []
    for side, v in (("maximum", hi), ("minimum", lo)):
        at = int(np.count_nonzero(x == v))
        if at < CLIP_MIN_COUNT or at < CLIP_MIN_FRACTION * n:
            continue
        inner = x[x < v] if side == "maximum" else x[x > v]
        nxt = float(np.max(inner)) if side == "maximum" else float(np.min(inner))
        near = int(np.count_nonzero(x == nxt))
        if at <= CLIP_PILE * near:
            continue
        idx = np.flatnonzero(x == v)
        found.append(("saturated", (axis,),
                      f"{axis}: {at} samples ({100 * at / n:.3g} % of the log, first at sample {int(idx[0])}, last at "
                      f"{int(idx[-1])}) sit exactly at its {side} {v / scale:.6g} {unit} ({near} at the next value): "
                      "the rate is clipped at the sensor's range limit (saturation) and the fit takes the clipped "
                      "samples as data (N comes out low); record within the range, or cut the clipped stretch with "
                      "{opt:segments}", ()))
    return found


def _unit_mix(gyro, noise) -> list[tuple]:
    levels = {a: noise[a] for a in gyro if noise[a] > 0 and math.isfinite(noise[a])}
    if len(levels) < 2:
        return []
    out = []
    for a, v in levels.items():
        others = [w for b, w in levels.items() if b != a]
        ref = float(np.median(others))
        ratio = v / ref
        r = ratio if ratio >= 1 else 1.0 / ratio
        for factor, words in UNIT_FACTORS:
            if abs(r / factor - 1.0) <= UNIT_MIX_RTOL:
                if len(levels) == 2 and ratio < 1:
                    break  # two axes: said once, from the noisier one
                rel = "above" if ratio > 1 else "below"
                out.append(("unit-mix", (a,),
                            f"{a}: its noise is {r:.4g}x {rel} the other axes' ({', '.join(b for b in levels if b != a)}): "
                            f"the unit factor {factor:.4g} ({words}); one unit for all columns reads one of them in "
                            "the wrong unit -- give each column's unit with {opt:unit} NAME=UNIT,... (or in the "
                            "header, 'gx[rad/s]')", ()))
                break
    return out


def _gravity(record, gyro, noise) -> list[tuple]:
    if not gyro:
        return []
    idx = [record.axis_names.index(a) for a in gyro]
    means = {a: float(np.mean(np.asarray(record.axis(a))[:MAX_SAMPLES])) / _scale(record, k) for a, k in zip(gyro, idx)}
    steady = [a for a in gyro if abs(means[a]) * _scale(record, record.axis_names.index(a))
              > GRAVITY_STEADY * noise[a] and noise[a] > 0]
    if not steady:
        return []
    norm = math.sqrt(sum(means[a] ** 2 for a in steady))
    for level, unit, least in ((9.80665, "m/s^2", 1), (1.0, "g", 2)):
        if len(steady) >= least and abs(norm / level - 1.0) <= GRAVITY_RTOL:
            parts = ", ".join(f"{a} {means[a]:.4g}" for a in steady)
            return [("gravity-like", tuple(steady),
                     f"{', '.join(steady)}: steady means {parts} ({record.input_unit} as read) make a vector of "
                     f"{norm:.4g}, gravity in {unit} (1 g = 9.80665 m/s^2): likely an accelerometer read as a gyro; "
                     f"give its unit as {{opt:unit}} {unit} (or gyro=...,accel={unit}), or leave it out with "
                     "{opt:columns}", (unit,))]
    return []


def _time_step(record) -> list[tuple]:
    smp = getattr(getattr(record, "signal", None), "sampling", None)
    if smp is None or smp.dt_source != "time column" or smp.time_unit not in (None, "s"):
        return []
    dt = float(smp.native_dt_s)
    step = round(dt)
    t0 = float(getattr(record, "t0_s", 0.0))
    if not (1 <= step <= 9) or abs(dt - step) > 1e-9 * step or abs(t0 - round(t0)) > 1e-9 * max(1.0, abs(t0)):
        return []
    col = smp.time_column or "the time column"
    return [("time-step", (),
             f"time column '{col}' is read as s and steps by exactly {step} from {t0:.6g} (whole numbers): a "
             f"sample index, or a time in ms read as s ({1000 / step:g} Hz read as {1 / step:g} Hz; a wrong rate "
             f"scales N by {math.sqrt(1000):.3g}); if so give {{opt:time_unit}} ms or {{opt:rate_hz}} HZ with "
             "{opt:time_column} none (a log really sampled every "
             f"{step} s needs nothing)", ())]
