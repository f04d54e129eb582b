"""Flicker (1/f) rate noise: bias instability B.

Allan variance flat at ``(2 ln 2 / pi) B^2 = 0.4413 B^2`` for tau well above the sample interval (the minimum ADEV
is ``0.6643 B``; IEEE Std 952-1997 Annex C); IEEE-952 rate PSD ``(B^2 / 2 pi) / f``; per sample the discrete-time
process with two-sided SDF ``B^2 / (2 pi |f|)`` on ``|f| <= 1/2`` (cycles/sample), i.e. one-sided PSD
``B^2 / (pi f_hz)`` whatever the sample rate, so GMWM's ``b2`` is ``B^2``; Haar WV ``B^2 c(tau/2)``
(:func:`flicker_wv_factor`, flat ``(ln 2 / pi) B^2``).  Flicker noise is not Markov: a Kalman filter carries it as
Gauss-Markov terms whose summed Allan variance is flat at ``0.4413 B^2`` over the fitted tau range
(:func:`fogdrift.models.statespace.flicker_as_gauss_markov`).  SI B [rad/s] = B[deg/h] (pi/180) / 3600.

The B headline fogdrift prints is the IEEE reading min ADEV / 0.664 (:mod:`fogdrift.noise.readouts`); the fitted
flicker coefficient of this row is a labelled detail.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ...errors import ConfigError
from ...units import B_FACTOR, RAD_PER_DEG, S_PER_H, STANDARD_GRAVITY_MPS2
from .gauss_markov import gm_avar_dph2
from .base import IEEE_952, IEEE_1293, LatentSpec, NoiseProcess, TermLaw, TermSpec

__all__ = ["PROCESS", "flicker_wv_factor", "flicker_noise", "flicker_as_gauss_markov", "B_FLAT_WV"]

#: Flat Haar WV of flicker noise in units of B^2: ln2 / pi = (2 ln2 / pi) B^2 / 2 (half the flat Allan variance,
#: :data:`fogdrift.units.B_FACTOR` squared).
B_FLAT_WV = B_FACTOR**2 / 2.0

_LN2, _LN3 = math.log(2.0), math.log(3.0)

TERM = TermSpec("B", "bias instability", 0, B_FACTOR**2, "deg/h", "deg/h", "_dph", "B [deg/h]",
                1.0, -1, IEEE_952 + "; flat level (2 ln2/pi) B^2 for tau >> 1/f0, sigma_min = 0.6643 B")
ACCEL_TERM = TermSpec("B", "bias instability", 0, B_FACTOR**2, "m/s^2", "ug", "_ug", "B [µg]",
                      1.0 / (STANDARD_GRAVITY_MPS2 * 1e-6), -1,
                      IEEE_1293 + "; 1 ug = 9.80665e-6 m/s^2; flat level (2 ln2/pi) B^2, sigma_min = 0.6643 B")

LAWS = {
    "adev": TermLaw(0, (B_FACTOR**2,), exact=False,
                    source=TERM.source + "; asymptotic plateau of flicker rate noise"),
    "hdev": TermLaw(0, ((4.0 * _LN2 - 1.5 * _LN3) / math.pi,), exact=False,
                    source="derived: (8/3) h_-1 int sin^6 x / x^3 dx = (4 ln2 - 1.5 ln3) h_-1 with "
                    "h_-1 = B^2/pi (0.3580 B^2, 0.811 of AVAR); asymptotic plateau, checked by quadrature"),
    "mdev": TermLaw(0, ((27.0 / 8.0 * _LN3 - 4.0 * _LN2) / math.pi,), exact=False,
                    source="derived: 2 h_-1 int sin^6 x / x^5 dx = (27/8 ln3 - 4 ln2) h_-1 with "
                    "h_-1 = B^2/pi (0.2977 B^2, 0.675 of AVAR); asymptotic plateau (m -> inf), checked "
                    "by quadrature"),
}


# ----------------------------------------------------------------------------------------
# Flicker (1/f) WV factor
# ----------------------------------------------------------------------------------------
_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)
_K_EXACT = 64  # periods integrated exactly before the averaged tail


def _gl_panels(a: float, b: float, n: int):
    """Nodes and weights of n equal Gauss-Legendre(16) panels on [a, b]."""
    edges = np.linspace(a, b, n + 1)
    h = np.diff(edges)[:, None] / 2.0
    c = (edges[:-1] + edges[1:])[:, None] / 2.0
    return (c + h * _GL_X).ravel(), (h * _GL_W).ravel()


def _g_minus_third_over_v(v):
    """(1/sin^2(pi v) - 1/(pi v)^2 - 1/3) / v, stable near 0 (series below 0.05)."""
    x = np.pi * v
    with np.errstate(divide="ignore", invalid="ignore"):
        direct = (1.0 / np.sin(x) ** 2 - 1.0 / (x * x) - 1.0 / 3.0) / v
    series = np.pi * x * (1.0 / 15.0 + x * x * (2.0 / 189.0 + x * x / 675.0))
    return np.where(v < 0.05, series, direct)


@functools.lru_cache(maxsize=4096)
def _flicker_c(m: int) -> float:
    """c(m) = (1/pi) int_0^{1/2} sin^4(pi f m) / (m^2 sin^2(pi f) f) df (see flicker_wv_factor)."""
    def env(u):  # E(u) = 1 / (m^2 sin^2(pi u / m) u)
        return 1.0 / (m * m * np.sin(np.pi * u / m) ** 2 * u)

    if m <= 2 * _K_EXACT:
        half = m / 2.0
        n_full = int(math.floor(half))
        x, w = _gl_panels(0.0, float(n_full), max(n_full, 1)) if n_full else (np.empty(0), np.empty(0))
        if half > n_full:
            x2, w2 = _gl_panels(float(n_full), half, 1)
            x, w = np.concatenate([x, x2]), np.concatenate([w, w2])
        return float(np.dot(w, np.sin(np.pi * x) ** 4 * env(x))) / math.pi
    K = _K_EXACT
    x, w = _gl_panels(0.0, float(K), K)
    exact = float(np.dot(w, np.sin(np.pi * x) ** 4 * env(x)))
    a = K / m
    xv, wv = _gl_panels(a, 0.5, 4)
    smooth = float(np.dot(wv, _g_minus_third_over_v(xv)))
    tail = (0.375 / (m * m)) * ((m * m / (K * K) - 4.0) / (2.0 * math.pi**2)
                                 + math.log(m / (2.0 * K)) / 3.0 + smooth)
    return (exact + tail) / math.pi


def flicker_wv_factor(tau):
    """Haar WV of flicker noise per unit ``B^2``: ``nu2(tau) = B^2 c(tau/2)``.

    Flicker (bias-instability) noise is taken as the discrete-time process with two-sided
    SDF ``B^2 / (2 pi |f|)`` on ``|f| <= 1/2`` (cycles/sample), i.e. one-sided PSD
    ``B^2 / (pi f_hz)`` in (deg/h)^2/Hz whatever the sample rate, which is how
    :func:`fogdrift.simulate.simulate` generates it.  Then ([PW2000]_ eq. 296)::

        nu2(tau) = int |H(f)|^2 S(f) df = (B^2 / pi) int_0^{1/2} sin^4(pi f m) / (m^2 sin^2(pi f) f) df

    which converges without a low-frequency cutoff (the Haar filter removes the mean) and
    tends to the flat ``(ln 2 / pi) B^2 = 0.2206 B^2`` for large ``m``.  The integral is
    evaluated by Gauss-Legendre quadrature over whole periods of ``sin^4`` (all of them
    for ``m <= 128``; the first 64 periods plus the period-averaged tail, integrated in
    closed form up to a smooth remainder, beyond; error < 1e-9).

    Examples
    --------
    >>> [round(float(c), 5) for c in flicker_wv_factor([2, 4, 2**20])]
    [0.26233, 0.2402, 0.22064]
    """
    t = np.asarray(tau, dtype=np.float64)
    m = t / 2.0
    if np.any(m < 1) or np.any(m != np.round(m)):
        raise ConfigError("flicker WV needs even integer scales tau >= 2")
    flat = np.ravel(m)
    out = np.array([_flicker_c(int(v)) for v in flat])
    return out.reshape(t.shape)


def flicker_noise(n: int, b2: float, rng: np.random.Generator) -> np.ndarray:
    """Gaussian flicker noise, shape (n,), with two-sided SDF ``b2 / (2 pi |f|)`` per cycle/sample (one-sided
    PSD ``b2 / (pi f_hz)`` at any sample rate).

    White noise shaped in the frequency domain over ``4 n`` points (``2 n`` beyond 2^24) and truncated to ``n``,
    so frequencies down to ``1 / (4 T)`` are present and the circular wrap-around is far from the record; zero
    mean.  Its Allan variance is flat to within a few per cent from ``tau = 4 dt`` to ``T / 4`` (about +19 % at
    m = 1 and +9 % at m = 2, the discrete-time sampling of 1/f noise, which :func:`flicker_wv_factor` follows).
    """
    length = 4 * n if n <= 2**24 else 2 * n
    nf = length // 2 + 1
    f = np.arange(nf) / length
    scale = np.zeros(nf)
    # E|X_k|^2 = length * S(f_k) for the unnormalised DFT; split over real and imaginary parts
    scale[1:] = np.sqrt(length * b2 / (2.0 * np.pi * f[1:]) / 2.0)
    spec = (rng.standard_normal(nf) + 1j * rng.standard_normal(nf)) * scale
    if length % 2 == 0:  # the Nyquist bin is real; keep E|X|^2 equal to the interior rule
        spec[-1] = spec[-1].real * math.sqrt(2.0)
    return np.fft.irfft(spec, n=length)[:n]


def simulate(x, n, dt_s, rng):
    """Flicker rate noise of ``B = x`` [deg/h] (:func:`flicker_noise` with ``b2 = B^2``; independent of dt)."""
    return flicker_noise(n, x * x, rng)


def flicker_as_gauss_markov(b_dph: float, tau_min_s: float, tau_max_s: float, *, max_terms: int = 4) -> list[dict]:
    """Gauss-Markov terms whose summed Allan variance is flat at 0.4413 B^2 over ``[tau_min_s, tau_max_s]``.

    Correlation times are log-spaced from ``tau_min_s/1.893`` to ``tau_max_s/1.893`` (where each
    term's AVAR peaks), about one per decade and at most ``max_terms``; the variances are fitted by
    non-negative least squares in relative error on 40 log-spaced taus (method notes §9.7: terms one
    decade apart give an AVAR ripple of about +-4 %).

    Parameters
    ----------
    b_dph : float
        Bias instability B [deg/h] (flat ADEV 0.6643 B).
    tau_min_s, tau_max_s : float
        Tau range [s] over which the flat Allan variance is matched (e.g. the range of the fit
        that identified B); beyond ``tau_max_s`` the terms decay like white noise.
    max_terms : int
        Most terms kept.

    Returns
    -------
    list of dict
        ``{"kind": "gauss_markov", "tc_s": ..., "sigma_dph": ...}``; empty when ``b_dph`` is 0.

    Examples
    --------
    >>> gms = flicker_as_gauss_markov(1.0, 1.0, 1000.0)
    >>> tau = np.geomspace(3.0, 300.0, 9)
    >>> avar = sum(gm_avar_dph2(tau, g["tc_s"], g["sigma_dph"]) for g in gms)
    >>> bool(np.all(np.abs(avar / 0.4413 - 1) < 0.2))
    True
    """
    from scipy.optimize import nnls

    b = float(b_dph)
    lo, hi = float(tau_min_s), float(tau_max_s)
    if not (math.isfinite(b) and b >= 0):
        raise ConfigError(f"b_dph must be a finite number >= 0; got {b_dph!r}")
    if not (0 < lo < hi and math.isfinite(hi)):
        raise ConfigError(f"flicker tau range must satisfy 0 < tau_min_s < tau_max_s; got {tau_min_s!r}, {tau_max_s!r}")
    if b == 0:
        return []
    n_tc = max(1, min(int(max_terms), int(math.ceil(math.log10(hi / lo))) + 1))
    tcs = np.geomspace(lo / 1.893, hi / 1.893, n_tc)
    taus = np.geomspace(lo, hi, 40)
    design = np.column_stack([gm_avar_dph2(taus, t, 1.0) for t in tcs]) / (B_FACTOR**2 * b * b)
    var, _ = nnls(design, np.ones(taus.size))
    return [{"kind": "gauss_markov", "tc_s": float(t), "sigma_dph": float(math.sqrt(v))}
            for t, v in zip(tcs, var) if v > 0]


def to_components(A, ctx):
    """Flicker ``0.4413 B^2 = A`` -> Gauss-Markov components flat over the fitted tau range, from the white/flicker
    crossover ``A_white / A`` on where that is inside the range (below it white noise dominates)."""
    if not A > 0:
        return []
    lo, hi = (float(t) for t in ctx["tau_range_s"])
    a_white = ctx.get("A_white", 0.0)
    if a_white > 0:
        lo = max(lo, min(a_white / A, hi / 10.0))
    return flicker_as_gauss_markov(math.sqrt(A / B_FACTOR**2), lo, hi, max_terms=ctx.get("max_flicker_terms", 4))


LATENT = LatentSpec(
    "FLICKER", "flicker noise (bias instability)", ("b2",), ("rate^2",),
    wv=lambda th, tau: th[0] * flicker_wv_factor(tau),
    sdf=lambda th, f: th[0] / (2.0 * np.pi * np.abs(f)),
    ieee=lambda th, dt: {"B_dph": math.sqrt(th[0])},
    simulate=lambda th, n, rng: flicker_noise(n, th[0], rng), aliases=("BI",),
)

PROCESS = NoiseProcess(
    "B", "flicker", term=TERM, accel_term=ACCEL_TERM, laws=LAWS, latent=LATENT,
    psd=lambda x, f: float(x) ** 2 / (2.0 * math.pi * np.asarray(f, dtype=np.float64)),
    simulate=simulate, sim_kwarg="bias_instability_dph", sim_stream=2,
    to_components=to_components, component_rank=3,
    si={"gyro": ("rad/s", RAD_PER_DEG / S_PER_H), "accel": ("m/s^2", STANDARD_GRAVITY_MPS2 * 1e-6)},
    source=TERM.source,
)
