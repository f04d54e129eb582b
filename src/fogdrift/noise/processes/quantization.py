"""Quantization noise: white angle (velocity) noise Q.

Allan variance ``3 Q^2 / tau^2`` (Q in (deg/h) s = arcsec = 4.848137 urad; IEEE Std 952-1997 Annex C, whose paper
form of the Q law the reference paper misprints); rate PSD ``(2 pi f)^2 Q^2 dt`` below Nyquist; per sample the
rounding difference ``x_t = q (U_t - U_{t-1}) sqrt(12)``, Haar WV ``6 q2 / tau^2`` (``q2 = Q^2`` in (deg/h)^2 per
sample); in a Kalman filter white measurement noise ``2 Q^2 / dt^2``; SI Q [rad] = Q[urad] 1e-6.
"""

from __future__ import annotations

import math

import numpy as np

from ...units import URAD_PER_ARCSEC
from .base import IEEE_952, IEEE_1293, SIM_EXACT, ComponentSpec, LatentSpec, NoiseProcess, TermLaw, TermSpec

TERM = TermSpec("Q", "quantization", -2, 3.0, "(deg/h) s = arcsec", "urad", "_urad", "Q [µrad]",
                URAD_PER_ARCSEC, 2, IEEE_952 + "; 1 (deg/h) s = 1 arcsec = 4.848137 urad")
ACCEL_TERM = TermSpec("Q", "velocity quantization", -2, 3.0, "(m/s^2) s = m/s", "m/s", "_mps", "Q [m/s]",
                      1.0, 2, IEEE_1293 + "; (m/s^2) s = m/s")

LAWS = {
    "adev": TermLaw(-2, (3.0,), source=TERM.source + "; " + SIM_EXACT),
    "hdev": TermLaw(-2, (10.0 / 3.0,), source="derived: the third difference of white angle noise has "
                    "variance (1+9+9+1) Q^2, divided by 6 tau^2; " + SIM_EXACT),
    "mdev": TermLaw(-3, (3.0,), dt_power=1, source="derived: the three m-point window sums of white "
                    "angle noise are disjoint, variance 6 m Q^2, so 3 Q^2 dt/tau^3; " + SIM_EXACT),
}


def simulate(x, n, dt_s, rng):
    """Quantization noise of ``Q = x`` [(deg/h) s]: the rate of white angle noise of std ``x``."""
    angle = rng.standard_normal(n + 1)
    return (x / dt_s) * np.diff(angle)


def _latent_simulate(theta, n, rng):
    u = rng.random(n + 1)
    return math.sqrt(12.0 * theta[0]) * np.diff(u)


def _densities(c, out):
    out["quant2"] += (c["q_urad"] / URAD_PER_ARCSEC) ** 2


def to_components(A, ctx):
    """Quantization ``3 Q^2 = A`` -> one ``quantization`` component [urad]."""
    return [{"kind": "quantization", "q_urad": math.sqrt(A / 3.0) * URAD_PER_ARCSEC}] if A > 0 else []


def _psd(x, f, dt_s=None):
    """IEEE-952 rate PSD of quantization, ``(2 pi f)^2 Q^2 dt`` (needs the sample interval)."""
    return (2.0 * math.pi * np.asarray(f, dtype=np.float64)) ** 2 * float(x) ** 2 * float(dt_s)


LATENT = LatentSpec(
    "QN", "quantization noise", ("q2",), ("rate^2",),
    wv=lambda th, tau: 6.0 * th[0] / np.asarray(tau, dtype=np.float64) ** 2,
    sdf=lambda th, f: 4.0 * th[0] * np.sin(np.pi * f) ** 2,
    ieee=lambda th, dt: {"Q_arcsec": math.sqrt(th[0]) * dt,
                         "Q_urad": math.sqrt(th[0]) * dt * 1e6 * math.pi / 648000.0},
    excess_kurtosis=-1.2, simulate=_latent_simulate,
)

PROCESS = NoiseProcess(
    "Q", "quantization", term=TERM, accel_term=ACCEL_TERM, laws=LAWS, latent=LATENT, psd=_psd,
    simulate=simulate, sim_kwarg="q_urad", sim_stream=0,
    component=ComponentSpec("quantization", ("q_urad",),
                            "quantization noise Q [urad], treated as white measurement noise", _densities),
    to_components=to_components, component_rank=1,
    si={"gyro": ("rad", 1e-6), "accel": ("m/s", 1.0)},
    source=TERM.source,
)
