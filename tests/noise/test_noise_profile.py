"""The profile interval's upper side never evaluates the fit past the coefficient's upper bound."""

from __future__ import annotations

import numpy as np
import pytest

from fogdrift.noise.engine import profile_interval


class _Stub:
    """Q(v) = (v - 5)^2 inside the bound; beyond it the fit is undefined (here: 0, which fooled the old bracket)."""

    def __init__(self, ub):
        self.upper = np.array([ub])

    def fit(self, cols, a0=None, fixed=None):
        v = fixed[1]
        return None, ((v - 5.0) ** 2 if v <= self.upper[0] else 0.0)

    def profile(self, cols, col, a0=None):  # ScoreProblem.profile: Q as a function of the pinned value
        return lambda v: self.fit(cols, a0, (col, v))[1]


@pytest.mark.parametrize("ub, hi", [(100.0, 6.0), (7.0, 6.0), (5.5, 5.5)])
def test_upper_side_of_a_quadratic_profile(ub, hi):
    lo, got = profile_interval(_Stub(ub), [0], np.array([5.0]), 0, 0.0, 1.0)
    assert lo == pytest.approx(4.0, abs=1e-6) and got == pytest.approx(hi, abs=1e-6)
