"""Units and physical constants.

The internal angular-rate unit of fogdrift is deg/h, the internal specific-force unit m/s^2, and
time is in seconds.  Every unit string a user gives (``--unit``, a ``gz[deg/s]`` header cell, a
bundle's ``input_unit``) is read by the one parser :func:`parse_unit`, which returns a
:class:`UnitSpec` naming the physical quantity; every sample interval is checked by the one
validator :func:`check_dt_s`.
Conversions happen only on the way in (:mod:`fogdrift.io`) and on the way out
(:mod:`fogdrift.report`, the CLI).

Name suffixes used across the package: ``_dph`` deg/h, ``_dps`` deg/s, ``_s`` seconds,
``_hz`` hertz, ``_deg`` degrees, ``_dprh`` deg/sqrt(h), ``_dph2`` deg/h^2,
``_dphrh`` deg/h^1.5 (= deg/h/sqrt(h)), ``_urad`` microradian, ``_arcsec`` arcsecond.

The unit relations themselves live here and only here: 1 h = 3600 s (:data:`S_PER_H`), 1 min = 60 s
(:data:`S_PER_MIN`), 1 deg = pi/180 rad (:data:`RAD_PER_DEG`, :data:`DEG_PER_RAD`) and 1 deg = 3600 arcsec
(:data:`ARCSEC_PER_DEG`).  Every other module names them instead of writing the number.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import ConfigError

__all__ = [
    "S_PER_H",
    "S_PER_MIN",
    "RAD_PER_DEG",
    "DEG_PER_RAD",
    "ARCSEC_PER_DEG",
    "QUANTITIES",
    "INTERNAL_UNITS",
    "KEY_SUFFIXES",
    "name_keys",
    "STANDARD_GRAVITY_MPS2",
    "SPECIFIC_FORCE_UNITS",
    "VELOCITY_INCREMENT_UNITS",
    "UnitSpec",
    "parse_unit",
    "valid_units",
    "check_rate_hz",
    "DT_MIN_S",
    "DT_MAX_S",
    "EARTH_RATE_DPH",
    "RATE_UNITS",
    "INCREMENT_UNITS",
    "rate_scale_to_dph",
    "increment_scale_to_dph",
    "earth_rate_projection_dph",
    "AXIS_DIRECTIONS",
    "check_dt_s",
    "TIME_UNITS",
    "time_scale_to_s",
    "URAD_PER_ARCSEC",
    "B_FACTOR",
    "TEMPERATURE_UNITS",
    "temperature_offset_to_c",
]

#: Seconds per hour, 1 h = 3600 s.  Rates are kept in deg/h while time is in seconds, so this is the factor between
#: a per-second and a per-hour figure (deg/s -> deg/h, deg/h^2 -> (deg/h)/s) and the length of a one-hour horizon.
S_PER_H = 3600.0

#: Seconds per minute, 1 min = 60 s (a time stamp or record length given in minutes).
S_PER_MIN = 60.0

#: Radians per degree, pi / 180: multiply an angle (or rate) in degrees by it to get radians (the SI exports).
RAD_PER_DEG = math.pi / 180.0

#: Degrees per radian, 180 / pi: multiply an angle (or rate) in radians by it to get degrees (rad/s, rad/h inputs).
#: Its own rounding of 180 / pi, not ``1 / RAD_PER_DEG``, so the tables below keep their values.
DEG_PER_RAD = 180.0 / math.pi

#: Arcseconds per degree, 1 deg = 3600 arcsec (the same number as :data:`S_PER_H`, a different fact: an angle).
ARCSEC_PER_DEG = 3600.0

#: WGS-84 Earth rotation rate 7.2921150e-5 rad/s expressed in deg/h (method notes §6).
EARTH_RATE_DPH = 7.2921150e-5 * DEG_PER_RAD * S_PER_H

#: One arcsecond in microradians, 1e6 pi / (180 * 3600) = 4.8481368.  Note that 1 (deg/h) s = 1/3600 deg
#: = 1 arcsec, so a quantization coefficient in the Allan-law units (rate deg/h, tau s) is in arcsec.
URAD_PER_ARCSEC = 1e6 * math.pi / (180.0 * ARCSEC_PER_DEG)

#: sqrt(2 ln 2 / pi) = 0.664282: the flat Allan deviation of flicker rate noise in units of the bias
#: instability B (IEEE Std 952-1997 Annex C; method notes 2.2).  The read-off sigma_min = 0.6643 B.
B_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)

#: Multiply a rate in the key's unit by the value to get deg/h.
RATE_UNITS: dict[str, float] = {
    "deg/h": 1.0,
    "deg/s": S_PER_H,
    "rad/s": DEG_PER_RAD * S_PER_H,
    "rad/h": DEG_PER_RAD,
    "arcsec/s": 1.0,  # 1 arcsec/s = 1/3600 deg per 1/3600 h = 1 deg/h
}

#: Multiply an angle increment per sample in the key's unit by the value, then divide by
#: the sample interval in seconds, to get deg/h.  (1 arcsec per second = 1 deg/h.)
INCREMENT_UNITS: dict[str, float] = {
    "deg": S_PER_H,
    "rad": DEG_PER_RAD * S_PER_H,
    "arcsec": 1.0,
}


#: Standard gravity g_n = 9.80665 m/s^2 (exact by definition, CGPM 1901; ISO 80000-3): the value of
#: one "g" in :data:`SPECIFIC_FORCE_UNITS`.  Not the local gravity of any site.
STANDARD_GRAVITY_MPS2 = 9.80665

#: Multiply a specific force in the key's unit by the value to get m/s^2 ("ug" is micro-g).
SPECIFIC_FORCE_UNITS: dict[str, float] = {
    "m/s^2": 1.0,
    "g": STANDARD_GRAVITY_MPS2,
    "mg": STANDARD_GRAVITY_MPS2 * 1e-3,
    "ug": STANDARD_GRAVITY_MPS2 * 1e-6,
}

#: Multiply a velocity increment per sample in the key's unit by the value, then divide by the sample
#: interval in seconds, to get m/s^2.
VELOCITY_INCREMENT_UNITS: dict[str, float] = {
    "m/s": 1.0,
}

#: The physical quantities a channel can carry, and the internal unit each is converted to on the way in.
INTERNAL_UNITS: dict[str, str] = {
    "angular_rate": "deg/h",
    "specific_force": "m/s^2",
}

#: Per quantity: the suffixes that name a value and its square in the internal unit in serialised keys and
#: column names (``adev_dph``/``avar_dph2`` for a gyro, ``adev_mps2``/``avar_m2ps4`` for an accelerometer).
KEY_SUFFIXES: dict[str, tuple[str, str]] = {
    "angular_rate": ("dph", "dph2"),
    "specific_force": ("mps2", "m2ps4"),
}

def name_keys(values: dict, quantity: str) -> dict:
    """``values`` with each key's internal-unit suffix (``_dph``, ``_dph2``) named for ``quantity``
    (:data:`KEY_SUFFIXES`); the same dict for an angular rate.

    Examples
    --------
    >>> name_keys({"robust_sigma_dph": 0.1, "var_dph2": 0.01, "count": 3}, "specific_force")
    {'robust_sigma_mps2': 0.1, 'var_m2ps4': 0.01, 'count': 3}
    """
    if quantity == "angular_rate":
        return values
    one, two = KEY_SUFFIXES[quantity]
    return {(k[:-5] + "_" + two if k.endswith("_dph2") else k[:-4] + "_" + one if k.endswith("_dph") else k): v
            for k, v in values.items()}


#: The quantities :func:`parse_unit` knows (the keys of :data:`INTERNAL_UNITS`).
QUANTITIES: tuple[str, ...] = tuple(INTERNAL_UNITS)

#: Per quantity: (rate table, increment table, what a rate is called, what an increment is called).
_UNIT_TABLES: dict[str, tuple[dict[str, float], dict[str, float], str, str]] = {
    "angular_rate": (RATE_UNITS, INCREMENT_UNITS, "a rate unit", "an angle increment per sample"),
    "specific_force": (SPECIFIC_FORCE_UNITS, VELOCITY_INCREMENT_UNITS, "a specific-force unit",
                       "a velocity increment per sample"),
}


@dataclass(frozen=True)
class UnitSpec:
    """A parsed unit string: the quantity it measures, rate or increment, and the factor to the internal unit.

    Attributes
    ----------
    text : str
        The unit as written, stripped (``"deg/s"``, ``"inc:arcsec"``, ``"mg"``).
    quantity : str
        ``"angular_rate"`` or ``"specific_force"`` (a key of :data:`INTERNAL_UNITS`).
    kind : str
        ``"rate"`` (a value per unit time: deg/s, m/s^2) or ``"increment"`` (an angle or velocity
        increment per sample, ``inc:<base>``).
    base : str
        The key in the quantity's rate or increment table (``"deg/s"``, ``"arcsec"``, ``"m/s"``).
    factor : float
        For a rate, the value in the internal unit of one ``base``; for an increment, the internal unit
        times seconds of one ``base`` (divide by the sample interval, see :meth:`scale_to_internal`).
    """

    text: str
    quantity: str
    kind: str
    base: str
    factor: float

    @property
    def internal_unit(self) -> str:
        """The quantity's internal unit (``"deg/h"`` or ``"m/s^2"``)."""
        return INTERNAL_UNITS[self.quantity]

    @property
    def needs_dt(self) -> bool:
        """True for an increment unit, whose scale depends on the sample interval."""
        return self.kind == "increment"

    def scale_to_internal(self, dt_s=None) -> float:
        """Factor that converts a value in this unit to the internal unit.

        Parameters
        ----------
        dt_s : float, optional
            Sample interval in s; needed (and checked by :func:`check_dt_s`) for an increment unit.

        Examples
        --------
        >>> parse_unit("deg/s").scale_to_internal()
        3600.0
        >>> parse_unit("inc:arcsec").scale_to_internal(0.01)   # 0.1 arcsec per 10 ms = 10 deg/h
        100.0
        >>> parse_unit("mg", "specific_force").scale_to_internal()
        0.00980665
        """
        if self.kind == "rate":
            return self.factor
        if dt_s is None:
            raise ConfigError(f"unit {self.text!r} is an increment per sample; its scale needs the sample interval dt_s")
        return self.factor / check_dt_s(dt_s)


