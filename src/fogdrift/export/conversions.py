"""Unit conversions of noise coefficients for the exports: IEEE units <-> SI densities, continuous <-> discrete.

Every coefficient is carried in SI inside :mod:`fogdrift.export` (the *rate unit* is rad/s for a gyro channel and
m/s^2 for an accelerometer channel):

=====  ===========================  ==============================  ===============================
term   gyro (SI)                    accelerometer (SI)              meaning
=====  ===========================  ==============================  ===============================
N      rad/s/sqrt(Hz) = rad/sqrt(s) m/s^2/sqrt(Hz) = m/s/sqrt(s)    white rate noise density (ARW/VRW)
K      rad/s^2/sqrt(Hz)             m/s^3/sqrt(Hz)                  random-walk density (RRW/AcRW)
B      rad/s                        m/s^2                           bias instability (flicker floor)
Q      rad                          m/s                             angle / velocity quantization
R      rad/s^2                      m/s^3                           ramp
sigma  rad/s                        m/s^2                           Gauss-Markov 1-sigma
=====  ===========================  ==============================  ===============================

Continuous -> discrete at an update rate f = 1/dt (the convention of Kalibr's "IMU Noise Model" wiki page,
https://github.com/ethz-asl/kalibr/wiki/IMU-Noise-Model, and of ORB-SLAM3's Tracking, which multiplies the noise
densities by sqrt(f) and divides the walks by sqrt(f)): white noise sigma_d = N sqrt(f); random-walk increment
sigma_bd = K / sqrt(f); first-order Gauss-Markov phi = exp(-dt/T_c), driving-noise sigma_d = sigma sqrt(1 - phi^2).

Sources of the factors: 1 deg = pi/180 rad; 1 h = 3600 s, so 1/sqrt(h) = 1/(60 sqrt(s)) (IEEE Std 952-1997
Annex C; docs/method-notes.md §9.7); 1 g = 9.80665 m/s^2 (standard gravity, :data:`fogdrift.units.STANDARD_GRAVITY_MPS2`);
1 mGal = 1e-5 m/s^2.
"""

from __future__ import annotations

import math

from ..errors import ConfigError
from ..noise.processes import process, processes
from ..noise.processes.gauss_markov import gm_avar_dph2
from ..units import ARCSEC_PER_DEG, RAD_PER_DEG, S_PER_H
# DEG (one degree in radians) and G0 (standard gravity [m/s^2], the "g" of mg / ug): the units module's
# constants under the names this module exports
from ..units import RAD_PER_DEG as DEG
from ..units import STANDARD_GRAVITY_MPS2 as G0

__all__ = [
    "DEG", "G0", "MGAL", "GM_FLICKER_SIGMA", "GM_PEAK_X",
    "arw_to_density", "density_to_arw", "vrw_to_density", "density_to_vrw", "rrw_to_density",
    "white_discrete", "walk_discrete", "gm_discrete", "to_si", "from_si", "quantity_of_unit",
    "single_gm_from_flicker", "UNIT_TABLE", "SI_UNITS", "si_unit", "vins_white", "vins_walk", "gm_rematch",
]

#: One milligal in m/s^2.
MGAL = 1e-5
#: x = tau/T_c at the Allan-variance peak of a first-order Gauss-Markov process, and the peak value in sigma^2
#: (IEEE Std 952-1997 C.6; maximise (2x - 3 + 4 e^-x - e^-2x)/x^2 numerically: 1.8926, 0.38114).
GM_PEAK_X = 1.8926178
_GM_PEAK_AVAR = 0.38113866
#: sigma / B of the one Gauss-Markov process whose Allan-variance peak equals the flicker floor 0.4413 B^2
#: (2 ln 2 / pi B^2): sqrt(0.44127 / 0.38114) = 1.0760.
GM_FLICKER_SIGMA = math.sqrt(2.0 * math.log(2.0) / math.pi / _GM_PEAK_AVAR)


def arw_to_density(arw_deg_rth: float) -> float:
    """Angle random walk N [deg/sqrt(h)] -> white-noise density [rad/s/sqrt(Hz)]: N * (pi/180) / 60.

    Examples
    --------
    >>> f"{arw_to_density(0.15):.4g}"   # 0.15 deg/sqrt(h) = 0.15 * 0.0174533 / 60
    '4.363e-05'
    """
    return float(arw_deg_rth) * RAD_PER_DEG / 60.0


