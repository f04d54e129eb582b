"""``fogdrift plan --fleet``: units of a type to record for its spread and mean of each term (issue 34 item 4).

The fixture ``tests/data/plan_fleet_adis16405.csv`` is the fleet table of ``fogdrift batch --command allan`` over the
five ADIS16405 sessions (``../shared/data/adis16405_static/adis16405_imu{1..5}.csv.gz --unit deg/s``), its term
columns kept.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.plan.fleet import (MAX_UNITS, fleet_pilot, make_fleet_plan, mean_width, parse_fleet_targets,
                                 read_fleet_table, sd_interval, spread_width, term_spread, units_needed)

FIXTURE = Path(__file__).resolve().parents[1] / "data" / "plan_fleet_adis16405.csv"
DRAWS = 4000
#: Three binomial standard errors of a 95 % coverage over DRAWS draws.
TOL = 3 * math.sqrt(0.95 * 0.05 / DRAWS)


# -- the statistics by hand --------------------------------------------------------------------------------------
def test_chi_square_quantiles_and_the_sd_interval_by_hand():
    from scipy.stats import chi2

    # published table values, 9 degrees of freedom: chi2_0.025 = 2.700, chi2_0.975 = 19.023
    assert chi2.ppf(0.025, 9) == pytest.approx(2.700, abs=5e-4)
    assert chi2.ppf(0.975, 9) == pytest.approx(19.023, abs=5e-4)
    lo, hi = sd_interval(2.0, 10)
    assert float(lo) == pytest.approx(2.0 * math.sqrt(9 / 19.023), rel=1e-4)
    assert float(hi) == pytest.approx(2.0 * math.sqrt(9 / 2.700), rel=2e-4)
    # the units' own variance comes off both ends of the total variance's interval
    lo, hi = sd_interval(2.0, 10, 1.0)
    assert float(lo) == pytest.approx(math.sqrt(4 * 9 / 19.023 - 1), rel=1e-4)
    assert float(hi) == pytest.approx(math.sqrt(4 * 9 / 2.700 - 1), rel=2e-4)
    assert float(sd_interval(1.0, 10, 5.0)[1]) == 0.0      # floored at 0
    # relative half-width of an SD from 10 units: (1.8256 - 0.6878) / 2
    assert float(spread_width(10)) == pytest.approx((math.sqrt(9 / 2.700) - math.sqrt(9 / 19.023)) / 2, rel=2e-4)


def test_mean_width_by_hand():
    # t_0.975 with 9 dof = 2.262 (published); cv 0.2 -> 2.262 * 0.2 / sqrt(10)
    assert float(mean_width(10, 0.2)) == pytest.approx(2.262 * 0.2 / math.sqrt(10), rel=2e-4)


def test_units_own_errors_widen_the_spread_and_units_needed_is_the_first_that_stays_met():
    m = np.arange(2, 2001)
    w0, w5 = spread_width(m, 0.0), spread_width(m, 0.5)
    assert np.all(w5 > w0) and np.all(np.diff(w0) < 0)
    # to first order the width is magnified by sigma_t^2 / sigma_b^2 = 2
    assert w5[-1] / w0[-1] == pytest.approx(2.0, rel=0.02)
    n = units_needed(w0, 0.25)
    assert w0[n - 2] <= 0.25 < w0[n - 3]
    assert units_needed(w0, 1e-6) is None and units_needed(w0, 20.0) == 2 and units_needed(w0, 10.0) == 3
    assert units_needed([0.1, 0.3, 0.2, 0.1], 0.25, m0=2) == 4     # 0.2 at 4 but every later one too
    assert math.isinf(spread_width(10, 1.0))


# -- coverage by Monte-Carlo (numpy only) ------------------------------------------------------------------------
def _draws(m, between, own, seed):
    rng = np.random.default_rng(seed)
    own = np.broadcast_to(np.asarray(own, dtype=float), (m,))
    x = 7.0 + between * rng.standard_normal((DRAWS, m)) + own * rng.standard_normal((DRAWS, m))
    return x, float(np.mean(own ** 2))


@pytest.mark.parametrize("m, own", [(4, 0.0), (4, 0.7), (10, 0.7), (25, 0.4)])
def test_spread_interval_covers_the_between_unit_sd_95_percent(m, own):
    x, w2 = _draws(m, 1.0, own, seed=100 + m)
    lo, hi = sd_interval(x.std(axis=1, ddof=1), m, w2)
    cover = np.mean((lo <= 1.0) & (1.0 <= hi))
    assert abs(cover - 0.95) < TOL, cover


def test_spread_interval_with_unequal_own_errors_stays_near_95_percent():
    x, w2 = _draws(10, 1.0, np.linspace(0.2, 1.2, 10), seed=5)
    lo, hi = sd_interval(x.std(axis=1, ddof=1), 10, w2)
    assert abs(np.mean((lo <= 1.0) & (1.0 <= hi)) - 0.95) < 0.02    # an approximation there, said in the docs


def test_mean_interval_covers_the_type_mean_95_percent():
    from scipy.stats import t

    m = 6
    x, _ = _draws(m, 1.0, 0.5, seed=11)
    h = t.ppf(0.975, m - 1) * x.std(axis=1, ddof=1) / math.sqrt(m)
    assert abs(np.mean(np.abs(x.mean(axis=1) - 7.0) <= h) - 0.95) < TOL


def test_a_swapped_dof_factor_or_quantile_order_fails_the_coverage():
    """The coverage check would catch M in place of M - 1, or the two quantiles swapped."""
    from scipy.stats import chi2

    m = 4
    x, w2 = _draws(m, 1.0, 0.7, seed=3)
    s2 = x.var(axis=1, ddof=1)
    q_lo, q_hi = chi2.ppf(0.025, m - 1), chi2.ppf(0.975, m - 1)

    def cover(k, a, b):
        lo = np.sqrt(np.maximum(k * s2 / a - w2, 0))
        hi = np.sqrt(np.maximum(k * s2 / b - w2, 0))
        return np.mean((lo <= 1.0) & (1.0 <= hi))

    assert abs(cover(m - 1, q_hi, q_lo) - 0.95) < TOL
    assert abs(cover(m, q_hi, q_lo) - 0.95) > TOL
    assert abs(cover(m - 1, q_lo, q_hi) - 0.95) > TOL


def test_the_planned_fleet_gives_the_promised_width_at_the_median():
    """Units planned for +-30 % on the spread: the median draw's interval is about that wide."""
    between, own = 1.0, 0.5
    w2 = own ** 2
    grid = np.arange(2, MAX_UNITS + 1)
    m = units_needed(spread_width(grid, w2 / (between ** 2 + w2)), 0.30)
    x, _ = _draws(m, between, own, seed=21)
    lo, hi = sd_interval(x.std(axis=1, ddof=1), m, w2)
    assert np.median((hi - lo) / 2 / between) == pytest.approx(0.30, rel=0.05)