def valid_units(quantity: str | None = "angular_rate") -> list[str]:
    """Every unit string :func:`parse_unit` accepts for ``quantity`` (None: for every quantity).

    Examples
    --------
    >>> valid_units()
    ['deg/h', 'deg/s', 'rad/s', 'rad/h', 'arcsec/s', 'inc:deg', 'inc:rad', 'inc:arcsec']
    >>> valid_units("specific_force")
    ['m/s^2', 'g', 'mg', 'ug', 'inc:m/s']
    """
    out: list[str] = []
    for q in _quantities(quantity):
        rates, incs, _, _ = _UNIT_TABLES[q]
        out += list(rates) + [f"inc:{k}" for k in incs]
    return out


def _quantities(quantity) -> tuple[str, ...]:
    if quantity is None:
        return QUANTITIES
    if quantity not in _UNIT_TABLES:
        raise ConfigError(f"unknown quantity {quantity!r}; expected one of {list(QUANTITIES)}")
    return (quantity,)


def parse_unit(unit, quantity: str | None = "angular_rate") -> UnitSpec:
    """Parse a unit string: the one unit parser of fogdrift.

    Parameters
    ----------
    unit : str
        A rate unit of the quantity (``"deg/s"``, ``"rad/s"``, ``"m/s^2"``, ``"mg"`` ...) or an
        increment per sample ``"inc:<base>"`` (``"inc:arcsec"``, ``"inc:m/s"``); surrounding blanks
        are ignored, nothing else is (``"DEG/S"`` is refused: units are never guessed).
    quantity : str or None
        ``"angular_rate"`` (default: a gyro channel), ``"specific_force"`` (an accelerometer
        channel), or None to accept a unit of any quantity.

    Returns
    -------
    UnitSpec

    Raises
    ------
    ConfigError
        If ``unit`` is not a unit of ``quantity``; the message lists the valid units.

    Examples
    --------
    >>> parse_unit("inc:arcsec")
    UnitSpec(text='inc:arcsec', quantity='angular_rate', kind='increment', base='arcsec', factor=1.0)
    >>> parse_unit("g", None).factor
    9.80665
    """
    qs = _quantities(quantity)
    if isinstance(unit, str):
        u = unit.strip()
        for q in qs:
            rates, incs, _, _ = _UNIT_TABLES[q]
            if u in rates:
                return UnitSpec(text=u, quantity=q, kind="rate", base=u, factor=float(rates[u]))
            if u.startswith("inc:") and u[4:].strip() in incs:
                base = u[4:].strip()
                return UnitSpec(text=u, quantity=q, kind="increment", base=base, factor=float(incs[base]))
    if len(qs) == 1:
        _, _, rate_word, inc_word = _UNIT_TABLES[qs[0]]
        what = f"{rate_word} or {inc_word}"
    else:
        what = "a unit of " + " or ".join(q.replace("_", " ") for q in qs)
    raise ConfigError(f"unknown unit {unit!r}; expected {what}, one of {valid_units(quantity)}")


