"""The Allan family of gyro rate statistics: Allan, Hadamard and modified Allan deviations.

One job per module:

* :mod:`~fogdrift.allan.statistics` -- the family as data (difference operator, supported
  samplings, EDF rule, SP 1065 equation of each statistic): :data:`STATISTICS`;
* :mod:`~fogdrift.allan._kernels` -- the compiled (numba) kernels;
* :mod:`~fogdrift.allan.grid` -- tau grids (:func:`tau_grid`);
* :mod:`~fogdrift.allan.ci` -- EDF (:func:`edf_simple`, :func:`edf_greenhall`) and chi-squared
  bounds (:func:`chi2_bounds`);
* :mod:`~fogdrift.allan.result` -- :class:`AllanResult`;
* :mod:`~fogdrift.allan.core` -- the entry point :func:`allan_variance` (``statistic=`` picks
  the operator, ``estimator=`` the sampling);
* :mod:`~fogdrift.allan.segments` -- the Allan variance of gap-free segments pooled without
  bridging a gap (:func:`allan_variance_segments`).

Examples
--------
>>> import numpy as np
>>> from fogdrift.allan import allan_variance
>>> y = np.random.default_rng(0).normal(size=4096)          # white rate noise, 1 (deg/h)^2
>>> r = allan_variance(y, 1.0, statistic="mdev", taus=[1, 64])
>>> r.statistic, r.column_names()[3], round(float(r.var[1] * 64 * 2), 1)   # MVAR ~ 1/(2 m)
('mdev', 'mdev_dph', 1.0)
"""

from .ci import P68, chi2_bounds, edf_greenhall, edf_simple
from .core import FAST_M0, IEEE952_ALPHAS, allan_variance
from .grid import tau_grid
from .result import AllanResult
from .segments import allan_variance_segments
from .statistics import ESTIMATORS, STATISTICS, Statistic, get_statistic

__all__ = [
    "AllanResult",
    "allan_variance",
    "allan_variance_segments",
    "tau_grid",
    "edf_simple",
    "edf_greenhall",
    "chi2_bounds",
    "ESTIMATORS",
    "IEEE952_ALPHAS",
    "FAST_M0",
    "STATISTICS",
    "Statistic",
    "get_statistic",
    "P68",
]
