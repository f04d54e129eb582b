"""Rate random walk K (gyro), acceleration random walk (accelerometer).

Allan variance ``K^2 tau / 3`` (K in (deg/h)/sqrt(s) = K[deg/h^1.5] / 60); IEEE-952 rate PSD ``(K / 2 pi)^2 / f^2``;
simulated as the exact interval average of Brownian motion, so the law holds at every m; per sample
``x_t = x_{t-1} + e_t``, ``Var e = gamma2 = K^2 dt``, Haar WV ``gamma2 (tau^2 + 2) / (12 tau)``; one random-walk
state in a Kalman filter, ``Var w = K^2 dt``; SI density K [rad/s^2/sqrt(Hz)] = K[deg/h^1.5] (pi/180) / 216000.
Claimed only from a sustained +1/2 slope (:func:`fogdrift.noise.rules.slope_claim`): a hump is a Markov term.
"""

from __future__ import annotations

import math

import numpy as np

from ...units import RAD_PER_DEG, S_PER_H
from .base import (IEEE_952, IEEE_1293, SIM_EXACT, SQRT_H, ComponentSpec, LatentSpec, NoiseProcess, TermLaw,
                   TermSpec)

TERM = TermSpec("K", "rate random walk", 1, 1.0 / 3.0, "(deg/h)/sqrt(s)", "deg/h^1.5", "_dphrh",
                "K [deg/h^1.5]", 60.0, -2, IEEE_952 + "; 1/sqrt(s) = 60/sqrt(h)")
ACCEL_TERM = TermSpec("K", "acceleration random walk", 1, 1.0 / 3.0, "(m/s^2)/sqrt(s)", "m/s^2/sqrt(h)",
                      "_mps2_rh", "K [m/s²/√h]", 60.0, -2,
                      IEEE_1293 + "; 1/sqrt(s) = 60/sqrt(h) (= 1/3600 of the m/s/h^1.5 figure)")

LAWS = {
    "adev": TermLaw(1, (1.0 / 3.0,), source=TERM.source + "; " + SIM_EXACT),
    "hdev": TermLaw(1, (1.0 / 6.0,), source="derived: cluster means of Brownian rate, "
                    "E(ybar3 - 2 ybar2 + ybar1)^2 = K^2 tau, divided by 6 (half the AVAR law); " + SIM_EXACT),
    "mdev": TermLaw(1, (11.0 / 40.0, 1.0 / 24.0, 1.0 / 60.0), source="derived: Brownian rate, "
                    "K^2 tau (11/40 + (dt/tau)^2/24 + (dt/tau)^4/60) (1/3 at m = 1, 33/40 of AVAR as "
                    "m -> inf); " + SIM_EXACT),
}


def simulate(x, n, dt_s, rng):
    """Rate random walk of ``K = x`` [(deg/h)/sqrt(s)]: ``y_k = (W_k + W_{k+1})/2 + e_k``, ``Var e = K^2 dt / 12``
    (the exact interval mean of Brownian motion, so the Allan variance is ``K^2 tau / 3`` at every m)."""
    w = np.empty(n + 1)
    w[0] = 0.0
    np.cumsum(rng.standard_normal(n), out=w[1:])
    w *= x * math.sqrt(dt_s)
    y = 0.5 * (w[:-1] + w[1:])
    y += (x * math.sqrt(dt_s / 12.0)) * rng.standard_normal(n)
    return y


def _latent_simulate(theta, n, rng):
    return np.cumsum(math.sqrt(theta[0]) * rng.standard_normal(n))


def _densities(c, out):
    out["random_walk"] = True
    out["rw2"] += (c["rrw_dphrh"] / SQRT_H) ** 2


def to_components(A, ctx):
    """Rate random walk ``K^2 / 3 = A`` -> one ``random_walk`` component [deg/h^1.5]."""
    return [{"kind": "random_walk", "rrw_dphrh": SQRT_H * math.sqrt(3.0 * A)}] if A > 0 else []


LATENT = LatentSpec(
    "RW", "random walk (rate random walk)", ("gamma2",), ("rate^2",),
    wv=lambda th, tau: th[0] * (np.asarray(tau, dtype=np.float64) ** 2 + 2.0)
    / (12.0 * np.asarray(tau, dtype=np.float64)),
    sdf=lambda th, f: th[0] / (4.0 * np.sin(np.pi * f) ** 2),
    ieee=lambda th, dt: {"K_dphrh": math.sqrt(th[0] / dt) * SQRT_H},
    simulate=_latent_simulate, aliases=("RRW",),
)

PROCESS = NoiseProcess(
    "K", "random_walk", term=TERM, accel_term=ACCEL_TERM, laws=LAWS, latent=LATENT,
    psd=lambda x, f: (float(x) / (2.0 * math.pi)) ** 2 / np.asarray(f, dtype=np.float64) ** 2,
    simulate=simulate, sim_kwarg="rrw_dphrh", sim_stream=3,
    component=ComponentSpec("random_walk", ("rrw_dphrh",), "rate random walk K [deg/h^1.5], one random-walk state",
                            _densities),
    to_components=to_components, component_rank=2,
    si={"gyro": ("rad/s^2/sqrt(Hz)", RAD_PER_DEG / S_PER_H**1.5), "accel": ("m/s^3/sqrt(Hz)", 1.0 / 60.0)},
    slope_rule=True, source=TERM.source,
)
