"""Haar MODWT wavelet variance (WV) of a gyro rate series, classical and robust.

Level ``j = 1..J`` uses the Haar maximal-overlap filter of width ``tau_j = 2^j`` samples
(the *scale*; the SMAC/GMWM convention, [GMWM]_ §1).  With ``m = tau_j / 2`` and
``ybar_t(m)`` the mean of ``x_{t-m+1..t}``, the coefficients are half the difference of
adjacent means::

    W_{j,t} = ( ybar_t(m) - ybar_{t-m}(m) ) / 2,     t = tau_j - 1 .. N - 1,

computed by the pyramid ``V_0 = x``, ``W_j[t] = (V_{j-1}[t] - V_{j-1}[t-a]) / 2``,
``V_j[t] = (V_{j-1}[t] + V_{j-1}[t-a]) / 2`` with ``a = 2^(j-1)``, keeping only indices where
both inputs exist: ``O(N J)`` operations, no wrap-around, exactly ``M_j = N - tau_j + 1``
non-boundary coefficients per level ([PW2000]_ §8.3, eq. 306b).  The unbiased
("brick-wall") estimator is ``nu2_j = (1/M_j) sum_t W_{j,t}^2``.

Relation to the Allan variance: ``nu2_j = AVAR(m = tau_j/2) / 2`` exactly for the
maximal-overlap AVAR estimate normalised by its ``N - 2m + 1`` terms.

Confidence interval (``eta3``, [PW2000]_ eq. 314c): ``eta_j = max(M_j / 2^j, 1)``,
``[eta nu2 / chi2_eta(0.975), eta nu2 / chi2_eta(0.025)]``.  It is conservative (the
model-based covariance of :mod:`fogdrift.gmwm.covariance` is 1.15-1.7x narrower in SD).

Robust variant (``robust=True``): instead of the mean of ``W^2`` each level uses Huber's
"proposal 2" M-estimate of scale (see :func:`huber_scale_constant`), which bounds the
influence of a single large coefficient.  It is consistent for Gaussian ``W`` (the
constant ``delta(c)`` makes ``E min(Z^2, c^2) = delta``) and has the requested Gaussian
efficiency; its variance is that of the classical estimator divided by the efficiency.

Units: the input is in its channel's internal unit (an angular rate in deg/h, a specific force in m/s^2), and every
WV is in its square; scales are given in samples (``tau_samples``) and in seconds (``scale_s = tau_samples * dt_s``).

References
----------
.. [PW2000] D. B. Percival, A. T. Walden, *Wavelet Methods for Time Series Analysis*,
   Cambridge University Press (2000), §8.3-8.4 (eqs. 306b, 313c, 314c).
.. [GMWM] fogdrift GMWM method notes, ``shared/docs/gmwm-notes.md`` §1 (after Guerrier,
   Skaloud, Stebler & Victoria-Feser, JASA 108(502), 2013).
.. [Huber1981] P. J. Huber, *Robust Statistics*, Wiley (1981), §5.3 ("proposal 2").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.special import ndtr

from .._util import check_series
from ..allan.sums import AllanSums
from ..errors import ConfigError, DataFormatError, InsufficientDataError
from ..noise.distributions import chi2_ppf
from ..units import check_dt_s, rate_scale_to_dph

__all__ = [
    "WvarResult",
    "haar_wvar",
    "from_curve",
    "eta3",
    "eta3_ci",
    "huber_scale_constant",
    "haar_coefficients",
]

_DEFAULT_EFFICIENCY = 0.6


# ----------------------------------------------------------------------------------------
# Confidence interval
# ----------------------------------------------------------------------------------------
def eta3(n_coef, tau_samples) -> np.ndarray:
    """Equivalent degrees of freedom ``eta3 = max(M_j / tau_j, 1)`` ([PW2000]_ eq. 314c).

    Examples
    --------
    >>> float(eta3(10**6 - 1024 + 1, 1024))
    975.5634765625
    """
    m = np.asarray(n_coef, dtype=np.float64)
    t = np.asarray(tau_samples, dtype=np.float64)
    return np.maximum(m / t, 1.0)


def eta3_ci(nu2, eta, level=0.95):
    """Chi-square interval ``[eta nu2 / chi2_eta(1-a/2), eta nu2 / chi2_eta(a/2)]``.

    Examples
    --------
    >>> lo, hi = eta3_ci(1.0, 975.5634765625)
    >>> round(float(lo), 10), round(float(hi), 9)
    (0.9168686541, 1.095033373)
    """
    a = 1.0 - float(level)
    nu2 = np.asarray(nu2, dtype=np.float64)
    eta = np.asarray(eta, dtype=np.float64)
    if nu2.ndim == 2 and eta.ndim == 1:
        eta = eta[:, None]
    lo = eta * nu2 / chi2_ppf(1.0 - a / 2.0, eta)
    hi = eta * nu2 / chi2_ppf(a / 2.0, eta)
    return lo, hi


# ----------------------------------------------------------------------------------------
# Result
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class WvarResult:
    """Haar wavelet variance at dyadic scales.

    Arrays are of shape ``(n_scales,)`` for one axis or ``(n_scales, n_axes)`` (the WV
    arrays only) for a multi-axis record; use :meth:`axis` to get one axis.

    Attributes
    ----------
    level : ndarray of int, shape (n_scales,)
        Level j (the filter covers ``2^j`` samples).
    tau_samples : ndarray of int
        Scale ``tau_j = 2^j`` in samples (Haar filter width).
    scale_s : ndarray
        Scale in s, ``tau_samples * dt_s``.  The matching Allan averaging time is
        ``scale_s / 2`` (see :attr:`allan_tau_s`).
    nu2_dph2 : ndarray
        Wavelet variance in (deg/h)^2.
    n_coef : ndarray of int
        Number of non-boundary coefficients ``M_j = N - tau_j + 1``.
    eta3 : ndarray
        Equivalent degrees of freedom ``max(M_j / tau_j, 1)``.
    ci_lo95_dph2, ci_hi95_dph2 : ndarray
        95 % chi-square interval (eta3), or the published one for :func:`from_curve`.
    dt_s : float
        Sample interval in s.
    n_samples : int
        Record length N.
    robust : bool
        True if the Huber-type robust estimator was used.
    efficiency : float
        Gaussian efficiency of the estimator (1 for the classical one).
    source : str
        ``"haar-modwt"`` or ``"table"``.
    axis_names : tuple of str
        Axis names (one per column of the WV arrays; ``("x",)`` for 1-D input).
    var_nonparam_dph4 : ndarray or None
        Nonparametric variance of ``nu2`` from the ACVS of ``W_j`` ((deg/h)^4), if requested.
    """

    level: np.ndarray
    tau_samples: np.ndarray
    scale_s: np.ndarray
    nu2_dph2: np.ndarray
    n_coef: np.ndarray
    eta3: np.ndarray
    ci_lo95_dph2: np.ndarray
    ci_hi95_dph2: np.ndarray
    dt_s: float
    n_samples: int
    robust: bool = False
    efficiency: float = 1.0
    source: str = "haar-modwt"
    axis_names: tuple = ("x",)
    var_nonparam_dph4: np.ndarray | None = field(default=None, repr=False)

    def __len__(self) -> int:
        return int(self.level.size)

    @property
    def n_axes(self) -> int:
        """Number of axes (columns of the WV arrays)."""
        return 1 if self.nu2_dph2.ndim == 1 else int(self.nu2_dph2.shape[1])

    @property
    def allan_tau_s(self) -> np.ndarray:
        """Allan averaging time ``scale_s / 2`` in s at which ``AVAR = 2 nu2``."""
        return self.scale_s / 2.0

    @property
    def unit(self) -> str:
        """Unit of ``nu2_dph2``."""
        return "(deg/h)^2"

    def axis(self, k=0) -> "WvarResult":
        """The result for one axis (by index or name) as a 1-D :class:`WvarResult`."""
        if self.nu2_dph2.ndim == 1:
            if k in (0, self.axis_names[0]):
                return self
            raise ConfigError(f"axis must be 0 or {self.axis_names[0]!r} for a one-axis result, got {k!r}")
        if isinstance(k, str):
            if k not in self.axis_names:
                raise ConfigError(f"unknown axis {k!r}; expected one of {list(self.axis_names)}")
            k = self.axis_names.index(k)
        if not (isinstance(k, (int, np.integer)) and 0 <= k < self.n_axes):
            raise ConfigError(f"axis index must be in 0..{self.n_axes - 1}, got {k!r}")
        vnp = None if self.var_nonparam_dph4 is None else self.var_nonparam_dph4[:, k]
        return replace(
            self,
            nu2_dph2=self.nu2_dph2[:, k],
            ci_lo95_dph2=self.ci_lo95_dph2[:, k],
            ci_hi95_dph2=self.ci_hi95_dph2[:, k],
            axis_names=(self.axis_names[k],),
            var_nonparam_dph4=vnp,
        )

    def select(self, mask) -> "WvarResult":
        """A result restricted to the scales where ``mask`` (bool or index array) is set."""
        idx = np.arange(len(self))[np.asarray(mask)] if np.asarray(mask).dtype == bool else np.asarray(mask)
        vnp = None if self.var_nonparam_dph4 is None else self.var_nonparam_dph4[idx]
        return replace(
            self,
            level=self.level[idx],
            tau_samples=self.tau_samples[idx],
            scale_s=self.scale_s[idx],
            nu2_dph2=self.nu2_dph2[idx],
            n_coef=self.n_coef[idx],
            eta3=self.eta3[idx],
            ci_lo95_dph2=self.ci_lo95_dph2[idx],
            ci_hi95_dph2=self.ci_hi95_dph2[idx],
            var_nonparam_dph4=vnp,
        )

    def to_dict(self) -> dict:
        """JSON-serialisable dict (units in the keys)."""
        out = {
            "level": [int(v) for v in self.level],
            "tau_samples": [int(v) for v in self.tau_samples],
            "scale_s": [float(v) for v in self.scale_s],
            "nu2_dph2": np.asarray(self.nu2_dph2, dtype=float).tolist(),
            "n_coef": [int(v) for v in self.n_coef],
            "eta3": [float(v) for v in self.eta3],
            "ci_lo95_dph2": np.asarray(self.ci_lo95_dph2, dtype=float).tolist(),
            "ci_hi95_dph2": np.asarray(self.ci_hi95_dph2, dtype=float).tolist(),
            "dt_s": float(self.dt_s),
            "n_samples": int(self.n_samples),
            "robust": bool(self.robust),
            "efficiency": float(self.efficiency),
            "source": self.source,
            "axis_names": list(self.axis_names),
        }
        if self.var_nonparam_dph4 is not None:
            out["var_nonparam_dph4"] = np.asarray(self.var_nonparam_dph4, dtype=float).tolist()
        return out

    @classmethod
    def from_table(cls, scale_s, wvar, *, n_samples, dt_s, ci_low=None, ci_high=None, unit="deg/h",
                   axis_name="x") -> "WvarResult":
        """Build a result from a published curve; see :func:`from_curve`."""
        return from_curve(scale_s, wvar, n_samples=n_samples, dt_s=dt_s, ci_low=ci_low, ci_high=ci_high,
                          unit=unit, axis_name=axis_name)


# ----------------------------------------------------------------------------------------
# Robust scale
# ----------------------------------------------------------------------------------------
def _huber_terms(c: float):
    """delta(c) = E min(Z^2, c^2) and the Gaussian efficiency of Huber's proposal-2 scale."""
    phi = np.exp(-c**2 / 2.0) / np.sqrt(2 * np.pi)  # the standard normal density (as scipy's norm.pdf)
    p_in = 2.0 * ndtr(c) - 1.0  # P(|Z| < c)
    e_z2_in = p_in - 2.0 * c * phi  # E[Z^2 1(|Z|<c)]
    delta = e_z2_in + c * c * (1.0 - p_in)
    # psi(z) = min(z^2, c^2) - delta; E psi^2 and E[z psi'(z)] = E[2 z^2 1(|z|<c)]
    e_z4_in = 3.0 * p_in - 2.0 * phi * (c**3 + 3.0 * c)  # E[Z^4 1(|Z|<c)]
    e_psi2 = e_z4_in + c**4 * (1.0 - p_in) - delta**2
    slope = 2.0 * e_z2_in
    # sigma^2-estimate: asymptotic var 4 E psi^2 / slope^2 sigma^4; classical (c = inf): 2 sigma^4
    efficiency = 2.0 / (4.0 * e_psi2 / slope**2)
    return delta, efficiency


