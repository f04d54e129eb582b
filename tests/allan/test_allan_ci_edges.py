"""Argument boundaries of ``fogdrift.allan.ci.edf_simple`` (found unasserted by the mutation run).

``n_phase >= 3`` and ``1 <= m <= (n_phase - 1) / 2``, integers: each boundary accepted, one step beyond
refused; the value at the smallest case by hand (white FM, SP 1065 Table 5).
"""

from __future__ import annotations

import pytest

from fogdrift.allan.ci import edf_simple
from fogdrift.errors import ConfigError


def test_smallest_valid_case_by_hand():
    # white FM, N = 3, m = 1: [3 (N-1)/(2m) - 2 (N-2)/N] 4m^2/(4m^2+5) = (3 - 2/3) * 4/9 = 28/27
    assert edf_simple(3, 1, 0) == pytest.approx(28.0 / 27.0, rel=1e-12)


@pytest.mark.parametrize("n_phase, m", [(3, 1), (5, 2), (9, 4), (10, 4)])
def test_boundaries_accepted(n_phase, m):
    assert edf_simple(n_phase, m, 0) > 0


@pytest.mark.parametrize("n_phase, m, what", [
    (2, 1, "n_phase"), (2.5, 1, "n_phase"), (10.5, 1, "n_phase must be an integer >= 3, got 10.5"), (5, 3, "m must be"), (9, 5, "m must be"), (10, 5, "m must be"),
    (9, 0, "m must be"), (9, 1.5, "m must be"),
])
def test_boundaries_refused(n_phase, m, what):
    with pytest.raises(ConfigError, match=what):
        edf_simple(n_phase, m, 0)


def test_m_refusal_states_the_valid_range():
    with pytest.raises(ConfigError) as err:
        edf_simple(10, 5, 0)
    assert str(err.value) == "m must be an integer in [1, (n_phase-1)/2] = [1, 4.5], got 5"


def test_safe_variant_returns_one_outside_the_table_and_the_formula_inside():
    from fogdrift.allan.ci import edf_formula, edf_simple_safe

    assert edf_simple_safe(2, 1, 0) == 1.0 and edf_simple_safe(2.9, 0.5, 0) == 1.0   # fewer than 3 phase points
    assert edf_simple_safe(5, 2.5, 0) == 1.0 and edf_simple_safe(10, 5, -2) == 1.0   # 2m > N - 1
    assert edf_simple_safe(3, 1, 0) == pytest.approx(28.0 / 27.0, rel=1e-12)         # smallest valid case
    assert edf_simple_safe(5, 2, 0) == edf_formula(5.0, 2.0, 0)                       # 2m = N - 1 is valid
    assert edf_simple_safe(10.5, 2.5, -1) == edf_formula(10.5, 2.5, -1)               # non-integer (fast)
