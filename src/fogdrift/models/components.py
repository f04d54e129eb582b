"""Noise fits -> state-space noise components: the one home of the mapping.

A fitted noise model becomes the list of components of :mod:`fogdrift.models.statespace` (IEEE-952 units:
N deg/sqrt(h), Q urad, K deg/h^1.5, Gauss-Markov T_c s and sigma deg/h, R deg/h^2), which the Kalman
compensator (:class:`fogdrift.models.kalman.Kalman`), the filter-consistency check
(:mod:`fogdrift.evaluation.consistency`) and the exports run:

* :func:`components_from_noise_fit`: an Allan noise fit (:class:`fogdrift.noise.NoiseFit`);
* :func:`components_from_gmwm`: a GMWM model (:class:`fogdrift.gmwm.ieee.IEEEResult`, or a
  :class:`fogdrift.gmwm.analysis.GmwmAxis` / selection holding one).

GMWM process -> component (the IEEE reading of :mod:`fogdrift.gmwm.ieee` is already in these units):

=========  ===========================================================================================
WN         white, ``arw_dprh = N``
QN         quantization, ``q_urad = Q``
RW         random walk, ``rrw_dphrh = K``
GM (each)  Gauss-Markov, ``tc_s = T_c``, ``sigma_dph = sigma_GM``
DR         ``ramp="state"``: a ramp with a random constant slope of 1-sigma R; ``ramp="random_walk"``: the
           random walk with the same Allan variance at the longest fitted tau, K^2/3 += R^2 tau_max / 2
           (in (deg/h)/sqrt(s) and (deg/h)/s; the rule of :func:`~fogdrift.models.statespace.components_from_allan`)
FLICKER    Gauss-Markov terms whose Allan variance is flat at 0.4413 B^2 over the fitted tau range
           (:func:`~fogdrift.models.statespace.flicker_as_gauss_markov`)
=========  ===========================================================================================
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ConfigError
from ..noise.processes import processes
from ..units import S_PER_H
from .statespace import check_components, components_from_allan, flicker_as_gauss_markov

__all__ = ["components_from_noise_fit", "components_from_gmwm", "gmwm_ieee"]


def components_from_noise_fit(noise) -> tuple[list[dict], list[str]]:
    """Noise components of an Allan noise fit (:class:`fogdrift.noise.NoiseFit`), and notes on what was left out.

    The power-law terms go through :func:`fogdrift.models.statespace.components_from_allan` (B as Gauss-Markov
    terms over the fitted tau range, a ramp as the random walk with its Allan variance at the longest tau); the
    Markov term M (when selected, with a correlation time) is one Gauss-Markov component; a periodic term S is
    left out (it integrates to a bounded angle Omega0 / (2 pi f), negligible beside the noise).

    Raises
    ------
    ConfigError
        The fit is not of the Allan variance (the coefficients are then no Allan-law A).
    """
    notes = []
    if noise.statistic != "adev":
        raise ConfigError(f"the consistency check needs an Allan-variance fit; this one is of {noise.statistic!r}")
    A = np.clip(np.asarray(noise.A, dtype=np.float64)[:5], 0.0, None)
    comps = components_from_allan(A, tau_range_s=(noise.tau_min_s, noise.tau_max_s))
    for p in processes():  # the shaped terms selected: each row's own components, or a note why none
        if p.power_law or p.name not in noise.selected:
            continue
        if p.to_components is not None:
            comps.extend(p.to_components((noise.shaped or {}).get(p.name) or {}, {}))
        else:
            notes.append("periodic term S left out (it integrates to a bounded angle)" if p.name == "S"
                         else f"{p.long_name} {p.name} left out (no state-space form)")
    if noise.no_fit:
        notes.append("no model fits this record's Allan curve: the components are the best candidate's")
    return check_components(comps), notes


def gmwm_ieee(ieee):
    """The IEEE reading inside a GMWM result: an ``IEEEResult`` itself, or ``.selection.ieee`` of an axis."""
    return getattr(getattr(ieee, "selection", None), "ieee", ieee)


def components_from_gmwm(ieee, *, ramp: str = "state") -> tuple[list[dict], list[str]]:
    """Noise components of a GMWM model's IEEE reading (:class:`fogdrift.gmwm.ieee.IEEEResult`, or a GMWM axis).

    WN -> white (N), QN -> quantization (Q), RW -> random walk (K), each GM -> a Gauss-Markov component (T_c,
    sigma), DR -> a ramp (see ``ramp``), FLICKER -> Gauss-Markov terms over the fitted tau range
    (:func:`fogdrift.models.statespace.flicker_as_gauss_markov`).

    Parameters
    ----------
    ieee : IEEEResult or GmwmAxis
        The reading (``terms`` keyed ``N_dprh``, ``Q_urad``, ``K_dphrh``, ``R_dph2``, ``B_dph``; ``gm`` with
        ``tc_s`` [s] and ``sigma_gm_dph`` [deg/h]; ``tau_range_s`` [s]).
    ramp : {"state", "random_walk"}
        ``"state"`` (default): DR is a ramp state with a random constant slope of 1-sigma R [deg/h^2].
        ``"random_walk"``: DR is folded into the random walk with the same Allan variance at the longest fitted
        tau, K_eff [deg/h^1.5] = 60 sqrt((K/60)^2 + 1.5 (R/3600)^2 tau_max) (the Kalman's rule, as for an
        Allan fit: a ramp seen in a training block rarely continues unchanged).

    Returns
    -------
    components : list of dict
    notes : list of str
        What was replaced, in words.

    Raises
    ------
    ConfigError
        A flicker or ramp-as-random-walk term with no finite fitted tau range; a bad ``ramp``.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> ie = NS(terms={"N_dprh": NS(value=0.1), "K_dphrh": NS(value=0.6), "R_dph2": NS(value=36.0)}, gm=[],
    ...         tau_range_s=(1.0, 1000.0))
    >>> [c["kind"] for c in components_from_gmwm(ie)[0]]
    ['white', 'random_walk', 'ramp']
    >>> comps, notes = components_from_gmwm(ie, ramp="random_walk")  # K^2 = 0.01^2 + 1.5 0.01^2 1000 (deg/h)^2/s
    >>> [(c["kind"], round(list(c.values())[1], 3)) for c in comps]
    [('white', 0.1), ('random_walk', 23.246)]
    """
    if ramp not in ("state", "random_walk"):
        raise ConfigError(f"ramp must be 'state' or 'random_walk'; got {ramp!r}")
    ie = gmwm_ieee(ieee)
    t = ie.terms
    comps, notes = [], []

    def tau_range(what):
        lo, hi = (float(x) for x in ie.tau_range_s)
        if not (0 < lo < hi and math.isfinite(hi)):
            raise ConfigError(f"the GMWM fit has a {what} term but no fitted tau range to replace it over")
        return lo, hi

    k_dphrh = float(t["K_dphrh"].value) if "K_dphrh" in t else None
    if "R_dph2" in t and ramp == "random_walk":
        r_dph2 = float(t["R_dph2"].value)
        k_s = math.sqrt((k_dphrh or 0.0) ** 2 / S_PER_H + 1.5 * (r_dph2 / S_PER_H) ** 2 * tau_range("ramp")[1])
        k_dphrh = 60.0 * k_s
        notes.append("ramp R folded into the random walk with its Allan variance at the longest fitted tau")
    if "N_dprh" in t:
        comps.append({"kind": "white", "arw_dprh": float(t["N_dprh"].value)})
    if "Q_urad" in t:
        comps.append({"kind": "quantization", "q_urad": float(t["Q_urad"].value)})
    if k_dphrh is not None:
        comps.append({"kind": "random_walk", "rrw_dphrh": k_dphrh})
    for g in ie.gm:
        comps.append({"kind": "gauss_markov", "tc_s": float(g["tc_s"].value),
                      "sigma_dph": float(g["sigma_gm_dph"].value)})
    if "R_dph2" in t and ramp == "state":
        comps.append({"kind": "ramp", "ramp_dph2": float(t["R_dph2"].value)})
    if "B_dph" in t:
        lo, hi = tau_range("flicker")
        comps.extend(flicker_as_gauss_markov(float(t["B_dph"].value), lo, hi))
        notes.append("flicker B replaced by Gauss-Markov terms over the fitted tau range")
    return check_components(comps), notes
