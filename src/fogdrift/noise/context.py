"""The data of one IEEE-952 fit (:func:`fogdrift.noise.identify`): working points, the statistic's laws, the design
columns, the per-point limits -- shared by the identification, its checks, its claims and its words, and by the
record planner (:mod:`fogdrift.plan.analytic`), which fits the expected curve of a model the same way.
"""

from __future__ import annotations

import math

import numpy as np

from ..allan.ci import edf_simple_safe
from .covariance import estimator_covariance, expected_variance, finite_record_covariance, ramp_cross_variance
from .discrepancy import discrepancy_relcov
from .distributions import chi2_ppf
from .processes import model_sdf
from .terms import TERM_TABLE, all_terms, laws_of, markov_shape, periodic_shape, power_terms

__all__ = ["FitContext", "point_limits", "flicker_shape"]

_names = all_terms  # the fit's columns: Q N B K R (then any registered power-law term), S, M


def point_limits(y, nu) -> np.ndarray:
    """Each point's ~4-sigma upper limit ``y nu / chi2_nu(3.17e-5)`` (the 4-sigma lower quantile of chi2_nu / nu);
    inf where nu << 1 (the quantile is 0: the point bounds nothing)."""
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return y * nu / chi2_ppf(3.17e-5, nu)


class FitContext:
    """Data of one fit: working points, the statistic's laws, sample interval, record length."""

    def __init__(self, tau, m, y, y_hi, n, dt, statistic, names, inflation=None, strides=None, lines=(),
                 tc_s=None):
        self.tau, self.m, self.y, self.y_hi = tau, m, y, y_hi
        self.inflation = np.ones(tau.size) if inflation is None else inflation
        self.strides = np.ones(tau.size) if strides is None else strides
        self.n, self.dt, self.statistic = n, dt, statistic
        self.laws = laws_of(statistic)
        self.names = names  # allowed terms, in the order of the fit's columns
        self.cols = tuple(_names().index(t) for t in names)
        # design column of each term (the law's tau shape; its constant is part of the fitted A)
        self.X = np.stack([self.laws[t].shape(tau, dt) if t in self.laws else np.zeros_like(tau) for t in power_terms()]
                          + [np.zeros_like(tau), np.zeros_like(tau)], axis=1)
        self.lines = tuple(lines)  # [(freq_hz, relative power)] of the periodic error (S), from the spectrum
        self.tc_s = None
        if self.lines:
            self.X[:, _names().index("S")] = periodic_shape(tau, self.lines, dt, statistic)
        if tc_s is not None:
            self.set_tc(tc_s)
        if "B" in self.laws:  # flicker: the sampled process is not flat at small m (+19 % at m = 1 for ADEV)
            self.X[:, _names().index("B")] *= flicker_shape(m, statistic)
        self.upper = self._upper()

    def set_tc(self, tc_s):
        """Set the Gauss-Markov correlation time [s] of the M column (the column of the shape at ``tc_s``)."""
        self.tc_s = float(tc_s)
        self.X[:, _names().index("M")] = markov_shape(self.tau, self.tc_s, self.statistic, self.dt)

    def _upper(self, C=None):
        """Largest coefficient of each term that keeps it, alone, below every point's ~4-sigma upper bound.

        With the model's relative covariance ``C`` the bound of a point is ``y nu / chi2_nu(3.2e-5)`` (the
        4-sigma lower quantile of chi2_nu / nu); before a model exists, the measured 95 % interval stretched to
        ~4 sigma.  A curve's EDF from its local slope can be badly off at a sharp turn, so the model's is used
        as soon as there is one.
        """
        if C is None:
            ub_pt = self.y * (self.y_hi / self.y) ** (4.0 / 1.96)
        else:
            ub_pt = point_limits(self.y, 2.0 / np.diag(C))
        out = np.array([np.min(ub_pt / self.X[:, i]) if np.all(self.X[:, i] > 0) else 0.0 for i in range(len(power_terms()))])
        # a shaped column can vanish at single taus (S at multiples of its period): bound it where it is non-zero
        shaped = [np.min(ub_pt[self.X[:, i] > 0] / self.X[self.X[:, i] > 0, i]) if np.any(self.X[:, i] > 0) else 0.0
                  for i in range(len(power_terms()), len(_names()))]
        return np.concatenate([out, shaped])

    def sub(self, start):
        c = FitContext.__new__(FitContext)
        c.__dict__.update(self.__dict__)
        for k in ("tau", "m", "y", "y_hi", "X", "inflation", "strides"):
            setattr(c, k, getattr(self, k)[start:])
        c.X = c.X.copy()  # its M column is set per correlation time: never share it with another context
        c.upper = c._upper()
        return c

    def x2(self, A):
        """Squared coefficient of each term in its Allan-law unit, from the law coefficients ``A``."""
        return {t: max(A[_names().index(t)], 0.0) / self.laws[t].scale(self.dt) for t in self.laws}

    def relcov(self, A, exact_ramp=False, allowance=True, finite_record=False):
        """Relative covariance of the working points under the model ``A`` (its spectrum, this statistic).

        ``finite_record=True`` (overlapping Allan variance only): the estimators' covariance summed exactly over
        the record's terms (:func:`~fogdrift.noise.covariance.finite_record_covariance`) instead of the large-``M``
        integral the fit itself uses; the planner's simulated records take it, since where ``m`` is a sizeable
        fraction of ``N`` the integral overstates the long taus' scatter and their correlation.

        A deterministic rate ramp has no spectrum.  For model *selection* (``exact_ramp=False``) it is given the
        variance of a rate random walk with the same Allan variance at the longest tau -- conservative, so that a
        spurious ramp in the full model cannot make the long-tau scatter look significant; for the final fit of a
        model that holds a ramp (``exact_ramp=True``) its real, much smaller effect is used
        (:func:`~fogdrift.noise.covariance.ramp_cross_variance`), which keeps the ramp estimate unbiased.
        """
        x2 = self.x2(A)
        a_allan = [TERM_TABLE[t].avar_coefficient * x2.get(t, 0.0) for t in power_terms()]
        mu = self.X @ A
        if not exact_ramp and a_allan[4] > 0:
            extra = 1.5 * a_allan[4] * float(self.tau[-1])
            a_allan[3] += extra
            if "K" in self.laws:
                # relative to the stand-in random walk's own mean: the stand-in lends the ramp its *relative*
                # scatter; dividing its variance by the (much smaller, short-tau) ramp mean instead made every
                # estimate look like ~0.1 EDF, so that any model -- even 10^5 x the data -- "fitted"
                # (the mean of the spectrum actually used: the ramp's own part replaced by the stand-in's)
                ir = _names().index("R")
                mu = mu - self.X[:, ir] * A[ir] + self.X[:, _names().index("K")] * (
                    extra / TERM_TABLE["K"].avar_coefficient * self.laws["K"].scale(self.dt))
        spec = model_sdf(a_allan, self.dt)  # the rows' per-sample spectra at these Allan coefficients
        i_m = _names().index("M")
        if A[i_m] > 0 and self.tc_s is not None:  # exact spectrum of the sampled Gauss-Markov process (AR(1))
            phi, s2 = math.exp(-self.dt / self.tc_s), A[i_m] / (2.0 * self.tc_s)
            base = spec

            def spec(f, base=base, phi=phi, s2=s2):
                return base(f) + s2 * (1 - phi * phi) / (1 - 2 * phi * np.cos(2 * np.pi * np.asarray(f)) + phi * phi)
        if finite_record and self.statistic == "adev":
            V = finite_record_covariance(self.m, self.n, spec)
        else:
            V = estimator_covariance(self.m, self.n, spec, statistic=self.statistic)
        if exact_ramp and a_allan[4] > 0 and self.statistic != "hdev":  # per-sample units: A_R dt^2
            # a strided sum (fast / non-overlapping sampling) no longer telescopes: about `stride` boundary blocks
            V = V + np.diag(self.strides * ramp_cross_variance(self.m, self.n, spec, a_allan[4] * self.dt**2))
        s = np.sqrt(self.inflation)
        C = V * np.outer(s, s) / np.outer(mu, mu)
        i_s = _names().index("S")
        if A[i_s] > 0 and self.lines:
            # a periodic error's share of each estimate gets the white-FM EDF of that tau (independent between
            # taus): a line's amplitude wanders, and as a deterministic sinusoid it would lend the points it
            # dominates a white-PM-like EDF of thousands.  At whole periods its share is 0 and nothing is added.

            share = self.X[:, i_s] * A[i_s] / mu
            nu_w = np.array([edf_simple_safe(self.n + 1, float(mm), 0) for mm in self.m])
            C = C + np.diag(share**2 * 2.0 / np.maximum(nu_w, 1.0))
        # the model-discrepancy allowance (a real sensor departs from the textbook sum by a few %), and a floor:
        # relative s.d. 1e-6 (a noise-free curve, or a term with no spectrum, still has rounding)
        # (``allowance=False``: the sampling error alone, which the fit-range scan uses to see a filter edge)
        extra = discrepancy_relcov(self.tau) if allowance else 0.0
        return C + extra + np.diag(np.full(mu.size, 1e-12))


def flicker_shape(m, statistic="adev") -> np.ndarray:
    """Variance of sampled flicker rate noise (two-sided spectrum ``1/|f|`` up to the Nyquist frequency) at
    averaging factors ``m``, relative to its large-``m`` plateau, which the IEEE-952 law uses at every tau.

    Examples
    --------
    >>> np.round(flicker_shape([1, 2, 4, 64]), 3).tolist()
    [1.189, 1.089, 1.029, 1.0]
    """
    m = np.asarray(m, dtype=np.float64)
    key = (statistic, tuple(m.tolist()))
    if key not in _FLICKER:
        spec = lambda f: 1.0 / np.abs(f)  # noqa: E731
        var = expected_variance(m, spec, statistic=statistic, per_octave=64)
        plateau = expected_variance([2.0**22], spec, statistic=statistic, per_octave=64)[0]
        _FLICKER[key] = var / plateau
    return _FLICKER[key]


_FLICKER: dict = {}