#: The sample intervals :func:`check_dt_s` accepts: 1 ns (1 GHz) to 1e9 s (about 32 years).  Outside
#: them a number is a typo or a unit slip, and downstream arithmetic (tau grids, least squares) breaks.
DT_MIN_S = 1e-9
DT_MAX_S = 1e9


#: Multiply a time stamp in the key's unit by the value to get seconds (time columns, ``time_unit``).
TIME_UNITS: dict[str, float] = {
    "s": 1.0,
    "ms": 1e-3,
    "us": 1e-6,
    "ns": 1e-9,
}


#: Add the value to a temperature in the key's unit to get deg C (temperature columns; keys compared
#: case-insensitively).  Only deg C and kelvin: a Fahrenheit column would need a scale too.
TEMPERATURE_UNITS: dict[str, float] = {
    "degc": 0.0,
    "deg c": 0.0,
    "c": 0.0,
    "°c": 0.0,
    "celsius": 0.0,
    "k": -273.15,
    "kelvin": -273.15,
}


def temperature_offset_to_c(unit: str) -> float:
    """Offset that converts a temperature in ``unit`` to deg C (0 for deg C, -273.15 for K).

    Raises
    ------
    ConfigError
        If ``unit`` is not a key of :data:`TEMPERATURE_UNITS` (any case).

    Examples
    --------
    >>> temperature_offset_to_c("degC"), temperature_offset_to_c("K")
    (0.0, -273.15)
    """
    key = unit.strip().lower() if isinstance(unit, str) else unit
    try:
        return TEMPERATURE_UNITS[key]
    except (KeyError, TypeError):
        raise ConfigError(
            f"unknown temperature unit {unit!r}; expected one of {sorted(TEMPERATURE_UNITS)} (any case)"
        ) from None


