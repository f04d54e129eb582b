"""Rate ramp R (gyro), acceleration ramp (accelerometer): a deterministic drift of the rate.

Allan variance ``R^2 tau^2 / 2`` (R in (deg/h)/s = R[deg/h^2] / 3600; IEEE Std 952-1997 Annex C, exact); the
Hadamard variance cancels it exactly; per sample ``x_t = omega t``, Haar WV ``omega^2 tau^2 / 16``; in a Kalman
filter a ramp state with a random constant slope of 1-sigma R, or (the default for a model identified from a
finite record) the random walk with the same Allan variance at the longest fitted tau; SI R [rad/s^2].
Claimed only from a sustained +1 slope (:func:`fogdrift.noise.rules.slope_claim`).
"""

from __future__ import annotations

import math

import numpy as np

from ...units import RAD_PER_DEG, S_PER_H
from .base import IEEE_952, IEEE_1293, ComponentSpec, LatentSpec, NoiseProcess, TermLaw, TermSpec

TERM = TermSpec("R", "rate ramp", 2, 0.5, "(deg/h)/s", "deg/h^2", "_dph2", "R [deg/h²]",
                S_PER_H, None, IEEE_952 + "; 1/s = 3600/h")
ACCEL_TERM = TermSpec("R", "acceleration ramp", 2, 0.5, "(m/s^2)/s", "m/s^2/h", "_mps2_ph", "R [m/s²/h]",
                      S_PER_H, None, IEEE_1293 + "; 1/s = 3600/h")

LAWS = {
    "adev": TermLaw(2, (0.5,), source=TERM.source + "; exact for fogdrift.simulate signals"),
    "mdev": TermLaw(2, (0.5,), source="derived: the second difference of a quadratic angle is constant, "
                    "so R^2 tau^2/2 as for AVAR; exact"),
}
UNESTIMABLE = {"hdev": "the Hadamard variance cancels a linear rate drift exactly (the third difference of a "
                       "quadratic angle is zero), so it carries no information on the rate ramp R"}


def simulate(x, n, dt_s, rng):
    """The ramp ``R t`` with ``R = x`` [(deg/h)/s], sampled at the interval centres."""
    return x * dt_s * (np.arange(n) + 0.5)


def _latent_simulate(theta, n, rng):
    return theta[0] * np.arange(n, dtype=np.float64)


def _densities(c, out):
    out["ramps"].append(c["ramp_dph2"] / S_PER_H)


def to_components(A, ctx):
    """Rate ramp ``R^2 / 2 = A`` -> one ``ramp`` component [deg/h^2] (used with ``ramp="state"``)."""
    return [{"kind": "ramp", "ramp_dph2": S_PER_H * math.sqrt(2.0 * A)}] if A > 0 else []


LATENT = LatentSpec(
    "DR", "drift (rate ramp)", ("omega",), ("rate per sample",),
    wv=lambda th, tau: th[0] ** 2 * np.asarray(tau, dtype=np.float64) ** 2 / 16.0,
    sdf=None,
    ieee=lambda th, dt: {"R_dph2": th[0] / dt * S_PER_H},
    simulate=_latent_simulate, aliases=("RAMP",),
)

PROCESS = NoiseProcess(
    "R", "ramp", term=TERM, accel_term=ACCEL_TERM, laws=LAWS, unestimable=UNESTIMABLE, latent=LATENT,
    simulate=simulate, sim_kwarg="ramp_dph2", sim_stream=None,
    component=ComponentSpec("ramp", ("ramp_dph2",),
                            "rate ramp R [deg/h^2]: a ramp state with a random constant slope of 1-sigma R",
                            _densities),
    to_components=to_components, component_rank=4,
    si={"gyro": ("rad/s^2", RAD_PER_DEG / S_PER_H ** 2), "accel": ("m/s^3", 1.0 / S_PER_H)},
    slope_rule=True, source=TERM.source,
)
