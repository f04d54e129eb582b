"""The Allan family as data: one record per statistic (difference operator, sampling, EDF rule).

The rate samples ``y_1..y_N`` (deg/h) are taken every ``tau0 = dt_s`` seconds; the angle
("phase") is ``p_0 = 0, p_k = tau0 sum_{i<=k} y_i`` (N + 1 points) and ``tau = m tau0``
(method notes 2.1).  Every statistic of the table is

    sigma^2(tau) = 1 / (norm tau^2 n_terms) * sum_k ( sum_l c_l P_{k + l m} )^2

where ``c`` is the difference operator (by lag ``l = 0, 1, ...``), ``P`` is the phase itself
or, for a *windowed* (modified) statistic, the average of m adjacent phase points
``P_k = (1/m) sum_{r<m} p_{k+r}``, ``norm = sum_l (c_0 + ... + c_l)^2`` (the squared
frequency-difference weights: 2 for Allan, 6 for Hadamard, so that white FM gives the same
level N^2/tau for both) and k runs over every start index (``"overlapping"``), over
``0, m, 2m, ...`` (``"non-overlapping"``) or over a strided subset (``"fast"``).

=========  ===============  ========  ======  =======================================  ====================
statistic  operator c       windowed  norm    samplings                                EDF
=========  ===============  ========  ======  =======================================  ====================
adev       (1, -2, 1)       no        2       overlapping, non-overlapping, fast       SP 1065 Table 5
hdev       (-1, 3, -3, 1)   no        6       overlapping, non-overlapping             Greenhall d = 3
mdev       (1, -2, 1)       yes       2       overlapping                              Greenhall d = 2, mod.
=========  ===============  ========  ======  =======================================  ====================

A combination outside ``samplings`` is refused (ConfigError).  Adding a statistic means adding
a record here (and a compiled kernel for a new operator in ``_kernels.OPERATORS``).

References
----------
.. [SP1065] W. J. Riley, *Handbook of Frequency Stability Analysis*, NIST SP 1065 (2008):
   Allan eqs. 6-7 (pp. 14-15) and 11 (p. 16); modified Allan eq. 14 (p. 17); Hadamard
   eqs. 17-18 (p. 20) and overlapping Hadamard eq. 20 (p. 21); simple EDF Table 5 (p. 40).
.. [GR2003] C. A. Greenhall, W. J. Riley, "Uncertainty of stability variances based on finite
   differences", Proc. 35th PTTI Meeting (2003).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from ..errors import ConfigError

__all__ = ["Statistic", "STATISTICS", "ESTIMATORS", "get_statistic"]

#: Sampling modes (``estimator=``) known to the package; each statistic lists those it supports.
ESTIMATORS = ("overlapping", "non-overlapping", "fast")


@dataclass(frozen=True)
class Statistic:
    """One member of the Allan family.

    Attributes
    ----------
    name : str
        Key in :data:`STATISTICS` and value of ``AllanResult.statistic`` (``"adev"``, ...).
    long_name : str
        E.g. ``"Hadamard deviation"``.
    var_name, dev_name : str
        Column stems of the variance and deviation in serialised results
        (``"hvar"`` -> ``hvar_dph2``, ``"hdev"`` -> ``hdev_dph``).
    coefficients : tuple of int
        Difference operator on phase points ``P_k, P_{k+m}, P_{k+2m}, ...`` (by lag).
    windowed : bool
        Whether ``P`` is the average of m adjacent phase points (modified statistics).
    samplings : tuple of str
        Supported ``estimator=`` values.
    edf_method : str
        ``"simple"`` (:func:`~fogdrift.allan.ci.edf_simple`, Allan only) or ``"greenhall"``
        (:func:`~fogdrift.allan.ci.edf_greenhall` with ``d = order``, ``modified = windowed``).
    dev_slopes : mapping of int to float
        Log-log slope of the deviation for each power-law alpha (noise identification).
    equation : str
        Where the estimator is defined.
    edf_source : str
        Where its EDF rule comes from.
    """

    name: str
    long_name: str
    var_name: str
    dev_name: str
    coefficients: tuple
    windowed: bool
    samplings: tuple
    edf_method: str
    dev_slopes: dict = field(repr=False)
    equation: str = field(repr=False)
    edf_source: str = field(repr=False)

    @property
    def order(self) -> int:
        """Order d of the phase difference (2 Allan, 3 Hadamard)."""
        return len(self.coefficients) - 1

    @property
    def norm(self) -> float:
        """``sum_l (c_0 + ... + c_l)^2``: 2 for the second difference, 6 for the third."""
        return float(np.sum(np.cumsum(self.coefficients) ** 2))

    def span(self, m):
        """Phase-index span of one term: ``order m`` (+ ``m - 1`` when windowed)."""
        m = np.asarray(m, dtype=np.int64)
        return self.order * m + (m - 1 if self.windowed else 0)

    def max_m(self, n_samples: int) -> int:
        """Largest m with at least one term in a record of ``n_samples`` rate samples."""
        n = int(n_samples)
        return (n + 1) // (self.order + 1) if self.windowed else n // self.order

    def n_terms(self, n_samples: int, m, stride) -> np.ndarray:
        """Number of squared differences averaged: ``(N - span(m)) // stride + 1``."""
        return (int(n_samples) - self.span(m)) // np.asarray(stride, dtype=np.int64) + 1

    def variance(self, sums, m, n_terms) -> np.ndarray:
        """sigma^2 from the kernel's sum of squares (phase in units of rate x samples).

        ``sums / (norm m^2 n_terms)``, with one more ``m^2`` for a windowed statistic (the
        kernel sums phase points instead of averaging them).
        """
        mf = np.asarray(m, dtype=np.float64)
        scale = mf**4 if self.windowed else mf**2
        return np.asarray(sums, dtype=np.float64) / (self.norm * scale * np.asarray(n_terms, dtype=np.float64))

    def check_sampling(self, estimator: str) -> None:
        """Raise ConfigError unless ``estimator`` is one of this statistic's samplings."""
        if estimator not in ESTIMATORS:
            raise ConfigError(f"estimator must be one of {ESTIMATORS}, got {estimator!r}")
        if estimator not in self.samplings:
            raise ConfigError(
                f"statistic={self.name!r} ({self.long_name}) supports estimator in {self.samplings}, "
                f"got {estimator!r}; use {{opt:estimator}} {self.samplings[0]} or {{opt:statistic}} adev"
            )