def density_to_arw(density_rad: float) -> float:
    """White-noise density [rad/s/sqrt(Hz)] -> angle random walk [deg/sqrt(h)] (inverse of :func:`arw_to_density`).

    Examples
    --------
    >>> round(density_to_arw(4.3633e-5), 4)
    0.15
    """
    return float(density_rad) * 60.0 / RAD_PER_DEG


def vrw_to_density(vrw_mps_rth: float) -> float:
    """Velocity random walk [m/s/sqrt(h)] -> white-noise density [m/s^2/sqrt(Hz)]: VRW / 60.

    Examples
    --------
    >>> vrw_to_density(0.12)   # 0.12 m/s/sqrt(h) = 0.12 m/s / (60 sqrt(s))
    0.002
    """
    return float(vrw_mps_rth) / 60.0


def density_to_vrw(density: float) -> float:
    """White-noise density [m/s^2/sqrt(Hz)] -> velocity random walk [m/s/sqrt(h)].

    Examples
    --------
    >>> density_to_vrw(0.002)
    0.12
    """
    return float(density) * 60.0


def rrw_to_density(rrw_deg_h15: float) -> float:
    """Rate random walk K [deg/h^1.5 = (deg/h)/sqrt(h)] -> random-walk density [rad/s^2/sqrt(Hz)]:
    K * (pi/180) / 3600 / 60.

    Examples
    --------
    >>> f"{rrw_to_density(216000 / 0.0174532925199):.6g}"   # 1 rad/s/sqrt(s) in deg/h^1.5
    '1'
    >>> f"{rrw_to_density(10.0):.4g}"
    '8.08e-07'
    """
    return float(rrw_deg_h15) * RAD_PER_DEG / S_PER_H / 60.0


def white_discrete(density: float, rate_hz: float) -> float:
    """Per-sample 1-sigma of white noise of ``density`` at ``rate_hz``: density * sqrt(rate).

    Examples
    --------
    >>> f"{white_discrete(4.3633e-5, 100.0):.6g}"   # rad/s per sample at 100 Hz
    '0.00043633'
    """
    return float(density) * math.sqrt(_rate(rate_hz))


def walk_discrete(density: float, rate_hz: float) -> float:
    """Per-sample 1-sigma of the increment of a random walk of ``density`` at ``rate_hz``: density / sqrt(rate).

    Examples
    --------
    >>> f"{walk_discrete(2e-5, 100.0):.6g}"
    '2e-06'
    """
    return float(density) / math.sqrt(_rate(rate_hz))


def gm_discrete(sigma: float, tc_s: float, rate_hz: float) -> tuple[float, float]:
    """First-order Gauss-Markov at ``rate_hz``: (phi, driving 1-sigma) = (e^(-dt/T_c), sigma sqrt(1 - phi^2)).

    Examples
    --------
    >>> phi, q = gm_discrete(1.0, 1.0, 1.0)   # dt = T_c: phi = 1/e, q = sqrt(1 - e^-2)
    >>> round(phi, 6), round(q, 6)
    (0.367879, 0.929873)
    """
    dt = 1.0 / _rate(rate_hz)
    if not (math.isfinite(tc_s) and tc_s > 0):
        raise ConfigError(f"Gauss-Markov correlation time must be a finite number > 0 s; got {tc_s!r}")
    phi = math.exp(-dt / tc_s)
    return phi, float(sigma) * math.sqrt(-math.expm1(-2.0 * dt / tc_s))


def vins_white(density: float, rate_hz: float) -> float:
    """VINS-Fusion's ``acc_n`` / ``gyr_n`` for a white density N at the IMU rate f: N sqrt(2 f).

    VINS-Fusion's ``IntegrationBase::midPointIntegration`` (vins_estimator/src/factor/integration_base.h) adds
    ``V noise V^T`` per IMU step, the rotation row of V holding 0.5 dt for the noise of each of the two samples it
    averages and ``noise`` holding ``gyr_n^2`` for each: 2 (0.5 dt)^2 gyr_n^2 = 0.5 dt^2 gyr_n^2 per step.  A white
    rate density N gives N^2 dt per step; equal when gyr_n = N sqrt(2/dt) (likewise for the velocity row and
    ``acc_n``).

    Examples
    --------
    >>> f"{vins_white(1e-4, 100.0):.6g}"   # 1e-4 * sqrt(200)
    '0.00141421'
    """
    return float(density) * math.sqrt(2.0 * _rate(rate_hz))


