"""Conversions between fitted law coefficients ``A`` and IEEE-952 coefficients (and the paper's Table 1)."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ConfigError
from ..units import S_PER_H, URAD_PER_ARCSEC
from .terms import TERM_TABLE, TERMS, laws_of

__all__ = ["coefficients_from_A", "paper_table1_from_A"]


def _check_A(A) -> np.ndarray:
    a = np.asarray(A, dtype=np.float64)
    if a.shape != (5,) or not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ConfigError(f"A must be 5 finite non-negative numbers A_-2..A_2, got {A!r}")
    return a


def coefficients_from_A(A, *, statistic="adev", dt_s=None) -> dict[str, float]:
    """IEEE-952 coefficients from the fitted A of each term (sigma^2 in (deg/h)^2, tau in s).

    Parameters
    ----------
    A : array_like, shape (5,)
        Non-negative coefficients of Q, N, B, K, R in the statistic's law (for the Allan
        variance: A_-2, A_-1, A_0, A_1, A_2).
    statistic : str, keyword-only
        Whose laws (:data:`VARIANCE_LAWS`); default ``"adev"``.
    dt_s : float or None, keyword-only
        Sample interval in s (needed for ``"mdev"``, whose white-PM constant is 3 dt).

    Returns
    -------
    dict
        ``Q`` [urad], ``Q_arcsec`` [arcsec], ``N`` [deg/sqrt(h)], ``B`` [deg/h],
        ``K`` [deg/h^1.5], ``R`` [deg/h^2] (R is absent for ``"hdev"``).

    Notes
    -----
    Method notes 2.3 (Allan): Q[arcsec] = sqrt(A_-2/3) (1 (deg/h) s = 1 arcsec),
    Q[urad] = 4.848137 sqrt(A_-2/3), N = sqrt(A_-1)/60, B = sqrt(A_0)/0.664282,
    K = 60 sqrt(3 A_1), R = 3600 sqrt(2 A_2); in general ``to_unit sqrt(A / c)`` with the
    statistic's constant c (:meth:`TermSpec.from_A`).

    Examples
    --------
    >>> c = coefficients_from_A([1.27635511e-1, 9.0e-2, 4.412712e-5, 3.7037037e-8, 9.6450617e-11])
    >>> {k: round(v, 6) for k, v in c.items()}
    {'Q': 1.0, 'Q_arcsec': 0.206265, 'N': 0.005, 'B': 0.01, 'K': 0.02, 'R': 0.05}
    """
    a = _check_A(A)
    laws = laws_of(statistic)
    out = {}
    for i, name in enumerate(TERMS):
        if name in laws:
            out[name] = TERM_TABLE[name].from_A(a[i], laws[name].scale(dt_s))
            if name == "Q":
                out["Q_arcsec"] = out["Q"] / URAD_PER_ARCSEC
    return out


def paper_table1_from_A(A) -> dict[str, float]:
    """The conversions of Tang et al. (2012) Table 1, for replication only.

    **Q is wrong** in the paper: ``1e6 * 3600 * pi * sqrt(3 A_-2) / 180`` is ``3 * 3600^2``
    times the correct value (factor 3 inverted, 3600 multiplied instead of divided; method
    notes 2.4).  N, K, R are correct; B uses the rounded constant 0.6643.

    Returns
    -------
    dict
        ``Q`` [urad, erroneous], ``N``, ``B``, ``K``, ``R`` as in :func:`coefficients_from_A`,
        and ``Q_is_wrong`` = 1.0 as a flag.

    Examples
    --------
    >>> A = [1.27635511e-1, 9.0e-2, 4.412712e-5, 3.7037037e-8, 9.6450617e-11]
    >>> round(paper_table1_from_A(A)["Q"] / coefficients_from_A(A)["Q"])
    38880000
    """
    a = _check_A(A)
    return {
        "Q": 1e6 * S_PER_H * math.pi * math.sqrt(3.0 * a[0]) / 180.0,  # as printed (the degree factor split around the sqrt)
        "N": math.sqrt(a[1]) / 60.0,
        "B": math.sqrt(a[2]) / 0.6643,
        "K": 60.0 * math.sqrt(3.0 * a[3]),
        "R": S_PER_H * math.sqrt(2.0 * a[4]),
        "Q_is_wrong": 1.0,
    }
