"""The model-discrepancy allowance: how far a real sensor's curve may depart from a sum of textbook terms.

A real gyro never follows a sum of IEEE-952 power laws (or of GMWM latent processes) to the sampling error of a
long record: at 10^6 samples the overlapping ADEV of the short taus has 10^4-10^5 degrees of freedom, so its 95 %
interval is +-0.5-1 %, while the sensor's own shape (an electronics filter edge, a temperature-dependent scale,
a slightly coloured "white" noise) departs from the textbook sum by a few per cent.  Judged against the sampling
error alone, every long clean log is "no model fits" -- a verdict no metrologist would sign.

Both estimators (the Allan fit, :mod:`fogdrift.noise.identify`, and GMWM, :mod:`fogdrift.gmwm`) therefore add one
stated allowance to the covariance of their curve estimates: a relative error of :data:`MODEL_DISCREPANCY_DEV`
(1 sigma) on the *deviation* at every tau, i.e. ``2 delta`` on the variance, correlated between taus as
``exp(-|log2(tau_i / tau_j)| / L)`` with ``L`` = :data:`DISCREPANCY_OCTAVES` (a shape error is smooth: it does
not average out over neighbouring taus).  The allowance enters the fit statistic, the model checks and the
profile intervals alike, so a model that follows a long clean curve within a few per cent is a fit, and its
intervals include the allowance.  A gross misfit (a hump read as a slope, a missing term) is still many times
the allowance and is still refused.

The same numbers serve both estimators: Allan-family variances and Haar wavelet variances are relative
quantities here, and ``tau`` is the averaging time or the Haar scale (any consistent unit; only ratios enter).
"""

from __future__ import annotations

import numpy as np

__all__ = ["MODEL_DISCREPANCY_DEV", "DISCREPANCY_OCTAVES", "discrepancy_relcov"]

#: Allowed relative departure (1 sigma) of a real sensor's deviation (ADEV, or the square root of the wavelet
#: variance) from the fitted model at any tau: 2 % (a 95 % band of about +-4 % in deviation).
MODEL_DISCREPANCY_DEV = 0.02

#: Correlation length of the allowance, in octaves of tau: neighbouring taus share most of a shape error.
DISCREPANCY_OCTAVES = 1.0


def discrepancy_relcov(tau, dev_rel=MODEL_DISCREPANCY_DEV, octaves=DISCREPANCY_OCTAVES) -> np.ndarray:
    """Relative covariance of the variance estimates added by the model-discrepancy allowance.

    ``C_ij = (2 dev_rel)^2 exp(-|log2(tau_i / tau_j)| / octaves)``: the relative error of a variance is twice
    that of its deviation.  Multiply by ``outer(mu, mu)`` (``mu`` the model's variances) for an absolute
    covariance.

    Parameters
    ----------
    tau : array_like, shape (n,)
        Averaging times or Haar scales (positive; any unit, only ratios enter).
    dev_rel : float
        Relative 1-sigma allowance on the deviation (default :data:`MODEL_DISCREPANCY_DEV`).
    octaves : float
        Correlation length in octaves of tau (default :data:`DISCREPANCY_OCTAVES`).

    Returns
    -------
    ndarray, shape (n, n)

    Examples
    --------
    >>> np.round(discrepancy_relcov([1.0, 2.0, 8.0]), 6).tolist()
    [[0.0016, 0.000589, 8e-05], [0.000589, 0.0016, 0.000217], [8e-05, 0.000217, 0.0016]]
    """
    lt = np.log2(np.asarray(tau, dtype=np.float64))
    if dev_rel <= 0:
        return np.zeros((lt.size, lt.size))
    return (2.0 * dev_rel) ** 2 * np.exp(-np.abs(lt[:, None] - lt[None, :]) / float(octaves))
