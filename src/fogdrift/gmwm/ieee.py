"""IEEE-952 quantities (N, K, R, Q, B, GM T_c and sigma) with intervals from a GMWM fit.

Conversions per component ([GMWM]_ §4; rate in deg/h, per-sample model, interval ``dt``):

=========  =====================================  =====================================
quantity   from                                   unit
=========  =====================================  =====================================
N          ``sqrt(sigma2 dt) / 60``               deg/sqrt(h)   (AVAR N^2 / T)
K          ``60 sqrt(gamma2 / dt)``               deg/h/sqrt(h) (AVAR K^2 T / 3)
R          ``3600 omega / dt``                    deg/h^2       (AVAR R^2 T^2 / 2)
Q          ``sqrt(q2) dt``                        arcsec (also urad) (AVAR 3 Q^2 / T^2)
T_c        ``dt / beta``                          s
sigma_GM   ``sqrt(sigma2 / (1 - phi^2))``         deg/h
B          ``sqrt(b2)`` (FLICKER)                 deg/h (flat ADEV 0.6643 B)
=========  =====================================  =====================================

Bias instability, each reading with the averaging time ``T`` where it occurs ([GMWM]_ §4):

* ``"flicker"``: ``B = sqrt(b2)`` of a FLICKER component (a model parameter, no ``T``).
* ``"min-avar"``: the classical IEEE reading ``B = sqrt(min_T AVAR_model(T)) / 0.6643`` (biased up where
  WN/RW overlap), searched over the Allan times the fit used, ``T`` in ``[s_1 / 2, s_J / 2]`` (``s_j``
  the first and last wavelet scales used; AVAR(T) = 2 WV(2T)).
* ``"gm-max"``: the GM hump read as a flicker plateau, ``B = sqrt(max_T AVAR_GMsum(T)) / 0.6643``; only
  GMs that are the largest component at one or more fitted scales and whose WV peak (scale
  ``3.785 T_c``) is at least twice the first scale used (a faster or buried GM is short-scale
  structure such as an output filter, not a flat region).  A detail, never the headline B.

**No value is read beyond the data** (:func:`_reading`): a reading whose ``T`` lies outside the fitted
range is never a number with an interval.  At the longest ``T`` used with the model's ADEV still
falling (or at the shortest, still rising) it is the 95 % upper bound of the model's ADEV there / 0.6643
(``value = None``, ``bound_dph`` and ``reason`` set); a GM hump peaking outside the range gives nothing
(``"not reached within the record"``).  The headline B of an axis (:attr:`IEEEResult.b_headline`) is the
flicker term when the model has one, else the min-AVAR reading.

Intervals: delta method in the free parameters ``z = log theta`` (the fit's ``cov_z``):
``se(log g) = sqrt(grad^T Cov grad)`` with ``grad = d log g / d z`` by central differences,
and ``g exp(+-1.96 se)``.  The sign of a drift is not identified by the WV (R >= 0).

References
----------
.. [GMWM] fogdrift GMWM method notes, ``shared/docs/gmwm-notes.md`` §4.
.. [IEEE952] IEEE Std 952-1997, Annex C (Allan variance noise terms).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..units import B_FACTOR
from .processes import PROCESSES, parse_model

__all__ = ["IEEEValue", "BiasInstability", "IEEEResult", "to_ieee", "B_ADEV_FACTOR"]

#: Flat Allan deviation of flicker noise in units of B: sqrt(2 ln2 / pi) (:data:`fogdrift.units.B_FACTOR`).
B_ADEV_FACTOR = B_FACTOR
_Z95 = 1.959963984540054
_STEP = 1e-5

_UNITS = {"N_dprh": "deg/sqrt(h)", "K_dphrh": "deg/h/sqrt(h)", "R_dph2": "deg/h^2", "Q_arcsec": "arcsec",
          "Q_urad": "urad", "B_dph": "deg/h", "tc_s": "s", "sigma_gm_dph": "deg/h"}


@dataclass(frozen=True)
class IEEEValue:
    """One quantity with its 95 % interval.

    Attributes
    ----------
    name : str
        Key with unit suffix (``"N_dprh"``, ``"tc_s"`` ...).
    value, lo95, hi95 : float
    unit : str
    se_log : float
        Standard error of ``log value`` (inf if not identified).
    component : str
        Model component it comes from (``"WN"``, ``"GM1"`` ...).
    """

    name: str
    value: float
    lo95: float
    hi95: float
    unit: str
    se_log: float
    component: str

    def to_dict(self) -> dict:
        return {k: (float(v) if isinstance(v, (float, np.floating)) else v) for k, v in self.__dict__.items()}


@dataclass(frozen=True)
class BiasInstability:
    """Bias instability B read from the fitted model by one rule.

    Attributes
    ----------
    rule : str
        ``"flicker"``, ``"min-avar"`` or ``"gm-max"`` (module docstring).
    value_dph, lo95_dph, hi95_dph : float or None
        B in deg/h with its 95 % interval; None when the reading lies outside the scales the fit used.
    tau_s : float or None
        Averaging time [s] of the reading (for a bound: the end of the fitted range it is read at; None
        for the flicker term and when nothing is read).
    bound_dph : float or None
        95 % upper bound in deg/h when ``value_dph`` is None and the data support one.
    reason : str
        Why there is no value (empty when there is one).
    label : str
        The rule in words, as shown to the user.
    """

    rule: str
    value_dph: float | None
    lo95_dph: float | None
    hi95_dph: float | None
    tau_s: float | None
    bound_dph: float | None
    reason: str
    label: str

    @property
    def flagged(self) -> bool:
        """True when this reading is not a value (a bound or nothing)."""
        return self.value_dph is None

    def text(self, digits: int = 4) -> str:
        """The reading as one cell: ``"39.2 [35.1, 43.8] deg/h at τ = 117 s"``, ``"< 7.06 deg/h (why)"`` or
        ``"not reached within the record (why)"``."""
        def f(x, d=digits):
            return f"{x:.{d}g}"

        if self.value_dph is not None:
            iv = "" if self.lo95_dph is None else f" [{f(self.lo95_dph, 3)}, {f(self.hi95_dph, 3)}]"
            at = "" if self.tau_s is None else f" at τ = {f(self.tau_s, 4)} s"
            return f"{f(self.value_dph)}{iv} deg/h{at}"
        if self.bound_dph is not None:
            return f"< {f(self.bound_dph, 3)} deg/h ({self.reason})"
        return f"not reached within the record ({self.reason})"

    def to_dict(self) -> dict:
        return {k: (float(v) if isinstance(v, (float, np.floating)) else v) for k, v in self.__dict__.items()}

    def as_b_min(self) -> dict:
        """This reading in the shape of the Allan fit's ``NoiseFit.b_min`` (one shape for both methods).

        ``{"value", "unit", "tau_s", "bound_only", "lo95", "hi95", "rule"}``, B in deg/h: ``value`` is the reading,
        or its 95 % upper bound with ``bound_only`` True; ``{}`` when nothing is read (as the Allan fit's empty
        ``b_min``).
        """
        if self.value_dph is None and self.bound_dph is None:
            return {}
        bound = self.value_dph is None
        return {"value": float(self.bound_dph if bound else self.value_dph), "unit": "deg/h",
                "tau_s": None if self.tau_s is None else float(self.tau_s), "bound_only": bound,
                "lo95": None if bound or self.lo95_dph is None else float(self.lo95_dph),
                "hi95": float(self.bound_dph) if bound else (None if self.hi95_dph is None else float(self.hi95_dph)),
                "rule": self.label}


@dataclass(frozen=True)
class IEEEResult:
    """IEEE-952 reading of a GMWM fit.

    Attributes
    ----------
    model : str
    terms : dict[str, IEEEValue]
        ``N_dprh``, ``K_dphrh``, ``R_dph2``, ``Q_arcsec``, ``Q_urad``, ``B_dph`` (FLICKER) where present.
    gm : list of dict
        Per GM (by increasing T_c): ``{"component", "tc_s": IEEEValue, "sigma_gm_dph": IEEEValue}``.
    b_gm : BiasInstability or None
        The GM-hump reading (``"gm-max"``), only with GMs that make a hump.
    b_min : BiasInstability
        The classical reading (``"min-avar"``).
    b_flicker : BiasInstability or None
        The FLICKER term as a reading (``"flicker"``), only with a FLICKER component.
    tau_range_s : tuple of float
        Allan times [s] the fit covers, ``(s_1 / 2, s_J / 2)``.
    dt_s : float
    n_samples : int
    """

    model: str
    terms: dict
    gm: list
    b_gm: BiasInstability | None
    b_min: BiasInstability
    dt_s: float
    n_samples: int
    b_flicker: BiasInstability | None = None
    tau_range_s: tuple = (float("nan"), float("nan"))

    @property
    def b_headline(self) -> BiasInstability:
        """The one B of the axis: the flicker term when the model has one, else the min-AVAR reading."""
        return self.b_flicker if self.b_flicker is not None else self.b_min

    @property
    def b_details(self) -> list:
        """The other B readings (never a second headline B): the min-AVAR reading beside a flicker term, the
        GM-hump reading."""
        return [b for b in (self.b_min if self.b_flicker is not None else None, self.b_gm) if b is not None]

    def to_dict(self) -> dict:
        return {
            "model": self.model,
            "terms": {k: v.to_dict() for k, v in self.terms.items()},
            "gm": [{k: (v.to_dict() if isinstance(v, IEEEValue) else v) for k, v in g.items()} for g in self.gm],
            "b_gm": None if self.b_gm is None else self.b_gm.to_dict(),
            "b_min": self.b_min.to_dict(),
            "b_flicker": None if self.b_flicker is None else self.b_flicker.to_dict(),
            "b_headline": self.b_headline.to_dict(),
            "tau_range_s": [float(v) for v in self.tau_range_s],
            "dt_s": float(self.dt_s),
            "n_samples": int(self.n_samples),
        }


def _delta(fun, z, cov):
    """(value, se of log value) of a positive scalar function of z."""
    v = fun(z)
    if not (v > 0 and math.isfinite(v)):
        return v, float("inf")
    g = np.zeros(z.size)
    for i in range(z.size):
        e = np.zeros(z.size)
        e[i] = _STEP
        vp, vm = fun(z + e), fun(z - e)
        if not (vp > 0 and vm > 0):
            return v, float("inf")
        g[i] = (math.log(vp) - math.log(vm)) / (2.0 * _STEP)
    nz = g != 0  # parameters the quantity does not depend on may have infinite variance
    sub = cov[np.ix_(nz, nz)]
    var = float(g[nz] @ sub @ g[nz]) if np.all(np.isfinite(sub)) else float("inf")
    return v, math.sqrt(max(var, 0.0))


def _exp(x: float) -> float:
    """``exp(x)``, ``inf`` beyond the float range: a log-normal 95 % bound ``v exp(1.96 se)`` with a huge but finite
    standard error (a fallback model's, se > ~362) is unbounded, not an OverflowError."""

    try:
        return math.exp(x)
    except OverflowError:
        return float("inf")


def _value(name, fun, z, cov, component) -> IEEEValue:
    v, se = _delta(fun, z, cov)
    lo = v * _exp(-_Z95 * se) if math.isfinite(se) else 0.0
    hi = v * _exp(_Z95 * se) if math.isfinite(se) else float("inf")
    return IEEEValue(name, float(v), float(lo), float(hi), _UNITS[name], float(se), component)


def _m_grid(m_max: float) -> np.ndarray:
    m_max = max(2.0, m_max)
    return np.unique(np.round(np.logspace(0.0, math.log10(m_max), int(40 * math.log10(m_max)) + 2)))


def to_ieee(fit) -> IEEEResult:
    """IEEE-952 quantities of a :class:`~fogdrift.gmwm.estimator.GMWMFit` with 95 % intervals.

    Parameters
    ----------
    fit : GMWMFit

    Returns
    -------
    IEEEResult

    Examples
    --------
    A per-sample WN of variance 1 (deg/h)^2 at 100 Hz is N = sqrt(0.01) / 60 deg/sqrt(h):

    >>> from fogdrift.gmwm import haar_wvar, simulate_latent, gmwm_fit
    >>> fit = gmwm_fit(haar_wvar(simulate_latent("WN", [1.0], 2**14, seed=0), 0.01), "WN")
    >>> r = to_ieee(fit)
    >>> round(r.terms["N_dprh"].value / (0.1 / 60), 2)
    1.0
    """
    mdl = parse_model(fit.model)
    z = np.asarray(fit.z, dtype=np.float64)
    cov = np.asarray(fit.cov_z, dtype=np.float64)
    dt = float(fit.dt_s)
    n = int(fit.n_samples)
    terms: dict = {}
    gms: list = []
    for key, lab, sl in zip(mdl.components, mdl.labels, mdl.slices):
        proc = PROCESSES[key]
        entries = {}
        for name in proc.ieee(np.exp(z[sl]), dt):
            def fun(zz, name=name, sl=sl, proc=proc):
                return proc.ieee(np.exp(zz[sl]), dt)[name]

            entries[name] = _value(name, fun, z, cov, lab)
        if key == "GM":
            gms.append({"component": lab, **entries})
        else:
            terms.update(entries)

    scales = np.asarray(fit.tau_samples, dtype=np.float64)
    m_lo, m_hi = float(scales[0]) / 2.0, float(scales[-1]) / 2.0  # Allan factors the fit covers
    tau_range = (m_lo * dt, m_hi * dt)
    m_used = _m_range(m_lo, m_hi)

    # the GM hump: GMs resolved by the scales (WV peak, scale 3.785 T_c, at least twice the first scale; a
    # faster GM is short-scale structure such as an output filter) and the largest component at one or more
    # fitted scales (a GM buried under the WN everywhere does not make a flat region)
    dominant = set(np.argmax(mdl.wv_components(np.exp(z), scales), axis=0).tolist())
    first_scale = float(fit.scale_s[0])
    gm_idx = [i for i, k in enumerate(mdl.components)
              if k == "GM" and i in dominant and 3.785 * dt / math.exp(z[mdl.slices[i].start]) >= 2.0 * first_scale]
    b_gm = None
    if gm_idx:
        tcs = [dt / math.exp(z[mdl.slices[i].start]) for i in gm_idx]
        sub = parse_model("+".join(["GM"] * len(gm_idx)))

        def gm_avar(zz, m):
            th = np.concatenate([np.exp(zz[mdl.slices[i]]) for i in gm_idx])
            return sub.avar(th, m)

        names = ", ".join(f"{mdl.labels[i]} T_c {tc:.3g} s" for i, tc in zip(gm_idx, tcs))
        m_a = _m_grid(20.0 * max(tcs) / dt)
        b_gm = _reading("gm-max", f"B read from the GM hump's ADEV peak / 0.664 ({names})", gm_avar, z, cov, dt,
                        m_a, m_lo, m_hi, peak=True)
    b_min = _reading("min-avar", "min of the model's ADEV / 0.664", lambda zz, m: mdl.avar(np.exp(zz), m), z, cov, dt,
                     m_used, m_lo, m_hi, peak=False)
    b_flicker = None
    if "B_dph" in terms:
        t = terms["B_dph"]
        b_flicker = BiasInstability("flicker", t.value, t.lo95, t.hi95, None, None, "",
                                    f"flicker term ({t.component})")
    return IEEEResult(model=mdl.name, terms=terms, gm=gms, b_gm=b_gm, b_min=b_min, dt_s=dt, n_samples=n,
                      b_flicker=b_flicker, tau_range_s=tau_range)


def _m_range(m_lo: float, m_hi: float) -> np.ndarray:
    """Integer Allan factors from ``m_lo`` to ``m_hi`` (both included), about 40 per decade."""
    m_lo, m_hi = max(1.0, m_lo), max(1.0, m_hi)
    k = max(2, int(40 * math.log10(m_hi / m_lo)) + 2)
    return np.unique(np.concatenate([[m_lo], np.round(np.logspace(math.log10(m_lo), math.log10(m_hi), k)), [m_hi]]))


def _reading(rule, label, avar, z, cov, dt, m, m_lo, m_hi, *, peak) -> BiasInstability:
    """One B reading ``sqrt(extremum of avar(z, m)) / 0.6643`` under the rule that no value is read beyond the data.

    ``avar(z, m)`` is the AVAR [(deg/h)^2] at Allan factors ``m``; the extremum (max for ``peak``, else min) is
    searched on ``m``.  Inside ``[m_lo, m_hi]`` (and not at its end): a value with its delta-method interval.
    A minimum at an end of the fitted range: the model's ADEV there is still falling (rising), so the 95 %
    upper limit of ``ADEV(end) / 0.6643`` bounds B.  A peak outside the range: nothing.
    """
    tau_lo, tau_hi = m_lo * dt, m_hi * dt

    def at(mm):
        return lambda zz: math.sqrt(float(avar(zz, np.asarray([mm], dtype=np.float64))[0])) / B_ADEV_FACTOR

    a = np.asarray(avar(z, m), dtype=np.float64)
    k = int(np.argmax(a) if peak else np.argmin(a))
    mk = float(m[k])
    inside = m_lo * (1 - 1e-9) <= mk <= m_hi * (1 + 1e-9) and (peak or 0 < k < m.size - 1)
    if inside:
        def ext(zz):
            aa = np.asarray(avar(zz, m), dtype=np.float64)
            return math.sqrt(float(np.max(aa) if peak else np.min(aa))) / B_ADEV_FACTOR

        val, se = _delta(ext, z, cov)
        lo = val * _exp(-_Z95 * se) if math.isfinite(se) else 0.0
        hi = val * _exp(_Z95 * se) if math.isfinite(se) else float("inf")
        return BiasInstability(rule, float(val), float(lo), float(hi), mk * dt, None, "", label)
    if peak:
        where = "after the longest" if mk > m_hi else "before the shortest"
        return BiasInstability(rule, None, None, None, None, None,
                               f"the hump's ADEV peak, at τ = {mk * dt:.4g} s, lies {where} τ the fit used "
                               f"({tau_hi if mk > m_hi else tau_lo:.4g} s)", label)
    end = m_hi if k == m.size - 1 else m_lo
    val, se = _delta(at(end), z, cov)
    bound = val * _exp(_Z95 * se) if math.isfinite(se) else None
    bound = bound if bound is not None and math.isfinite(bound) else None  # no finite bound: nothing, not "B < inf"
    how = "still falls at the longest" if end == m_hi else "still rises from the shortest"
    reason = f"the model's ADEV {how} τ the fit used, {end * dt:.4g} s"
    if bound is None:
        return BiasInstability(rule, None, None, None, end * dt, None, reason, label)
    reason = f"95 % upper bound: {reason}"
    return BiasInstability(rule, None, None, None, end * dt, float(bound), reason, label)
