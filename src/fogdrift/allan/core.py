"""The entry point :func:`allan_variance`: one statistic of the Allan family at a grid of taus.

``statistic=`` picks the difference operator (:data:`~fogdrift.allan.statistics.STATISTICS`:
Allan, Hadamard, modified Allan); ``estimator=`` picks the sampling of start indices:

``"overlapping"`` (default)
    every start index, e.g. for the Allan variance
    ``sum_{k=0}^{N-2m} (p_{k+2m} - 2 p_{k+m} + p_k)^2 / (2 tau^2 (N-2m+1))``.
``"non-overlapping"``
    start indices ``0, m, 2m, ...`` only (``K - 1`` Allan or ``K - 2`` Hadamard terms,
    ``K = floor(N/m)``).
``"fast"`` (Allan only)
    exact overlapping for ``m < 2 * FAST_M0`` (``FAST_M0 = 4``); for larger ``m`` the same
    squared second differences are summed over every ``b``-th start index only,
    ``b = 2^floor(log2(m / FAST_M0))`` (so at least ``FAST_M0`` overlapping offsets per
    cluster length remain).  Each term is an exact term of the overlapping sum, so the
    estimator is unbiased and the taus are exactly those requested; only its variance is
    larger.  Its EDF is the Table-5 value of the series decimated by ``b`` (``N/b + 1``
    points, ``m/b``), never more than the fully overlapping EDF; for white FM the loss is at
    most about 7 %.  For b >= 8 every term touches its own cache lines, so the cost of a tau
    falls like 1/b.

Numerics (safe for 10^8 samples): the mean is removed before integrating (every statistic is
invariant to a constant rate), the angle is accumulated by blocked summation (a running sum
inside each block of 65536 samples, block offsets accumulated with Neumaier compensation, so
rounding grows with the block length, not with N), and the squared differences are summed per
block of start indices and the block sums added pairwise.  A 1e4 deg/h offset on unit noise
changes the result by < 1e-9 relative (tested).  Extra memory is one float64 angle array of
N + 1 points (plus the float64 copy of the input if it was not float64 already), except for the
overlapping Allan deviation on grids with few long lags (octave, decade; at least
:data:`~fogdrift.allan._kernels.FUSED_MIN` samples): there one fused pass
(:func:`~fogdrift.allan._kernels.allan_sums_fused`) rebuilds the angle block by block where the
operator reads it and never stores it, with the same sums bit for bit (``progress`` is then
called once, at the end).
"""

from __future__ import annotations

import math

import numpy as np

from .._util import check_series
from ..errors import ConfigError, InsufficientDataError
from ..units import check_dt_s
from . import _kernels
from .ci import P68, chi2_bounds, edf_greenhall, edf_simple_safe, edf_simple_safe_array, resolve_alpha
from .grid import tau_grid
from .result import AllanResult
from .statistics import get_statistic

__all__ = ["allan_variance", "result_from_sums", "choose_alphas", "IEEE952_ALPHAS", "FAST_M0"]

#: ``noise_alpha="auto"`` trusts a phase-noise slope (alpha > 0, white PM: EDF ~ N/2 even at long tau) only
#: where at least this many averaging intervals m fit in the record; below it the smallest EDF among the
#: IEEE-952 alphas is used (on the PSINS RLG the tau^-1 fall at 328 s -- 5.6 intervals, a bounded platform
#: disturbance -- was given EDF 72 000 and a +-0.5 % interval).
AUTO_MIN_INTERVALS = 16

#: Power-law exponents of the IEEE-952 noise terms (Q: +2 white PM, N: 0 white FM,
#: B: -1 flicker FM, K: -2 random-walk FM), used by ``noise_alpha="auto"``/``"conservative"``.
IEEE952_ALPHAS = (2, 0, -1, -2)

#: Fast estimator: exact for m < 2*FAST_M0, otherwise at least FAST_M0 offsets per cluster.
FAST_M0 = 4