def huber_scale_constant(efficiency=_DEFAULT_EFFICIENCY):
    """Clipping constant ``c`` and consistency constant ``delta`` of Huber's proposal-2 scale.

    The robust WV of a level solves ``(1/M) sum_t min(W_t^2 / s, c^2) = delta`` for ``s``
    ([Huber1981]_ §5.3), with ``delta(c) = E min(Z^2, c^2)`` for ``Z ~ N(0, 1)`` (so that
    ``s -> nu2`` for Gaussian coefficients) and ``c`` chosen so that the asymptotic
    Gaussian efficiency of ``s`` relative to the mean of ``W^2`` equals ``efficiency``::

        delta(c) = (2 Phi(c) - 1) - 2 c phi(c) + 2 c^2 (1 - Phi(c))
        eff(c)   = 2 (E[Z^2 1(|Z|<c)])^2 / (E[min(Z^2,c^2)^2] - delta^2)

    Parameters
    ----------
    efficiency : float
        Gaussian efficiency in (0, 1); 0.6 (default) is the R packages' default.

    Returns
    -------
    (c, delta) : tuple of float

    Examples
    --------
    >>> c, delta = huber_scale_constant(0.6)
    >>> round(c, 4), round(delta, 4)
    (1.2245, 0.6486)
    """
    eff = float(efficiency)
    if not 0.0 < eff < 1.0:
        raise ConfigError(f"efficiency must be in (0, 1), got {efficiency!r}")
    from scipy.optimize import brentq

    c = brentq(lambda c: _huber_terms(c)[1] - eff, 1e-3, 50.0, xtol=1e-14)
    return float(c), float(_huber_terms(c)[0])


