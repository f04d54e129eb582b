"""Equivalent degrees of freedom (EDF) and chi-squared confidence bounds of the Allan family.

Kept apart, as in allantools' ``ci.py``:

* :func:`edf_simple` -- the simple Howe-Allan-Barnes formulas of [SP1065]_ Table 5 (p. 40) for
  the overlapping Allan variance (used for ``statistic="adev"``);
* :func:`edf_greenhall` -- the general EDF algorithm of Greenhall & Riley [GR2003]_ for
  variances built from d-th differences of phase: the Allan (d = 2), Hadamard (d = 3) and
  modified Allan (d = 2, ``modified=True``) variances, overlapping or not.  Table 5 of
  [SP1065]_ covers the overlapping Allan variance only; for the Hadamard and modified Allan
  variances fogdrift uses this algorithm, as Stable32 and allantools do (no simpler published
  formula was found for them; the text of SP 1065 itself was not available to check further).
  It is implemented from the paper's equations (7)-(10) and (13), not an approximation of
  them; the asymptotic constants of its Tables 1-3 are *computed* here (by quadrature and in
  closed form, :func:`greenhall_constants`, stored to 12 digits in :data:`GREENHALL_AB`) and
  checked against the published, rounded table values in the tests.  For white PM
  (alpha = +2) of the unmodified variances the basic sum has only d non-zero lags and is
  summed exactly for every record length (the paper's closed form holds when
  ``ceil(M/S) > d``; the exact sum also covers the short records it leaves out).  Note that
  the algorithm models continuous-time noise: for white FM at small m and few terms its EDF
  differs from that of i.i.d. rate samples (e.g. 14.3 instead of 12.2 at N = 20, m = 1);
* :func:`chi2_bounds` -- ``[var edf / chi2_{1-q/2}(edf), var edf / chi2_{q/2}(edf)]``,
  [SP1065]_ Sec. 5.3 (eqs. 44-45);
* :func:`resolve_alpha` -- the power-law alpha assumed at each tau (given, from the local
  log-log slope of the deviation, or the most conservative one);
* :func:`periodic_alpha` -- no phase-noise (white/flicker PM) alpha where the spectrum found a
  periodic error: a sinusoid's Allan deviation falls like tau^-1 and looks like white PM, whose
  EDF (tens of thousands at short tau) would make its bounds ~1 % wide.

References
----------
.. [SP1065] W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065 (2008).
.. [HAB1981] D. A. Howe, D. W. Allan, J. A. Barnes, "Properties of signal sources and
   measurement methods", Proc. 35th Frequency Control Symposium (1981).
.. [GR2003] C. A. Greenhall, W. J. Riley, "Uncertainty of stability variances based on finite
   differences", Proc. 35th PTTI Meeting (2003): eqs. 7-10 and 13, Tables 1-3.
"""

from __future__ import annotations

import math
import warnings
from functools import lru_cache
from types import MappingProxyType

import numpy as np

from ..errors import ConfigError, InsufficientDataError

__all__ = [
    "edf_simple",
    "edf_greenhall",
    "greenhall_constants",
    "GREENHALL_AB",
    "chi2_bounds",
    "resolve_alpha",
    "alpha_from_slope",
    "periodic_alpha",
    "POWER_LAW_ALPHAS",
    "P68",
]

#: Power-law exponents alpha of S_y(f) ~ f^alpha handled by the EDF formulas:
#: +2 white PM, +1 flicker PM, 0 white FM, -1 flicker FM, -2 random-walk FM.
POWER_LAW_ALPHAS = (2, 1, 0, -1, -2)

#: Probability inside +-1 sigma of a normal distribution, erf(1/sqrt 2) = 0.682689...
P68 = math.erf(1.0 / math.sqrt(2.0))

#: Greenhall & Riley's J_max: up to this many lags the basic sum is evaluated term by term.
_JMAX = 100


