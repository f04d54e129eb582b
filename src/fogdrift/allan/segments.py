"""The overlapping Allan variance of several gap-free segments of one record, no gap bridged.

A record cut into pieces (disturbed intervals removed by :func:`fogdrift.screen.screen_record`,
dropouts, separate runs of the same sensor) must not be concatenated: a second difference
that straddles a cut compares angles across the gap and adds a step that the sensor never
made.  Here every segment contributes only the second differences that lie wholly inside it,
and the terms of all segments are pooled with equal weight per term::

    AVAR(tau) = sum_s S_s(m) / (2 m^2 sum_s n_s(m)),
    S_s(m)    = sum_{k=0}^{N_s-2m} (p_{s,k+2m} - 2 p_{s,k+m} + p_{s,k})^2,
    n_s(m)    = N_s - 2m + 1 terms (none where N_s < 2m),

with ``p_s`` the angle of segment s (rate x samples, N_s + 1 points) and tau = m dt.  This is
the average of the per-segment Allan variances weighted by their term counts n_s(m); with one
segment it is :func:`fogdrift.allan.allan_variance` (overlapping) exactly.

EDF: the segments are disjoint stretches of a noise whose Allan terms decorrelate beyond about
2m samples, so their estimates are treated as independent and the EDF is the sum of the
per-segment Table-5 EDFs (:func:`fogdrift.allan.ci.edf_simple`, N_s + 1 phase points) of
the segments that have terms at that tau -- exact for chi-squared estimates that are
independent and have a common scale, and a slight overstatement for segments separated by
less than 2m samples, or for flicker and random-walk noise, whose segments stay correlated
across a short gap.  Clipped to ``[1, n_terms]``; bounds as in :func:`fogdrift.allan.allan_variance`.
"""

from __future__ import annotations

import numpy as np

from .._util import check_series
from ..errors import ConfigError, InsufficientDataError
from ..units import check_dt_s
from . import _kernels
from .ci import P68, chi2_bounds, edf_simple_safe
from .core import AUTO_MIN_INTERVALS, choose_alphas
from .grid import tau_grid
from .result import AllanResult
from .statistics import get_statistic

__all__ = ["allan_variance_segments", "check_segments"]


def check_segments(segments, n_samples: int) -> list[tuple[int, int]]:
    """Segments as sorted, non-overlapping ``(start, stop)`` sample-index pairs inside the record.

    ``stop`` is exclusive (Python slice convention).  Empty segments are dropped.

    Raises
    ------
    ConfigError
        A pair that is not two integers with ``0 <= start <= stop <= n_samples``, or two
        segments that overlap.

    Examples
    --------
    >>> check_segments([(50, 80), (0, 20), (30, 30)], 100)
    [(0, 20), (50, 80)]
    """
    out = []
    try:
        pairs = [tuple(s) for s in segments]
    except TypeError:
        raise ConfigError(f"segments must be (start, stop) sample-index pairs, got {segments!r}") from None
    for pair in pairs:
        if len(pair) != 2:
            raise ConfigError(f"a segment is a (start, stop) pair, got {pair!r}")
        a, b = pair
        if int(a) != a or int(b) != b or not 0 <= int(a) <= int(b) <= n_samples:
            raise ConfigError(f"segment {pair!r} must satisfy 0 <= start <= stop <= {n_samples} (integers)")
        if int(b) > int(a):
            out.append((int(a), int(b)))
    out.sort()
    for (a0, b0), (a1, b1) in zip(out, out[1:]):
        if a1 < b0:
            raise ConfigError(f"segments ({a0}, {b0}) and ({a1}, {b1}) overlap")
    return out


