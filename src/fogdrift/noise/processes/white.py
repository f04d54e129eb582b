"""White rate noise: angle random walk N (gyro), velocity random walk (accelerometer).

Allan variance ``N^2 / tau`` (N in (deg/h) sqrt(s) = 60 N[deg/sqrt(h)]); one-sided rate PSD ``N^2`` [(deg/h)^2/Hz];
per sample ``x_t = e_t``, ``Var e = sigma2 = N^2 / dt``, Haar WV ``sigma2 / tau``; a Kalman measurement noise
``Var v = N^2 / dt``; SI density N [rad/s/sqrt(Hz)] = N[deg/sqrt(h)] (pi/180) / 60 (IEEE Std 952-1997 Annex C).
"""

from __future__ import annotations

import math

import numpy as np

from ...units import RAD_PER_DEG
from .base import (IEEE_952, IEEE_1293, SIM_EXACT, SQRT_H, ComponentSpec, LatentSpec, NoiseProcess, TermLaw,
                   TermSpec)

TERM = TermSpec("N", "angle random walk", -1, 1.0, "(deg/h) sqrt(s)", "deg/sqrt(h)", "_dprh", "N [deg/√h]",
                1.0 / 60.0, 0, IEEE_952 + "; sqrt(s) = sqrt(h)/60")
ACCEL_TERM = TermSpec("N", "velocity random walk", -1, 1.0, "(m/s^2) sqrt(s)", "m/s/sqrt(h)", "_mps_rh",
                      "N [m/s/√h]", 60.0, 0, IEEE_1293 + "; m/s/sqrt(s) = 60 m/s/sqrt(h) (sqrt(h) = 60 sqrt(s))")

LAWS = {
    "adev": TermLaw(-1, (1.0,), source=TERM.source + "; " + SIM_EXACT),
    "hdev": TermLaw(-1, (1.0,), source="derived: the second difference of white-rate cluster means has "
                    "variance 6 N^2/tau, divided by 6 (the normalisation of SP 1065 eq. 17); " + SIM_EXACT),
    "mdev": TermLaw(-1, (0.5, 0.5), source="derived: triangular weights with sum of squares m^3 + m give "
                    "N^2/(2 tau) (1 + dt^2/tau^2); " + SIM_EXACT),
}


def simulate(x, n, dt_s, rng):
    """White rate noise of ``N = x`` [(deg/h) sqrt(s)]: std ``x / sqrt(dt)`` per sample."""
    return (x / math.sqrt(dt_s)) * rng.standard_normal(n)


def _latent_simulate(theta, n, rng):
    return math.sqrt(theta[0]) * rng.standard_normal(n)


def _densities(c, out):
    out["white2"] += (SQRT_H * c["arw_dprh"]) ** 2


def to_components(A, ctx):
    """White noise ``N^2 = A`` -> one ``white`` component [deg/sqrt(h)]."""
    return [{"kind": "white", "arw_dprh": math.sqrt(A) / SQRT_H}] if A > 0 else []


LATENT = LatentSpec(
    "WN", "white noise (angle random walk)", ("sigma2",), ("rate^2",),
    wv=lambda th, tau: th[0] / np.asarray(tau, dtype=np.float64),
    sdf=lambda th, f: np.full(np.shape(f), th[0]),
    ieee=lambda th, dt: {"N_dprh": math.sqrt(th[0] * dt) / SQRT_H},
    simulate=_latent_simulate, aliases=("ARW",),
)

PROCESS = NoiseProcess(
    "N", "white", term=TERM, accel_term=ACCEL_TERM, laws=LAWS, latent=LATENT,
    psd=lambda x, f: np.full(np.shape(f), float(x) ** 2),
    simulate=simulate, sim_kwarg="arw_dprh", sim_stream=1,
    component=ComponentSpec("white", ("arw_dprh",),
                            "white rate noise (angle random walk N [deg/sqrt(h)]), measurement noise", _densities),
    to_components=to_components, component_rank=0,
    si={"gyro": ("rad/s/sqrt(Hz)", RAD_PER_DEG / 60.0), "accel": ("m/s^2/sqrt(Hz)", 1.0 / 60.0)},
    source=TERM.source,
)
