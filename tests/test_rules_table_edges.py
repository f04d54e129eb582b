"""Edges of tables, by their rules (issue 24).

* A decade tau grid (1-2-5 per decade) keeps every 1-2-5 value up to AND INCLUDING ``m_max``: when ``m_max`` is
  itself a 1-2-5 value (N = 4 m_max at the default max_fraction 0.25) it is the last grid point.
* The Earth-rate rule of the plausibility check compares the LENGTH of the mean vector of a quiet 3-axis record
  with 0.2 x 15.04 deg/h: a triad whose axis means cancel (sum 0, length 10 deg/h) is plausible; one whose mean
  vector is short (length 1.4 deg/h) is not, whatever the signs.
* The GMWM batch summary's ``fit_n_points`` is the number of scales the selected fit used: the WV's scales less
  the excluded short ones, = fit dof + parameters, compared on a record where the exclusion removes 3 scales.

Each test names the one-line bug it catches (``tests/deliberate_bugs.py``, block H-tests24).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from fogdrift.allan import allan_variance, tau_grid
from fogdrift.io import from_array
from fogdrift.plausibility import EARTH_FRACTION, check_record


# ---------------------------------------------------------------------------------------------------------------
# decade grid


@pytest.mark.parametrize("m_max", [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, 5000, 100_000])
def test_decade_grid_ends_at_m_max_when_it_is_a_1_2_5_value(m_max):
    """N = 4 m_max: the grid is every 1-2-5 value <= m_max, written out here, ending at m_max itself.
    Catches: ``m < m_max`` for ``m <= m_max`` (the last decade point dropped), a decade range one short."""
    want = sorted(f * 10**k for k in range(7) for f in (1, 2, 5) if f * 10**k <= m_max)
    got = tau_grid(4 * m_max, 0.1, "decade").tolist()
    assert got == want and got[-1] == m_max
    if m_max > 1:
        assert tau_grid(4 * m_max - 4, 0.1, "decade").tolist() == [m for m in want if m < m_max]  # m_max - 1


@pytest.mark.parametrize("statistic, n", [("adev", 100), ("hdev", 150), ("mdev", 149)])
def test_decade_grid_ends_at_the_statistics_own_limit_when_it_is_a_1_2_5_value(statistic, n):
    """max_fraction 0.5 lets the statistic's own limit bind: m <= N // 2 (Allan), N // 3 (Hadamard), (N + 1) // 3
    (modified): 50 in all three cases here, and 50 is the last grid point (and the last tau of the deviation)."""
    assert tau_grid(n, 1.0, "decade", max_fraction=0.5, statistic=statistic).tolist() == [1, 2, 5, 10, 20, 50]
    x = np.random.default_rng(0).normal(0.0, 1.0, n)
    res = allan_variance(x, 0.5, taus="decade", max_fraction=0.5, statistic=statistic)
    assert res.tau_s[-1] == pytest.approx(25.0) and np.isfinite(res.dev[-1])


# ---------------------------------------------------------------------------------------------------------------
# plausibility: Earth-rate rule on the mean VECTOR


def _quiet_triad(means, seed=0):
    """Navigation-grade white noise (1 deg/h per 10-ms sample: N = 1 x 0.1 / 60 = 1.7e-3 deg/sqrt(h)) around the
    given axis means [deg/h]."""
    rng = np.random.default_rng(seed)
    x = np.column_stack([m + rng.normal(0.0, 1.0, 40_000) for m in means])
    return from_array(x, dt_s=0.01, unit="deg/h", axis_names=("gx", "gy", "gz"))


@pytest.mark.parametrize("means", [(10.0, -10.0, 0.0), (8.0, -4.0, -4.0), (-6.0, 3.0, 3.0)])
def test_quiet_triad_whose_axis_means_cancel_is_plausible(means):
    """The means sum to 0 but the vector is 10 / 9.8 / 7.3 deg/h long (> 0.2 x 15.04 = 3.0): the Earth rate can be
    in it, no finding.  Catches: the rule on the sum (or mean) of the axis means instead of the vector length."""
    assert abs(sum(means)) < 1e-12 and np.linalg.norm(means) > EARTH_FRACTION * 15.04
    assert check_record(_quiet_triad(means)) == []


@pytest.mark.parametrize("means", [(1.0, -1.0, 0.0), (1.0, 1.0, 0.0), (0.0, 0.0, 2.5)])
def test_quiet_triad_with_a_short_mean_vector_is_flagged_whatever_the_signs(means):
    """|mean vector| 1.4 / 1.4 / 2.5 deg/h < 3.0 deg/h: the Earth-rate finding, on every axis.
    Catches: the comparison turned round, or the length of the vector replaced by one axis's mean."""
    found = check_record(_quiet_triad(means))
    assert [f.rule for f in found] == ["earth-rate"] and found[0].axes == ("gx", "gy", "gz")


# ---------------------------------------------------------------------------------------------------------------
# GMWM batch summary: point counts with excluded scales


def test_gmwm_batch_row_counts_only_the_scales_the_fit_used(tmp_path):
    """WN+RW through a 2-tap moving average (an output filter), 2^16 - 1 samples: 14 scales, the selection
    excludes levels 1-3 (as in tests/gmwm/test_gmwm_selection.py), so the fit uses 11 scales: fit_n_points = 11 =
    dof 9 + 2 parameters, noise.json's levels 4-14.  Catches: fit_n_points as every scale of the WV (14), or as
    the dof."""
    from fogdrift.fleet.commands import run_noise_command
    from fogdrift.fleet.summary import read_summary, write_summary
    from fogdrift.gmwm import simulate_latent

    x = simulate_latent("WN+RW", [1.0, 1e-5], 2**16, seed=8)
    y = np.convolve(x, [0.5, 0.5], mode="valid")
    rec = from_array(y, dt_s=0.01, unit="deg/h", axis_names=("gz",))
    (row,) = run_noise_command(rec, {"gmwm": {"model": "WN+RW"}}, tmp_path)
    doc = json.loads((tmp_path / "noise.json").read_text())
    text = json.dumps(doc)
    assert row["noise_model"] == "WN+RW"
    assert row["fit_n_points"] == 11 and row["fit_dof"] == 9
    assert row["fit_n_points"] == row["fit_dof"] + 2
    assert '"levels_used": [4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14]' in text.replace("\n", "")
    write_summary([row], tmp_path / "summary.parquet")
    (back,) = read_summary(tmp_path / "summary.parquet")
    assert (back["fit_n_points"], back["fit_dof"]) == (11, 9)