def allan_variance_segments(y, dt_s, segments, *, taus="octave", noise_alpha="auto",
                            max_fraction=0.25) -> AllanResult:
    """The overlapping Allan variance pooled over gap-free segments of one record.

    Parameters
    ----------
    y : array_like, shape (n_samples,)
        The whole record's series in its channel's internal unit (deg/h, m/s^2; the variances are in its square).
    dt_s : float
        Sample interval tau0 in s.
    segments : sequence of (int, int)
        ``(start, stop)`` sample indices, stop exclusive, e.g.
        :attr:`fogdrift.screen.ScreenResult.quiet_segments`.  Must not overlap.
    taus : str, int or array_like, keyword-only
        Tau grid as for :func:`~fogdrift.allan.tau_grid`, built on the longest segment
        (``max_fraction`` of its length for the named grids).  Taus longer than a segment
        allows (``2m > N_s``) take no terms from it; a tau that no segment allows is refused.
    noise_alpha : "auto", "conservative", int or array_like, keyword-only
        As for :func:`~fogdrift.allan.allan_variance` (``"auto"``: the slope of the pooled curve;
        the few-intervals rule uses the longest segment).
    max_fraction : float, keyword-only
        See ``taus``.

    Returns
    -------
    AllanResult
        ``statistic="adev"``, ``estimator="overlapping"``; ``n_terms`` the pooled count
        ``sum_s n_s(m)``, ``n_samples`` the samples inside the segments, ``edf`` the sum of the
        used segments' EDFs (module docstring).  Accepted by :func:`fogdrift.noise.fit_noise`.

    Raises
    ------
    ConfigError
        Bad segments, ``dt_s``, ``taus`` or ``noise_alpha``.
    InsufficientDataError
        No segment of at least 2 samples.

    Notes
    -----
    ``AVAR(tau) = sum_s S_s(m) / (2 m^2 sum_s n_s(m))`` (module docstring): the per-segment
    Allan variances ``S_s / (2 m^2 n_s)`` averaged with weights ``n_s``.

    Examples
    --------
    Two segments of a record whose middle holds a step: no term straddles the cut.

    >>> import numpy as np
    >>> y = np.r_[[1., 3, 2, 5, 4, 4], [100., 100], [6., 3, 5, 1, 2, 2]]
    >>> r = allan_variance_segments(y, 1.0, [(0, 6), (8, 14)], taus=[1, 2])
    >>> r.n_terms.tolist(), r.n_samples, [round(float(v), 6) for v in r.avar_dph2]
    ([10, 6], 12, [2.25, 1.333333])
    """
    y = np.ascontiguousarray(check_series(y, "y"))
    dt = check_dt_s(dt_s)
    segs = [s for s in check_segments(segments, y.size) if s[1] - s[0] >= 2]
    if not segs:
        raise InsufficientDataError("an Allan variance of segments needs a segment of at least 2 samples",
                                    needed=2, got=0)
    stat = get_statistic("adev")
    lengths = np.array([b - a for a, b in segs], dtype=np.int64)
    n_long = int(lengths.max())
    m = tau_grid(n_long, dt, taus, max_fraction=max_fraction, statistic="adev")

    sums = np.zeros(m.size)
    terms = np.zeros(m.size, dtype=np.int64)
    for (a, b), n_s in zip(segs, lengths):
        use = 2 * m <= n_s
        if not use.any():
            continue
        p = _kernels.phase_dph_samples(y[a:b])
        ones = np.ones(int(use.sum()), dtype=np.int64)
        sums[use] += _kernels.operator_sums(p, m[use], ones, stat.coefficients, stat.windowed)
        terms[use] += stat.n_terms(int(n_s), m[use], ones)
    var = stat.variance(sums, m, terms)
    tau_s = (m * dt).astype(np.float64)

    def edf_of(i, a):
        """Sum of the Table-5 EDFs of the segments with terms at tau number i."""
        used = lengths[2 * m[i] <= lengths]
        return float(sum(edf_simple_safe(int(n_s) + 1, int(m[i]), a) for n_s in used))

    # the same noise-type and phase-noise caution as allan_variance (the few-intervals rule on the longest segment)
    alphas, edf, rule = choose_alphas(noise_alpha, tau_s, var, stat, edf_of, n_long < AUTO_MIN_INTERVALS * m)
    edf = np.clip(np.nan_to_num(edf, nan=1.0, posinf=float(terms.max())), 1.0, np.maximum(terms, 1))

    lo68, hi68 = chi2_bounds(var, edf, P68)
    lo95, hi95 = chi2_bounds(var, edf, 0.95)
    return AllanResult(
        tau_s=tau_s,
        m=m.astype(np.int64),
        var=var,
        dev=np.sqrt(var),
        n_terms=terms,
        edf=edf,
        dev_lo68=np.sqrt(lo68),
        dev_hi68=np.sqrt(hi68),
        dev_lo95=np.sqrt(lo95),
        dev_hi95=np.sqrt(hi95),
        noise_alpha=alphas,
        estimator="overlapping",
        edf_rule=(f"sum over the {len(segs)} segment(s) with terms at each tau of the simple EDF "
                  "(Howe-Allan-Barnes, SP 1065 Table 5) with N_s+1 phase points; " + rule),
        dt_s=dt,
        n_samples=int(lengths.sum()),
        statistic="adev",
    )