def vins_walk(density: float, rate_hz: float) -> float:
    """VINS-Fusion's ``acc_w`` / ``gyr_w`` for a random-walk density K at the IMU rate f: K sqrt(f).

    ``midPointIntegration``'s V maps ``gyr_w`` to the bias row with dt: dt^2 gyr_w^2 per step; a random walk of
    density K grows by K^2 dt per step; equal when gyr_w = K / sqrt(dt).

    Examples
    --------
    >>> f"{vins_walk(1e-6, 100.0):.6g}"    # 1e-6 * sqrt(100)
    '1e-05'
    """
    return float(density) * math.sqrt(_rate(rate_hz))


def gm_rematch(sigma: float, tc_s: float, tc_common_s: float) -> float:
    """The 1-sigma of a Gauss-Markov process of correlation time ``tc_common_s`` whose Allan variance at the
    original's peak (tau = 1.8926 ``tc_s``) equals the original's there (the Gauss-Markov Allan law of
    :mod:`fogdrift.noise.processes.gauss_markov`) (for formats with one correlation time
    for all axes: KF-GINS's ``corrtime``).

    Examples
    --------
    >>> gm_rematch(2.0, 50.0, 50.0)          # the same T_c: unchanged
    2.0
    >>> round(gm_rematch(1.0, 10.0, 100.0), 4)   # a longer T_c needs a larger sigma for the same ADEV at 18.9 s
    1.8636
    """
    if tc_s == tc_common_s:
        return float(sigma)
    peak_tau = GM_PEAK_X * float(tc_s)
    ratio = float(gm_avar_dph2(peak_tau, tc_s, 1.0)) / float(gm_avar_dph2(peak_tau, tc_common_s, 1.0))
    return float(sigma) * math.sqrt(ratio)


def single_gm_from_flicker(b: float, tau_b_s: float) -> tuple[float, float]:
    """The one Gauss-Markov process (sigma, T_c) whose Allan-deviation peak is the flicker floor 0.664 B at tau_B.

    T_c = tau_B / 1.8926 (where a GM's Allan variance peaks), sigma = 1.0760 B (its peak 0.38114 sigma^2 equals
    2 ln2/pi B^2).  A single GM is what KF-GINS and gnss-ins-sim take; :func:`fogdrift.models.statespace.
    flicker_as_gauss_markov` gives the several-GM fit over a tau range used in the state-space model.

    Examples
    --------
    >>> s, t = single_gm_from_flicker(10.0, 100.0)
    >>> round(s, 3), round(t, 3)
    (10.76, 52.837)
    """
    return GM_FLICKER_SIGMA * float(b), float(tau_b_s) / GM_PEAK_X


def _rate(rate_hz) -> float:
    try:
        r = float(rate_hz)
    except (TypeError, ValueError):
        r = math.nan
    if not (math.isfinite(r) and r > 0):
        raise ConfigError(f"the update rate must be a finite number > 0 Hz; got {rate_hz!r} (pass {{opt:rate}})")
    return r