# Deviation slopes mu (sigma ~ tau^mu) for S_y ~ f^alpha: mu = -(alpha + 1)/2 for alpha <= 1,
# and -1 for white PM (alpha = +2) in the unmodified variances, whose white/flicker PM slopes
# coincide; the modified Allan deviation separates them (-3/2 and -1): the standard power-law
# slopes tabulated in SP 1065 (its noise-identification discussion).
_SLOPES_UNMODIFIED = MappingProxyType({2: -1.0, 1: -1.0, 0: -0.5, -1: 0.0, -2: 0.5})
_SLOPES_MODIFIED = MappingProxyType({2: -1.5, 1: -1.0, 0: -0.5, -1: 0.0, -2: 0.5})

#: The Allan family, keyed by ``statistic=`` name.
STATISTICS = MappingProxyType(
    {
        "adev": Statistic(
            name="adev",
            long_name="Allan deviation",
            var_name="avar",
            dev_name="adev",
            coefficients=(1, -2, 1),
            windowed=False,
            samplings=("overlapping", "non-overlapping", "fast"),
            edf_method="simple",
            dev_slopes=_SLOPES_UNMODIFIED,
            equation="SP 1065 eqs. 6-7 (non-overlapping, pp. 14-15) and 11 (overlapping, p. 16)",
            edf_source="SP 1065 Table 5 (p. 40), Howe-Allan-Barnes simple EDF",
        ),
        "hdev": Statistic(
            name="hdev",
            long_name="Hadamard deviation",
            var_name="hvar",
            dev_name="hdev",
            coefficients=(-1, 3, -3, 1),
            windowed=False,
            samplings=("overlapping", "non-overlapping"),
            edf_method="greenhall",
            dev_slopes=_SLOPES_UNMODIFIED,
            equation="SP 1065 eqs. 17-18 (non-overlapping, p. 20) and 20 (overlapping, p. 21)",
            edf_source="Greenhall & Riley (2003) with d = 3 (SP 1065 Table 5 covers the Allan variance only)",
        ),
        "mdev": Statistic(
            name="mdev",
            long_name="modified Allan deviation",
            var_name="mvar",
            dev_name="mdev",
            coefficients=(1, -2, 1),
            windowed=True,
            samplings=("overlapping",),
            edf_method="greenhall",
            dev_slopes=_SLOPES_MODIFIED,
            equation="SP 1065 eq. 14 (p. 17)",
            edf_source="Greenhall & Riley (2003) with d = 2, modified (SP 1065 Table 5 covers the Allan variance only)",
        ),
    }
)


def get_statistic(name) -> Statistic:
    """The :class:`Statistic` record for ``name``, or ConfigError listing the known names.

    Examples
    --------
    >>> s = get_statistic("hdev")
    >>> s.order, s.norm, s.samplings
    (3, 6.0, ('overlapping', 'non-overlapping'))
    >>> get_statistic("mdev").n_terms(100, [1, 10], 1).tolist()   # N + 2 - 3m
    [99, 72]
    """
    if isinstance(name, Statistic):
        return name
    try:
        return STATISTICS[name]
    except (KeyError, TypeError):
        raise ConfigError(
            f"statistic must be one of {tuple(STATISTICS)}, got {name!r}; set {{opt:statistic}}"
        ) from None