# -- the pilot table ---------------------------------------------------------------------------------------------
def test_the_adis_fixture_pilot():
    rows, path = read_fleet_table(FIXTURE)
    pilot = fleet_pilot(rows, str(path))
    assert pilot.n_rows == 15 and pilot.axes == ["gx", "gy", "gz"] and pilot.quantity == "angular_rate"
    assert len(pilot.terms["N"]["value"]) == 15 and len(pilot.terms["B"]["value"]) == 11
    assert len(pilot.terms["K"]["value"]) == 2 and "Q" not in pilot.terms
    assert pilot.units["B"] == "deg/h"
    sp, mn = parse_fleet_targets(None, None, tuple(pilot.terms))
    plan = make_fleet_plan(pilot, sp, mn, units=30, explicit=False)
    assert list(plan.terms) == ["N", "B"]
    assert any(n.startswith("K: 2 unit(s) of 15") for n in plan.notes)
    assert any(n.startswith("B: 11 of 15 units resolve it") for n in plan.notes)
    n = plan.terms["N"]
    r = term_spread(pilot.terms["N"]["value"], pilot.terms["N"]["lo95"], pilot.terms["N"]["hi95"])
    assert n["between_sd"] == pytest.approx(math.sqrt(r["sd"] ** 2 - r["within_sd"] ** 2))
    assert n["spread_units"] == units_needed(spread_width(np.arange(2, MAX_UNITS + 1), n["within_share"]), 0.25)
    lo_m, hi_m = n["spread_units_range"]
    assert lo_m <= n["spread_units"] <= hi_m
    lines = plan.lines()
    assert lines[0].startswith("N spread (between-unit SD 0.135 deg/sqrt(h)") and "from 15 pilot units" in lines[0]
    assert f"to ±25 %: {n['spread_units']} units" in lines[0] and "type mean (2.46 deg/sqrt(h)) to ±10 %" in lines[0]
    assert lines[-1].startswith("a fleet of 30 units gives N spread ±")
    d = plan.to_dict()
    json.dumps(d, allow_nan=False)
    assert d["terms"]["B"]["n"] == 11 and d["units"] == 30