def _fast_strides(m: np.ndarray) -> np.ndarray:
    """Start-index strides b of the fast estimator: 1 for m < 2*FAST_M0, else 2^floor(log2(m/FAST_M0))."""
    b = np.ones_like(m)
    big = m >= 2 * FAST_M0
    b[big] = 2 ** np.floor(np.log2(m[big] / FAST_M0)).astype(np.int64)
    return b


def allan_variance(
    y,
    dt_s,
    *,
    taus="octave",
    estimator="overlapping",
    statistic="adev",
    noise_alpha="auto",
    max_fraction=0.25,
    progress=None,
) -> AllanResult:
    """An Allan-family variance and deviation of a rate series, with EDF and chi-squared bounds.

    Parameters
    ----------
    y : array_like, shape (n_samples,)
        The series at a constant sample interval, finite, in its channel's internal unit (an angular rate in deg/h,
        a specific force in m/s^2: :data:`fogdrift.units.INTERNAL_UNITS`); the deviations are in that unit.
    dt_s : float
        Sample interval tau0 in s.
    taus : str, int or array_like, keyword-only
        Tau grid, see :func:`~fogdrift.allan.tau_grid` (``"octave"``, ``"decade"``, ``"all"``,
        an int for that many log-spaced taus, or an array of tau in s).
    estimator : {"overlapping", "non-overlapping", "fast"}, keyword-only
        Sampling of start indices (module docstring).  ``statistic="hdev"`` supports
        overlapping and non-overlapping, ``"mdev"`` overlapping only; other combinations
        raise ConfigError.
    statistic : {"adev", "hdev", "mdev"}, keyword-only
        Allan (default), Hadamard or modified Allan deviation: the difference operator
        (:data:`~fogdrift.allan.STATISTICS`).
    noise_alpha : "auto", "conservative", int or array_like, keyword-only
        Power-law alpha used for the EDF at each tau.  ``"auto"`` (default): from the local
        log-log slope mu of the deviation (least-squares slope over the taus within a factor 2
        of each tau), mapped to the IEEE-952 type (alpha = +2, 0, -1, -2) whose slope for this
        statistic is nearest; for the Allan deviation mu < -0.75 -> +2 (Q), < -0.25 -> 0 (N),
        < +0.25 -> -1 (B), otherwise -2 (K; also used for a ramp).  A phase-noise type (alpha > 0)
        is trusted only where at least :data:`AUTO_MIN_INTERVALS` intervals m fit in the record;
        elsewhere the smallest EDF among the IEEE-952 types is used.
        ``"conservative"``: the smallest EDF among alpha = 2, 0, -1, -2 at each tau.
        An int or an array of shape (n_tau,) fixes alpha (2, 1, 0, -1 or -2).
    max_fraction : float, keyword-only
        Largest m of named/int grids as a fraction of N (see :func:`~fogdrift.allan.tau_grid`).
    progress : callable or None, keyword-only
        Called as ``progress(done, total)`` with the number of taus finished.

    Returns
    -------
    AllanResult
        With ``statistic`` set; ``var``/``dev`` hold the statistic (for ``"adev"``
        also readable as ``avar_dph2``/``adev_dph``), in the series' unit.

    Raises
    ------
    DataFormatError
        ``y`` is not a finite 1-D numeric array.
    InsufficientDataError
        Fewer than 2 samples (3 for the Hadamard deviation).
    ConfigError
        Bad ``dt_s``, ``taus``, ``estimator``, ``statistic``, their combination, or
        ``noise_alpha``.

    Notes
    -----
    With the angle ``p`` (N + 1 points, module docstring of :mod:`fogdrift.allan.statistics`):

    * Allan, overlapping ([SP1065]_ eq. 11, method notes 2.1)::

        sigma^2(tau) = 1 / (2 tau^2 (N - 2m + 1)) * sum_{k=0}^{N-2m} (p_{k+2m} - 2 p_{k+m} + p_k)^2

      non-overlapping ([SP1065]_ eq. 7): ``sum_j (ybar_{j+1} - ybar_j)^2 / (2 (K - 1))``.
    * Hadamard, overlapping ([SP1065]_ eq. 20)::

        sigma_H^2(tau) = 1 / (6 tau^2 (N - 3m + 1)) * sum_{k=0}^{N-3m} (p_{k+3m} - 3 p_{k+2m} + 3 p_{k+m} - p_k)^2

      non-overlapping ([SP1065]_ eqs. 17-18): ``sum_j (ybar_{j+2} - 2 ybar_{j+1} + ybar_j)^2 / (6 (K - 2))``.
    * Modified Allan ([SP1065]_ eq. 14)::

        mod sigma^2(tau) = 1 / (2 m^2 tau^2 (N - 3m + 2))
                           * sum_{j=0}^{N-3m+1} ( sum_{i=j}^{j+m-1} p_{i+2m} - 2 p_{i+m} + p_i )^2

    EDF: Allan -- :func:`~fogdrift.allan.edf_simple` with ``n_phase = N + 1`` (overlapping),
    with the ``K + 1`` cluster-mean phase points and m = 1 (non-overlapping, i.e. the
    overlapping formula on the decimated series), or ``floor(N/b) + 1`` points and ``m/b`` but
    at most the overlapping value (fast); Hadamard and modified Allan --
    :func:`~fogdrift.allan.edf_greenhall` (d = 3, or d = 2 modified; stride factor m for
    overlapping, 1 for non-overlapping).  Clipped to ``[1, n_terms]``.  Bounds
    (:func:`~fogdrift.allan.chi2_bounds`): ``var * edf / chi2_{1-p/2}(edf)`` to
    ``var * edf / chi2_{p/2}(edf)``, square-rooted for the deviation.

    References
    ----------
    .. [SP1065] W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065 (2008).

    Examples
    --------
    >>> r = allan_variance([1, 3, 2, 5, 4, 4, 6, 3], 1.0, taus=[1, 2, 3])
    >>> [round(float(v), 10) for v in r.avar_dph2]
    [2.0, 0.7, 1.2777777778]
    >>> h = allan_variance([1, 3, 2, 5, 4, 4, 6, 3], 1.0, taus=[1, 2], statistic="hdev")
    >>> h.statistic, [round(float(v), 10) for v in h.var]
    ('hdev', [1.9722222222, 0.1805555556])
    """
    stat = get_statistic(statistic)
    y = np.ascontiguousarray(check_series(y, "y"))
    dt = check_dt_s(dt_s)
    stat.check_sampling(estimator)
    n = y.size
    if n < 2:
        raise InsufficientDataError(f"an Allan variance needs at least 2 rate samples, got {n}", needed=2, got=n)
    m = tau_grid(n, dt, taus, max_fraction=max_fraction, statistic=stat.name)
    if estimator == "fast":
        strides = _fast_strides(m)
    elif estimator == "non-overlapping":
        strides = m.copy()
    else:
        strides = np.ones_like(m)
    if progress is not None and not callable(progress):
        raise ConfigError(f"progress must be a callable(done, total) or None, got {progress!r}")

    if stat.name == "adev" and estimator == "overlapping" and _kernels.fused_lags(n, m) is not None:
        # every tau in one pass over the rate, the angle never stored; the same sums bit for bit
        sums = _kernels.allan_sums_fused(y, m)
        if progress is not None:
            progress(m.size, m.size)
        return result_from_sums(sums, n, m, strides, dt, statistic=stat.name, estimator=estimator,
                                noise_alpha=noise_alpha)
    p = _kernels.phase_dph_samples(y)
    sums = np.empty(m.size)
    if progress is None:
        groups = [np.arange(m.size)]
    else:
        groups = np.array_split(np.arange(m.size), max(1, math.ceil(m.size / 8)))
    done = 0
    for g in groups:
        sums[g] = _kernels.operator_sums(p, m[g], strides[g], stat.coefficients, stat.windowed)
        done += g.size
        if progress is not None:
            progress(done, m.size)
    del p

    return result_from_sums(sums, n, m, strides, dt, statistic=stat.name, estimator=estimator,
                            noise_alpha=noise_alpha)