def _check_alpha(alpha) -> int:
    try:
        a = int(alpha)
    except (TypeError, ValueError):
        raise ConfigError(f"alpha must be one of 2, 1, 0, -1, -2, got {alpha!r}") from None
    if a != alpha or a not in POWER_LAW_ALPHAS:
        raise ConfigError(f"alpha must be one of 2, 1, 0, -1, -2, got {alpha!r}")
    return a


# ----------------------------------------------------------------------------------------
# Simple EDF (SP 1065 Table 5)
# ----------------------------------------------------------------------------------------
def edf_simple(n_phase, m, alpha) -> float:
    """Simple equivalent degrees of freedom of the overlapping Allan variance.

    Parameters
    ----------
    n_phase : int
        Number of phase (angle) points, N = number of rate samples + 1 (>= 3).
    m : int
        Averaging factor, ``1 <= m <= (n_phase - 1) / 2``.
    alpha : int
        Power-law noise exponent: +2 white PM (quantization Q), +1 flicker PM, 0 white FM
        (ARW N), -1 flicker FM (bias instability B), -2 random-walk FM (RRW K).

    Returns
    -------
    float
        The EDF.  Not clipped (may be < 1 or inf at the smallest N; callers clip).

    Raises
    ------
    ConfigError
        Invalid ``alpha``, ``n_phase`` or ``m``.

    Notes
    -----
    Howe, Allan & Barnes (1981) [HAB1981]_, tabulated in [SP1065]_ Table 5 (p. 40),
    with N phase points:

    * white PM: (N+1)(N-2m) / (2(N-m))
    * flicker PM: exp( sqrt( ln((N-1)/(2m)) ln((2m+1)(N-1)/4) ) )
    * white FM: [3(N-1)/(2m) - 2(N-2)/N] 4m^2/(4m^2+5)
    * flicker FM: m = 1: 2(N-2)^2/(2.3N - 4.9); m >= 2: 5N^2/(4m(N+3m))
    * random-walk FM: ((N-2)/m) ((N-1)^2 - 3m(N-1) + 4m^2)/(N-3)^2

    The flicker-FM m = 1 case keeps the square of (N-2) (allantools 2024.6 drops it).

    Examples
    --------
    >>> round(edf_simple(1025, 16, 0), 4)
    93.5471
    >>> round(edf_simple(1025, 1, -1), 4)
    889.6787
    """
    a = _check_alpha(alpha)
    N = float(n_phase)
    mm = float(m)
    if N != int(n_phase) or N < 3:
        raise ConfigError(f"n_phase must be an integer >= 3, got {n_phase!r}")
    if mm != int(m) or mm < 1 or 2 * mm > N - 1:
        raise ConfigError(f"m must be an integer in [1, (n_phase-1)/2] = [1, {(N - 1) / 2}], got {m!r}")
    return edf_formula(N, mm, a)


def edf_formula(N: float, mm: float, a: int) -> float:
    """SP 1065 Table 5 formulas (see :func:`edf_simple`); unchecked, float arguments."""
    return float(_table5(np.array([N], dtype=np.float64), np.array([mm], dtype=np.float64), int(a))[0])


