"""Units and physical constants.

The internal angular-rate unit of fogdrift is deg/h and time is in seconds.
Conversions happen only on the way in (:mod:`fogdrift.io`) and on the way out
(:mod:`fogdrift.report`, the CLI).

Name suffixes used across the package: ``_dph`` deg/h, ``_dps`` deg/s, ``_s`` seconds,
``_hz`` hertz, ``_deg`` degrees, ``_dprh`` deg/sqrt(h), ``_dph2`` deg/h^2,
``_dphrh`` deg/h^1.5 (= deg/h/sqrt(h)), ``_urad`` microradian, ``_arcsec`` arcsecond.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import ConfigError

__all__ = [
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

#: WGS-84 Earth rotation rate 7.2921150e-5 rad/s expressed in deg/h (method notes §6).
EARTH_RATE_DPH = 7.2921150e-5 * 180.0 / math.pi * 3600.0

#: One arcsecond in microradians, 1e6 pi / (180 * 3600) = 4.8481368.  Note that 1 (deg/h) s = 1/3600 deg
#: = 1 arcsec, so a quantization coefficient in the Allan-law units (rate deg/h, tau s) is in arcsec.
URAD_PER_ARCSEC = 1e6 * math.pi / (180.0 * 3600.0)

#: sqrt(2 ln 2 / pi) = 0.664282: the flat Allan deviation of flicker rate noise in units of the bias
#: instability B (IEEE Std 952-1997 Annex C; method notes 2.2).  The read-off sigma_min = 0.6643 B.
B_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)

#: Multiply a rate in the key's unit by the value to get deg/h.
RATE_UNITS: dict[str, float] = {
    "deg/h": 1.0,
    "deg/s": 3600.0,
    "rad/s": 180.0 / math.pi * 3600.0,
    "rad/h": 180.0 / math.pi,
    "arcsec/s": 1.0,  # 1 arcsec/s = 1/3600 deg per 1/3600 h = 1 deg/h
}

#: Multiply an angle increment per sample in the key's unit by the value, then divide by
#: the sample interval in seconds, to get deg/h.  (1 arcsec per second = 1 deg/h.)
INCREMENT_UNITS: dict[str, float] = {
    "deg": 3600.0,
    "rad": 180.0 / math.pi * 3600.0,
    "arcsec": 1.0,
}


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
    """Return a sample interval [s] as a float, or raise ConfigError naming ``name`` if it is not finite and > 0."""
    try:
        dt = float(dt_s)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be a number of seconds > 0, got {dt_s!r}") from None
    if not (dt > 0 and math.isfinite(dt)):
        raise ConfigError(f"{name} must be a finite number of seconds > 0, got {dt_s!r}")
    return dt


def rate_scale_to_dph(unit: str) -> float:
    """Factor that converts a rate in ``unit`` to deg/h.

    Examples
    --------
    >>> rate_scale_to_dph("deg/s")
    3600.0
    """
    try:
        return RATE_UNITS[unit]
    except KeyError:
        raise ConfigError(
            f"unknown rate unit {unit!r}; expected one of {sorted(RATE_UNITS)} "
            f"or an increment unit {sorted('inc:' + u for u in INCREMENT_UNITS)}"
        ) from None


def increment_scale_to_dph(unit: str, dt_s: float) -> float:
    """Factor that converts an angle increment per sample (``unit``) to a rate in deg/h.

    Examples
    --------
    >>> increment_scale_to_dph("arcsec", 0.01)   # 0.1 arcsec per 10 ms = 10 deg/h
    100.0
    """
    if unit not in INCREMENT_UNITS:
        raise ConfigError(f"unknown increment unit {unit!r}; expected one of {sorted(INCREMENT_UNITS)}")
    if not dt_s > 0:
        raise ConfigError(f"sample interval must be > 0 s, got {dt_s!r}")
    return INCREMENT_UNITS[unit] / dt_s


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