def test_an_unresolved_spread_is_said_and_not_planned():
    rows = [{"file": f"f{i}", "axis": "gx", "quantity": "angular_rate", "N_dprh": v, "N_lo95_dprh": v - 0.2,
             "N_hi95_dprh": v + 0.2, "N_status": "resolved"} for i, v in enumerate([1.0, 1.01, 0.99, 1.0])]
    plan = make_fleet_plan(fleet_pilot(rows, "t"), {"N": 0.25}, {"N": 0.1})
    r = plan.terms["N"]
    assert not r["resolved"] and r["between_sd"] == 0 and r["spread_units"] is None
    # the mean is planned with the SD M units will show: at least their own errors (0.2 / 1.96), not the pilot's 0.008
    assert r["total_sd"] == pytest.approx(0.2 / 1.959964) and r["sd"] < 0.01
    assert r["mean_units"] == units_needed(mean_width(np.arange(2, MAX_UNITS + 1), r["total_sd"] / r["mean"]), 0.1) == 7
    assert any("spread not resolved from the pilot: the units' own intervals explain it" in n for n in plan.notes)
    assert "not plannable" in plan.lines()[0]


def test_a_parquet_table_written_by_batch_reads_as_the_csv(tmp_path):
    pytest.importorskip("pyarrow")
    from fogdrift.fleet.summary import write_summary

    rows, _ = read_fleet_table(FIXTURE)
    out = tmp_path / "batch"
    out.mkdir()
    write_summary(rows, out / "summary.parquet")
    back, path = read_fleet_table(out)
    assert path.name == "summary.parquet"
    a, b = fleet_pilot(rows, "csv"), fleet_pilot(back, "parquet")
    assert a.terms == b.terms


# -- refusals ----------------------------------------------------------------------------------------------------
def test_bad_tables_are_refused_in_one_line_naming_the_file_and_flag(tmp_path):
    with pytest.raises(DataFormatError, match=r"fleet= .*nowhere\.parquet: no such file"):
        read_fleet_table(tmp_path / "nowhere.parquet")
    with pytest.raises(DataFormatError, match=r"no summary\.parquet in this folder"):
        read_fleet_table(tmp_path)
    (tmp_path / "t.csv").write_text("file,axis,status\na,gx,ok\n")
    rows, _ = read_fleet_table(tmp_path / "t.csv")
    with pytest.raises(DataFormatError, match=r"t\.csv: no term columns"):
        fleet_pilot(rows, str(tmp_path / "t.csv"))
    few = [{"file": "a", "axis": "gx", "N_dprh": 1.0, "N_lo95_dprh": 0.9, "N_hi95_dprh": 1.1,
            "N_status": "resolved"}] * 2
    with pytest.raises(ConfigError, match=r"N: 2 unit\(s\) of 2 in few.csv resolve it; the fleet plan needs at "
                                          r"least 3"):
        make_fleet_plan(fleet_pilot(few, "few.csv"), {"N": 0.25}, {})
    with pytest.raises(ConfigError, match="no term is resolved in 3 or more"):
        make_fleet_plan(fleet_pilot(few, "few.csv"), {"N": 0.25}, {}, explicit=False)
    with pytest.raises(ConfigError, match=r"axis= 'gq' is not an axis"):
        fleet_pilot(few, "few.csv", axis="gq")
    with pytest.raises(ConfigError, match=r"units= must be between 2"):
        make_fleet_plan(fleet_pilot(few * 2, "few.csv"), {"N": 0.25}, {}, units=1)


