"""Filter-ready state-space model of a channel: the continuous-time model and its exact discretisation (Van Loan).

The noise components are built by :mod:`fogdrift.models.statespace` (``components_from_allan`` for Q, N, B, K, R,
with B replaced by Gauss-Markov terms by ``flicker_as_gauss_markov``; GMWM / Markov Gauss-Markov terms appended),
so the exported model is the one fogdrift's own Kalman filter runs.  Those functions are linear in the rate unit:
a gyro channel's components are in deg/h (statespace's own units), an accelerometer channel's in m/s^2 in place
of deg/h.  The matrices are returned in SI (rad/s or m/s^2).

Continuous time, states x = [bias, random walk, GM_1..GM_m, ramp, ramp slope] (those present)::

    dx/dt = F x + w,  E[w w^T] = Qc delta(t)     y = H x + v,  v white of density N (plus quantization)

with F = 0 except F_gm = -1/T_c and F[ramp, slope] = 1; Qc_rw = K^2, Qc_gm = 2 sigma^2 / T_c.  Discretised at
dt = 1/rate exactly by Van Loan's method (C. F. Van Loan, "Computing integrals involving the matrix exponential",
IEEE Trans. Autom. Control 23(3):395-404, 1978): expm([[-F, Qc], [0, F^T]] dt) = [[., Phi^-1 Qd], [0, Phi^T]].
The measurement variance per sample is r = N^2 / dt + 2 Q^2 / dt^2 (quantization as white noise, as
:func:`fogdrift.models.statespace.state_space`).  The result is checked against statespace's closed forms
(``check_max_abs``).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ConfigError
from ..models.statespace import check_components, component_densities, components_from_allan, state_space
from ..noise.terms import TERM_TABLE, TERMS
from ..units import RAD_PER_DEG, S_PER_H, URAD_PER_ARCSEC
from .model import ChannelModel

__all__ = ["van_loan", "channel_components", "continuous_model", "discrete_model", "COMPONENT_RATE_UNIT"]

#: Rate unit of a channel's statespace components, and its value in SI.
COMPONENT_RATE_UNIT = {"gyro": ("deg/h", RAD_PER_DEG / S_PER_H), "accel": ("m/s^2", 1.0)}


def van_loan(F, Qc, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact discretisation of dx/dt = F x + w (E[w w^T] = Qc delta) over ``dt_s``: (Phi, Qd).

    Phi = e^(F dt), Qd = integral_0^dt e^(F s) Qc e^(F^T s) ds, from one matrix exponential (Van Loan 1978).

    Examples
    --------
    Scalar Gauss-Markov, T_c = 2 s, sigma = 3 (Qc = 2 sigma^2 / T_c): Phi = e^(-dt/T_c), Qd = sigma^2 (1 - Phi^2).

    >>> phi, qd = van_loan([[-0.5]], [[9.0]], 1.0)
    >>> round(float(phi[0, 0]), 8), round(float(qd[0, 0]), 8), round(9 * (1 - math.exp(-1.0)), 8)
    (0.60653066, 5.68908503, 5.68908503)
    """
    from scipy.linalg import expm

    F = np.atleast_2d(np.asarray(F, dtype=np.float64))
    Qc = np.atleast_2d(np.asarray(Qc, dtype=np.float64))
    n = F.shape[0]
    if F.shape != (n, n) or Qc.shape != (n, n):
        raise ConfigError(f"F and Qc must be square and of one size; got {F.shape} and {Qc.shape}")
    dt = float(dt_s)
    if not (math.isfinite(dt) and dt > 0):
        raise ConfigError(f"dt_s must be a finite number > 0; got {dt_s!r}")
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n] = -F
    M[:n, n:] = Qc
    M[n:, n:] = F.T
    E = expm(M * dt)
    phi = E[n:, n:].T
    qd = phi @ E[:n, n:]
    return phi, 0.5 * (qd + qd.T)


