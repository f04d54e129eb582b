"""Synthetic gyro rate signals with known IEEE-952 noise terms.

Each term is drawn by its row's simulator (:mod:`fogdrift.noise.processes`, ``simulate``).  Every term is generated so that its Allan variance is the IEEE-952 law (method notes 2.2),
with sigma in deg/h and tau in s:

=====  =====================================  ==========================================
term   generated as                            Allan variance
=====  =====================================  ==========================================
Q      white *angle* noise q_k, std Q, rate    3 Q^2 / tau^2 (exact for every m >= 1;
       (q_{k+1} - q_k) / dt                    Q in (deg/h) s = arcsec)
N      white rate noise, std N / sqrt(dt)      N^2 / tau (N in (deg/h) sqrt(s) = 60 N[deg/sqrt h])
B      flicker (1/f) rate noise by FFT         2 ln2 / pi B^2 = 0.4413 B^2 (flat)
       shaping, one-sided PSD B^2/(pi f)
K      random walk of the rate, each sample    K^2 tau / 3 (exact: sample = interval
       the interval mean of Brownian motion    average of the continuous walk)
R      ramp R t                                R^2 tau^2 / 2 (exact)
=====  =====================================  ==========================================

plus a constant bias and, optionally, the Earth-rate projection for a latitude and axis.

The flicker term is white noise shaped in the frequency domain over ``4 * n_samples``
points (``2 *`` beyond 2^24 samples) and truncated to ``n_samples``, so frequencies down to
``1 / (4 T)`` are present and the circular wrap-around is far from the record; its Allan
variance is flat to within a few per cent from ``tau = 4 dt`` to ``T / 4`` (about +19 % at m = 1
and +9 % at m = 2, from the discrete-time sampling of 1/f noise).
"""

from __future__ import annotations

import math

import numpy as np

from ._util import check_count
from .errors import ConfigError
from .noise.processes import processes
from .units import B_FACTOR as B_FLAT_FACTOR  # the flat ADEV of flicker rate noise in units of B
from .units import URAD_PER_ARCSEC, check_dt_s, earth_rate_projection_dph

__all__ = ["simulate", "URAD_PER_ARCSEC", "B_FLAT_FACTOR"]


def _nonneg(name, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}") from None
    if not (v >= 0 and math.isfinite(v)):
        raise ConfigError(f"{name} must be a finite number >= 0, got {value!r}")
    return v


def simulate(
    n_samples,
    dt_s,
    *,
    q_urad=0.0,
    arw_dprh=0.0,
    bias_instability_dph=0.0,
    rrw_dphrh=0.0,
    ramp_dph2=0.0,
    bias_dph=0.0,
    latitude_deg=None,
    axis="up",
    seed,
    **more,
) -> np.ndarray:
    """Simulate a static gyro's rate output in deg/h.

    Parameters
    ----------
    n_samples : int
        Number of rate samples (>= 2).
    dt_s : float
        Sample interval in s.
    q_urad : float, keyword-only
        Quantization (white angle) noise Q in microradians.
    arw_dprh : float, keyword-only
        Angle random walk N in deg/sqrt(h).
    bias_instability_dph : float, keyword-only
        Bias instability B in deg/h (flat Allan deviation 0.664 B).
    rrw_dphrh : float, keyword-only
        Rate random walk K in deg/h^1.5 (deg/h/sqrt(h)).
    ramp_dph2 : float, keyword-only
        Rate ramp R in deg/h^2.
    bias_dph : float, keyword-only
        Constant bias in deg/h (any sign).
    latitude_deg : float or None, keyword-only
        If given, add the Earth-rate component sensed by ``axis`` at this latitude
        (:func:`fogdrift.units.earth_rate_projection_dph`).
    axis : str or sequence of 3 floats, keyword-only
        Sensitive-axis orientation for the Earth-rate projection (``"up"``, ``"north"``, ...
        or an east-north-up vector).
    seed : int or numpy.random.Generator, keyword-only, required
        Seed.  Each noise term draws from its own child stream (``SeedSequence.spawn``), so
        switching one term on or off leaves the others' realisations unchanged.
    **more : float, keyword-only
        The coefficient of a registered process (:func:`fogdrift.noise.processes.register`), by its row's
        ``sim_kwarg``, in its term's reported unit.

    Returns
    -------
    ndarray, shape (n_samples,)
        Rate in deg/h.

    Raises
    ------
    ConfigError
        Negative or non-finite coefficients, bad ``n_samples``/``dt_s``/``seed``/axis.

    Notes
    -----
    Conversions to the mixed units of the Allan law (sigma in deg/h, tau in s), IEEE Std
    952-1997 Annex C / method notes 2.3: Q[(deg/h) s] = Q[urad] / 4.848137,
    N[(deg/h) sqrt(s)] = 60 N[deg/sqrt(h)], K[(deg/h)/sqrt(s)] = K[deg/h^1.5] / 60,
    R[(deg/h)/s] = R[deg/h^2] / 3600.  The random-walk term uses the exact interval average
    of Brownian motion, ``y_k = (W_k + W_{k+1})/2 + e_k``, ``Var e_k = K^2 dt / 12``, so its
    Allan variance is ``K^2 tau / 3`` at every m.

    Examples
    --------
    >>> y = simulate(1000, 0.1, arw_dprh=0.01, bias_dph=2.0, seed=1)
    >>> y.shape, round(float(y.mean()), 1)
    ((1000,), 2.0)
    """
    n = check_count(n_samples)
    dt = check_dt_s(dt_s)
    given = {"q_urad": q_urad, "arw_dprh": arw_dprh, "bias_instability_dph": bias_instability_dph,
             "rrw_dphrh": rrw_dphrh, "ramp_dph2": ramp_dph2}
    known = {p.sim_kwarg for p in processes() if p.sim_kwarg and p.simulate is not None}
    unknown = sorted(set(more) - known)
    if unknown:
        raise ConfigError(f"simulate() got unknown term keyword(s) {unknown}; expected {sorted(known)}")
    given.update(more)
    rows = [p for p in processes() if p.sim_kwarg in given]
    # each term's coefficient in the Allan-law units of its row (Q (deg/h) s, N (deg/h) sqrt(s), B deg/h, ...)
    x = {p.name: _nonneg(p.sim_kwarg, given[p.sim_kwarg]) / p.term.to_unit for p in rows}
    try:
        bias = float(bias_dph)
    except (TypeError, ValueError):
        raise ConfigError(f"bias_dph must be a finite number, got {bias_dph!r}") from None
    if not math.isfinite(bias):
        raise ConfigError(f"bias_dph must be a finite number, got {bias_dph!r}")
    n_streams = max([4] + [p.sim_stream + 1 for p in rows if p.sim_stream is not None])
    if isinstance(seed, np.random.Generator):
        streams = seed.spawn(n_streams)
    else:
        try:
            streams = [np.random.default_rng(s) for s in np.random.SeedSequence(seed).spawn(n_streams)]
        except (TypeError, ValueError):
            raise ConfigError(f"seed must be a non-negative int or a numpy Generator, got {seed!r}") from None

    y = np.full(n, bias, dtype=np.float64)
    if latitude_deg is not None:
        y += earth_rate_projection_dph(latitude_deg, axis)
    for p in rows:  # each row's simulator, on its own child stream
        if x[p.name] > 0:
            y += p.simulate(x[p.name], n, dt, None if p.sim_stream is None else streams[p.sim_stream])
    return y