def _table5(n: np.ndarray, q: np.ndarray, a: int) -> np.ndarray:
    """The Table-5 EDF of power-law alpha ``a`` at ``n`` phase points and averaging factor ``q`` (float arrays,
    unchecked): the one home of the formulas (:func:`edf_formula`, :func:`edf_simple_safe_array`)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        if a == 2:
            return (n + 1) * (n - 2 * q) / (2 * (n - q))
        if a == 1:
            return np.exp(np.sqrt(np.log((n - 1) / (2 * q)) * np.log((2 * q + 1) * (n - 1) / 4)))
        if a == 0:
            return (3 * (n - 1) / (2 * q) - 2 * (n - 2) / n) * 4 * q**2 / (4 * q**2 + 5)
        if a == -1:
            return np.where(q <= 1, 2 * (n - 2) ** 2 / (2.3 * n - 4.9), 5 * n**2 / (4 * q * (n + 3 * q)))
        return ((n - 2) / q) * ((n - 1) ** 2 - 3 * q * (n - 1) + 4 * q**2) / (n - 3) ** 2


def edf_simple_safe(n_phase, m, alpha) -> float:
    """Table-5 EDF without argument checks; n_phase and m may be non-integer (fast estimator)."""
    if n_phase < 3 or 2 * m > n_phase - 1:
        return 1.0
    return edf_formula(float(n_phase), float(m), int(alpha))


def edf_simple_safe_array(n_phase, m, alpha) -> np.ndarray:
    """:func:`edf_simple_safe` element by element over arrays (broadcast): the same formulas, evaluated per alpha
    on the elements that have it, and 1 where the record is too short for the tau.

    Examples
    --------
    >>> edf_simple_safe_array(1025, np.array([1, 16, 600]), np.array([-1, 0, 0])).round(4).tolist()
    [889.6787, 93.5471, 1.0]
    """
    N, mm, a = np.broadcast_arrays(np.asarray(n_phase, dtype=np.float64), np.asarray(m, dtype=np.float64),
                                   np.asarray(alpha, dtype=np.int64))
    out = np.ones(N.shape, dtype=np.float64)
    ok = ~((N < 3) | (2 * mm > N - 1))
    for value in np.unique(a[ok]):
        k = ok & (a == value)
        out[k] = _table5(N[k], mm[k], int(value))
    return out


# ----------------------------------------------------------------------------------------
# Greenhall & Riley (2003)
# ----------------------------------------------------------------------------------------
def _xlogabs(t: np.ndarray) -> np.ndarray:
    """ln|t| with the convention 0 where t == 0 (it always multiplies a power of t)."""
    at = np.abs(t)
    out = np.zeros_like(at)
    np.log(at, out=out, where=at > 0)
    return out


def _sw(t, alpha: int) -> np.ndarray:
    """[GR2003]_ eq. 7: the generalised autocovariance kernel of phase noise with S_y ~ f^alpha."""
    t = np.asarray(t, dtype=np.float64)
    at = np.abs(t)
    if alpha == 2:
        return -at
    if alpha == 1:
        return t**2 * _xlogabs(t)
    if alpha == 0:
        return at**3
    if alpha == -1:
        return -(t**4) * _xlogabs(t)
    if alpha == -2:
        return -(at**5)
    if alpha == -3:
        return t**6 * _xlogabs(t)
    if alpha == -4:
        return at**7
    raise ValueError(alpha)


def _sx(t, F: float, alpha: int) -> np.ndarray:
    """[GR2003]_ eq. 8: sw after the frequency-averaging filter of F points (F = inf: its limit)."""
    if math.isinf(F):
        if alpha == 1:  # -d^2/dt^2 of t^2 ln|t|, constant dropped (the d-th difference removes it)
            return -2.0 * _xlogabs(np.asarray(t, dtype=np.float64))
        return _sw(t, alpha + 2)
    t = np.asarray(t, dtype=np.float64)
    return F * F * (2.0 * _sw(t, alpha) - _sw(t - 1.0 / F, alpha) - _sw(t + 1.0 / F, alpha))


def _diff_weights(d: int) -> list[tuple[int, int]]:
    """(k, c_k) with c_k = (-1)^k binom(2d, d+k), k = -d..d: the 2d-th central difference."""
    return [(k, (-1) ** abs(k) * math.comb(2 * d, d + k)) for k in range(-d, d + 1)]


def _sz(t, F: float, alpha: int, d: int) -> np.ndarray:
    """[GR2003]_ eq. 9: sum_k c_k sx(t + k)."""
    t = np.asarray(t, dtype=np.float64)
    return sum(c * _sx(t + k, F, alpha) for k, c in _diff_weights(d))


def _basic_sum(J: int, M: float, S: float, F: float, alpha: int, d: int) -> float:
    """[GR2003]_ eq. 10: sz(0)^2 + (1 - J/M) sz(J/S)^2 + 2 sum_{j=1}^{J-1} (1 - j/M) sz(j/S)^2."""
    j = np.arange(1, int(J), dtype=np.float64)
    total = float(_sz(0.0, F, alpha, d)) ** 2
    total += (1.0 - J / M) * float(_sz(J / S, F, alpha, d)) ** 2
    if j.size:
        total += 2.0 * float(np.sum((1.0 - j / M) * _sz(j / S, F, alpha, d) ** 2))
    return total


@lru_cache(maxsize=None)
def greenhall_constants(alpha: int, d: int, modified: bool) -> tuple[float, float]:
    """Asymptotic constants (a0, a1) of ``1/edf ~ (a0 - a1/r)/r`` for many lags ([GR2003]_ Tables 1-2).

    ``a0 = 2 int_0^{d+1} sz(t)^2 dt / sz(0)^2`` and ``a1 = 2 int_0^{d+1} t sz(t)^2 dt / sz(0)^2``:
    the basic sum (eq. 10) with ``S -> inf`` lags per unit of t becomes these integrals.
    ``modified`` uses F = 1 (Table 1), otherwise F = inf (Table 2).  For the unmodified
    variances with alpha = +1, sz(0) diverges like ln m, so the constants are returned without
    that normalisation (Table 2's alpha = +1 row; the divisor is :func:`_table3` ``(b0 + b1 ln m)^2``).
    Computed by adaptive quadrature split at the integers (where the log kernels are singular).

    Examples
    --------
    >>> [round(v, 3) for v in greenhall_constants(0, 2, True)]   # Table 1: 1.033, 0.607
    [1.033, 0.607]
    >>> [round(v, 3) for v in greenhall_constants(-1, 2, False)]  # Table 2: 0.852, 0.375
    [0.852, 0.375]
    """
    from scipy.integrate import IntegrationWarning, quad

    F = 1.0 if modified else math.inf

    def f0(t):
        return float(_sz(t, F, alpha, d)) ** 2

    def f1(t):
        return t * f0(t)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IntegrationWarning)
        i0 = sum(quad(f0, k, k + 1, limit=200, epsabs=0.0, epsrel=1e-11)[0] for k in range(d + 1))
        i1 = sum(quad(f1, k, k + 1, limit=200, epsabs=0.0, epsrel=1e-11)[0] for k in range(d + 1))
    norm = 1.0 if (alpha == 1 and not modified) else float(_sz(0.0, F, alpha, d)) ** 2
    return 2.0 * i0 / norm, 2.0 * i1 / norm


#: (a0, a1) of :func:`greenhall_constants` for every (alpha, d, modified) the algorithm needs,
#: computed once by that function (12 digits; ``test_allan_ci`` recomputes them by quadrature
#: and compares them with the published, rounded Tables 1-2).  Data, so that an EDF does not
#: pay ~0.3 s of quadrature per noise type.
GREENHALL_AB = MappingProxyType({
    (2, 1, True): (0.666666666667, 0.333333333333),
    (1, 1, True): (0.839609844672, 0.345378900016),
    (0, 1, True): (1.07857142857, 0.367857142857),
    (2, 2, True): (0.777777777778, 0.5),
    (1, 2, True): (0.996652190045, 0.615594030578),
    (0, 2, True): (1.03333333333, 0.607142857143),
    (-1, 2, True): (1.04759308687, 0.533911715442),
    (-2, 2, True): (1.30223327331, 0.535499624343),
    (2, 3, True): (0.88, 0.666666666667),
    (1, 3, True): (1.14099936692, 0.842805644798),
    (0, 3, True): (1.18392857143, 0.848214285714),
    (-1, 3, True): (1.18023979145, 0.815800254393),
    (-2, 3, True): (1.17511904762, 0.777398989899),
    (1, 1, False): (78.5635344306, 25.1708556546),
    (0, 1, False): (0.666666666667, 0.166666666667),
    (1, 2, False): (789.530796012, 410.428653196),
    (0, 2, False): (0.666666666667, 0.333333333333),
    (-1, 2, False): (0.852204147712, 0.374732175732),
    (-2, 2, False): (1.07857142857, 0.367857142857),
    (1, 3, False): (9948.55100075, 6520.10025389),
    (0, 3, False): (0.777777777778, 0.5),
    (-1, 3, False): (0.996997298895, 0.616716835822),
    (-2, 3, False): (1.03333333333, 0.607142857143),
})


def _constants(alpha: int, d: int, modified: bool) -> tuple[float, float]:
    try:
        return GREENHALL_AB[(alpha, d, modified)]
    except KeyError:  # pragma: no cover - every valid combination is tabulated
        return greenhall_constants(alpha, d, modified)


def _table3(d: int) -> tuple[float, float]:
    """[GR2003]_ Table 3: sz(0, m, +1, d) = b0 + b1 ln m + O(1/m^2) for flicker PM.

    sx(0) = 2 ln m and sx(k) -> -(2 ln|k| + 3) for k != 0, so b1 = 2 binom(2d, d) and
    b0 = 3 binom(2d, d) - 2 sum_{k != 0} c_k ln|k| (6, 15.23, 47.8 for d = 1, 2, 3).
    """
    c0 = math.comb(2 * d, d)
    b0 = 3.0 * c0 - 2.0 * sum(c * math.log(abs(k)) for k, c in _diff_weights(d) if k != 0)
    return b0, 2.0 * c0


def edf_greenhall(alpha, d, m, n_phase, *, overlapping=True, modified=False) -> float:
    """EDF of a variance built from d-th differences of phase ([GR2003]_).

    Parameters
    ----------
    alpha : int
        Power-law exponent of the rate (frequency) PSD, one of 2, 1, 0, -1, -2.
    d : int
        Order of the phase difference: 2 Allan and modified Allan, 3 Hadamard.
    m : int
        Averaging factor (tau = m dt_s), >= 1.
    n_phase : int
        Number of phase (angle) points, N = number of rate samples + 1.
    overlapping : bool, keyword-only
        Every start index (stride factor S = m) or one term per tau (S = 1).
    modified : bool, keyword-only
        Modified variance (phase averaged over m points, filter factor F = 1) or not (F = m).

    Returns
    -------
    float
        The EDF (not clipped).

    Raises
    ------
    ConfigError
        Bad arguments, or ``alpha + 2 d <= 1`` (the variance does not converge for that noise).
    InsufficientDataError
        The record holds no complete term (M < 1).

    Notes
    -----
    With ``L = m/F + m d`` phase points per term, ``M = 1 + floor(S (N - L)/m)`` terms,
    ``J = min(M, (d+1) S)`` and ``r = M/S`` ([GR2003]_ eqs. 11-13 and the four cases of its
    Sec. 5):

    * ``J <= 100``: ``1/edf = BasicSum(J, M, S, F) / (M sz(0)^2)`` (eqs. 10, 13); for the
      unmodified variances with alpha <= 0, F = m while ``m (d+1) <= 100``, else F = inf;
    * ``J > 100`` and ``r > d + 1``: ``1/edf = (a0 - a1/r)/r`` (Tables 1-2, constants from
      :func:`greenhall_constants`; alpha = +1 unmodified divides by ``(b0 + b1 ln m)^2``,
      Table 3);
    * ``J > 100`` and ``r <= d + 1``: the basic sum with 100 lags and ``S' = 100/r``;
    * white PM (alpha = +2), unmodified: sx vanishes off the lattice ``t = 0, +-1, ...``, so
      the sum has non-zero terms only at ``j = k S``, k = 1..d; it is summed exactly.

    Examples
    --------
    >>> round(edf_greenhall(0, 2, 16, 1025), 2)        # overlapping AVAR, white FM (Table 5: 93.55)
    88.49
    >>> round(edf_greenhall(0, 2, 16, 1025, modified=True), 2)   # MVAR
    59.73
    >>> round(edf_greenhall(0, 3, 16, 1025), 2)        # overlapping HVAR
    74.35
    """

    a = _check_alpha(alpha)
    if d not in (1, 2, 3) or int(d) != d:
        raise ConfigError(f"d (difference order) must be 1, 2 or 3, got {d!r}")
    if a + 2 * d <= 1:
        raise ConfigError(f"alpha + 2 d must be > 1 for a convergent variance, got alpha={a}, d={d}")
    try:
        mm = int(m)
        N = int(n_phase)
    except (TypeError, ValueError):
        raise ConfigError(f"m and n_phase must be integers, got {m!r}, {n_phase!r}") from None
    if mm != m or mm < 1 or N != n_phase:
        raise ConfigError(f"m must be an integer >= 1 and n_phase an integer, got {m!r}, {n_phase!r}")
    F = 1.0 if modified else float(mm)
    S = float(mm) if overlapping else 1.0
    L = mm / F + mm * d
    M = 1.0 + math.floor(S * (N - L) / mm)
    if M < 1:
        raise InsufficientDataError(
            f"{N} phase points hold no complete term at m={mm} (needs {int(L) + 1})", needed=int(L) + 1, got=N
        )
    J = min(M, (d + 1) * S)
    r = M / S

    if not modified and a == 2:
        # sx(t, m, 2) = m^2 (|t - 1/m| + |t + 1/m| - 2|t|) is 2m at t = 0 and 0 for |t| >= 1/m:
        # only lags j = k S (t = k integer) contribute; sum them exactly for every M.
        sz_k = [float(_sz(float(k), F, 2, d)) for k in range(d + 1)]
        total = sz_k[0] ** 2
        for k in range(1, d + 1):
            j = k * S
            if j <= J - 1:
                total += 2.0 * (1.0 - j / M) * sz_k[k] ** 2
            elif j == J:
                total += (1.0 - J / M) * sz_k[k] ** 2
        return M * sz_k[0] ** 2 / total

    if modified:
        if J <= _JMAX:
            return M * float(_sz(0.0, 1.0, a, d)) ** 2 / _basic_sum(J, M, S, 1.0, a, d)
        if r > d + 1:
            a0, a1 = _constants(a, d, True)
            return 1.0 / ((a0 - a1 / r) / r)
        return _JMAX * float(_sz(0.0, 1.0, a, d)) ** 2 / _basic_sum(_JMAX, _JMAX, _JMAX / r, 1.0, a, d)

    if a <= 0:
        if J <= _JMAX:
            Fp = float(mm) if mm * (d + 1) <= _JMAX else math.inf
            return M * float(_sz(0.0, Fp, a, d)) ** 2 / _basic_sum(J, M, S, Fp, a, d)
        if r > d + 1:
            a0, a1 = _constants(a, d, False)
            return 1.0 / ((a0 - a1 / r) / r)
        return _JMAX * float(_sz(0.0, math.inf, a, d)) ** 2 / _basic_sum(_JMAX, _JMAX, _JMAX / r, math.inf, a, d)

    # alpha = +1 (flicker PM), unmodified
    if J <= _JMAX:
        return M * float(_sz(0.0, float(mm), 1, d)) ** 2 / _basic_sum(J, M, S, float(mm), 1, d)
    b0, b1 = _table3(d)
    norm = (b0 + b1 * math.log(mm)) ** 2
    if r > d + 1:
        a0, a1 = _constants(1, d, False)
        return norm * r / (a0 - a1 / r)
    mp = _JMAX / r
    return norm * _JMAX / _basic_sum(_JMAX, _JMAX, mp, mp, 1, d)


# ----------------------------------------------------------------------------------------
# Confidence bounds
# ----------------------------------------------------------------------------------------
def chi2_bounds(var, edf, confidence) -> tuple[np.ndarray, np.ndarray]:
    """Chi-squared confidence bounds of a variance estimate ([SP1065]_ Sec. 5.3, eqs. 44-45).

    Parameters
    ----------
    var : array_like
        Variance estimates.
    edf : array_like
        Their equivalent degrees of freedom (> 0), same shape.
    confidence : float
        Two-sided confidence level in (0, 1), e.g. :data:`P68` or 0.95.

    Returns
    -------
    lo, hi : ndarray
        ``var edf / chi2.ppf(1 - q/2, edf)`` and ``var edf / chi2.ppf(q/2, edf)``,
        ``q = 1 - confidence`` (variance units; take square roots for a deviation).

    Examples
    --------
    >>> lo, hi = chi2_bounds([1.0], [93.5471], P68)
    >>> round(float(lo[0]), 6), round(float(hi[0]), 6)
    (0.872829, 1.170539)
    """
    from scipy.special import chdtri  # inverse survival function of chi^2: chdtri(df, q)

    if not 0.0 < float(confidence) < 1.0:
        raise ConfigError(f"confidence must be in (0, 1), got {confidence!r}")
    v = np.asarray(var, dtype=np.float64)
    e = np.asarray(edf, dtype=np.float64)
    q = 1.0 - float(confidence)
    lo = v * e / chdtri(e, q / 2.0)  # chi2.ppf(1 - q/2, edf)
    hi = v * e / chdtri(e, 1.0 - q / 2.0)  # chi2.ppf(q/2, edf)
    return lo, hi


# ----------------------------------------------------------------------------------------
# Which alpha at each tau
# ----------------------------------------------------------------------------------------
def local_slopes(x, y, half_width=math.log(2.0)) -> np.ndarray:
    """Least-squares slope of ``y`` against ``x`` at each point over the points within ``half_width`` of it
    (``|x_j - x_i| <= half_width (1 + 1e-9)``; the 3 nearest points where that leaves fewer than 2).

    O(n) for any grid: each window is a ``searchsorted`` range of the sorted ``x`` and its sums come from prefix
    sums of ``x - x0``, ``y - y0``, their squares and product (``x0``, ``y0`` the means: the windows' centred sums
    lose at most ``eps max(x - x0)^2 / var_window(x)`` to cancellation, ~1e-13 on an Allan grid).

    Examples
    --------
    >>> local_slopes(np.log([1.0, 2, 4, 8, 16]), 0.5 * np.log([1.0, 2, 4, 8, 16])).round(12).tolist()
    [0.5, 0.5, 0.5, 0.5, 0.5]
    """
    x = np.asarray(x, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    n = x.size
    order = np.argsort(x, kind="stable")
    xs, ys = x[order], y[order]
    xs0, ys0 = xs - xs.mean(), ys - ys.mean()
    c = half_width * (1 + 1e-9)
    lo = np.searchsorted(xs0, xs0 - c, side="left")
    hi = np.searchsorted(xs0, xs0 + c, side="right")

    def prefix(v):
        return np.concatenate([[0.0], np.cumsum(v)])

    px, py, pxx, pxy = prefix(xs0), prefix(ys0), prefix(xs0 * xs0), prefix(xs0 * ys0)
    k = (hi - lo).astype(np.float64)
    sx, sy = px[hi] - px[lo], py[hi] - py[lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        out = ((pxy[hi] - pxy[lo]) - sx * sy / k) / ((pxx[hi] - pxx[lo]) - sx * sx / k)
    for i in np.flatnonzero(k < 2):  # sparse grid: the nearest neighbours
        j = np.argsort(np.abs(xs - xs[i]))[:3] if n >= 3 else np.arange(n)
        u = xs[j] - xs[j].mean()
        out[i] = np.dot(u, ys[j] - ys[j].mean()) / np.dot(u, u)
    res = np.empty(n)
    res[order] = out
    return res


def alpha_from_slope(tau_s, var, slopes, candidates) -> np.ndarray:
    """Per-tau alpha from the local log-log slope of the deviation.

    The slope mu at each tau is the least-squares slope of log sqrt(var) against log tau over
    the taus within a factor 2 (the 3 nearest taus where that leaves fewer than 2); the alpha
    among ``candidates`` whose expected slope ``slopes[alpha]`` is nearest to mu is chosen
    (ties: the larger expected slope).  For the Allan deviation with candidates (2, 0, -1, -2) this is
    mu < -0.75 -> +2, < -0.25 -> 0, < 0.25 -> -1, else -2.  Taus with zero variance take the
    alpha of the nearest tau with one.
    """
    alpha = np.zeros(tau_s.size, dtype=np.int64)
    ok = var > 0
    if ok.sum() < 2:
        return alpha
    lt = np.log(tau_s[ok])
    ls = 0.5 * np.log(var[ok])
    slope = local_slopes(lt, ls)
    cand = np.array(sorted(candidates, key=lambda a: -slopes[int(a)]), dtype=np.int64)  # ties: larger slope
    mus = np.array([slopes[int(c)] for c in cand])
    alpha[ok] = cand[np.argmin(np.abs(slope[:, None] - mus[None, :]), axis=1)]
    if not ok.all():
        idx = np.flatnonzero(ok)
        for i in np.flatnonzero(~ok):
            alpha[i] = alpha[idx[np.argmin(np.abs(idx - i))]]
    return alpha


def resolve_alpha(noise_alpha, tau_s, var, *, slopes, candidates):
    """``(alphas, rule)`` for ``noise_alpha`` = "auto", "conservative", an int or an array.

    Returns the string ``"conservative"`` instead of an array for that mode (the caller picks
    the smallest EDF per tau).  ``rule`` describes the choice in words.
    """
    if isinstance(noise_alpha, str):
        if noise_alpha == "auto":
            mus = ", ".join(f"{a:+d}: {slopes[a]:+g}" for a in sorted(candidates, reverse=True))
            return (
                alpha_from_slope(tau_s, var, slopes, candidates),
                f"alpha per tau from the local log-log deviation slope mu (taus within x2), nearest of ({mus})",
            )
        if noise_alpha == "conservative":
            cands = ", ".join(f"{a:+d}" for a in sorted(candidates, reverse=True))
            return "conservative", f"alpha per tau giving the smallest EDF among {cands}"
        raise ConfigError(
            f"noise_alpha must be 'auto', 'conservative', an int or an array, got {noise_alpha!r}"
        )
    arr = np.asarray(noise_alpha)
    if arr.ndim == 0:
        arr = np.full(tau_s.size, arr)
    if arr.shape != tau_s.shape:
        raise ConfigError(f"noise_alpha array must have shape {tau_s.shape} (one per tau), got {arr.shape}")
    if not np.all(np.isin(arr, POWER_LAW_ALPHAS)):
        raise ConfigError(f"noise_alpha values must be in (2, 1, 0, -1, -2), got {np.unique(arr).tolist()}")
    return arr.astype(np.int64), "alpha given by the caller"


def periodic_alpha(alphas, periodic) -> tuple[np.ndarray, str]:
    """``(alphas, rule)`` with every phase-noise alpha (+2 white PM, +1 flicker PM) replaced by 0 (white FM) when the
    series holds periodic content (``periodic`` true: the spectrum found a line).

    A periodic error's Allan variance ``Omega0^2 sin^4(pi f tau) / (pi f tau)^2`` (IEEE Std 952-1997 Annex C) falls
    like tau^-2, the slope of quantization; the slope rule would then give those taus the white-PM EDF (about
    ``N / m``: tens of thousands), i.e. intervals of ~1 %, although the estimate of a line's contribution is far
    less certain (its amplitude wanders; the curve oscillates between the line's nulls).  White FM's EDF (the
    simple EDF at alpha = 0, well below white PM's once m > 1) is the conservative choice; the noise fit's
    covariance makes the same one for its S term (white rate noise as the stand-in).
    Where ``periodic`` is false the alphas are returned unchanged.

    Examples
    --------
    >>> periodic_alpha(np.array([2, 0, -1]), True)[0].tolist()
    [0, 0, -1]
    >>> periodic_alpha(np.array([2, 0, -1]), False)[0].tolist()
    [2, 0, -1]
    """
    a = np.asarray(alphas, dtype=np.int64).copy()
    if not periodic:
        return a, ""
    hit = a > 0
    a[hit] = 0
    return a, ("; periodic content in the spectrum: white FM (alpha 0) instead of a phase-noise alpha at "
               f"{int(hit.sum())} tau(s) whose slope a spectral line explains")