# ------------------------------------------------------------------------------------------------------------------
# unit strings of result files -> SI
# ------------------------------------------------------------------------------------------------------------------
#: (term kind, unit as written after normalisation) -> (quantity, factor to SI).  Term kinds: N, K, B, Q, R, sigma
#: (a Gauss-Markov 1-sigma or any rate), q_c (Markov driving density, IEEE-952 C.6).
UNIT_TABLE: dict[tuple[str, str], tuple[str, float]] = {
    # gyro
    ("N", "deg/sqrt(h)"): ("gyro", RAD_PER_DEG / 60.0),
    ("N", "rad/s/sqrt(Hz)"): ("gyro", 1.0),
    ("N", "rad/sqrt(s)"): ("gyro", 1.0),
    ("N", "deg/s/sqrt(Hz)"): ("gyro", RAD_PER_DEG),
    ("N", "deg/h/sqrt(Hz)"): ("gyro", RAD_PER_DEG / S_PER_H),
    ("N", "deg/h*sqrt(s)"): ("gyro", RAD_PER_DEG / S_PER_H),
    ("K", "deg/h^1.5"): ("gyro", RAD_PER_DEG / S_PER_H**1.5),
    ("K", "deg/h/sqrt(h)"): ("gyro", RAD_PER_DEG / S_PER_H**1.5),
    ("K", "rad/s^2/sqrt(Hz)"): ("gyro", 1.0),
    ("K", "rad/s^1.5"): ("gyro", 1.0),
    ("B", "deg/h"): ("gyro", RAD_PER_DEG / S_PER_H),
    ("B", "deg/s"): ("gyro", RAD_PER_DEG),
    ("B", "rad/s"): ("gyro", 1.0),
    ("Q", "urad"): ("gyro", 1e-6),
    ("Q", "arcsec"): ("gyro", RAD_PER_DEG / ARCSEC_PER_DEG),
    ("Q", "rad"): ("gyro", 1.0),
    ("R", "deg/h^2"): ("gyro", RAD_PER_DEG / S_PER_H ** 2),
    ("R", "rad/s^2"): ("gyro", 1.0),
    ("q_c", "deg/h/sqrt(s)"): ("gyro", RAD_PER_DEG / S_PER_H),
    # accelerometer (IEEE Std 1293 units and SI)
    ("N", "m/s/sqrt(h)"): ("accel", 1.0 / 60.0),
    ("N", "m/s^2/sqrt(Hz)"): ("accel", 1.0),
    ("N", "m/s/sqrt(s)"): ("accel", 1.0),
    ("N", "m/s^2*sqrt(s)"): ("accel", 1.0),
    ("N", "ug/sqrt(Hz)"): ("accel", G0 * 1e-6),
    ("N", "mg/sqrt(Hz)"): ("accel", G0 * 1e-3),
    ("K", "m/s^3/sqrt(Hz)"): ("accel", 1.0),
    ("K", "m/s^2/sqrt(s)"): ("accel", 1.0),
    ("K", "m/s^2.5"): ("accel", 1.0),
    ("K", "m/s^2/sqrt(h)"): ("accel", 1.0 / 60.0),
    ("K", "m/s/h^1.5"): ("accel", 1.0 / S_PER_H**1.5),
    ("K", "m/s/h/sqrt(h)"): ("accel", 1.0 / S_PER_H**1.5),
    ("K", "ug/sqrt(s)"): ("accel", G0 * 1e-6),
    ("B", "m/s^2"): ("accel", 1.0),
    ("B", "ug"): ("accel", G0 * 1e-6),
    ("B", "mg"): ("accel", G0 * 1e-3),
    ("B", "g"): ("accel", G0),
    ("B", "mGal"): ("accel", MGAL),
    ("B", "m/s/h"): ("accel", 1.0 / S_PER_H),
    ("Q", "m/s"): ("accel", 1.0),
    ("Q", "mm/s"): ("accel", 1e-3),
    ("R", "m/s^3"): ("accel", 1.0),
    ("R", "m/s^2/h"): ("accel", 1.0 / S_PER_H),
    ("R", "m/s/h^2"): ("accel", 1.0 / S_PER_H ** 2),
    ("q_c", "m/s^2/sqrt(s)"): ("accel", 1.0),
}

#: SI unit of the Markov driving density (IEEE-952 C.6) per quantity; every term's own SI unit is its row's.
_Q_C_SI = {"gyro": "rad/s/sqrt(s)", "accel": "m/s^2/sqrt(s)"}


def si_unit(quantity: str, term: str) -> str:
    """SI unit of ``term`` (a letter of :mod:`fogdrift.noise.processes`, ``sigma`` or ``q_c``) for ``"gyro"`` or
    ``"accel"``: the row's ``si`` (``sigma``: the Gauss-Markov row's).

    Examples
    --------
    >>> si_unit("gyro", "K"), si_unit("accel", "N"), si_unit("gyro", "sigma")
    ('rad/s^2/sqrt(Hz)', 'm/s^2/sqrt(Hz)', 'rad/s')
    """
    if term == "q_c":
        return _Q_C_SI[quantity]
    return process("M" if term == "sigma" else term).si[quantity][0]