def _robust_level(w2: np.ndarray, c: float, delta: float) -> float:
    """Solve mean(min(w2/s, c^2)) = delta for s by the monotone fixed point s <- mean(min(w2, c^2 s))/delta."""
    s = float(np.median(w2)) / 0.4549364231195724  # median of chi2_1
    if s <= 0.0:
        s = float(np.mean(w2)) or 0.0
        if s == 0.0:
            return 0.0
    c2 = c * c
    for _ in range(500):
        s_new = float(np.minimum(w2, c2 * s).mean()) / delta
        if abs(s_new - s) <= 1e-13 * s:
            return s_new
        s = s_new
    return s


# ----------------------------------------------------------------------------------------
# Pyramid
# ----------------------------------------------------------------------------------------
def _default_levels(n: int) -> int:
    return max(1, int(math.floor(math.log2(n))) - 1)


def _check_levels(levels, n: int) -> int:
    jmax = int(math.floor(math.log2(n))) if n >= 2 else 0
    if levels is None:
        return _default_levels(n)
    try:
        j = int(levels)
    except (TypeError, ValueError):
        raise ConfigError(f"levels must be an integer >= 1 or None, got {levels!r}") from None
    if j != levels or j < 1:
        raise ConfigError(f"levels must be an integer >= 1 or None, got {levels!r}")
    if j > jmax:
        raise InsufficientDataError(
            f"{n} samples allow at most {jmax} levels (2^J <= N); got levels={j}; pass a smaller {{opt:levels}}",
            needed=2**j, got=n,
        )
    return j


