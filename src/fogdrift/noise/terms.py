"""The IEEE-952 noise terms as tables: views of the noise-process table for the Allan-family fit.

The facts live in the rows of :mod:`fogdrift.noise.processes` (one module per process); this module gives the
views the fit, the report, the pipeline and the CLI read: :data:`TERM_TABLE` (letter -> :class:`TermSpec`: long
name, power-law alpha, Allan law, units, header label, conversion to the reported unit, source; live, a registered
power-law process appears), :data:`ACCEL_TERM_TABLE` (IEEE Std 1293), :data:`VARIANCE_LAWS` (for each statistic of
:data:`fogdrift.allan.STATISTICS`, how each term enters its variance), :data:`UNESTIMABLE` (why a statistic cannot
see a term), and the shaped Annex C terms S and M with their variance shapes.

Units: rate deg/h, tau and dt in s; a term's coefficient X in these "Allan-law units"
(``law_unit``) is converted to the reported unit by ``to_unit``.

The laws marked "derived" were derived from the noise PSD and the statistic's transfer function (or directly from
the difference operator) and are checked in ``tests/noise/test_noise.py`` and ``tests/noise/test_noise_processes.py``: by
quadrature (flicker constants, each row's PSD against its Allan law), against exact discrete sums, and on
simulated signals at a tolerance set by the EDF.
"""

from __future__ import annotations

from types import MappingProxyType

from ..errors import ConfigError
from .processes import gauss_markov, sinusoid
from .processes import power_law_names as _power_law_names
from .processes import TableView
from .processes import processes as _processes
from .processes import shaped_names as _shaped_names
from .processes.base import TermLaw, TermSpec
from .processes.gauss_markov import markov_shape
from .processes.sinusoid import periodic_shape, sinusoid_shape

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
    "power_terms",
    "all_terms",
    "sinusoid_shape",
    "periodic_shape",
    "markov_shape",
]


# ----------------------------------------------------------------------------------------
# The IEEE-952 terms: views of the noise-process table
# ----------------------------------------------------------------------------------------
#: The IEEE-952 power-law terms (Q, N, B, K, R, and any registered one), in order of the power of tau in the Allan
#: variance: the ``term`` of each row of :mod:`fogdrift.noise.processes`.
TERM_TABLE = TableView(lambda: {p.name: p.term for p in _processes() if p.power_law}, "TERM_TABLE")

#: The accelerometer twins (IEEE Std 1293): the same Allan laws with specific force [m/s^2] in place of rate; B in ug.
ACCEL_TERM_TABLE = TableView(lambda: {p.name: p.accel_term for p in _processes() if p.power_law}, "ACCEL_TERM_TABLE")

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
# Each statistic's law for each term: views of the rows' laws
# ----------------------------------------------------------------------------------------
_STATISTIC_NAMES = ("adev", "hdev", "mdev")


#: The law of each term under each statistic (keys: ``AllanResult.statistic``, then term), from the rows' ``laws``.
#: A term missing from a statistic's table contributes nothing to it (see :data:`UNESTIMABLE`).
VARIANCE_LAWS = MappingProxyType({
    st: TableView(lambda st=st: {p.name: p.laws[st] for p in _processes() if p.power_law and st in p.laws}, st)
    for st in _STATISTIC_NAMES})


#: Why a statistic cannot estimate a term: (statistic, term) -> reason.
UNESTIMABLE = TableView(lambda: {(st, p.name): why for p in _processes() for st, why in p.unestimable.items()},
                        "UNESTIMABLE")


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
SHAPED_TERMS = MappingProxyType({"S": sinusoid.SHAPED, "M": gauss_markov.SHAPED})
#: Every term the noise fit can select: the five power-law terms, then S and M.
ALL_TERMS = TERMS + tuple(SHAPED_TERMS)


def power_terms() -> tuple:
    """The power-law terms now in the table: Q, N, B, K, R, then any registered one (live; :data:`TERMS` is the
    built-in five)."""
    return _power_law_names()


def all_terms() -> tuple:
    """Every term the Allan fit can select now: :func:`power_terms`, then S and M (live; :data:`ALL_TERMS` is the
    built-in seven).  The position of a term in this tuple is its column in the fit."""
    return _power_law_names() + _shaped_names()