def time_scale_to_s(unit: str) -> float:
    """Factor that converts a time stamp in ``unit`` to seconds.

    Raises
    ------
    ConfigError
        If ``unit`` is not a key of :data:`TIME_UNITS` (the message lists them).

    Examples
    --------
    >>> time_scale_to_s("ms")
    0.001
    """
    try:
        return TIME_UNITS[unit]
    except (KeyError, TypeError):
        raise ConfigError(f"unknown time unit {unit!r}; expected one of {list(TIME_UNITS)}") from None


def check_dt_s(dt_s, name: str = "dt_s") -> float:
    """The one sample-interval validator: ``dt_s`` [s] as a float in [:data:`DT_MIN_S`, :data:`DT_MAX_S`].

    Parameters
    ----------
    dt_s : float
        Sample interval in s.
    name : str
        How the message names the setting (``"dt_s"``, ``"{opt:rate_hz}"`` ...).

    Raises
    ------
    ConfigError
        One line naming ``name`` if ``dt_s`` is not a number, not finite, <= 0, or outside
        1e-9 .. 1e9 s.

    Examples
    --------
    >>> check_dt_s(0.01)
    0.01
    >>> check_dt_s(1e-300)
    Traceback (most recent call last):
    ...
    fogdrift.errors.ConfigError: dt_s must be a sample interval between 1e-09 s and 1e+09 s, got 1e-300
    """
    if isinstance(dt_s, bool):
        raise ConfigError(f"{name} must be a number of seconds > 0, got {dt_s!r}")
    try:
        dt = float(dt_s)
    except (TypeError, ValueError, OverflowError):
        raise ConfigError(f"{name} must be a number of seconds > 0, got {dt_s!r}") from None
    if not (dt > 0 and math.isfinite(dt)):
        raise ConfigError(f"{name} must be a finite number > 0 (seconds); got {dt_s!r}")
    if not DT_MIN_S <= dt <= DT_MAX_S:
        raise ConfigError(f"{name} must be a sample interval between {DT_MIN_S:g} s and {DT_MAX_S:g} s, got {dt_s!r}")
    return dt