def haar_coefficients(x, levels):
    """Yield ``(j, W_j)`` for ``j = 1..levels``: the non-boundary Haar MODWT coefficients.

    Private-kernel style: ``x`` must be a finite float64 1-D array with ``2^levels <= len(x)``.
    ``W_j`` has ``len(x) - 2^j + 1`` entries, the first at time index ``2^j - 1``.

    Examples
    --------
    >>> [w.tolist() for _, w in haar_coefficients(np.arange(6.0), 2)]
    [[0.5, 0.5, 0.5, 0.5, 0.5], [1.0, 1.0, 1.0]]
    """
    v = np.asarray(x, dtype=np.float64)
    # running sums S_j = 2^j V_j avoid one multiplication per level and sample
    for j in range(1, levels + 1):
        a = 1 << (j - 1)
        w = np.subtract(v[a:], v[:-a])
        w *= 0.5 ** j
        yield j, w
        v = np.add(v[a:], v[:-a]) if j < levels else None


def _classical_nu2(x: np.ndarray, dt: float, levels: int) -> np.ndarray:
    """Classical WV of levels 1..J as half the overlapping Allan variance at ``m = 2^(j-1)``
    (exact identity, [GMWM]_ §9.2): the second-difference sums have one home, the compiled
    kernels of :mod:`fogdrift.allan` (compensated phase, parallel blocks), taken through
    :class:`~fogdrift.allan.sums.AllanSums` as :func:`fogdrift.allan.allan_variance` takes them below
    :data:`~fogdrift.allan.sums.CHUNKED_MIN_SAMPLES` samples (the same values) and out of core above it
    (no 8-bytes-per-sample angle array; equal to 1e-12 relative)."""
    sums = AllanSums(x, dt, "adev", "overlapping")
    m = sums.grid(np.left_shift(1, np.arange(levels)).astype(np.float64) * dt)
    sums.compute((m,))
    return sums.result(m, 0).avar_dph2 / 2.0