def choose_alphas(noise_alpha, tau_s, var, stat, edf_of, few_intervals, *, edf_many=None):
    """The noise type (power-law alpha) and EDF of each tau: ``noise_alpha`` resolved (:func:`resolve_alpha`),
    ``"conservative"`` the smallest EDF among the IEEE-952 alphas; with ``"auto"``, where ``few_intervals`` (fewer
    than :data:`AUTO_MIN_INTERVALS` averaging intervals fit in the record) and the slope says phase noise, the
    smallest EDF too (a bounded disturbance at long tau looks the same).  ``edf_of(i, alpha)`` is the EDF rule;
    ``edf_many(idx, alphas)``, when given, the same rule over arrays of tau numbers and alphas (one call instead of
    one per tau: thousands of taus with ``--taus all``).  Returns ``(alphas, edf, rule)``."""
    m_size = len(tau_s)

    def many(idx, a):
        if edf_many is not None:
            return np.asarray(edf_many(idx, a), dtype=np.float64)
        return np.array([edf_of(i, b) for i, b in zip(idx.tolist(), a.tolist())], dtype=np.float64)

    def candidates(idx):  # (len(idx), n_alphas): every IEEE-952 alpha's EDF at each tau
        return np.column_stack([many(idx, np.full(idx.size, a, dtype=np.int64)) for a in IEEE952_ALPHAS]) \
            if idx.size else np.empty((0, len(IEEE952_ALPHAS)))

    alphas, rule = resolve_alpha(noise_alpha, tau_s, var, slopes=stat.dev_slopes, candidates=IEEE952_ALPHAS)
    if isinstance(alphas, str):  # conservative
        cands = candidates(np.arange(m_size))
        pick = np.argmin(cands, axis=1)
        return np.asarray(IEEE952_ALPHAS, dtype=np.int64)[pick], cands[np.arange(m_size), pick], rule
    alphas = np.array(alphas, dtype=np.int64)
    edf = many(np.arange(m_size), alphas)
    if isinstance(noise_alpha, str):  # auto: a phase-noise slope at long tau is not evidence of phase noise
        few = np.flatnonzero((alphas > 0) & np.asarray(few_intervals, dtype=bool))
        if few.size:
            cand = candidates(few)
            k = np.nanargmin(cand, axis=1)
            best = cand[np.arange(few.size), k]
            take = best < edf[few]
            alphas[few[take]] = np.asarray(IEEE952_ALPHAS, dtype=np.int64)[k[take]]
            edf[few[take]] = best[take]
            rule += (f"; where fewer than {AUTO_MIN_INTERVALS} averaging intervals fit in the record and the "
                     "slope says phase noise (alpha > 0: a bounded disturbance at long tau looks the same), "
                     "the smallest EDF among the IEEE-952 alphas")
    return alphas, edf, rule