def channel_components(ch: ChannelModel, *, max_flicker_terms: int = 4) -> tuple[list, list]:
    """statespace components of ``ch`` (rate unit :data:`COMPONENT_RATE_UNIT`), and the terms left out with why.

    Only terms with an estimate enter (when no model fits the record, the best candidate's values, flagged by the
    caller); a term not in the selected model is listed in the second return value with its reason and bound.
    """
    unit, scale = COMPONENT_RATE_UNIT[ch.quantity]
    A = np.zeros(5)
    used, left = [], []
    for i, name in enumerate(TERMS):
        t = ch.terms.get(name)
        if t is None:
            continue
        if (t.has_estimate or (ch.no_fit and t.value is not None)) and t.si:
            x = t.si / scale
            A[i] = TERM_TABLE[name].avar_coefficient * x * x     # the Allan law c X^2 of the term table
            used.append(name)
        else:
            left.append({"term": name, "reason": t.reason or "not in the selected model",
                         "hi95": t.hi95, "unit": t.unit})
    lo, hi = ch.tau_range_s
    if not (lo and hi and math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
        lo, hi = 1.0 / ch.rate_hz, 1e4
    comps = components_from_allan(A, tau_range_s=(lo, hi), terms=tuple(used), ramp="state",
                                  max_flicker_terms=max_flicker_terms) if used else []
    for g in ch.gms:
        comps.append({"kind": "gauss_markov", "tc_s": g.tc_s, "sigma_dph": g.sigma_si / scale})
    return check_components(comps), left


def continuous_model(components, scale: float) -> dict:
    """Continuous-time matrices of a component list (order and names as :func:`fogdrift.models.statespace.state_space`).

    Returns ``F``, ``Qc`` (SI rate unit^2 / s), ``H``, ``names``, ``white_density`` (N, SI), ``quantization``
    (Q, SI rate unit x s).
    """
    d = component_densities(components)
    names = ["bias"]
    qc = [0.0]
    fdiag = [0.0]
    white2, quant2, ramps = d["white2"], d["quant2"], d["ramps"]
    if d["random_walk"]:
        names.append("random_walk")
        qc.append(d["rw2"])
        fdiag.append(0.0)
    for tc, sigma in d["gms"]:
        names.append(f"gm_{tc:.4g}s")
        qc.append(2.0 * sigma**2 / tc)
        fdiag.append(-1.0 / tc)
    n = len(names) + (2 if ramps else 0)
    F = np.zeros((n, n))
    Qc = np.zeros((n, n))
    H = np.ones(n)
    for i, (f, q) in enumerate(zip(fdiag, qc)):
        F[i, i] = f
        Qc[i, i] = q
    if ramps:
        names += ["ramp", "ramp_slope"]
        F[n - 2, n - 1] = 1.0
        H[n - 1] = 0.0
    s2 = scale * scale
    return {"names": names, "F": F, "Qc": Qc * s2, "H": H, "white_density": math.sqrt(white2) * scale,
            "quantization": math.sqrt(quant2) * scale,
            "ramp_slope_sigma": math.sqrt(float(np.sum(np.square(ramps)))) * scale if ramps else 0.0}


def discrete_model(ch: ChannelModel, rate_hz: float) -> dict:
    """The channel's continuous model and its exact discretisation at ``rate_hz``, JSON-ready (SI units).

    Includes ``check_max_abs``: the largest difference between the Van Loan (Phi, Qd, r) and the closed forms of
    :func:`fogdrift.models.statespace.state_space` (round-off when both hold).
    """
    comps, left = channel_components(ch)
    unit, scale = COMPONENT_RATE_UNIT[ch.quantity]
    si_rate = "rad/s" if ch.quantity == "gyro" else "m/s^2"
    dt = 1.0 / float(rate_hz)
    cm = continuous_model(comps, scale)
    phi, qd = van_loan(cm["F"], cm["Qc"], dt)
    r = cm["white_density"] ** 2 / dt + 2.0 * cm["quantization"] ** 2 / dt ** 2
    check = None
    if any(c["kind"] in ("white", "quantization") for c in comps):
        ss = state_space(comps, dt_s=dt, bias_prior_dph=1.0)
        s2 = scale * scale
        check = float(max(np.max(np.abs(ss.F - phi)), np.max(np.abs(ss.Q * s2 - qd)) / max(np.max(np.abs(qd)), 1e-300),
                          abs(ss.r * s2 - r) / max(r, 1e-300)))
    terms_si = []
    for c in comps:
        k = c["kind"]
        if k == "white":
            terms_si.append({"kind": k, "density": 60.0 * c["arw_dprh"] * scale, "unit": f"{si_rate}/sqrt(Hz)"})
        elif k == "quantization":
            terms_si.append({"kind": k, "q": c["q_urad"] / URAD_PER_ARCSEC * scale,
                             "unit": "rad" if ch.quantity == "gyro" else "m/s"})
        elif k == "random_walk":
            terms_si.append({"kind": k, "density": c["rrw_dphrh"] / 60.0 * scale, "unit": f"{si_rate}/s/sqrt(Hz)"})
        elif k == "gauss_markov":
            terms_si.append({"kind": k, "sigma": c["sigma_dph"] * scale, "unit": si_rate, "tc_s": c["tc_s"]})
        else:
            terms_si.append({"kind": k, "slope_sigma": c["ramp_dph2"] / S_PER_H * scale, "unit": f"{si_rate}/s"})
    return {
        "rate_unit": si_rate,
        "continuous_terms": terms_si,
        "components": comps,
        "components_rate_unit": unit,
        "components_note": ("statespace components (fogdrift.models.statespace) in "
                            + ("its own units (deg/h)" if unit == "deg/h" else
                               "m/s^2 in place of deg/h (its formulas are linear in the rate unit)")),
        "terms_left_out": left,
        "continuous": {"states": cm["names"], "F": cm["F"].tolist(), "Qc": cm["Qc"].tolist(),
                       "Qc_unit": f"({si_rate})^2/s", "H": cm["H"].tolist(),
                       "white_density": cm["white_density"], "white_density_unit": f"{si_rate}/sqrt(Hz)",
                       "quantization": cm["quantization"],
                       "quantization_unit": "rad" if ch.quantity == "gyro" else "m/s",
                       "ramp_slope_sigma": cm["ramp_slope_sigma"], "ramp_slope_unit": f"{si_rate}/s"},
        "discrete": {"rate_hz": float(rate_hz), "dt_s": dt, "states": cm["names"], "Phi": phi.tolist(),
                     "Qd": qd.tolist(), "Qd_unit": f"({si_rate})^2", "H": cm["H"].tolist(), "r": r,
                     "r_unit": f"({si_rate})^2",
                     "method": "Van Loan (1978): expm([[-F, Qc], [0, F^T]] dt); r = N^2/dt + 2 Q^2/dt^2"},
        "check_max_abs": check,
        "check_note": "largest |difference| (Phi absolute, Qd and r relative) from statespace.state_space's closed forms",
    }