def _registered_units() -> dict:
    """(term, reported unit) -> (quantity, factor) of every row's own reported unit (registered rows included)."""
    out = {}
    for p in processes():
        for quantity, spec in (("gyro", p.term), ("accel", p.accel_term)):
            if spec is not None and quantity in p.si:
                out[(p.name, _normalise(spec.unit))] = (quantity, p.si[quantity][1])
    return out


def _lookup(term: str, unit: str):
    key = (_kind(term), _normalise(unit))
    hit = UNIT_TABLE.get(key)
    return hit if hit is not None else _registered_units().get(key)


#: SI unit of each (quantity, term kind), from the rows of :mod:`fogdrift.noise.processes`.
SI_UNITS = {(q, t): si_unit(q, t) for q in ("gyro", "accel") for t in ("N", "K", "B", "Q", "R", "sigma", "q_c")}

_REPLACE = (("µ", "u"), ("μ", "u"), (" ", ""), ("(m/s^2)", "m/s^2"), ("(rad/s)", "rad/s"), ("(deg/h)", "deg/h"),
            ("(deg/s)", "deg/s"), ("·", "*"), ("√", "sqrt"), ("sqrt(hr)", "sqrt(h)"), ("/hr", "/h"),
            ("²", "^2"), ("³", "^3"), ("s2", "s^2"), ("s3", "s^3"), ("sqrthr", "sqrt(h)"), ("sqrth", "sqrt(h)"),
            ("sqrtHz", "sqrt(Hz)"),
            ("sqrts", "sqrt(s)"), ("sqrt(hz)", "sqrt(Hz)"))


def _normalise(unit: str) -> str:
    u = str(unit)
    for a, b in _REPLACE:
        u = u.replace(a, b)
    return u


def _kind(term: str) -> str:
    return "B" if term == "sigma" else term


def quantity_of_unit(term: str, unit: str) -> str | None:
    """``"gyro"``, ``"accel"`` or None (unknown) for a coefficient of ``term`` written in ``unit``.

    Examples
    --------
    >>> quantity_of_unit("N", "deg/√h"), quantity_of_unit("N", "m/s/sqrt(h)"), quantity_of_unit("N", "furlong")
    ('gyro', 'accel', None)
    """
    hit = _lookup(term, unit)
    return None if hit is None else hit[0]


def to_si(value, term: str, unit: str) -> tuple[float | None, str, str]:
    """``value`` of ``term`` (N, K, B, Q, R, sigma, q_c) in ``unit`` -> (SI value, SI unit, conversion in words).

    Raises
    ------
    ConfigError
        The unit is not one fogdrift knows for that term (the message lists the known ones).

    Examples
    --------
    >>> v, u, how = to_si(0.15, "N", "deg/sqrt(h)")
    >>> f"{v:.4g}", u, how
    ('4.363e-05', 'rad/s/sqrt(Hz)', 'x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))')
    >>> v, u, _ = to_si(0.2, "B", "mg")   # 0.2 mg = 0.2e-3 * 9.80665 m/s^2
    >>> round(v, 9), u
    (0.00196133, 'm/s^2')
    """
    hit = _lookup(term, unit)
    if hit is None:
        known = sorted({u for (k, u) in {**UNIT_TABLE, **_registered_units()} if k == _kind(term)})
        raise ConfigError(f"unit {unit!r} of term {term} is not one fogdrift can convert; expected one of "
                          f"{', '.join(known)}")
    quantity, factor = hit
    unit_si = si_unit(quantity, term if term in ("sigma", "q_c") else _kind(term))
    how = f"x {factor:.6g} ({unit} -> {unit_si})"
    return (None if value is None else float(value) * factor), unit_si, how


def from_si(value_si: float, term: str, unit: str) -> float:
    """Inverse of :func:`to_si`: an SI value of ``term`` written in ``unit``.

    Examples
    --------
    >>> round(from_si(0.00196133, "B", "mg"), 6)
    0.2
    >>> round(from_si(4.3633231e-5, "N", "deg/sqrt(h)"), 6)
    0.15
    """
    hit = _lookup(term, unit)
    if hit is None:
        raise ConfigError(f"unit {unit!r} of term {term} is not one fogdrift can convert")
    return float(value_si) / hit[1]