def check_rate_hz(rate_hz, name: str = "rate_hz") -> float:
    """A sample rate [Hz] as a float whose interval ``1 / rate_hz`` passes :func:`check_dt_s`.

    Raises
    ------
    ConfigError
        One line naming ``name`` if ``rate_hz`` is not a finite number > 0 or lies outside
        1e-9 .. 1e9 Hz.

    Examples
    --------
    >>> check_rate_hz(100.0)
    100.0
    >>> check_rate_hz(1e300)
    Traceback (most recent call last):
    ...
    fogdrift.errors.ConfigError: rate_hz must be a sample rate between 1e-09 Hz and 1e+09 Hz, got 1e+300
    """
    if isinstance(rate_hz, bool):
        raise ConfigError(f"{name} must be a number of Hz > 0, got {rate_hz!r}")
    try:
        fs = float(rate_hz)
    except (TypeError, ValueError, OverflowError):
        raise ConfigError(f"{name} must be a number of Hz > 0, got {rate_hz!r}") from None
    if not (fs > 0 and math.isfinite(fs)):
        raise ConfigError(f"{name} must be a finite number of Hz > 0, got {rate_hz!r}")
    if not DT_MIN_S <= 1.0 / fs <= DT_MAX_S:  # the interval check_dt_s takes (1 / 1e9 Hz is exactly 1e-9 s)
        raise ConfigError(f"{name} must be a sample rate between {1.0 / DT_MAX_S:g} Hz and {1.0 / DT_MIN_S:g} Hz, "
                          f"got {rate_hz!r}")
    return fs


def rate_scale_to_dph(unit: str) -> float:
    """Factor that converts a rate in ``unit`` to deg/h.

    Examples
    --------
    >>> rate_scale_to_dph("deg/s")
    3600.0
    """
    spec = parse_unit(unit) if isinstance(unit, str) and unit in RATE_UNITS else None
    if spec is None:
        raise ConfigError(
            f"unknown rate unit {unit!r}; expected one of {sorted(RATE_UNITS)} "
            f"or an increment unit {sorted('inc:' + u for u in INCREMENT_UNITS)}"
        )
    return spec.factor


def increment_scale_to_dph(unit: str, dt_s: float) -> float:
    """Factor that converts an angle increment per sample (``unit``) to a rate in deg/h.

    Examples
    --------
    >>> increment_scale_to_dph("arcsec", 0.01)   # 0.1 arcsec per 10 ms = 10 deg/h
    100.0
    """
    if not isinstance(unit, str) or unit not in INCREMENT_UNITS:
        raise ConfigError(f"unknown increment unit {unit!r}; expected one of {sorted(INCREMENT_UNITS)}")
    return parse_unit("inc:" + unit).scale_to_internal(dt_s)


#: Unit vectors (east, north, up) of named sensitive-axis orientations.
AXIS_DIRECTIONS: dict[str, tuple[float, float, float]] = {
    "up": (0.0, 0.0, 1.0),
    "down": (0.0, 0.0, -1.0),
    "north": (0.0, 1.0, 0.0),
    "south": (0.0, -1.0, 0.0),
    "east": (1.0, 0.0, 0.0),
    "west": (-1.0, 0.0, 0.0),
}


def earth_rate_projection_dph(latitude_deg: float, axis="up") -> float:
    """Earth-rate component sensed by an axis on a static base, in deg/h.

    In local east-north-up axes the Earth rate is ``w_ie (0, cos L, sin L)``; an axis with
    unit vector ``u`` senses ``w_ie (u_N cos L + u_U sin L)`` (method notes §6).

    Parameters
    ----------
    latitude_deg : float
        Geodetic latitude L in degrees, in [-90, 90].
    axis : str or sequence of 3 floats
        ``"up"``, ``"down"``, ``"north"``, ``"south"``, ``"east"``, ``"west"`` or an
        (east, north, up) direction vector (normalised here).

    Returns
    -------
    float
        Sensed Earth rate in deg/h.

    Examples
    --------
    >>> round(earth_rate_projection_dph(30.0, "up"), 6)
    7.520533
    """
    if not -90.0 <= float(latitude_deg) <= 90.0:
        raise ConfigError(f"latitude must be in [-90, 90] deg, got {latitude_deg!r}")
    if isinstance(axis, str):
        try:
            u = np.asarray(AXIS_DIRECTIONS[axis.lower()])
        except KeyError:
            raise ConfigError(
                f"unknown axis orientation {axis!r}; expected one of {sorted(AXIS_DIRECTIONS)} "
                "or an (east, north, up) vector"
            ) from None
    else:
        u = np.asarray(axis, dtype=float)
        if u.shape != (3,) or not np.all(np.isfinite(u)) or np.linalg.norm(u) == 0:
            raise ConfigError(f"axis vector must be 3 finite numbers, not all zero, got {axis!r}")
        u = u / np.linalg.norm(u)
    lat = math.radians(float(latitude_deg))
    return float(EARTH_RATE_DPH * (u[1] * math.cos(lat) + u[2] * math.sin(lat)))