def test_cli_plan_fleet(tmp_path):
    from typer.testing import CliRunner

    from fogdrift.cli import _commands

    out = tmp_path / "p"
    res = CliRunner().invoke(_commands(), ["plan", "--fleet", str(FIXTURE), "--target", "N:30%",
                                           "--mean-target", "N:5%,B:10%", "--units", "20", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "N spread (between-unit SD" in res.output and "to ±30 %:" in res.output
    assert "a fleet of 20 units gives N spread ±" in res.output
    d = json.loads((out / "plan.json").read_text())
    assert d["fleet"]["terms"]["N"]["spread_target"] == 0.3 and d["fleet"]["terms"]["B"]["mean_target"] == 0.1
    assert d["fleet"]["terms"]["B"]["spread_target"] is None
    # the figure and the curve it draws: the expected widths against fleet size, the same rule as the plan's
    from fogdrift.plan.fleet import CURVE_UNITS, spread_width

    n = d["fleet"]["terms"]["N"]
    assert (out / "plan.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert n["curve"]["units"] == CURVE_UNITS.tolist() and n["curve"]["units"][0] == 2
    assert n["curve"]["units"][-1] == 10_000
    np.testing.assert_allclose(n["curve"]["spread_width"], spread_width(CURVE_UNITS, n["within_share"]), rtol=1e-12)
    assert np.all(np.diff(n["curve"]["mean_width"]) < 0)      # more units, a narrower mean


@pytest.mark.parametrize("args, words", [
    (["--fleet", "nowhere/summary.parquet"], "--fleet nowhere/summary.parquet: no such file"),
    (["--fleet", str(FIXTURE), "--target", "K:25%"], "--fleet K: 2 unit(s) of 15"),
    (["--fleet", str(FIXTURE), "--units", "1"], "--units must be between 2"),
    (["--fleet", str(FIXTURE), "--model", "N=1 deg/sqrt(h)"], "drop the pilot FILE, --model, --length"),
    (["--units", "5"], "give --fleet"),
    (["--fleet", str(FIXTURE), "--estimator", "gmwm"], "does not say which estimator made its rows")])
def test_cli_plan_fleet_refusals_are_one_line(tmp_path, args, words):
    from typer.testing import CliRunner

    from fogdrift.cli import _commands

    res = CliRunner().invoke(_commands(), ["plan", *args, "--out", str(tmp_path / "p")])
    assert res.exit_code == 1
    text = res.output.strip()
    assert words in text and len(text.splitlines()) == 1, text


def test_one_estimators_rows_are_planned_never_two_pooled():
    """A unit measured by both estimators would count twice: rows of batch allan/analyze are the Allan fit's, of
    batch noise the GMWM's; both asked for takes whichever the table holds, and refuses a table of both."""
    from fogdrift.errors import ConfigError
    from fogdrift.plan.fleet import rows_of_estimator

    allan = [{"command": "allan", "axis": "gx"}, {"command": "analyze", "axis": "gy"}]
    gmwm = [{"command": "noise", "axis": "gx"}]
    assert rows_of_estimator(allan) == (allan, "allan") and rows_of_estimator(gmwm, ("gmwm",)) == (gmwm, "gmwm")
    assert rows_of_estimator(allan + gmwm, ("gmwm",)) == (gmwm, "gmwm")
    assert rows_of_estimator(allan + gmwm, ("allan",)) == (allan, "allan")
    with pytest.raises(ConfigError, match="holds rows of the Allan fit .* and of the GMWM"):
        rows_of_estimator(allan + gmwm)
    with pytest.raises(ConfigError, match="holds Allan fit rows only; .*gmwm finds none"):
        rows_of_estimator(allan, ("gmwm",))
    bare = [{"axis": "gx"}]                                   # a CSV without the batch's command column
    assert rows_of_estimator(bare) == (bare, None)
    with pytest.raises(ConfigError, match="does not say which estimator"):
        rows_of_estimator(bare, ("allan",))
