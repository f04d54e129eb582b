"""Model-based covariance of Allan-family variance estimates at arbitrary averaging factors.

For a Gaussian rate process with two-sided per-sample spectrum ``S(f)`` (``|f| <= 1/2``, sample interval as the
time unit) every estimator of the Allan family is the mean of ``M`` squared outputs of a linear filter with squared
gain ``|G_m(f)|^2``.  For large ``M`` ([PW2000]_ §8.3, the same argument as for the wavelet variance; method notes
§9)::

    E sigma2_m            = int_{-1/2}^{1/2} |G_m(f)|^2 S(f) df
    Cov(sigma2_i, sigma2_j) = 2 / sqrt(M_i M_j) int_{-1/2}^{1/2} |G_i(f)|^2 |G_j(f)|^2 S(f)^2 df

with, for ``tau = m dt`` (``D_m`` the Dirichlet kernel of an ``m``-sample mean):

========  ======================================================  ===========
statistic squared gain ``|G_m(f)|^2``                             terms ``M``
========  ======================================================  ===========
adev      ``2 sin^4(pi f m) / (m^2 sin^2(pi f))``                 ``N - 2m + 1``
hdev      ``(8/3) sin^6(pi f m) / (m^2 sin^2(pi f))``             ``N - 3m + 1``
mdev      ``2 sin^6(pi f m) / (m^4 sin^4(pi f))``                 ``N - 3m + 2``
========  ======================================================  ===========

(Allan: half the squared difference of adjacent ``m``-means; Hadamard: a sixth of the squared second difference
of ``m``-means; modified Allan: the Allan filter followed by an ``m``-sample mean.)

Quadrature.  The integrands oscillate with period ``1/m`` in ``f``; a uniform grid fine enough for the largest
``m`` would need ``~8 m_max`` points per tau.  Instead the frequency axis is cut into log-spaced cells (48 per
octave from ``1e-3/m_max`` to ``1/2``; 16 cells per octave change the standard deviations by < 4e-4 relative against 48); in each cell the slowly varying factor ``S^2/sin^{2q}(pi f)`` is taken at the
cell centre and the oscillating factor ``sin^{2p}(pi f m_i) sin^{2p}(pi f m_j)`` is averaged over the cell
*exactly* (it is a finite cosine series; in cells where it varies slowly it is evaluated directly, which avoids
cancellation).  Against Monte Carlo (white + random walk, N = 2^16, 400 replicates) the standard deviations agree
within the replicate error (3.5 %) and the adjacent-tau correlations within 0.04 (tests).  Cost: ``O(n_tau^2 *
n_cells)`` with ``n_cells ~ 48 log2(500 m_max)``; 18 octave taus take ~0.03 s, 40 taus ~0.15 s.

Limits.  The large-``M`` formula overstates the standard deviation where ``m`` is a sizeable fraction of ``N``
(about +7 % at ``m = N/8`` and +20 % at ``m = N/4`` in the Monte Carlo check): intervals there are conservative.

References
----------
.. [PW2000] D. B. Percival, A. T. Walden, *Wavelet Methods for Time Series Analysis*, Cambridge (2000), §8.3.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError

__all__ = ["FilterSpec", "FILTERS", "estimator_covariance", "expected_variance", "n_terms",
           "ramp_cross_variance"]


@dataclass(frozen=True)
class FilterSpec:
    """``|G_m(f)|^2 = gain * sin^(2p)(pi f m) / (m^m_power * sin^(2q)(pi f))``; ``M = N - span*m + extra``."""

    name: str
    gain: float
    p: int
    q: int
    m_power: int
    span: int
    extra: int


#: Squared-gain table of each statistic (see the module docstring).
FILTERS: dict[str, FilterSpec] = {
    "adev": FilterSpec("adev", 2.0, 2, 1, 2, 2, 1),
    "hdev": FilterSpec("hdev", 8.0 / 3.0, 3, 1, 2, 3, 1),
    "mdev": FilterSpec("mdev", 2.0, 3, 2, 4, 3, 2),
}

#: cos(2 k x) coefficients of sin^(2p) x, k = 0..p.
_SIN_POWER = {2: np.array([3 / 8, -1 / 2, 1 / 8]), 3: np.array([10 / 32, -15 / 32, 6 / 32, -1 / 32])}

_KERNEL = {}


def _spec(statistic) -> FilterSpec:
    try:
        return FILTERS[statistic]
    except KeyError:
        raise ConfigError(f"no covariance model for statistic {statistic!r}; expected one of {sorted(FILTERS)}") from None


def n_terms(m, n_samples, statistic="adev") -> np.ndarray:
    """Number of overlapping terms ``M`` of the statistic at averaging factors ``m`` for ``n_samples`` rates."""
    f = _spec(statistic)
    return n_samples - f.span * np.asarray(m, dtype=np.float64) + f.extra


def _cells(m_max: float, per_octave: int):
    f_min = 1e-3 / m_max
    n_oct = math.log2(0.5 / f_min)
    edges = 0.5 * 2.0 ** (-np.linspace(n_oct, 0.0, int(math.ceil(n_oct * per_octave)) + 1))
    return edges[:-1].copy(), edges[1:].copy()


def _kernel():
    if "cov" not in _KERNEL:
        import numba

        @numba.njit(cache=True)
        def cov(m, a, b, P, coef, out):  # pragma: no cover - compiled
            """out[i, j] = sum_cells mean_cell[sin^2p(pi f m_i) sin^2p(pi f m_j)] P_cell (coef: cos series)."""
            nm = m.size
            nc = a.size
            nk = coef.size
            pw = 2 * (nk - 1)
            # sin(w b[c]) of the previous cell, per (p, q, sign): the cells tile the band (b[c - 1] == a[c]), so it
            # is this cell's sin(w a[c]), the same number (half the sines)
            upper = np.empty(2 * nk * nk)
            for i in range(nm):
                for j in range(i, nm):
                    mi = m[i]
                    mj = m[j]
                    mx = max(mi, mj)
                    acc = 0.0
                    known = False
                    for c in range(nc):
                        d = b[c] - a[c]
                        fm = 0.5 * (a[c] + b[c])
                        if mx * d < 0.1:
                            si = abs(math.sin(math.pi * fm * mi))
                            sj = abs(math.sin(math.pi * fm * mj))
                            v = si**pw * sj**pw
                            known = False
                        else:
                            reuse = known and b[c - 1] == a[c]
                            v = 0.0
                            k = 0
                            for p in range(nk):
                                for q in range(nk):
                                    cc = 0.5 * coef[p] * coef[q]
                                    for sgn in (-1.0, 1.0):
                                        w = 2.0 * math.pi * (p * mi + sgn * q * mj)
                                        x = w * d
                                        sb = math.sin(w * b[c])
                                        sa = upper[k] if reuse else math.sin(w * a[c])
                                        upper[k] = sb
                                        k += 1
                                        if abs(x) < 1e-6:
                                            v += cc * math.cos(w * fm)
                                        else:
                                            v += cc * (sb - sa) / x
                            known = True
                        acc += v * P[c]
                    out[i, j] = acc
                    out[j, i] = acc

        _KERNEL["cov"] = cov
    return _KERNEL["cov"]


def estimator_covariance(m, n_samples, spectrum, *, statistic="adev", per_octave=16) -> np.ndarray:
    """Covariance matrix of the overlapping estimates at averaging factors ``m`` (per-sample rate units^2 squared).

    Parameters
    ----------
    m : array_like of int, shape (n_tau,)
        Averaging factors (``tau = m dt``).
    n_samples : int
        Number of rate samples ``N``.
    spectrum : callable
        Two-sided per-sample rate spectrum ``S(f)`` for ``0 < f <= 1/2`` (vectorised), e.g. :func:`fogdrift.noise.processes.model_sdf`.
    statistic : {"adev", "hdev", "mdev"}
    per_octave : int
        Quadrature cells per octave of frequency.

    Returns
    -------
    ndarray, shape (n_tau, n_tau)
        ``Cov(sigma2_i, sigma2_j)`` in the squared units of ``S``.

    Examples
    --------
    White noise of unit variance: the relative variance of the overlapping AVAR at ``m`` is about ``2/edf``
    with the white-FM EDF of SP 1065 Table 5 (``(3(N-1)/(2m) - 2(N-2)/N) 4m^2/(4m^2+5)``, N phase points).

    >>> import numpy as np
    >>> v = estimator_covariance([16], 100_000, lambda f: np.ones_like(f))[0, 0]
    >>> edf = (3 * 100_000 / 32 - 2 * 99_999 / 100_001) * 1024 / 1029
    >>> round(float(v / (1 / 16) ** 2 * edf / 2), 2)
    1.0
    """
    spec = _spec(statistic)
    m = np.ascontiguousarray(np.asarray(m, dtype=np.float64))
    M = n_terms(m, n_samples, statistic)
    if m.ndim != 1 or m.size == 0 or np.any(m < 1) or np.any(M < 1):
        raise ConfigError(f"averaging factors must be >= 1 and leave >= 1 term with N = {n_samples}; got {m!r}")
    a, b = _cells(float(m.max()), int(per_octave))
    fm = 0.5 * (a + b)
    P = np.asarray(spectrum(fm), dtype=np.float64) ** 2 / np.sin(np.pi * fm) ** (4 * spec.q) * (b - a)
    S = np.empty((m.size, m.size))
    _kernel()(m, a, b, P, _SIN_POWER[spec.p], S)
    mk = m**spec.m_power
    return 4.0 * spec.gain**2 * S / np.outer(mk, mk) / np.sqrt(np.outer(M, M))


def expected_variance(m, spectrum, *, statistic="adev", per_octave=16) -> np.ndarray:
    """``E sigma2_m = int |G_m|^2 S df`` at averaging factors ``m`` (same quadrature as the covariance).

    Examples
    --------
    >>> import numpy as np
    >>> np.round(expected_variance([1, 4, 64], lambda f: np.ones_like(f)) * [1, 4, 64], 3).tolist()
    [1.0, 1.0, 1.0]
    """
    spec = _spec(statistic)
    m = np.asarray(m, dtype=np.float64)
    a, b = _cells(float(m.max()), int(per_octave))
    fm = 0.5 * (a + b)
    slow_fac = np.asarray(spectrum(fm), dtype=np.float64) / np.sin(np.pi * fm) ** (2 * spec.q) * (b - a)
    coef = _SIN_POWER[spec.p]
    out = np.empty(m.size)
    for k, mk in enumerate(m):
        osc = np.zeros_like(fm)
        for p, c in enumerate(coef):
            w = 2 * np.pi * p * mk
            x = w * (b - a)
            with np.errstate(divide="ignore", invalid="ignore"):
                avg = np.where(np.abs(x) < 1e-6, np.cos(w * fm), (np.sin(w * b) - np.sin(w * a)) / x)
            osc += c * avg
        osc = np.where(mk * (b - a) < 0.1, np.sin(np.pi * fm * mk) ** (2 * spec.p), osc)
        out[k] = 2 * spec.gain * (osc @ slow_fac) / mk**spec.m_power
    return out


def ramp_cross_variance(m, n_samples, spectrum, a_ramp, *, per_octave=16) -> np.ndarray:
    """Variance that a deterministic rate ramp adds to the overlapping Allan-variance estimate (per-sample units).

    With a ramp the second difference of angle is ``d_k + c`` (``c`` constant, ``c^2 / (2 tau^2)`` the ramp's
    Allan variance ``A_R tau^2``), so the estimate gains the cross term ``c mean(d) / tau^2``.  The sum of the
    ``d_k`` telescopes to two boundary blocks of ``m`` overlapping ``m``-sample angle increments (triangular
    weights), hence ``Var = 4 A_R int sin^4(pi f m)/sin^4(pi f) S(f) df / M^2`` (``tau`` in samples; ``A_R`` in
    per-sample units).  Against 200 simulated records (white noise + ramp, 2^18 samples) it predicts the
    measured relative s.d. of the ramp-dominated estimates (1.1e-3 at m = 32768).  A ramp's estimates are far
    more precise than a random process with the same Allan variance; treating it as one would bias the fit.
    """
    m = np.asarray(m, dtype=np.float64)
    M = n_terms(m, n_samples, "adev")
    a, b = _cells(float(m.max()), int(per_octave))
    fm = 0.5 * (a + b)
    slow = np.asarray(spectrum(fm), dtype=np.float64) / np.sin(np.pi * fm) ** 4 * (b - a)
    coef = _SIN_POWER[2]
    out = np.empty(m.size)
    for k, mk in enumerate(m):
        osc = np.zeros_like(fm)
        for p, c in enumerate(coef):
            w = 2 * np.pi * p * mk
            x = w * (b - a)
            with np.errstate(divide="ignore", invalid="ignore"):
                avg = np.where(np.abs(x) < 1e-6, np.cos(w * fm), (np.sin(w * b) - np.sin(w * a)) / x)
            osc += c * avg
        osc = np.where(mk * (b - a) < 0.1, np.sin(np.pi * fm * mk) ** 4, osc)
        out[k] = 2.0 * (osc @ slow)  # both signs of f
    return 4.0 * float(a_ramp) * out / M**2