def result_from_sums(sums, n, m, strides, dt_s, *, statistic, estimator, noise_alpha) -> AllanResult:
    """The :class:`AllanResult` (variance, EDF, alpha, bounds, every field) from the operator sums.

    The one place where sums of squared differences become a result: :func:`allan_variance` and the
    out-of-core :func:`fogdrift.allan.chunked.allan_variance_chunked` both end here, so equal sums give
    equal results field by field.

    Parameters
    ----------
    sums : ndarray, shape (n_tau,)
        Per-tau sums of the squared difference operator over the sampled start indices, with the
        angle in (deg/h) x samples (:func:`fogdrift.allan._kernels.phase_dph_samples`; phase
        points, not window means, for a windowed statistic): (deg/h)^2 x samples^2, as
        :meth:`~fogdrift.allan.statistics.Statistic.variance` takes them.
    n : int
        Number of rate samples N.
    m, strides : ndarray of int, shape (n_tau,)
        Averaging factors and start-index strides (1 overlapping, m non-overlapping, b fast).
    dt_s : float
        Sample interval in s.
    statistic : {"adev", "hdev", "mdev"}, keyword-only
    estimator : {"overlapping", "non-overlapping", "fast"}, keyword-only
    noise_alpha : "auto", "conservative", int or array_like, keyword-only
        As for :func:`allan_variance`.

    Returns
    -------
    AllanResult
    """
    stat = get_statistic(statistic)
    m = np.asarray(m, dtype=np.int64)
    strides = np.asarray(strides, dtype=np.int64)
    dt = float(dt_s)
    n_terms = stat.n_terms(n, m, strides)
    var = stat.variance(sums, m, n_terms)
    tau_s = m * dt

    edf_of, edf_many, cap_many, base = _edf_rule(stat, estimator, n, m, strides)
    alphas, edf, rule = choose_alphas(noise_alpha, tau_s, var, stat, edf_of, n < AUTO_MIN_INTERVALS * m,
                                      edf_many=edf_many)
    if cap_many is not None:  # a strided (fast) sum cannot have more EDF than the full overlapping one
        edf = np.minimum(edf, cap_many(np.arange(m.size), alphas))
    edf = np.clip(np.nan_to_num(edf, nan=1.0, posinf=float(n_terms.max())), 1.0, np.maximum(n_terms, 1))

    lo68, hi68 = chi2_bounds(var, edf, P68)
    lo95, hi95 = chi2_bounds(var, edf, 0.95)
    return AllanResult(
        tau_s=tau_s.astype(np.float64),
        m=m.astype(np.int64),
        var=var,
        dev=np.sqrt(var),
        n_terms=n_terms.astype(np.int64),
        edf=edf,
        dev_lo68=np.sqrt(lo68),
        dev_hi68=np.sqrt(hi68),
        dev_lo95=np.sqrt(lo95),
        dev_hi95=np.sqrt(hi95),
        noise_alpha=np.asarray(alphas, dtype=np.int64),
        estimator=estimator,
        edf_rule=base + "; " + rule,
        dt_s=dt,
        n_samples=int(n),
        statistic=stat.name,
    )