def _acvs_variance(w: np.ndarray) -> float:
    """Nonparametric Var(mean w^2) = 2 A / M, A = s_0^2/2 + sum_{k>=1} s_k^2 ([PW2000]_ eq. 312c)."""
    m = w.size
    nfft = 1 << int(math.ceil(math.log2(2 * m)))
    spec = np.fft.rfft(w, nfft)
    acvs = np.fft.irfft(spec.real**2 + spec.imag**2, nfft)[:m] / m
    a = 0.5 * acvs[0] ** 2 + float(np.einsum("i,i->", acvs[1:], acvs[1:]))
    return 2.0 * a / m


def haar_wvar(y, dt_s, *, levels=None, robust=False, efficiency=_DEFAULT_EFFICIENCY,
              nonparametric_var=False, axis_names=None) -> WvarResult:
    """Haar MODWT wavelet variance of a rate series, with eta3 confidence intervals.

    Parameters
    ----------
    y : array_like, shape (n_samples,) or (n_samples, n_axes)
        The series at a constant sample interval in its channel's internal unit (deg/h for a gyro, m/s^2 for an
        accelerometer: every WV is in its square); a 2-D array is processed column by column.
    dt_s : float
        Sample interval in s.
    levels : int or None, keyword-only
        Number of levels J (scales ``2, 4, ..., 2^J`` samples).  Default
        ``floor(log2 N) - 1`` (the last scale then has eta3 of about 1-3).
    robust : bool, keyword-only
        Use the Huber-type M-estimate of scale per level instead of the mean of ``W^2``
        (for logs with outliers; see the module docstring).
    efficiency : float, keyword-only
        Gaussian efficiency of the robust estimator, in (0, 1); ignored unless ``robust``.
    nonparametric_var : bool, keyword-only
        Also compute the nonparametric variance of each ``nu2`` from the sample ACVS of
        ``W_j`` (FFT, ``O(N log N)`` per level; divided by ``efficiency`` if robust).
    axis_names : sequence of str, optional
        Names of the columns (default ``x`` for 1-D input, ``ax0, ax1, ...`` otherwise).

    Returns
    -------
    WvarResult

    Raises
    ------
    DataFormatError
        Non-numeric, non-finite or >2-D input.
    InsufficientDataError
        Fewer than 2 samples, or ``2^levels`` larger than the record.
    ConfigError
        Bad ``dt_s``, ``levels`` or ``efficiency``.

    Notes
    -----
    ``nu2_j = (1/M_j) sum_{t=tau_j-1}^{N-1} W_{j,t}^2`` ([PW2000]_ eq. 306b), unbiased for
    any process whose first differences are stationary; equal to half the maximal-overlap
    Allan variance at ``m = tau_j/2``.  The mean is removed first (the WV ignores a constant).
    Cost: the classical estimator is computed as ``AVAR(m_j) / 2`` by
    :func:`fogdrift.allan.allan_variance` (compiled, parallel; 2.9 s for 1e8 samples and 25
    levels, see ``bench/bench_gmwm.py``); the robust and nonparametric options use the NumPy
    pyramid (:func:`haar_coefficients`, three copies).

    Examples
    --------
    White noise of variance 1 has ``nu2 = 1/tau``:

    >>> rng = np.random.default_rng(0)
    >>> r = haar_wvar(rng.standard_normal(2**16), 0.01, levels=4)
    >>> r.tau_samples.tolist(), [round(float(v * t), 1) for v, t in zip(r.nu2_dph2, r.tau_samples)]
    ([2, 4, 8, 16], [1.0, 1.0, 1.0, 1.0])
    >>> r.scale_s.tolist()
    [0.02, 0.04, 0.08, 0.16]
    """
    dt = check_dt_s(dt_s)
    try:
        arr = np.asarray(y, dtype=np.float64)
    except (TypeError, ValueError):
        raise DataFormatError(f"y must be a numeric array, got {type(y).__name__}") from None
    if arr.ndim == 2:
        cols = [check_series(arr[:, k], f"y[:, {k}]") for k in range(arr.shape[1])]
        if not cols:
            raise DataFormatError("y has no columns; expected shape (n_samples, n_axes)")
    elif arr.ndim == 1:
        cols = [check_series(arr, "y")]
    else:
        raise DataFormatError(f"y must be 1-D or 2-D; expected (n_samples,) or (n_samples, n_axes), got {arr.shape}")
    n = cols[0].size
    if n < 2:
        raise InsufficientDataError(f"a wavelet variance needs at least 2 samples, got {n}", needed=2, got=n)
    J = _check_levels(levels, n)
    if robust:
        c, delta = huber_scale_constant(efficiency)
        eff = float(efficiency)
    else:
        eff = 1.0
    if axis_names is None:
        names = ("x",) if arr.ndim == 1 else tuple(f"ax{k}" for k in range(len(cols)))
    else:
        names = tuple(str(a) for a in axis_names)
        if len(names) != len(cols):
            raise ConfigError(f"axis_names must name {len(cols)} axes, got {len(names)}")

    nu2 = np.empty((J, len(cols)))
    vnp = np.empty((J, len(cols))) if nonparametric_var else None
    level = np.arange(1, J + 1, dtype=np.int64)
    tau = np.left_shift(1, level).astype(np.int64)
    n_coef = n - tau + 1
    for k, x in enumerate(cols):
        if not (robust or nonparametric_var):
            nu2[:, k] = _classical_nu2(x, dt, J)
            continue
        x = x - x.mean()
        for j, w in haar_coefficients(x, J):
            if robust:
                w2 = w * w
                nu2[j - 1, k] = _robust_level(w2, c, delta)
            else:
                nu2[j - 1, k] = float(np.einsum("i,i->", w, w)) / w.size  # no BLAS threads
            if nonparametric_var:
                vnp[j - 1, k] = _acvs_variance(w) / eff
    eta = eta3(n_coef, tau)
    if arr.ndim == 1:
        nu2 = nu2[:, 0]
        vnp = None if vnp is None else vnp[:, 0]
    lo, hi = eta3_ci(nu2, eta)
    return WvarResult(
        level=level, tau_samples=tau, scale_s=tau * dt, nu2_dph2=nu2, n_coef=n_coef, eta3=eta,
        ci_lo95_dph2=lo, ci_hi95_dph2=hi, dt_s=dt, n_samples=int(n), robust=bool(robust),
        efficiency=eff, source="haar-modwt", axis_names=names, var_nonparam_dph4=vnp,
    )


