"""Tau grids: the cluster sizes m (tau = m dt_s) at which an Allan-family statistic is evaluated."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ConfigError, InsufficientDataError
from ..units import check_dt_s
from .statistics import get_statistic

__all__ = ["tau_grid", "MAX_TAUS"]

#: Largest number of taus a grid may have (``"all"`` on a long record is refused beyond it).
MAX_TAUS = 100_000


def tau_grid(n_samples, dt_s, taus="octave", *, max_fraction=0.25, statistic="adev") -> np.ndarray:
    """Cluster sizes m (unique, sorted, int64) for a tau specification.

    Parameters
    ----------
    n_samples : int
        Number of rate samples N (>= 2).
    dt_s : float
        Sample interval in s.
    taus : str, int or array_like
        ``"octave"``: m = 1, 2, 4, 8, ...; ``"decade"``: m = 1, 2, 5, 10, 20, 50, ...
        (1-2-5 per decade); ``"all"``: every m; an int ``n``: ``n`` log-spaced values from 1
        to ``m_max``, rounded to integers and de-duplicated (so fewer than ``n`` at small m);
        an array of tau in s: ``m = round(tau / dt_s)``, de-duplicated.
    max_fraction : float, keyword-only
        For the named and integer grids, ``m_max = floor(max_fraction * N)``; default 0.25
        (at least N/2 + 1 overlapping Allan terms and 3 non-overlapping differences at the
        largest tau).  Must be in (0, 0.5].
    statistic : str, keyword-only
        ``"adev"`` (default), ``"hdev"`` or ``"mdev"``: every m must leave at least one term,
        i.e. ``m <= N // 2`` (Allan), ``N // 3`` (Hadamard) or ``(N + 1) // 3`` (modified
        Allan); named and integer grids are cut there, explicit taus beyond it are refused.

    Returns
    -------
    ndarray of int64, shape (n_tau,)

    Raises
    ------
    ConfigError
        Unknown keyword or statistic, bad number, tau outside ``[dt_s/2, (m_max + 0.5) dt_s]``,
        or more than 100000 taus.
    InsufficientDataError
        ``n_samples < 2`` (``< 3`` for the Hadamard deviation).

    Examples
    --------
    >>> tau_grid(100, 0.1).tolist()
    [1, 2, 4, 8, 16]
    >>> tau_grid(1000, 1.0, "decade").tolist()
    [1, 2, 5, 10, 20, 50, 100, 200]
    >>> tau_grid(10, 1.0, [1.0, 3.0], statistic="hdev").tolist()
    [1, 3]
    """
    dt = check_dt_s(dt_s)
    stat = get_statistic(statistic)
    n = int(n_samples)
    need = stat.span(1) if stat.windowed else stat.order
    if n < max(2, int(need)):
        raise InsufficientDataError(
            f"the {stat.long_name} needs at least {max(2, int(need))} rate samples, got {n}",
            needed=max(2, int(need)),
            got=n,
        )
    if not (0 < float(max_fraction) <= 0.5):
        raise ConfigError(f"max_fraction must be in (0, 0.5], got {max_fraction!r}")
    m_top = stat.max_m(n)
    m_max = max(1, min(int(math.floor(float(max_fraction) * n)), m_top))
    if isinstance(taus, str):
        kind = taus.lower()
        if kind == "octave":
            m = 2 ** np.arange(int(math.floor(math.log2(m_max))) + 1)
        elif kind == "decade":
            m = np.array([f * 10**k for k in range(int(math.log10(m_max)) + 2) for f in (1, 2, 5)])
            m = m[m <= m_max]
        elif kind == "all":
            if m_max > MAX_TAUS:
                raise ConfigError(
                    f"taus='all' would give {m_max} taus (limit {MAX_TAUS}); "
                    "use an int for log-spaced taus"
                )
            m = np.arange(1, m_max + 1)
        else:
            raise ConfigError(
                f"taus must be 'octave', 'decade', 'all', an int or an array of τ values [s], got {taus!r}"
            )
    elif isinstance(taus, (int, np.integer)) and not isinstance(taus, bool):
        if not 1 <= int(taus) <= MAX_TAUS:
            raise ConfigError(f"taus as a count must be in [1, {MAX_TAUS}], got {taus!r}")
        m = np.rint(np.logspace(0.0, math.log10(m_max), int(taus))) if int(taus) > 1 else np.ones(1)
    else:
        try:
            t = np.asarray(taus, dtype=np.float64).ravel()
        except (TypeError, ValueError):
            raise ConfigError(f"taus must be a keyword, an int or an array of τ values [s], got {taus!r}") from None
        if t.size == 0 or not np.all(np.isfinite(t)):
            raise ConfigError(f"taus must be a non-empty array of finite τ values [s], got {taus!r}")
        m = np.rint(t / dt)
        if m.min() < 1 or m.max() > m_top:
            bad = t[(m < 1) | (m > m_top)][0]
            raise ConfigError(
                f"tau {float(bad)!r} s is outside the computable range of the {stat.long_name}; expected "
                f"{dt} s <= tau <= {m_top * dt} s (1 <= m <= {m_top} for {n} samples at {dt} s)"
            )
        if m.size > MAX_TAUS:
            raise ConfigError(f"at most {MAX_TAUS} taus, got {m.size}")
    return np.unique(m.astype(np.int64))
