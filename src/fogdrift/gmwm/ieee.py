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

Bias instability from GMs, both rules of [GMWM]_ §4, each with the averaging time where it
occurs: (a) ``B = sqrt(max_T AVAR_GMsum(T)) / 0.6643`` (the GM bump read as a flicker
plateau; only GMs that are the largest component at one or more fitted scales and whose WV
peak, at scale ``3.785 T_c``, is at least twice the first scale used: a faster or buried GM
is short-scale structure such as an output filter, not a flat region), and (b) the classical reading ``B = sqrt(min_T AVAR_total(T)) / 0.6643`` (biased
up where WN/RW overlap).  A value is *flagged* when its T exceeds ``N dt / 4`` (the curve
is extrapolated there).  Rule (b) is searched over ``T <= N dt / 2``; rule (a) wherever the
GM peak is.

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

from .processes import PROCESSES, parse_model

__all__ = ["IEEEValue", "BiasInstability", "IEEEResult", "to_ieee", "B_ADEV_FACTOR"]

#: Flat Allan deviation of flicker noise in units of B: sqrt(2 ln2 / pi).
B_ADEV_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)
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
        ``"gm-max"`` (rule a) or ``"min-avar"`` (rule b).
    value_dph, lo95_dph, hi95_dph : float
        B in deg/h with its 95 % interval.
    tau_s : float
        Averaging time where the max/min occurs.
    flagged : bool
        True when ``tau_s > N dt / 4`` (extrapolated beyond the reliable part of the record).
    note : str
    """

    rule: str
    value_dph: float
    lo95_dph: float
    hi95_dph: float
    tau_s: float
    flagged: bool
    note: str

    def to_dict(self) -> dict:
        return {k: (float(v) if isinstance(v, (float, np.floating)) else v) for k, v in self.__dict__.items()}


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
        Rule (a), only with GMs.
    b_min : BiasInstability
        Rule (b).
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

    def to_dict(self) -> dict:
        return {
            "model": self.model,
            "terms": {k: v.to_dict() for k, v in self.terms.items()},
            "gm": [{k: (v.to_dict() if isinstance(v, IEEEValue) else v) for k, v in g.items()} for g in self.gm],
            "b_gm": None if self.b_gm is None else self.b_gm.to_dict(),
            "b_min": self.b_min.to_dict(),
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


def _value(name, fun, z, cov, component) -> IEEEValue:
    v, se = _delta(fun, z, cov)
    lo = v * math.exp(-_Z95 * se) if math.isfinite(se) else 0.0
    hi = v * math.exp(_Z95 * se) if math.isfinite(se) else float("inf")
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

    # rule (a) uses the GMs resolved by the scales: WV peak (scale 3.785 T_c) at least twice the
    # first scale; a faster GM is short-scale structure (e.g. an output filter), not bias instability
    # and that are the largest component at one or more of the fitted scales (a GM buried under
    # the WN everywhere does not make a flat region)
    scales = np.asarray(fit.tau_samples, dtype=np.float64)
    dominant = set(np.argmax(mdl.wv_components(np.exp(z), scales), axis=0).tolist())
    first_scale = float(fit.scale_s[0])
    gm_idx = [i for i, k in enumerate(mdl.components)
              if k == "GM" and i in dominant and 3.785 * dt / math.exp(z[mdl.slices[i].start]) >= 2.0 * first_scale]
    b_gm = None
    if gm_idx:
        tcs = [dt / math.exp(z[mdl.slices[i].start]) for i in gm_idx]
        m_a = _m_grid(20.0 * max(tcs) / dt)
        sub = parse_model("+".join(["GM"] * len(gm_idx)))

        def gm_avar(zz):
            th = np.concatenate([np.exp(zz[mdl.slices[i]]) for i in gm_idx])
            return sub.avar(th, m_a)

        def b_a(zz):
            return math.sqrt(float(np.max(gm_avar(zz)))) / B_ADEV_FACTOR

        val, se = _delta(b_a, z, cov)
        tau_a = float(m_a[int(np.argmax(gm_avar(z)))] * dt)
        flagged = tau_a > n * dt / 4.0
        b_gm = BiasInstability(
            "gm-max", float(val), float(val * math.exp(-_Z95 * se)) if math.isfinite(se) else 0.0,
            float(val * math.exp(_Z95 * se)) if math.isfinite(se) else float("inf"), tau_a, bool(flagged),
            "sqrt(max AVAR of the GM sum)/0.6643" + (" at T > N dt/4: extrapolated" if flagged else ""),
        )
    m_b = _m_grid(max(n // 2, 2))

    def total_avar(zz):
        return mdl.avar(np.exp(zz), m_b)

    def b_b(zz):
        return math.sqrt(float(np.min(total_avar(zz)))) / B_ADEV_FACTOR

    val, se = _delta(b_b, z, cov)
    tau_b = float(m_b[int(np.argmin(total_avar(z)))] * dt)
    flagged = tau_b > n * dt / 4.0
    edge = tau_b >= m_b[-1] * dt * 0.999
    note = "sqrt(min implied total AVAR)/0.6643 (classical reading, biased up by WN/RW overlap)"
    if edge:
        note += ("; the minimum is at the longest T searched (N dt/2), beyond the reliable N dt/4: the "
                 "implied AVAR still falls there, so this is an extrapolated upper bound at best")
    elif flagged:
        note += "; at T > N dt/4: extrapolated"
    b_min = BiasInstability(
        "min-avar", float(val), float(val * math.exp(-_Z95 * se)) if math.isfinite(se) else 0.0,
        float(val * math.exp(_Z95 * se)) if math.isfinite(se) else float("inf"), tau_b, bool(flagged), note,
    )
    return IEEEResult(model=mdl.name, terms=terms, gm=gms, b_gm=b_gm, b_min=b_min, dt_s=dt, n_samples=n)
