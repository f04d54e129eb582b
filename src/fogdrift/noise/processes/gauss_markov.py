"""First-order Gauss-Markov (exponentially correlated) rate noise: the Markov term M of IEEE Std 952 Annex C.6.

Allan variance ``(q_c T_c)^2 / tau [1 - T_c/(2 tau) (3 - 4 e^(-tau/T_c) + e^(-2 tau/T_c))]`` (:func:`markov_shape`;
a hump: like a rate random walk ``q_c^2 tau / 3`` below ``T_c`` and like white noise above), stationary 1-sigma
``sigma = q_c sqrt(T_c / 2)``; IEEE-952 rate PSD ``(q_c T_c)^2 / (1 + (2 pi f T_c)^2)``; per sample the AR(1)
``x_t = phi x_{t-1} + e_t``, ``phi = exp(-beta)``, ``beta = dt / T_c``, Haar WV :func:`ar1_wv` (stable form); one
Gauss-Markov state in a Kalman filter (``phi``, ``Var w = sigma^2 (1 - phi^2)``); SI sigma [rad/s] and q_c
[rad/s/sqrt(s)].  GMWM carries bias instability as one to three of these ([GMWM] notes §4).
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import ConfigError
from ...units import RAD_PER_DEG, S_PER_H
from ..covariance import expected_variance
from .base import ComponentSpec, LatentSpec, NoiseProcess

__all__ = ["PROCESS", "ar1_wv", "markov_shape", "gm_avar_dph2"]

SHAPED = {"long_name": "exponentially correlated (first-order Gauss-Markov) noise", "unit": "deg/h/sqrt(s)",
          "sigma_unit": "deg/h", "tc_unit": "s",
          "source": "IEEE Std 952-1997 Annex C.6 (exponentially correlated noise): sigma^2 = (q_c T_c)^2 / tau "
                    "[1 - T_c/(2 tau) (3 - 4 exp(-tau/T_c) + exp(-2 tau/T_c))]; sigma = q_c sqrt(T_c/2)"}

_STATISTICS = ("adev", "hdev", "mdev")


# ----------------------------------------------------------------------------------------
def ar1_wv(beta, sigma2, tau):
    """Haar WV of an AR(1) with ``phi = exp(-beta)`` and innovation variance ``sigma2``.

    Parameters
    ----------
    beta : float or ndarray
        ``-ln phi`` (> 0), per sample.
    sigma2 : float or ndarray
        Innovation variance (rate^2).
    tau : array_like
        Haar scales in samples (even integers >= 2).

    Returns
    -------
    ndarray
        ``nu2(tau)`` in rate^2, broadcast over the inputs.

    Notes
    -----
    The textbook form ``sigma2 [m(1-phi^2) - 3phi + 4phi^(m+1) - phi^(2m+1)] /
    [2 m^2 (1-phi)^2 (1-phi^2)]`` loses all digits when ``1 - phi`` is small ([GMWM]_ §2,
    "numerical trap").  With ``u = -expm1(-beta) = 1 - phi`` and ``v = -expm1(-m beta)``::

        nu2 / sigma2 = [m u (2-u) - (1-u) v (2+v)] / [2 m^2 u^3 (2-u)]

    and for ``m beta < 1e-3`` the series ``(2m^2+1)/(12m) - beta (3m^3-4m^2-2)/(24m)
    + beta^2 (m-1)(7m^3-8m^2-3m-3)/(120m)``.  Relative error below 1e-9 over
    ``beta = 1e-7..50`` and ``tau = 2..2^24`` (tested against 50-digit decimal arithmetic).

    Examples
    --------
    >>> [round(float(v), 10) for v in ar1_wv(-math.log(0.9), 1.0, [2, 8, 64, 1024])]
    [0.2631578947, 0.5680840625, 0.9001211711, 0.0949458072]
    """
    m = np.asarray(tau, dtype=np.float64) / 2.0
    if np.ndim(beta) == 0 and np.ndim(sigma2) == 0:  # fast path: one process, many scales
        b = float(beta)
        u = -math.expm1(-b)
        mb = m * b
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            v = -np.expm1(-mb)
            out = (m * u * (2.0 - u) - (1.0 - u) * v * (2.0 + v)) / (2.0 * m * m * u**3 * (2.0 - u))
        small = mb < 1e-3
        if np.any(small):
            ms = m[small] if np.ndim(m) else m
            ser = _ar1_series(ms, b)
            if np.ndim(out):
                out[small] = ser
            else:
                out = ser
        return float(sigma2) * out
    beta = np.asarray(beta, dtype=np.float64)
    sigma2 = np.asarray(sigma2, dtype=np.float64)
    beta, sigma2, m = np.broadcast_arrays(beta, sigma2, m)
    mb = m * beta
    u = -np.expm1(-beta)
    v = -np.expm1(-mb)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        closed = (m * u * (2.0 - u) - (1.0 - u) * v * (2.0 + v)) / (2.0 * m * m * u**3 * (2.0 - u))
    return sigma2 * np.where(mb < 1e-3, _ar1_series(m, beta), closed)


def _ar1_series(m, beta):
    """Small-(m beta) expansion of the AR(1) WV per unit innovation variance ([GMWM]_ §2)."""
    return ((2.0 * m * m + 1.0) / (12.0 * m)
            - beta * (3.0 * m**3 - 4.0 * m * m - 2.0) / (24.0 * m)
            + beta * beta * (m - 1.0) * (7.0 * m**3 - 8.0 * m * m - 3.0 * m - 3.0) / (120.0 * m))




def markov_shape(tau_s, tc_s, statistic="adev", dt_s=None) -> np.ndarray:
    """Variance shape of first-order Gauss-Markov rate noise with correlation time ``tc_s`` [s]: ``A = (q_c T_c)^2``
    [(deg/h)^2 s] multiplies it (IEEE-952 Annex C.6).

    ``adev``: the Annex C law ``1/tau [1 - T_c/(2 tau) (3 - 4 e^(-tau/T_c) + e^(-2 tau/T_c))]`` (-> ``tau / (3 T_c^2)``,
    i.e. ``q_c^2 tau / 3``, for ``tau << T_c``, like a rate random walk of ``K = q_c``, and ``1/tau`` for ``tau >> T_c``, like white noise).  ``hdev`` and
    ``mdev``: not derived in closed form; the expectation of the estimator under the exact spectrum of the sampled
    process (an AR(1) with ``phi = exp(-dt/T_c)``, :func:`fogdrift.noise.covariance.expected_variance`), which needs
    ``dt_s``.
    """
    t = np.asarray(tau_s, dtype=np.float64)
    tc = float(tc_s)
    if statistic == "adev":
        x = t / tc
        with np.errstate(over="ignore", invalid="ignore"):
            small = x < 1e-3  # series: (1/tau) (x^2/3 - x^3/4 + ...) avoids the cancellation
            big = (1.0 - (3.0 - 4.0 * np.exp(-x) + np.exp(-2.0 * x)) / (2.0 * x)) / t
            ser = (x * x / 3.0 - x**3 / 4.0) / t
        return np.where(small, ser, big)
    if statistic not in _STATISTICS:
        raise ConfigError(f"no Gauss-Markov law for statistic {statistic!r}; expected one of {_STATISTICS}")
    if dt_s is None:
        raise ConfigError("the Gauss-Markov law of hdev/mdev needs the sample interval dt_s")

    dt = float(dt_s)
    phi = math.exp(-dt / tc)
    s2 = 1.0 / (2.0 * tc)  # process variance per unit A: A = (q_c T_c)^2 = 2 sigma^2 T_c

    def spec(f):
        return s2 * (1.0 - phi * phi) / (1.0 - 2.0 * phi * np.cos(2.0 * np.pi * np.asarray(f)) + phi * phi)

    return expected_variance(np.rint(t / dt), spec, statistic=statistic, per_octave=32)


def gm_avar_dph2(tau_s, tc_s: float, sigma_dph: float) -> np.ndarray:
    """Allan variance [(deg/h)^2] of a first-order Gauss-Markov rate with correlation time ``tc_s`` and 1-sigma.

    AVAR(tau) = sigma^2 (T/tau)^2 (2x - 3 + 4 e^-x - e^-2x), x = tau/T (continuous-time process;
    IEEE Std 952 Annex C, method notes §9.4); maximum 0.3811 sigma^2 at tau = 1.893 T.  A series in
    x is used for x < 1e-2 (the closed form cancels catastrophically there).

    Examples
    --------
    >>> round(float(gm_avar_dph2(1.893, 1.0, 1.0)), 4)
    0.3811
    """
    x = np.asarray(tau_s, dtype=np.float64) / float(tc_s)
    small = x < 1e-2
    xs = np.where(small, 1.0, x)
    closed = (2.0 * xs - 3.0 + 4.0 * np.exp(-xs) - np.exp(-2.0 * xs)) / xs**2
    series = (2.0 / 3.0) * x - 0.5 * x**2 + (7.0 / 30.0) * x**3
    return float(sigma_dph) ** 2 * np.where(small, series, closed)


def _gm_ieee(th, dt):
    beta, s2 = th
    u = -math.expm1(-beta)
    return {"tc_s": dt / beta, "sigma_gm_dph": math.sqrt(s2 / (u * (2.0 - u)))}


def _gm_sdf(th, f):
    beta, s2 = th
    u = -math.expm1(-beta)
    return s2 / (u * u + 4.0 * (1.0 - u) * np.sin(np.pi * f) ** 2)


def _latent_simulate(theta, n, rng):
    from scipy.signal import lfilter

    beta, s2 = theta
    phi = math.exp(-beta)
    u = -math.expm1(-beta)
    e = math.sqrt(s2) * rng.standard_normal(n)
    x0 = math.sqrt(s2 / (u * (2.0 - u))) * rng.standard_normal()
    e[0] = x0
    return lfilter([1.0], [1.0, -phi], e)


def _densities(c, out):
    out["gms"].append((c["tc_s"], c["sigma_dph"]))


def to_components(fit, ctx):
    """A fitted Markov term (``{"tc_s", "sigma_dph"}``) -> one ``gauss_markov`` component."""
    if fit and fit.get("tc_s") and fit.get("sigma_dph"):
        return [{"kind": "gauss_markov", "tc_s": float(fit["tc_s"]), "sigma_dph": float(fit["sigma_dph"])}]
    return []


LATENT = LatentSpec(
    "GM", "Gauss-Markov / AR(1)", ("beta", "sigma2"), ("1/sample", "rate^2"),
    wv=lambda th, tau: ar1_wv(th[0], th[1], tau),
    sdf=_gm_sdf, ieee=_gm_ieee, simulate=_latent_simulate, aliases=("AR1", "AR(1)", "GAUSSMARKOV"),
)

PROCESS = NoiseProcess(
    "M", "gauss_markov", shaped=SHAPED, shape=markov_shape, latent=LATENT,
    psd=lambda qc_tc, f, tc_s: float(qc_tc) ** 2 / (1.0 + (2.0 * math.pi * np.asarray(f) * float(tc_s)) ** 2),
    component=ComponentSpec("gauss_markov", ("tc_s", "sigma_dph"),
                            "first-order Gauss-Markov state: correlation time [s], 1-sigma [deg/h]", _densities),
    to_components=to_components, component_rank=5,
    si={"gyro": ("rad/s", RAD_PER_DEG / S_PER_H), "accel": ("m/s^2", 1.0)},
    source=SHAPED["source"],
)
