"""Is a record plausible for any gyro?  Checks that catch a wrong rate unit or time unit.

Multiplying every sample by a constant changes no ratio (slopes, B/N, signal-to-noise), so a wrong unit
shows only in absolute levels.  :func:`check_record` applies four rules to a record in deg/h and names
the units under which the numbers would be plausible:

``white-noise``
    The white-noise floor ``N_floor = min over tau of sigma(tau) sqrt(tau) / 60`` [deg/sqrt(h)] (sigma the
    overlapping Allan deviation in deg/h, tau in s) is an upper bound of the angle random walk N: every
    IEEE-952 term adds to sigma^2(tau), and the N term alone is N^2 3600 / tau (method notes §2.2, §2.3).
    A floor whose 68 % upper bound is below :data:`ARW_MIN_DPRH` (1e-6 deg/sqrt(h): quieter than any portable
    gyro, see *Gyro classes*) or whose 68 % lower bound is above :data:`ARW_MAX_DPRH` (100 deg/sqrt(h), noisier
    than any gyro at every tau) is implausible.  A quiet floor inside the seismic / strategic class
    (1e-6 to 1e-3 deg/sqrt(h)) is not warned on its own: a 3-axis record of that grade is still checked by the
    Earth-rate rule.
``range``
    ``max |rate|`` above :data:`RANGE_MAX_DPH` (1e4 deg/s) is beyond the range of any gyro.
``earth-rate``
    A 3-axis record whose white-noise floor is navigation grade (below :data:`NAV_GRADE_DPRH` on every axis)
    resolves the Earth rate, 15.04 deg/h (method notes §6), in its mean vector; a mean vector shorter than
    :data:`EARTH_FRACTION` of it says the numbers are smaller than their unit claims (e.g. a deg/s log read
    as deg/h), unless the Earth rate and bias were removed beforehand or the base was not static.
``sample-rate``
    A sample rate at or below :data:`RATE_MIN_HZ` (0.1 Hz) or above :data:`RATE_MAX_HZ` suggests a time
    column read in the wrong unit (a 100 Hz log with its time in ms read as s comes out at 0.1 Hz).

A unit is "likely" when the record rescaled to it passes the first three rules; candidates are tried in
:data:`CANDIDATE_UNITS` order (the common gyro output units first) and at most two are named, each with the
gyro class its figure corresponds to.

Gyro classes
------------
:data:`GYRO_CLASSES` names the class a white-noise floor corresponds to (:func:`gyro_class`); the messages name
it instead of calling a figure impossible.  The edges are conventional and approximate (texts differ by a
factor of a few; grades are often defined by bias stability rather than N).  The quiet end relies on:

* portable seismic-grade FOGs: the three-axis fibre-optic rotational seismograph FORS, ARW 35-45 nrad/s/sqrt(Hz)
  = 1.2e-4 to 1.5e-4 deg/sqrt(h) (A. T. Kurzych, L. R. Jaroszewicz, M. Dudek, "Rotational motion investigation
  in seismology - remote sensing by an optical fiber seismograph", *Adv. Opt. Technol.* 2024,
  doi:10.3389/aot.2024.1494705); the issue quotes datasheet-class values near 1.8e-5 deg/sqrt(h) for the
  blueSeis-3A (not checked here).  Hence the seismic / strategic class reaches down to about 1e-5 and the
  warning starts a decade lower, at 1e-6 deg/sqrt(h);
* a 1.6 m x 1.6 m ring laser in a laboratory: about 2 nrad/s/sqrt(Hz) = 7e-6 deg/sqrt(h) (arXiv:2207.04942);
* the metre-scale geodetic ring laser G (Wettzell): an Allan deviation below 1e-9 of the Earth rate
  (1.5e-8 deg/h) at about 1e4 s (arXiv:2208.09134), i.e. a white-noise floor of at most about 2.5e-8
  deg/sqrt(h) - the quietest Sagnac gyro reported.  Below :data:`QUIETEST_DPRH` (1e-8 deg/sqrt(h)) no gyro
  built is that quiet.

A density in rad/s/sqrt(Hz) is converted as N [deg/sqrt(h)] = density x 206265 / 60 (1 deg/h/sqrt(Hz) =
1/60 deg/sqrt(h)); a one-sided density would give N smaller by sqrt(2), well inside the class edges.

The checks warn; they never change the data.  Messages name settings as ``{opt:unit}`` (see
:mod:`fogdrift.errors`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ._util import fmt_number
from .errors import ConfigError, FogdriftWarning, render_options
from .health import health_findings
from .allan.sums import AllanSums
from .units import EARTH_RATE_DPH, S_PER_H, STANDARD_GRAVITY_MPS2, parse_unit

__all__ = [
    "Finding",
    "NoiseFloor",
    "check_record",
    "gyro_class",
    "noise_floor",
    "warn_implausible",
    "ARW_MIN_DPRH",
    "ARW_MAX_DPRH",
    "QUIETEST_DPRH",
    "GYRO_CLASSES",
    "RANGE_MAX_DPH",
    "NAV_GRADE_DPRH",
    "EARTH_FRACTION",
    "RATE_MIN_HZ",
    "RATE_MAX_HZ",
    "CANDIDATE_UNITS",
    "MAX_CHECK_SAMPLES",
    "MIN_CLUSTERS",
]

#: Quieter than any portable gyro: seismic / strategic-grade FOGs reach about 1e-5 [deg/sqrt(h)]; only
#: metre-scale ring lasers in geodetic observatories go below (module docstring, *Gyro classes*).
ARW_MIN_DPRH = 1e-6
#: Quieter than any gyro built: the ring laser G (Wettzell) reaches about 2.5e-8 [deg/sqrt(h)].
QUIETEST_DPRH = 1e-8
#: Noisier than any gyro [deg/sqrt(h)].
ARW_MAX_DPRH = 100.0
#: Beyond the measurement range of any gyro: 1e4 deg/s [deg/h].
RANGE_MAX_DPH = 1e4 * S_PER_H
#: A white-noise floor below this [deg/sqrt(h)] is navigation grade: such a gyro resolves the Earth rate.
NAV_GRADE_DPRH = 0.01
#: A static navigation-grade triad's mean vector is at least this fraction of the Earth rate.
EARTH_FRACTION = 0.2
#: Gyro classes by white-noise floor N: (upper edge [deg/sqrt(h)], name), quietest first; conventional,
#: approximate edges (module docstring, *Gyro classes*).  :func:`gyro_class` reads it.
GYRO_CLASSES = (
    (QUIETEST_DPRH, "quieter than any gyro built (the quietest, the metre-scale ring laser G, reaches about "
                    "2.5e-8 deg/√h)"),
    (ARW_MIN_DPRH, "the class of metre-scale ring lasers in geodetic observatories, quieter than any portable "
                   "gyro (seismic / strategic-grade FOGs reach about 1e-5 deg/√h)"),
    (1e-3, "seismic / strategic grade"),
    (NAV_GRADE_DPRH, "navigation grade"),
    (0.5, "tactical grade"),
    (ARW_MAX_DPRH, "industrial / consumer grade (MEMS)"),
    (math.inf, "noisier than any gyro"),
)
#: Sample rates at or below / above these [Hz] suggest a time column read in the wrong unit.
RATE_MIN_HZ = 0.1
RATE_MAX_HZ = 2e5
#: Units tried when naming the likely unit: the common gyro output units, most common first (increments only
#: when the data were read as increments; rad/h and arcsec/s are rare enough not to be suggested).
CANDIDATE_UNITS = ("deg/s", "rad/s", "deg/h", "inc:arcsec", "inc:rad", "inc:deg")
#: The noise floor uses at most this many samples per axis (the first ones), so the check stays cheap.
MAX_CHECK_SAMPLES = 1 << 22
#: Taus longer than 1/MIN_CLUSTERS of the record are left out of the noise floor: a minimum over noisy
#: estimates is biased low (with 40 clusters one white-noise ADEV estimate is within about +-11 % at 68 %).
MIN_CLUSTERS = 40


@dataclass(frozen=True)
class NoiseFloor:
    """White-noise floor of one axis [deg/sqrt(h)]: the estimate and its 68 % bounds (see the module docstring)."""

    estimate: float
    lo68: float
    hi68: float


@dataclass(frozen=True)
class Finding:
    """One implausibility.

    Attributes
    ----------
    rule : str
        ``"white-noise"``, ``"range"``, ``"earth-rate"``, ``"sample-rate"``, ``"gravity"``, or a sensor-health
        rule of :mod:`fogdrift.health` (``"frozen"``, ``"saturated"``, ``"unit-mix"``, ``"gravity-like"``,
        ``"time-step"``).
    axes : tuple of str
        Axes concerned (empty for the sample rate).
    message : str
        One line; settings are written ``{opt:NAME}`` (render with :func:`fogdrift.errors.render_options`).
    likely_units : tuple of str
        Units under which the numbers would be plausible, most likely first (may be empty).
    """

    rule: str
    axes: tuple
    message: str
    likely_units: tuple = ()

    def render(self, flags: dict | None = None) -> str:
        """The message with ``{opt:NAME}`` rendered through ``flags`` (library spelling ``NAME=`` by default)."""
        return render_options(self.message, flags)


def noise_floor(rate_dph, dt_s, *, keep: list | None = None) -> NoiseFloor:
    """White-noise floor ``min over tau of sigma(tau) sqrt(tau_s) / 60`` [deg/sqrt(h)] of one rate series.

    Uses the overlapping Allan deviation on the octave grid of :func:`fogdrift.allan.allan_variance`, the taus
    up to 1/:data:`MIN_CLUSTERS` of the record, and at most :data:`MAX_CHECK_SAMPLES` samples.
    ``lo68``/``hi68`` take the same minimum over the 68 % bounds.

    ``keep``: a list to which the :class:`~fogdrift.allan.sums.AllanSums` behind the floor is appended when
    it covers the whole series (at most :data:`MAX_CHECK_SAMPLES` samples), for the Allan analysis to reuse.

    Examples
    --------
    White rate noise of 0.5 deg/sqrt(h) sampled at 100 Hz has sigma = 60 N / sqrt(tau) = 300 deg/h at tau = 0.01 s:

    >>> import numpy as np
    >>> x = np.random.default_rng(1).normal(0.0, 300.0, 200_000)
    >>> round(noise_floor(x, 0.01).estimate, 1)
    0.5
    """

    whole = np.asarray(rate_dph, dtype=np.float64)
    x = whole[:MAX_CHECK_SAMPLES]
    if x.size < 8:
        return NoiseFloor(math.nan, math.nan, math.nan)
    # the octave overlapping ADEV (allan_variance's result, field by field), through sums the analysis can reuse
    sums = AllanSums(x, dt_s, "adev", "overlapping")
    octave = sums.grid("octave")
    sums.compute((octave,))
    res = sums.result(octave, "auto")
    if keep is not None and x.size == whole.size:
        sums.source = rate_dph
        keep.append(sums)
    keep = x.size / np.asarray(res.m, dtype=np.float64) >= MIN_CLUSTERS
    if not keep.any():
        keep = np.ones(np.asarray(res.m).shape, dtype=bool)
    root = np.sqrt(np.asarray(res.tau_s, dtype=np.float64)[keep]) / 60.0
    return NoiseFloor(float(np.min(res.adev_dph[keep] * root)), float(np.min(res.adev_lo68_dph[keep] * root)),
                      float(np.min(res.adev_hi68_dph[keep] * root)))


def gyro_class(n_dprh: float) -> str:
    """The gyro class whose white-noise floor is ``n_dprh`` [deg/sqrt(h)] (:data:`GYRO_CLASSES`).

    Examples
    --------
    >>> gyro_class(5.5e-5), gyro_class(2.4), gyro_class(3e-7).split(",")[0]
    ('seismic / strategic grade', 'industrial / consumer grade (MEMS)', 'the class of metre-scale ring lasers in geodetic observatories')
    """
    if not math.isfinite(n_dprh):
        return "class unknown"
    return next(name for edge, name in GYRO_CLASSES if n_dprh < edge)


def _factor(unit: str, record) -> float:
    """Multiply the record's deg/h values by this to get what they would be were the file in ``unit``
    (parsed by :func:`fogdrift.units.parse_unit`, the one unit parser)."""
    return parse_unit(unit).scale_to_internal(record.dt_s) / float(record.scale_to_internal)


def _read_as_increments(unit) -> bool:
    """True when the record was read in an increment unit (``inc:...``); False for a rate or no declared unit."""
    try:
        return parse_unit(unit).kind == "increment"
    except ConfigError:
        return False


def _fmt(x: float) -> str:
    """Three significant digits, plain from 1e-3 to 1e4, ``n/a`` when not finite (:func:`fogdrift._util.fmt_number`)."""
    return fmt_number(x, 3, nonfinite="n/a", sci_outside=(1e-3, 1e4), zero=None)


def _violations(floors, peaks, means, factor: float = 1.0) -> set:
    """Rules broken by the record rescaled by ``factor`` (floors, peaks, means per axis)."""
    broken = set()
    if any(f.hi68 * factor < ARW_MIN_DPRH or f.lo68 * factor > ARW_MAX_DPRH for f in floors if math.isfinite(f.hi68)):
        broken.add("white-noise")
    if any(p * factor > RANGE_MAX_DPH for p in peaks):
        broken.add("range")
    if len(means) == 3 and all(math.isfinite(f.hi68) and f.hi68 * factor < NAV_GRADE_DPRH for f in floors) \
            and float(np.linalg.norm(means)) * factor < EARTH_FRACTION * EARTH_RATE_DPH:
        broken.add("earth-rate")
    return broken


def check_record(record, *, sums: dict | None = None) -> list[Finding]:
    """Findings for a :class:`~fogdrift.io.GyroRecord` that no gyro would produce (see the module docstring).

    ``sums``: a dict that receives, per gyro axis checked on its whole series, the Allan operator sums of its
    noise floor (:class:`~fogdrift.allan.sums.AllanSums`), for :func:`fogdrift.pipeline.run_allan` (``sums=``)
    to reuse instead of computing the octave ADEV again.

    The sensor-health rules of :mod:`fogdrift.health` (frozen stretches, clipping, axes in mixed units,
    gravity on a gyro channel, a time column counting samples or ms) are added after the unit rules.

    Returns
    -------
    list of Finding
        Empty when the record is plausible.  Each finding's ``likely_units`` lists the units under which the
        numbers pass the white-noise, range and Earth-rate rules.

    Examples
    --------
    A 0.5 deg/sqrt(h) gyro whose deg/h log was read as deg/s looks 3600 times noisier than any gyro:

    >>> import numpy as np
    >>> from fogdrift.io import from_array
    >>> numbers = np.random.default_rng(1).normal(0.0, 300.0, 20_000)  # deg/h in the file
    >>> [(f.rule, f.likely_units) for f in check_record(from_array(numbers, dt_s=0.01, unit="deg/s"))]
    [('white-noise', ('deg/h',))]
    """
    findings = _unit_findings(record, sums)
    gravity = any(f.rule == "gravity" for f in findings)
    return findings + [Finding(*h) for h in health_findings(record) if not (gravity and h[0] == "gravity-like")]


def _unit_findings(record, sums: dict | None = None) -> list[Finding]:
    quantities = record.quantities
    if "specific_force" in quantities:  # the gyro rules for the gyro channels, the accelerometer rules for the rest
        gyro = [n for n, q in zip(record.axis_names, quantities) if q == "angular_rate"]
        accel = [n for n, q in zip(record.axis_names, quantities) if q == "specific_force"]
        findings = [f for f in _unit_findings(record.select(gyro), sums) if f.rule != "sample-rate"] if gyro else []
        return findings + accel_findings(record.select(accel)) + _rate_findings(record)
    return _gyro_findings(record, sums) + gravity_like_findings(record) + _rate_findings(record)


def _gyro_findings(record, sums: dict | None = None) -> list[Finding]:
    names = tuple(record.axis_names)
    floors = []
    for n in names:
        keep = []
        floors.append(noise_floor(record.axis(n), record.dt_s, keep=keep))
        if sums is not None and keep:
            sums[n] = keep[0]
    rates = [np.asarray(record.axis(n), dtype=np.float64) for n in names]
    peaks = [float(max(r.max(), -r.min())) if r.size else 0.0 for r in rates]  # max |rate|, no |r| copy
    means = [float(np.mean(r)) if r.size else 0.0 for r in rates]
    unit = record.input_unit
    broken = _violations(floors, peaks, means)
    findings = []
    if broken:
        likely = []
        for cand in CANDIDATE_UNITS:
            if cand == unit or (parse_unit(cand).kind == "increment" and not _read_as_increments(unit)):
                continue  # increments are named only when the data were read as increments
            f = _factor(cand, record)
            if not _violations(floors, peaks, means, f) and not any(math.isclose(f, _factor(u, record))
                                                                    for u in likely):
                likely.append(cand)
        likely = tuple(likely[:2])
        hint = _hint(likely, floors, record)
        if "white-noise" in broken:
            low = [n for n, f in zip(names, floors) if f.hi68 < ARW_MIN_DPRH]
            high = [n for n, f in zip(names, floors) if f.lo68 > ARW_MAX_DPRH]
            axes = tuple(low or high)
            levels = ", ".join(f"{n} {_fmt(f.estimate)}" for n, f in zip(names, floors) if n in axes)
            quietest = min(f.estimate for n, f in zip(names, floors) if n in axes)
            what = (f"white-noise floor N <= {levels} deg/√h with the rate read as {unit}: "
                    f"{gyro_class(quietest)}") if low else \
                   (f"implausibly noisy for any gyro: white-noise floor N = {levels} deg/√h at every τ with the rate "
                    f"read as {unit}, above {ARW_MAX_DPRH:g} deg/√h")
            findings.append(Finding("white-noise", axes, f"{what}; {hint}", likely))
        if "range" in broken:
            axes = tuple(n for n, p in zip(names, peaks) if p > RANGE_MAX_DPH)
            levels = ", ".join(f"{n} {p / S_PER_H:.3g} deg/s" for n, p in zip(names, peaks) if n in axes)
            findings.append(Finding("range", axes, f"max |rate| {levels} with the rate read as {unit} is beyond the "
                                                   f"range of any gyro ({RANGE_MAX_DPH / S_PER_H:g} deg/s); {hint}",
                                    likely))
        if "earth-rate" in broken:
            norm = float(np.linalg.norm(means))
            worst = max(f.estimate for f in floors)
            findings.append(Finding(
                "earth-rate", names,
                f"with the rate read as {unit} these 3 axes are {gyro_class(worst)} or better (white-noise floor "
                f"N <= {_fmt(worst)} deg/√h) yet their mean vector is {norm:.3g} deg/h; a static "
                f"gyro of that grade shows the Earth rate, {EARTH_RATE_DPH:.2f} deg/h (unless bias and Earth rate were "
                f"removed before, or the base moved); {hint}", likely))
    return findings


def _rate_findings(record) -> list[Finding]:
    findings = []
    fs = record.fs_hz
    if fs <= RATE_MIN_HZ or fs > RATE_MAX_HZ:
        slow = fs <= RATE_MIN_HZ
        findings.append(Finding(
            "sample-rate", (),
            f"sample rate {fs:.4g} Hz (interval {record.dt_s:.4g} s) is unusually {'low' if slow else 'high'} for a "
            f"gyro log; check {{opt:time_unit}} ({_slow_words(record.dt_s) if slow else 'a time column in s read as ms gives a 1000 times shorter step'}) "
            "and {opt:rate_hz}"))
    return findings


def _slow_words(dt_s: float) -> str:
    """What a long step suggests: ms read as s (1000x), or us read as s (10^6x) for a step of 500 s and more."""
    if dt_s >= 500.0:
        return (f"a time column in us read as s gives a 10^6 times longer step ({1e6 / dt_s:.4g} Hz read as "
                f"{1 / dt_s:.4g} Hz); in ms, 1000 times")
    return "a time column in ms read as s gives a 1000 times longer step"


#: Relative tolerance of "the mean vector of a static accelerometer triad is 1 g".
GRAVITY_RTOL = 0.1
#: Specific-force units tried, in order, when a static triad's mean is not 1 g.
ACCEL_CANDIDATES = ("g", "m/s^2", "mg", "ug")


def accel_findings(record) -> list[Finding]:
    """The accelerometer twin of the Earth-rate rule: a static triad reads gravity, ``|mean| = 1 g``.

    Applies to a record of three accelerometer channels (m/s^2 inside); a mean vector whose length is not
    within :data:`GRAVITY_RTOL` of standard gravity (9.80665 m/s^2) says the numbers are read in the wrong unit
    (mg read as g: 1000 g) or the base moved or was not level-free (the checks warn, never change data).  With
    fewer than three accelerometer channels gravity's direction is unknown: nothing is checked (the gyro rules,
    white-noise class and Earth rate, have no accelerometer twin here).

    Examples
    --------
    >>> import numpy as np
    >>> from fogdrift.io import from_array
    >>> x = np.tile([0.0, 0.0, -1.0], (2000, 1)) + np.random.default_rng(0).normal(0, 1e-3, (2000, 3))
    >>> accel_findings(from_array(x, dt_s=0.01, unit="g", axis_names=["ax", "ay", "az"]))
    []
    >>> [f.likely_units for f in accel_findings(from_array(x, dt_s=0.01, unit="mg", axis_names=["ax", "ay", "az"]))]
    [('g',)]
    """
    if record.n_axes != 3:
        return []
    means = [float(np.mean(record.axis(n))) for n in record.axis_names]
    norm = float(np.linalg.norm(means))
    g0 = STANDARD_GRAVITY_MPS2
    if abs(norm / g0 - 1.0) <= GRAVITY_RTOL:
        return []
    unit = record.input_unit
    scale = record.signal.channels[0].scale_to_internal
    raw = norm / scale  # the mean vector's length in the numbers as read
    likely = tuple(u for u in ACCEL_CANDIDATES if u != unit
                   and abs(raw * parse_unit(u, "specific_force").scale_to_internal() / g0 - 1.0) <= GRAVITY_RTOL)
    hint = f"the numbers fit {' or '.join(likely)}: check {{opt:unit}}" if likely else         "check {opt:unit} (or the triad was not static)"
    return [Finding("gravity", tuple(record.axis_names),
                    f"with the specific force read as {unit} the mean vector of these 3 accelerometer axes is "
                    f"{norm / g0:.4g} g ({norm:.4g} m/s^2); a static triad reads 1 g; {hint}", likely)]


def gravity_like_findings(record) -> list[Finding]:
    """A "gyro" triad whose mean vector is 1 g in m/s^2 or in g (one axis along it) is likely an accelerometer.

    Applies to three angular-rate channels: when the mean vector's length in the numbers as read is within 2 % of
    9.80665 or of 1 and one axis holds over 90 % of it (gravity along one axis of a levelled triad), the
    channels are likely accelerometers read with an angular-rate unit.
    """
    if record.n_axes != 3:
        return []
    scale = record.signal.channels[0].scale_to_internal
    means = np.array([float(np.mean(record.axis(n))) for n in record.axis_names]) / scale
    norm = float(np.linalg.norm(means))
    if norm <= 0 or float(np.max(means**2)) / norm**2 < 0.9:
        return []
    for level, unit in ((STANDARD_GRAVITY_MPS2, "m/s^2"), (1.0, "g")):
        if abs(norm / level - 1.0) <= 0.02:
            return [Finding("gravity", tuple(record.axis_names),
                            f"read as {record.input_unit}, the mean vector of these 3 axes is {norm:.4g} with one "
                            f"axis along it: gravity in {unit} (1 g = 9.80665 m/s^2), so these are likely "
                            f"accelerometers; give their unit as {{opt:unit}} {unit} (or gyro=...,accel={unit})",
                            (unit,))]
    return []


def _hint(likely, floors, record) -> str:
    if not likely:
        return "check {opt:unit}"
    worst = max((f.estimate for f in floors if math.isfinite(f.estimate)), default=math.nan)
    named = " or ".join(f"{u} (N <= {_fmt(worst * _factor(u, record))} deg/√h, "
                        f"{gyro_class(worst * _factor(u, record))} or better)" for u in likely)
    return f"the numbers fit {named}: check {{opt:unit}}"


def warn_implausible(record) -> list[Finding]:
    """:func:`check_record`, issuing one :class:`~fogdrift.errors.FogdriftWarning` per finding; returns them."""
    findings = check_record(record)
    for f in findings:
        warnings.warn(f"{record.source}: {f.render()}", FogdriftWarning, stacklevel=2)
    return findings
