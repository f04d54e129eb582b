"""Simulate sums of the latent processes of :mod:`fogdrift.gmwm.processes` (per-sample definitions).

Each component is drawn by its row's simulator (:mod:`fogdrift.noise.processes`, ``latent.simulate``).  Each component draws from its own child stream of ``numpy.random.SeedSequence(seed)``, so
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

import numpy as np

from .._util import check_count
from ..errors import ConfigError
from .processes import PROCESSES, parse_model

__all__ = ["simulate_latent"]


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
        sim = PROCESSES[key].simulate
        if sim is None:
            raise ConfigError(f"process {key} has no simulator (its row in fogdrift.noise.processes gives none)")
        x += sim(th[sl], n, rng)
    return x