def _edf_rule(stat, estimator, n, m, strides):
    """``(edf_of(i, alpha), edf_many(idx, alphas) or None, cap_many(idx, alphas) or None, description)`` for a
    statistic and sampling.

    ``edf_of`` is the unclipped EDF of tau number i (``edf_many`` the same over arrays, for the closed-form rules);
    ``cap_many`` an upper bound applied after alpha is chosen (the fast estimator's EDF never exceeds the
    overlapping one).
    """
    n_phase = n + 1
    if stat.edf_method == "greenhall":
        overlapping = estimator == "overlapping"

        def edf_of(i, a):
            return edf_greenhall(int(a), stat.order, int(m[i]), n_phase, overlapping=overlapping,
                                 modified=stat.windowed)

        text = (f"Greenhall-Riley EDF (d={stat.order}{', modified' if stat.windowed else ''}, "
                f"{'stride factor m' if overlapping else 'stride factor 1'}) with N+1 phase points")
        return edf_of, None, None, text

    # Allan deviation: phase points and averaging factor of the series whose overlapping
    # Table-5 EDF applies
    if estimator == "overlapping":
        edf_n, edf_m = np.full(m.size, n_phase), m
        text = "simple EDF (Howe-Allan-Barnes, SP 1065 Table 5) with N+1 phase points"
    elif estimator == "non-overlapping":
        edf_n, edf_m = n // m + 1, np.ones_like(m)
        text = "simple EDF (SP 1065 Table 5) of the K+1 cluster-mean phase points at m=1"
    else:
        edf_n, edf_m = n / strides + 1, m / strides
        text = "simple EDF (SP 1065 Table 5) of the block-averaged series (N/b+1 points, m/b)"

    def edf_of(i, a):
        return edf_simple_safe(edf_n[i], edf_m[i], a)

    def edf_many(idx, a):
        return edf_simple_safe_array(edf_n[idx], edf_m[idx], a)

    def cap_many(idx, a):
        return edf_simple_safe_array(n_phase, m[idx], a)

    return edf_of, edf_many, (cap_many if estimator == "fast" else None), text
