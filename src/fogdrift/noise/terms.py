"""The IEEE-952 noise terms as data: one table of facts, and each Allan-family statistic's laws.

:data:`TERM_TABLE` is the one home of the statistic-independent facts of the five terms Q, N,
B, K, R (long name, power-law alpha, Allan law, units, header label, conversion to the reported
unit, source).  :data:`VARIANCE_LAWS` gives, for each statistic of :data:`fogdrift.allan.STATISTICS`,
how each term enters its variance; :data:`UNESTIMABLE` says why a statistic cannot see a term.
:mod:`fogdrift.noise` (the fit) re-exports all of it; report, pipeline and CLI should read
units, headers and long names from here.

Units: rate deg/h, tau and dt in s; a term's coefficient X in these "Allan-law units"
(``law_unit``) is converted to the reported unit by ``to_unit``.

The laws marked "derived" were derived for this module from the noise PSD and the statistic's
transfer function (or directly from the difference operator) and are checked in
``tests/test_noise.py``: by quadrature (flicker constants), against exact discrete sums, and on
simulated signals at a tolerance set by the EDF.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from ..errors import ConfigError
from ..units import B_FACTOR, STANDARD_GRAVITY_MPS2, URAD_PER_ARCSEC
from .covariance import expected_variance

__all__ = [
    "TermSpec",
    "TERM_TABLE",
    "ACCEL_TERM_TABLE",
    "TERM_TABLES",
    "term_table",
    "display_units",
    "SHAPED_UNITS",
    "TERMS",
    "TERM_UNITS",
    "TERM_HEADERS",
    "term_spec",
    "TermLaw",
    "VARIANCE_LAWS",
    "UNESTIMABLE",
    "laws_of",
    "default_terms",
    "SHAPED_TERMS",
    "ALL_TERMS",
    "sinusoid_shape",
    "periodic_shape",
    "markov_shape",
]


# ----------------------------------------------------------------------------------------
# The IEEE-952 terms: one table
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class TermSpec:
    """Facts of one IEEE-952 noise term (statistic-independent).

    Attributes
    ----------
    name : str
        ``"Q"``, ``"N"``, ``"B"``, ``"K"`` or ``"R"``.
    long_name : str
        ``"quantization"``, ``"angle random walk"``, ...
    avar_power : int
        Power of tau of the term in the Allan variance (-2 .. 2).
    avar_coefficient : float
        ``c`` in the Allan law ``sigma^2 = c X^2 tau^avar_power`` (X in ``law_unit``).
    law_unit : str
        Unit of the coefficient X when the rate is in deg/h and tau in s.
    unit : str
        Unit in which fogdrift reports the term.
    suffix : str
        Name suffix of that unit in column and key names (``"_urad"``, ``"_dprh"``, ...).
    header : str
        Table header label, e.g. ``"N [deg/√h]"``.
    to_unit : float
        X[unit] = ``to_unit`` * X[law_unit].
    alpha : int or None
        Power-law exponent of the rate PSD (the EDF noise type); None for the deterministic ramp.
    source : str
        Where the law and conversion come from.
    """

    name: str
    long_name: str
    avar_power: int
    avar_coefficient: float
    law_unit: str
    unit: str
    suffix: str
    header: str
    to_unit: float
    alpha: int | None
    source: str

    def from_A(self, A, coefficient=None) -> float:
        """The term in ``unit`` from its fitted coefficient ``A = c X^2`` (``c`` default: Allan).

        Examples
        --------
        >>> round(term_spec("K").from_A(3.7037037e-8), 6)      # K^2/3 with K = 0.02 deg/h^1.5
        0.02
        """
        c = self.avar_coefficient if coefficient is None else float(coefficient)
        return self.to_unit * math.sqrt(float(A) / c)

    def to_A(self, value, coefficient=None) -> float:
        """Inverse of :meth:`from_A`: ``c (value / to_unit)^2``."""
        c = self.avar_coefficient if coefficient is None else float(coefficient)
        return c * (float(value) / self.to_unit) ** 2


_IEEE = "IEEE Std 952-1997 Annex C; method notes 2.2-2.3"

#: The five IEEE-952 terms, in order of the power of tau in the Allan variance.
TERM_TABLE = MappingProxyType({
    "Q": TermSpec("Q", "quantization", -2, 3.0, "(deg/h) s = arcsec", "urad", "_urad", "Q [µrad]",
                  URAD_PER_ARCSEC, 2, _IEEE + "; 1 (deg/h) s = 1 arcsec = 4.848137 urad"),
    "N": TermSpec("N", "angle random walk", -1, 1.0, "(deg/h) sqrt(s)", "deg/sqrt(h)", "_dprh",
                  "N [deg/√h]", 1.0 / 60.0, 0, _IEEE + "; sqrt(s) = sqrt(h)/60"),
    "B": TermSpec("B", "bias instability", 0, B_FACTOR**2, "deg/h", "deg/h", "_dph", "B [deg/h]",
                  1.0, -1, _IEEE + "; flat level (2 ln2/pi) B^2 for tau >> 1/f0, sigma_min = 0.6643 B"),
    "K": TermSpec("K", "rate random walk", 1, 1.0 / 3.0, "(deg/h)/sqrt(s)", "deg/h^1.5", "_dphrh",
                  "K [deg/h^1.5]", 60.0, -2, _IEEE + "; 1/sqrt(s) = 60/sqrt(h)"),
    "R": TermSpec("R", "rate ramp", 2, 0.5, "(deg/h)/s", "deg/h^2", "_dph2", "R [deg/h²]",
                  3600.0, None, _IEEE + "; 1/s = 3600/h"),
})

_IEEE_ACCEL = ("IEEE Std 1293-2018 (accelerometers) Annex on the Allan variance: the same laws as IEEE Std 952-1997 "
               "Annex C with specific force [m/s^2] in place of rate; term names per IEEE Std 528-2019")

#: The accelerometer twins of the five terms (the Allan laws are the same; the rate is specific force in m/s^2, so
#: the law units are (m/s^2) s = m/s, (m/s^2) sqrt(s), m/s^2, (m/s^2)/sqrt(s), (m/s^2)/s).  B is reported in ug
#: (1 ug = 9.80665e-6 m/s^2, standard gravity, CGPM 1901); the JSON also gives it in m/s^2.
ACCEL_TERM_TABLE = MappingProxyType({
    "Q": TermSpec("Q", "velocity quantization", -2, 3.0, "(m/s^2) s = m/s", "m/s", "_mps", "Q [m/s]",
                  1.0, 2, _IEEE_ACCEL + "; (m/s^2) s = m/s"),
    "N": TermSpec("N", "velocity random walk", -1, 1.0, "(m/s^2) sqrt(s)", "m/s/sqrt(h)", "_mps_rh",
                  "N [m/s/√h]", 60.0, 0, _IEEE_ACCEL + "; m/s/sqrt(s) = 60 m/s/sqrt(h) (sqrt(h) = 60 sqrt(s))"),
    "B": TermSpec("B", "bias instability", 0, B_FACTOR**2, "m/s^2", "ug", "_ug", "B [µg]",
                  1.0 / (STANDARD_GRAVITY_MPS2 * 1e-6), -1,
                  _IEEE_ACCEL + "; 1 ug = 9.80665e-6 m/s^2; flat level (2 ln2/pi) B^2, sigma_min = 0.6643 B"),
    "K": TermSpec("K", "acceleration random walk", 1, 1.0 / 3.0, "(m/s^2)/sqrt(s)", "m/s^2/sqrt(h)", "_mps2_rh",
                  "K [m/s²/√h]", 60.0, -2, _IEEE_ACCEL + "; 1/sqrt(s) = 60/sqrt(h) (= 1/3600 of the m/s/h^1.5 figure)"),
    "R": TermSpec("R", "acceleration ramp", 2, 0.5, "(m/s^2)/s", "m/s^2/h", "_mps2_ph", "R [m/s²/h]",
                  3600.0, None, _IEEE_ACCEL + "; 1/s = 3600/h"),
})

#: The term table of each quantity (:data:`fogdrift.units.QUANTITIES`): the gyro's IEEE-952 table and the
#: accelerometer's.  The Allan laws (powers, coefficients, alphas) are the same; units and names differ.
TERM_TABLES = MappingProxyType({"angular_rate": TERM_TABLE, "specific_force": ACCEL_TERM_TABLE})

#: Units of the shaped terms per quantity: S amplitude and M driving density (rate unit, rate unit/sqrt(s)).
SHAPED_UNITS = MappingProxyType({"angular_rate": ("deg/h", "deg/h/sqrt(s)"),
                                 "specific_force": ("m/s^2", "m/s^2/sqrt(s)")})


def term_table(quantity="angular_rate"):
    """The term table of a channel's quantity (``"angular_rate"``: gyro, ``"specific_force"``: accelerometer).

    Examples
    --------
    >>> term_table("specific_force")["N"].long_name, term_table("specific_force")["N"].unit
    ('velocity random walk', 'm/s/sqrt(h)')
    """
    try:
        return TERM_TABLES[quantity or "angular_rate"]
    except (KeyError, TypeError):
        raise ConfigError(f"no term table for quantity {quantity!r}; expected one of {list(TERM_TABLES)}") from None


def display_units(quantity="angular_rate") -> dict:
    """The units as printed for people for a quantity (``DISPLAY_UNITS`` for a gyro)."""
    return {k: v.header.split("[", 1)[1].rstrip("]") for k, v in term_table(quantity).items()}


#: Noise terms in order of the power of tau in the Allan variance: Q, N, B, K, R.
TERMS = tuple(TERM_TABLE)
#: Units in which :class:`NoiseFit` reports each term.
TERM_UNITS = {k: v.unit for k, v in TERM_TABLE.items()}
#: Table header labels ("Q [µrad]", ...).
TERM_HEADERS = {k: v.header for k, v in TERM_TABLE.items()}
#: The units as printed for people (tables, notes, read-outs): "µrad", "deg/√h", "deg/h", "deg/h^1.5", "deg/h²".
#: ``TERM_UNITS`` (ASCII) stays the unit string of JSON and CSV fields.
DISPLAY_UNITS = {k: v.header.split("[", 1)[1].rstrip("]") for k, v in TERM_TABLE.items()}


def term_spec(name) -> TermSpec:
    """The :class:`TermSpec` of ``name`` (``"Q"``, ``"N"``, ``"B"``, ``"K"``, ``"R"``).

    Examples
    --------
    >>> s = term_spec("N")
    >>> s.long_name, s.unit, s.header, s.avar_power
    ('angle random walk', 'deg/sqrt(h)', 'N [deg/√h]', -1)
    """
    try:
        return TERM_TABLE[name]
    except (KeyError, TypeError):
        raise ConfigError(f"term must be one of {TERMS}, got {name!r}") from None


# ----------------------------------------------------------------------------------------
# Each statistic's law for each term
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class TermLaw:
    """How one term enters one statistic's variance.

    ``sigma^2(tau) = X^2 dt^dt_power tau^power sum_k series[k] (dt/tau)^(2k)``, X in the
    term's ``law_unit``.  The fit estimates ``A = series[0] dt^dt_power X^2``, the coefficient
    of the leading power, with the design column :meth:`shape`.

    Attributes
    ----------
    power : int
        Leading power of tau.
    series : tuple of float
        ``series[0]`` is the constant of the leading power, the rest the small-m corrections.
    dt_power : int
        Power of the sample interval in the constant (1 for white PM under MVAR).
    exact : bool
        True if exact at every m for the signals of :func:`fogdrift.simulate.simulate`;
        False for the asymptotic flicker plateau.
    source : str
    """

    power: int
    series: tuple
    dt_power: int = 0
    exact: bool = True
    source: str = ""

    def scale(self, dt_s) -> float:
        """``A / X^2 = series[0] dt^dt_power``."""
        if self.dt_power and dt_s is None:
            raise ConfigError("this law needs the sample interval dt_s")
        return self.series[0] * (float(dt_s) ** self.dt_power if self.dt_power else 1.0)

    def shape(self, tau_s, dt_s=None, *, leading_only=False) -> np.ndarray:
        """Design column ``tau^power (1 + sum_{k>=1} series[k]/series[0] (dt/tau)^(2k))``."""
        t = np.asarray(tau_s, dtype=np.float64)
        # float ** int64-array (the 'dd->d' pow loop), bit-identical to the earlier tau[:, None] ** powers
        out = np.power(t, np.full(t.shape, self.power, dtype=np.int64))
        if len(self.series) > 1 and not leading_only:
            if dt_s is None:
                raise ConfigError("this law needs the sample interval dt_s")
            r2 = (float(dt_s) / t) ** 2
            out = out * (1.0 + sum(c / self.series[0] * r2**k for k, c in enumerate(self.series[1:], 1)))
        return out


_LN2, _LN3 = math.log(2.0), math.log(3.0)
_SIM = "exact for fogdrift.simulate signals"

#: The law of each term under each statistic (keys: ``AllanResult.statistic``, then term).
#: A term missing from a statistic's table contributes nothing to it (see :data:`UNESTIMABLE`).
VARIANCE_LAWS = MappingProxyType({
    "adev": MappingProxyType({  # the Allan laws of TERM_TABLE
        k: TermLaw(v.avar_power, (v.avar_coefficient,), exact=(k != "B"),
                   source=v.source + ("; asymptotic plateau of flicker rate noise" if k == "B" else "; " + _SIM))
        for k, v in TERM_TABLE.items()
    }),
    "hdev": MappingProxyType({
        "Q": TermLaw(-2, (10.0 / 3.0,), source="derived: the third difference of white angle noise has "
                     "variance (1+9+9+1) Q^2, divided by 6 tau^2; " + _SIM),
        "N": TermLaw(-1, (1.0,), source="derived: the second difference of white-rate cluster means has "
                     "variance 6 N^2/tau, divided by 6 (the normalisation of SP 1065 eq. 17); " + _SIM),
        "B": TermLaw(0, ((4.0 * _LN2 - 1.5 * _LN3) / math.pi,), exact=False,
                     source="derived: (8/3) h_-1 int sin^6 x / x^3 dx = (4 ln2 - 1.5 ln3) h_-1 with "
                     "h_-1 = B^2/pi (0.3580 B^2, 0.811 of AVAR); asymptotic plateau, checked by quadrature"),
        "K": TermLaw(1, (1.0 / 6.0,), source="derived: cluster means of Brownian rate, "
                     "E(ybar3 - 2 ybar2 + ybar1)^2 = K^2 tau, divided by 6 (half the AVAR law); " + _SIM),
    }),
    "mdev": MappingProxyType({
        "Q": TermLaw(-3, (3.0,), dt_power=1, source="derived: the three m-point window sums of white "
                     "angle noise are disjoint, variance 6 m Q^2, so 3 Q^2 dt/tau^3; " + _SIM),
        "N": TermLaw(-1, (0.5, 0.5), source="derived: triangular weights with sum of squares m^3 + m give "
                     "N^2/(2 tau) (1 + dt^2/tau^2); " + _SIM),
        "B": TermLaw(0, ((27.0 / 8.0 * _LN3 - 4.0 * _LN2) / math.pi,), exact=False,
                     source="derived: 2 h_-1 int sin^6 x / x^5 dx = (27/8 ln3 - 4 ln2) h_-1 with "
                     "h_-1 = B^2/pi (0.2977 B^2, 0.675 of AVAR); asymptotic plateau (m -> inf), checked "
                     "by quadrature"),
        "K": TermLaw(1, (11.0 / 40.0, 1.0 / 24.0, 1.0 / 60.0), source="derived: Brownian rate, "
                     "K^2 tau (11/40 + (dt/tau)^2/24 + (dt/tau)^4/60) (1/3 at m = 1, 33/40 of AVAR as "
                     "m -> inf); " + _SIM),
        "R": TermLaw(2, (0.5,), source="derived: the second difference of a quadratic angle is constant, "
                     "so R^2 tau^2/2 as for AVAR; exact"),
    }),
})

#: Why a statistic cannot estimate a term: (statistic, term) -> reason.
UNESTIMABLE = MappingProxyType({
    ("hdev", "R"): "the Hadamard variance cancels a linear rate drift exactly (the third difference of a "
                   "quadratic angle is zero), so it carries no information on the rate ramp R",
})


def laws_of(statistic):
    """The law table of a statistic (ConfigError for an unknown one)."""
    try:
        return VARIANCE_LAWS[statistic]
    except (KeyError, TypeError):
        raise ConfigError(
            f"no IEEE-952 variance laws for statistic {statistic!r}; expected one of {tuple(VARIANCE_LAWS)}"
        ) from None


def default_terms(statistic="adev") -> tuple:
    """The terms a statistic can estimate, in :data:`TERMS` order (all five except R for hdev).

    Examples
    --------
    >>> default_terms("hdev")
    ('Q', 'N', 'B', 'K')
    """
    laws = laws_of(statistic)
    return tuple(t for t in TERMS if t in laws)


# ----------------------------------------------------------------------------------------
# The two shaped terms of IEEE-952 Annex C: sinusoidal (S) and exponentially correlated (M)
# ----------------------------------------------------------------------------------------
#: Facts of the two Annex C terms that are not power laws of tau (long name, reported units, source).
#: Their variance is ``A * shape(tau)``: S ``A = Omega0^2`` [(deg/h)^2] with :func:`periodic_shape` (its frequencies
#: come from the spectrum), M ``A = (q_c T_c)^2`` [(deg/h)^2 s] with :func:`markov_shape` (``T_c`` fitted).
SHAPED_TERMS = MappingProxyType({
    "S": {"long_name": "sinusoidal (periodic) error", "unit": "deg/h", "freq_unit": "Hz",
          "source": "IEEE Std 952-1997 Annex C.7 (sinusoidal noise): sigma^2 = Omega0^2 (sin^2(pi f0 tau) / "
                    "(pi f0 tau))^2; here exact for sampled data: pi f0 tau -> m sin(pi f0 dt)"},
    "M": {"long_name": "exponentially correlated (first-order Gauss-Markov) noise", "unit": "deg/h/sqrt(s)",
          "sigma_unit": "deg/h", "tc_unit": "s",
          "source": "IEEE Std 952-1997 Annex C.6 (exponentially correlated noise): sigma^2 = (q_c T_c)^2 / tau "
                    "[1 - T_c/(2 tau) (3 - 4 exp(-tau/T_c) + exp(-2 tau/T_c))]; sigma = q_c sqrt(T_c/2)"},
})
#: Every term the noise fit can select: the five power-law terms, then S and M.
ALL_TERMS = TERMS + tuple(SHAPED_TERMS)


def sinusoid_shape(tau_s, freq_hz, dt_s, statistic="adev", *, envelope=False) -> np.ndarray:
    """Variance of a unit-amplitude sinusoid of ``freq_hz`` [Hz] at ``tau_s`` [s] (``A = Omega0^2`` multiplies it).

    Derived for sampled data: the ``m``-sample mean of ``sin(2 pi f t_k + phi)`` is a sinusoid of amplitude
    ``D_m = sin(pi f tau) / (m sin(pi f dt))``; a first difference at lag ``tau`` multiplies the amplitude by
    ``2 sin(pi f tau)``, a second difference by ``4 sin^2(pi f tau)``, and a squared sinusoid averages to 1/2::

        adev: D_m^2 sin^2(pi f tau)          = sin^4(pi f tau) / (m sin(pi f dt))^2
        hdev: (4/3) D_m^2 sin^4(pi f tau)    = (4/3) sin^6(pi f tau) / (m sin(pi f dt))^2
        mdev: D_m^4 sin^2(pi f tau)          = sin^6(pi f tau) / (m sin(pi f dt))^4

    As ``dt -> 0`` (``m sin(pi f dt) -> pi f tau``) the Allan law is IEEE-952 Annex C's
    ``(sin^2(pi f tau) / (pi f tau))^2``.  Zero at every multiple of the period.  Checked against exact
    discrete computations on noiseless sinusoids in ``tests/test_noise_periodic.py``.

    ``envelope=True``: the same law with ``sin(pi f tau)`` replaced by 1 (``1 / (m sin(pi f dt))^2`` for ``adev``),
    the upper envelope of the oscillating law: a real line's amplitude and frequency wander, which fills the nulls,
    and its variance can reach the envelope at any ``tau``.

    Examples
    --------
    >>> float(sinusoid_shape(0.05, 20.0, 0.01)[()]) < 1e-30     # a whole period: the sinusoid cancels
    True
    >>> round(float(sinusoid_shape(0.05, 20.0, 0.01, envelope=True)[()]), 4)   # 1 / (5 sin(0.2 pi))^2
    0.1158
    """
    t = np.asarray(tau_s, dtype=np.float64)
    f, dt = float(freq_hz), float(dt_s)
    m = np.rint(t / dt)
    s_tau = np.ones(t.shape) if envelope else np.sin(np.pi * f * m * dt)
    den = m * np.sin(np.pi * f * dt)
    with np.errstate(divide="ignore", invalid="ignore"):
        if statistic == "adev":
            out = s_tau**4 / den**2
        elif statistic == "hdev":
            out = (4.0 / 3.0) * s_tau**6 / den**2
        elif statistic == "mdev":
            out = s_tau**6 / den**4
        else:
            laws_of(statistic)
            raise ConfigError(f"no sinusoid law for statistic {statistic!r}")
    return np.where(np.isfinite(out), out, 0.0)


def periodic_shape(tau_s, lines, dt_s, statistic="adev", *, envelope=False) -> np.ndarray:
    """Variance shape of a periodic error made of spectral lines ``[(freq_hz, relative_power), ...]``.

    The lines' powers relative to the first (the fundamental, ``relative_power`` 1) are fixed from the spectrum and
    one scale ``A = Omega0^2`` (the fundamental's squared amplitude [(deg/h)^2]) is fitted: the lines of one periodic
    error share its amplitude drift, the spectrum measures their ratios far better than the tau curve could, and one
    parameter per component keeps the model selection from trading harmonics against Q.  ``envelope``: each line's
    envelope instead of its law (:func:`sinusoid_shape`).
    """
    t = np.asarray(tau_s, dtype=np.float64)
    out = np.zeros(t.shape)
    for f, r in lines:
        out = out + float(r) * sinusoid_shape(t, f, dt_s, statistic, envelope=envelope)
    return out


def markov_shape(tau_s, tc_s, statistic="adev", dt_s=None) -> np.ndarray:
    """Variance shape of first-order Gauss-Markov rate noise with correlation time ``tc_s`` [s]: ``A = (q_c T_c)^2``
    [(deg/h)^2 s] multiplies it (IEEE-952 Annex C.6).

    ``adev``: the Annex C law ``1/tau [1 - T_c/(2 tau) (3 - 4 e^(-tau/T_c) + e^(-2 tau/T_c))]`` (-> ``tau / (3 T_c^2)``,
    i.e. ``q_c^2 tau / 3``, for ``tau << T_c``, like a rate random walk of ``K = q_c``, and ``1/tau`` for ``tau >> T_c``, like white noise).  ``hdev`` and
    ``mdev``: not derived in closed form; the expectation of the estimator under the exact spectrum of the sampled
    process (an AR(1) with ``phi = exp(-dt/T_c)``, :func:`fogdrift.noise.covariance.expected_variance`), which needs
    ``dt_s``.
    """
    t = np.asarray(tau_s, dtype=np.float64)
    tc = float(tc_s)
    if statistic == "adev":
        x = t / tc
        with np.errstate(over="ignore", invalid="ignore"):
            small = x < 1e-3  # series: (1/tau) (x^2/3 - x^3/4 + ...) avoids the cancellation
            big = (1.0 - (3.0 - 4.0 * np.exp(-x) + np.exp(-2.0 * x)) / (2.0 * x)) / t
            ser = (x * x / 3.0 - x**3 / 4.0) / t
        return np.where(small, ser, big)
    laws_of(statistic)
    if dt_s is None:
        raise ConfigError("the Gauss-Markov law of hdev/mdev needs the sample interval dt_s")

    dt = float(dt_s)
    phi = math.exp(-dt / tc)
    s2 = 1.0 / (2.0 * tc)  # process variance per unit A: A = (q_c T_c)^2 = 2 sigma^2 T_c

    def spec(f):
        return s2 * (1.0 - phi * phi) / (1.0 - 2.0 * phi * np.cos(2.0 * np.pi * np.asarray(f)) + phi * phi)

    return expected_variance(np.rint(t / dt), spec, statistic=statistic, per_octave=32)