def from_curve(scale_s, wvar, *, n_samples, dt_s, ci_low=None, ci_high=None, unit="deg/h",
               axis_name="x") -> WvarResult:
    """Wrap a published Haar WV curve (e.g. the SMAC tables) as a :class:`WvarResult`.

    Parameters
    ----------
    scale_s : array_like, shape (n_scales,)
        Scales in s (Haar filter width ``2^j dt_s``); must be distinct powers of two times
        ``dt_s`` (relative tolerance 1e-6).
    wvar : array_like, shape (n_scales,)
        Wavelet variance in ``unit``^2.
    n_samples : int
        Length of the record the curve came from.
    dt_s : float
        Its sample interval in s.
    ci_low, ci_high : array_like, optional
        Published 95 % interval (``unit``^2); default: the eta3 interval.
    unit : str
        Rate unit of the curve (:data:`fogdrift.units.RATE_UNITS`); values are converted
        to (deg/h)^2.
    axis_name : str

    Returns
    -------
    WvarResult
        With ``source="table"``; ``M_j`` and eta3 recomputed from ``n_samples``.

    Examples
    --------
    >>> r = from_curve([0.002, 0.004], [1e-9, 5e-10], n_samples=10**6, dt_s=0.001, unit="deg/s")
    >>> r.tau_samples.tolist(), [round(float(v), 6) for v in r.nu2_dph2]
    ([2, 4], [0.01296, 0.00648])
    """
    dt = check_dt_s(dt_s)
    scale = np.asarray(scale_s, dtype=np.float64)
    nu = np.asarray(wvar, dtype=np.float64)
    if scale.ndim != 1 or scale.shape != nu.shape or scale.size == 0:
        raise DataFormatError(
            f"scale_s and wvar must be 1-D of equal length; got shapes {scale.shape} and {nu.shape}"
        )
    if not (np.all(np.isfinite(scale)) and np.all(np.isfinite(nu)) and np.all(nu > 0) and np.all(scale > 0)):
        raise DataFormatError("scale_s and wvar must be finite and > 0")
    try:
        n = int(n_samples)
    except (TypeError, ValueError):
        raise ConfigError(f"n_samples must be an integer >= 2, got {n_samples!r}") from None
    tau_f = scale / dt
    level = np.rint(np.log2(tau_f)).astype(np.int64)
    tau = np.left_shift(1, np.maximum(level, 0)).astype(np.int64)
    if np.any(level < 1) or not np.allclose(tau, tau_f, rtol=1e-6, atol=0):
        bad = int(np.argmax(~np.isclose(tau, tau_f, rtol=1e-6, atol=0) | (level < 1)))
        raise DataFormatError(
            f"scale_s[{bad}] = {scale[bad]!r} s is not 2^j * dt_s (dt_s = {dt!r}); expected a power-of-two "
            "Haar scale; check {opt:dt_s}"
        )
    if np.any(np.diff(level) <= 0):
        raise DataFormatError("scale_s must be strictly increasing")
    if n < int(tau[-1]):
        raise ConfigError(f"n_samples = {n} is shorter than the largest scale ({int(tau[-1])} samples)")
    f2 = rate_scale_to_dph(unit) ** 2
    n_coef = n - tau + 1
    eta = eta3(n_coef, tau)
    if (ci_low is None) != (ci_high is None):
        raise ConfigError("give both ci_low and ci_high, or neither")
    if ci_low is None:
        lo, hi = eta3_ci(nu, eta)
    else:
        lo = np.asarray(ci_low, dtype=np.float64)
        hi = np.asarray(ci_high, dtype=np.float64)
        if lo.shape != nu.shape or hi.shape != nu.shape:
            raise DataFormatError("ci_low and ci_high must have the shape of wvar")
    return WvarResult(
        level=level, tau_samples=tau, scale_s=tau * dt, nu2_dph2=nu * f2, n_coef=n_coef, eta3=eta,
        ci_lo95_dph2=lo * f2, ci_hi95_dph2=hi * f2, dt_s=dt, n_samples=n, robust=False,
        efficiency=1.0, source="table", axis_names=(str(axis_name),),
    )
