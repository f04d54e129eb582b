"""Simulate sums of the latent processes of :mod:`fogdrift.gmwm.processes` (per-sample definitions).

Each component draws from its own child stream of ``numpy.random.SeedSequence(seed)``, so
the realisation of one component does not depend on the others.  Definitions ([GMWM]_ §2):

* QN: ``x_t = sqrt(12 q2) (U_t - U_{t-1})``, ``U ~ U(0, 1)`` (``n + 1`` uniforms).
* WN: ``x_t = sqrt(sigma2) e_t``.
* RW: ``x_t = x_{t-1} + sqrt(gamma2) e_t``, ``x_0 = sqrt(gamma2) e_0``.
* DR: ``x_t = omega t``, ``t = 0..n-1``.
* GM (AR(1)): ``x_t = phi x_{t-1} + sqrt(sigma2) e_t``, ``phi = exp(-beta)``, with ``x_0``
  drawn from the stationary law ``N(0, sigma2 / (1 - phi^2))``.
* FLICKER: Gaussian noise with two-sided SDF ``b2 / (2 pi |f|)`` synthesised in the
  frequency domain on ``4 n`` points (``2 n`` beyond 2^24) and truncated to ``n``
  (zero mean, frequencies below ``1/(4 n)`` absent; the Haar WV does not see them).

References
----------
.. [GMWM] fogdrift GMWM method notes, ``shared/docs/gmwm-notes.md`` §2.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.signal import lfilter

from .._util import check_count
from ..errors import ConfigError
from .processes import parse_model

__all__ = ["simulate_latent"]


def _flicker(n: int, b2: float, rng: np.random.Generator) -> np.ndarray:
    length = 4 * n if n <= 2**24 else 2 * n
    nf = length // 2 + 1
    f = np.arange(nf) / length
    scale = np.zeros(nf)
    # E|X_k|^2 = length * S(f_k) for the unnormalised DFT; split over real and imaginary parts
    scale[1:] = np.sqrt(length * b2 / (2.0 * np.pi * f[1:]) / 2.0)
    spec = (rng.standard_normal(nf) + 1j * rng.standard_normal(nf)) * scale
    if length % 2 == 0:
        spec[-1] = spec[-1].real * math.sqrt(2.0)
    return np.fft.irfft(spec, n=length)[:n]


def simulate_latent(model, theta, n_samples, *, seed) -> np.ndarray:
    """Simulate ``n_samples`` of a latent model (rate, same unit as ``theta``'s variances).

    Parameters
    ----------
    model : str or LatentModel
        E.g. ``"WN+RW+GM"``.
    theta : array_like
        Natural parameters in the model's order (:attr:`LatentModel.param_names`).
    n_samples : int
        Length (>= 2).
    seed : int or numpy.random.SeedSequence, keyword-only
        Seed (required).

    Returns
    -------
    ndarray, shape (n_samples,)

    Examples
    --------
    >>> x = simulate_latent("WN+GM", [1.0, 0.01, 1e-3], 10_000, seed=1)
    >>> x.shape
    (10000,)
    """
    mdl = parse_model(model)
    th = np.asarray(theta, dtype=np.float64)
    if th.shape != (mdl.n_params,) or not np.all(np.isfinite(th)) or np.any(th <= 0):
        raise ConfigError(f"theta must be {mdl.n_params} finite values > 0 {mdl.param_names}, got {theta!r}")
    n = check_count(n_samples)
    try:
        ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    except (TypeError, ValueError):
        raise ConfigError(f"seed must be a non-negative int or a SeedSequence, got {seed!r}") from None
    rngs = [np.random.default_rng(s) for s in ss.spawn(len(mdl.components))]
    x = np.zeros(n)
    for key, sl, rng in zip(mdl.components, mdl.slices, rngs):
        p = th[sl]
        if key == "WN":
            x += math.sqrt(p[0]) * rng.standard_normal(n)
        elif key == "QN":
            u = rng.random(n + 1)
            x += math.sqrt(12.0 * p[0]) * np.diff(u)
        elif key == "RW":
            x += np.cumsum(math.sqrt(p[0]) * rng.standard_normal(n))
        elif key == "DR":
            x += p[0] * np.arange(n, dtype=np.float64)
        elif key == "FLICKER":
            x += _flicker(n, p[0], rng)
        elif key == "GM":
            beta, s2 = p
            phi = math.exp(-beta)
            u = -math.expm1(-beta)
            e = math.sqrt(s2) * rng.standard_normal(n)
            x0 = math.sqrt(s2 / (u * (2.0 - u))) * rng.standard_normal()
            e[0] = x0
            x += lfilter([1.0], [1.0, -phi], e)
    return x
