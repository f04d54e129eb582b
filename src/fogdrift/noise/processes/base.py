"""The row types of the noise-process table: :class:`NoiseProcess` and the parts it is made of.

A noise process (white rate noise, quantization, flicker, rate random walk, rate ramp, a sinusoid, a first-order
Gauss-Markov process, ...) is one :class:`NoiseProcess`: everything fogdrift knows about it, in one place --

* its IEEE-952 / IEEE-1293 identity and units (:class:`TermSpec`, gyro and accelerometer) for a power-law term, or
  the facts of a shaped Annex C term (S, M);
* how it enters each Allan-family statistic (:class:`TermLaw` per statistic, or a variance ``shape``);
* its per-sample latent form for GMWM (:class:`LatentSpec`: parameters, Haar wavelet variance, spectral density,
  IEEE reading, simulator);
* its one-sided rate PSD;
* its continuous state-space block (:class:`ComponentSpec`: the Kalman component it becomes and the densities the
  filter and the exports discretise);
* its SI unit and the factor from its reported unit (the exports);
* its simulator in the reported parametrisation (:func:`fogdrift.simulate.simulate`).

Every estimator and command reads these rows (:mod:`fogdrift.noise.processes`); a protection or a law added to a
row reaches the Allan fit, GMWM, the Kalman model, the consistency check, the exports and the simulators at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Callable, Mapping

import numpy as np

from ...errors import ConfigError

__all__ = ["TermSpec", "TermLaw", "LatentSpec", "ComponentSpec", "NoiseProcess"]

_EMPTY = MappingProxyType({})


@dataclass(frozen=True)
class TermSpec:
    """Facts of one IEEE-952 power-law noise term (statistic-independent).

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
        >>> from fogdrift.noise.terms import term_spec
        >>> round(term_spec("K").from_A(3.7037037e-8), 6)      # K^2/3 with K = 0.02 deg/h^1.5
        0.02
        """
        c = self.avar_coefficient if coefficient is None else float(coefficient)
        return self.to_unit * math.sqrt(float(A) / c)

    def to_A(self, value, coefficient=None) -> float:
        """Inverse of :meth:`from_A`: ``c (value / to_unit)^2``."""
        c = self.avar_coefficient if coefficient is None else float(coefficient)
        return c * (float(value) / self.to_unit) ** 2


@dataclass(frozen=True)
class TermLaw:
    """How one term enters one statistic's variance.

    ``sigma^2(tau) = X^2 dt^dt_power tau^power sum_k series[k] (dt/tau)^(2k)``, X in the
    term's ``law_unit``.  The fit estimates ``A = series[0] dt^dt_power X^2``, the coefficient
    of the leading power, with the design column :meth:`shape`.

    Attributes
    ----------
    power : int or float
        Leading power of tau (an integer for the IEEE-952 terms).
    series : tuple of float
        ``series[0]`` is the constant of the leading power, the rest the small-m corrections.
    dt_power : int
        Power of the sample interval in the constant (1 for white PM under MVAR).
    exact : bool
        True if exact at every m for the signals of :func:`fogdrift.simulate.simulate`;
        False for the asymptotic flicker plateau.
    source : str
    """

    power: float
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
        if float(self.power).is_integer():
            # float ** int64-array (the 'dd->d' pow loop), bit-identical to the earlier tau[:, None] ** powers
            out = np.power(t, np.full(t.shape, int(self.power), dtype=np.int64))
        else:  # a fractional power law (a registered process)
            out = np.power(t, float(self.power))
        if len(self.series) > 1 and not leading_only:
            if dt_s is None:
                raise ConfigError("this law needs the sample interval dt_s")
            r2 = (float(dt_s) / t) ** 2
            out = out * (1.0 + sum(c / self.series[0] * r2**k for k, c in enumerate(self.series[1:], 1)))
        return out


@dataclass(frozen=True)
class LatentSpec:
    """The per-sample (latent) form of a process, as GMWM models it ([GMWM] notes §2).

    Attributes
    ----------
    name : str
        GMWM registry key (``"WN"``, ``"QN"``, ``"RW"``, ``"DR"``, ``"FLICKER"``, ``"GM"``).
    long_name : str
    params : tuple of str
        Natural parameters, all > 0 (free parameters are their logarithms).
    param_units : tuple of str
        Units of ``params`` (``rate`` is deg/h, per sample).
    wv : callable
        ``wv(theta, tau) -> nu2`` with ``theta`` of shape ``(len(params),)``, tau the Haar scale in samples.
    sdf : callable or None
        ``sdf(theta, f) -> S(f)`` two-sided in rate^2 per cycle/sample, ``|f| <= 1/2``;
        None for a deterministic process (drift).
    ieee : callable
        ``ieee(theta, dt_s) -> {quantity: value}`` (keys carry units).
    excess_kurtosis : float
        Excess kurtosis of the iid innovations (0: Gaussian; QN: -1.2, uniform rounding);
        enters the fourth-cumulant term of the WV covariance.
    simulate : callable or None
        ``simulate(theta, n, rng) -> x`` (rate, the unit of ``theta``'s variances), the per-sample definition.
    aliases : tuple of str
        Other spellings accepted in model strings (upper case).
    """

    name: str
    long_name: str
    params: tuple
    param_units: tuple
    wv: Callable
    sdf: Callable | None
    ieee: Callable
    excess_kurtosis: float = 0.0
    simulate: Callable | None = None
    aliases: tuple = ()


@dataclass(frozen=True)
class ComponentSpec:
    """The Kalman-filter component a process becomes (IEEE units; JSON-ready dicts ``{"kind": kind, key: value}``).

    Attributes
    ----------
    kind : str
        Component kind (``"white"``, ``"quantization"``, ``"random_walk"``, ``"gauss_markov"``, ``"ramp"``).
    keys : tuple of str
        Parameter keys in order.
    description : str
        One line with units.
    densities : callable
        ``densities(component, out)``: adds the component's densities in Allan-law units to the dict ``out`` of
        :func:`fogdrift.models.statespace.component_densities` (``white2``, ``quant2``, ``rw2``, ``gms``, ``ramps``).
    """

    kind: str
    keys: tuple
    description: str
    densities: Callable


@dataclass(frozen=True)
class NoiseProcess:
    """One noise process: the one definition every estimator, model, export and simulator reads.

    Attributes
    ----------
    name : str
        IEEE letter and registry key (``"Q"``, ``"N"``, ``"B"``, ``"K"``, ``"R"``, ``"S"``, ``"M"``).
    key : str
        Name in words used as a component/module name (``"white"``, ``"quantization"``, ...).
    term, accel_term : TermSpec or None
        Identity and units of a power-law term for a gyro (IEEE 952) and an accelerometer (IEEE 1293).
    laws : mapping
        Statistic (``"adev"``, ``"hdev"``, ``"mdev"``) -> :class:`TermLaw`; a statistic missing here cannot see the
        process (the reason in ``unestimable``).
    unestimable : mapping
        Statistic -> why it carries no information on the process.
    shaped : mapping or None
        Facts of a shaped Annex C term (S, M): long name, units, source.
    shape : callable or None
        Variance shape of a shaped term (its own signature; see the row's module).
    latent : LatentSpec or None
        The GMWM form.
    psd : callable or None
        ``psd(x, f_hz) -> S(f)``: one-sided rate PSD [(deg/h)^2/Hz] of the process with coefficient ``x`` in the
        term's ``law_unit`` (power-law terms).
    simulate : callable or None
        ``simulate(x, n, dt_s, rng) -> rate [deg/h]`` with ``x`` in the term's ``law_unit``: the signal whose
        Allan variance is the row's ``adev`` law.
    sim_kwarg : str or None
        Keyword of :func:`fogdrift.simulate.simulate` that sets the process (value in the term's ``unit``).
    sim_stream : int or None
        Index of the process's child random stream in :func:`fogdrift.simulate.simulate`.
    component : ComponentSpec or None
        The state-space component the process becomes.
    to_components : callable or None
        ``to_components(A, ctx) -> list of component dicts`` from the Allan-law coefficient ``A`` (deg/h, s) and a
        context dict (``tau_range_s``, ``A_white``, ``max_flicker_terms``); ``component_rank`` orders them.
    component_rank : int
        Order of the process's components in a component list.
    si : mapping
        Quantity (``"gyro"``, ``"accel"``) -> ``(SI unit, factor from the reported unit to SI)``.
    slope_rule : bool
        True if the process is claimed only from a sustained slope over an octave (rate random walk, ramp:
        :func:`fogdrift.noise.rules.slope_claim`).
    source : str
    """

    name: str
    key: str
    term: TermSpec | None = None
    accel_term: TermSpec | None = None
    laws: Mapping = field(default_factory=dict)
    unestimable: Mapping = field(default_factory=dict)
    shaped: Mapping | None = None
    shape: Callable | None = None
    latent: LatentSpec | None = None
    psd: Callable | None = None
    simulate: Callable | None = None
    sim_kwarg: str | None = None
    sim_stream: int | None = None
    component: ComponentSpec | None = None
    to_components: Callable | None = None
    component_rank: int = 99
    si: Mapping = field(default_factory=dict)
    slope_rule: bool = False
    source: str = ""

    @property
    def long_name(self) -> str:
        """The process in words (the gyro term's long name, or the shaped term's)."""
        if self.term is not None:
            return self.term.long_name
        if self.shaped is not None:
            return self.shaped["long_name"]
        return self.latent.long_name if self.latent is not None else self.key

    @property
    def power_law(self) -> bool:
        """True for a term that enters the Allan variance as ``A tau^p`` (a column of the linear fit)."""
        return self.term is not None


#: Source strings shared by the rows.
IEEE_952 = "IEEE Std 952-1997 Annex C; method notes 2.2-2.3"
IEEE_1293 = ("IEEE Std 1293-2018 (accelerometers) Annex on the Allan variance: the same laws as IEEE Std 952-1997 "
             "Annex C with specific force [m/s^2] in place of rate; term names per IEEE Std 528-2019")
SIM_EXACT = "exact for fogdrift.simulate signals"
#: sqrt(1 h / 1 s) = sqrt(S_PER_H): N[(deg/h) sqrt(s)] = 60 N[deg/sqrt(h)], K[(deg/h)/sqrt(s)] = K[deg/h^1.5] / 60.
SQRT_H = 60.0
