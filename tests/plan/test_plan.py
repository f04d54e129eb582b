"""fogdrift plan (issue 34): parsing refusals, hand-checked statistics, analytic vs Monte-Carlo lengths and the
planner's honesty on a simulated MEMS-like gyro (10 Hz: N, B, K)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fogdrift.errors import ConfigError
from fogdrift.plan import make_plan, parse_length, parse_model, parse_targets
from fogdrift.plan.model import fmt_length
from fogdrift.plan.analytic import analytic_widths, expected_inflation
from fogdrift.plan.core import _mc_length, crossing
from fogdrift.plan.montecarlo import summarise

MEMS = "N=0.3 deg/sqrt(h), B=5 deg/h, K=20 deg/h^1.5"
RLG = "N=0.003 deg/sqrt(h), B=0.004 deg/h, K=0.002 deg/h^1.5"


# -- parsing ----------------------------------------------------------------------------------------------------
def test_model_units_by_hand():
    m = parse_model("N=0.6 deg/h/sqrt(Hz), B=0.001 deg/s, K=1 deg/s/sqrt(s), Q=1 arcsec, R=1 deg/s^2", 0.1)
    assert m.coefficients["N"] == pytest.approx(0.01)          # 1 deg/sqrt(h) = 60 deg/h/sqrt(Hz)
    assert m.coefficients["B"] == pytest.approx(3.6)
    assert m.coefficients["K"] == pytest.approx(3600.0**1.5)   # 1/s^1.5 = 3600^1.5 /h^1.5
    assert m.coefficients["Q"] == pytest.approx(4.8481368)     # 1 arcsec = 4.848 urad
    assert m.coefficients["R"] == pytest.approx(3600.0**2)


def test_law_coefficients_give_the_ieee_allan_variance():
    # N = 0.3 deg/sqrt(h) -> ADEV(1 s) = 0.3 * 60 = 18 deg/h; B = 5 -> flat AVAR 0.4413 * 25; K = 20 -> K^2 tau / 3
    m = parse_model(MEMS, 0.1)
    A = m.law_coefficients()
    assert A[1] == pytest.approx(18.0**2)
    assert A[2] == pytest.approx(2 * math.log(2) / math.pi * 25.0)
    assert A[3] == pytest.approx((20.0 / 60.0) ** 2 / 3.0)


@pytest.mark.parametrize("text, words", [
    ("N=0.3", "no unit"), ("N=0.3 deg/furlong", "unknown unit"), ("X=1 deg/h", "unknown term"),
    ("N=1 deg/sqrt(h), N=2 deg/sqrt(h)", "twice"), ("N 0.3 deg/sqrt(h)", "TERM=VALUE"), ("", "empty"),
    ("N=0 deg/sqrt(h)", "no noise term"), ("S=1 deg/h", "unknown term")])
def test_model_refusals(text, words):
    with pytest.raises(ConfigError, match=words):
        parse_model(text, 0.01)


def test_model_needs_a_positive_interval():
    with pytest.raises(ConfigError, match="sample interval"):
        parse_model("N=1 deg/sqrt(h)", 0.0)


@pytest.mark.parametrize("text, words", [
    ("B:10", "between 0 and 100"), ("B:0%", "between 0 and 100"), ("R:10%", "no R term"), ("B10%", "TERM:WIDTH"),
    ("Z:5%", "unknown term"), ("B:10%,B:20%", "twice")])
def test_target_refusals(text, words):
    with pytest.raises(ConfigError, match=words):
        parse_targets(text, ("N", "B"))


def test_targets_and_lengths_parse():
    assert parse_targets("B:10%, N:0.02", ("N", "B")) == {"B": 0.1, "N": 0.02}
    assert parse_targets("", ("N", "K")) == {"N": 0.05, "K": 0.25}
    assert parse_length("1.5 d") == 129600.0 and parse_length("45min") == 2700.0
    for bad in ("2 fortnights", "-1h", "h", "0s"):
        with pytest.raises(ConfigError):
            parse_length(bad)


# -- the small statistics, by hand ------------------------------------------------------------------------------
def test_expected_inflation_by_hand():
    # dof = 1: E[max(1, X)] = P(X <= 1) + E[X; X > 1] = 0.682689 + (1 - F_3(1)) = 0.682689 + 0.801252
    assert expected_inflation(1) == pytest.approx(0.682689 + 0.801252, abs=1e-5)
    rng = np.random.default_rng(0)
    x = rng.chisquare(8, 400_000) / 8
    assert expected_inflation(8) == pytest.approx(np.maximum(1, x).mean(), abs=3e-3)


def test_crossing_log_log_interpolation():
    # y = 1/sqrt(x): falls to 0.25 at x = 16, from the grid points 4 and 64
    assert crossing([4.0, 64.0], [0.5, 0.125], 0.25) == pytest.approx(16.0)
    assert crossing([1.0, 2.0], [math.inf, 0.1], 0.2) == 2.0
    assert crossing([1.0, 2.0], [0.5, 0.4], 0.2) is None
    assert crossing([1.0, 2.0], [0.1, 0.05], 0.2) == 1.0


def test_length_grid_ends_at_thirty_days():
    """The half-octave grid from 64 samples stops at 24.3 d at 1 Hz; the last point is 30 d itself, so a length
    between the two (the RLG-like B's 80 % length, 26.2 d) is found, not answered "not within 30 d"."""
    from fogdrift.plan.core import MAX_LENGTH_S, _grid_n

    ns = _grid_n(1.0)
    assert ns[-1] == int(MAX_LENGTH_S) and ns[-2] < 0.85 * MAX_LENGTH_S and ns[0] == 64


def test_mc_length_reads_the_local_slope():
    L = [100.0, 400.0, 1600.0]
    w = [0.2, 0.1, 0.05]  # slope -1/2
    assert _mc_length(400.0, 0.12, 0.1, L, w) == pytest.approx(400.0 * 1.2**2)
    assert _mc_length(400.0, 0.12, 0.1, L, [0.1, 0.1, 0.1]) is None  # at its floor: no length to read


def test_summarise_by_hand():
    m = parse_model("N=1 deg/sqrt(h), B=2 deg/h", 0.1)
    fits = [{"N": (1.0, 0.9, 1.1, "resolved"), "B": (2.0, 0.0, 3.0, "unresolved")},
            {"N": (1.05, 0.945, 1.155, "resolved"), "B": (2.5, 2.1, 2.9, "resolved")},
            {"N": (0.8, 0.76, 0.84, "resolved"), "B": (1.8, 1.44, 2.16, "resolved")}]
    s = summarise(m, fits, {"N": 0.06})
    assert s["N"]["median_width"] == pytest.approx(0.1)      # widths 0.1, 0.1, 0.05
    assert s["N"]["coverage"] == pytest.approx(2 / 3)         # [0.76, 0.84] misses 1
    assert s["N"]["met_fraction"] == pytest.approx(1 / 3)
    assert s["B"]["resolved_fraction"] == pytest.approx(2 / 3)
    assert s["B"]["coverage"] == pytest.approx(2 / 3)         # [0, 3] and [1.44, 2.16] hold 2, [2.1, 2.9] does not
    assert s["B"]["median_width"] == pytest.approx(0.2)       # inf, 0.16, 0.2 (an unresolved seed counts as infinitely wide)


def test_white_noise_width_falls_as_one_over_root_length_then_floors():
    """N alone: the expected half-width falls about as 1/sqrt(length) on short records and stops at the floor
    the 2 % model-discrepancy allowance sets."""
    m = parse_model("N=1 deg/sqrt(h)", 1.0)
    w = [analytic_widths(m, n)["N"]["rel_width"] for n in (256, 1024, 2**24)]
    assert 1.5 < w[0] / w[1] < 2.2
    assert 0.01 < w[2] < 0.03


def test_rate_random_walk_is_not_resolved_on_a_short_record():
    m = parse_model(MEMS, 0.1)
    short, long_ = analytic_widths(m, 2**12), analytic_widths(m, 2**22)
    assert not short["K"]["resolved"] and short["N"]["resolved"]
    assert long_["K"]["resolved"]


# -- a plan from a pilot's fit ------------------------------------------------------------------------------------
def _pilot_fit():
    """The Allan fit of ADIS16405 session 1, axis gy, first 120 000 samples at 100 Hz (its figures, rounded)."""
    from types import SimpleNamespace

    from fogdrift.noise.result import NoiseTerm

    terms = {"Q": NoiseTerm("Q", None, "urad", 0.0, 61.3, "absent", ""),
             "N": NoiseTerm("N", 2.537, "deg/sqrt(h)", 2.409, 2.678, "resolved", ""),
             "B": NoiseTerm("B", 45.95, "deg/h", 0.0, 61.27, "unresolved", ""),
             "K": NoiseTerm("K", None, "deg/h^1.5", 0.0, 718.3, "absent", ""),
             "R": NoiseTerm("R", None, "deg/h^2", 0.0, 2795.0, "absent", "")}
    return SimpleNamespace(terms=terms, selected=("N", "B"), fit_tau_s=np.array([0.16, 0.32, 0.64]))


def test_a_pilot_plan_fits_from_the_pilots_first_tau():
    """The pilot's fit left out the taus below 0.16 s (correlated samples): the plan's fit starts there too, and
    N, best known at the short taus, is wider.  Measured on ADIS16405 session 1 gy (docs/plan.md): N at 10^6
    samples +-2.5 % from 0.01 s, +-3.8 % from 0.16 s; the full session's fit gives +-3.4 %."""
    from dataclasses import replace

    from fogdrift.plan import model_from_fit

    m = model_from_fit(_pilot_fit(), 0.01)
    assert m.tau_min_s == pytest.approx(0.16) and any("0.16 s" in n for n in m.notes)
    here = analytic_widths(replace(m, bounds={}), 10**6)
    everywhere = analytic_widths(replace(m, tau_min_s=None, bounds={}), 10**6)
    assert here["_fit"]["tau_min_s"] == pytest.approx(0.16) and everywhere["_fit"]["tau_min_s"] == pytest.approx(0.01)
    assert here["N"]["rel_width"] > 1.3 * everywhere["N"]["rel_width"]


def test_a_pilot_plan_allows_for_the_long_tau_terms_the_pilot_only_bounded():
    """K and R were only bounded by the 20-min pilot: the plan's union holds the model with each at half its
    bound, so B (which K's rise competes with) is wider; Q is not carried (the pilot's short taus bound it as well
    as the full record will).  Measured on gy: B at 10^6 samples +-13.9 % without, +-22.6 % with; the full
    session's fit (N+B+K) gives +-24.9 %."""
    from dataclasses import replace

    from fogdrift.plan import model_from_fit
    from fogdrift.plan.analytic import BOUND_FRACTION

    m = model_from_fit(_pilot_fit(), 0.01)
    assert set(m.bounds) == {"K", "R"} and m.bounds["K"] == pytest.approx(718.3) and BOUND_FRACTION == 0.5
    with_b = analytic_widths(m, 10**6)
    without = analytic_widths(replace(m, bounds={}), 10**6)
    assert with_b["B"]["rel_width"] > 1.4 * without["B"]["rel_width"]
    assert with_b["N"]["rel_width"] >= without["N"]["rel_width"]
    assert m.to_dict()["bounds"]["K"]["hi95"] == pytest.approx(718.3)


# -- analytic against Monte-Carlo, and the planner's honesty ------------------------------------------------------
SEEDS = 12


@pytest.fixture(scope="module")
def mems_plan():
    m = parse_model(MEMS, 0.1)
    return make_plan(m, {"N": 0.05, "B": 0.25}, length_s=3600.0, monte_carlo=SEEDS, workers=2)


def test_analytic_and_monte_carlo_lengths_agree(mems_plan):
    # measured (10 Hz MEMS): N to +-5 % planned at 21.6 min; 48 seeds there imply 20.2 min (docs/plan.md)
    r = mems_plan.terms["N"]
    assert r["mc"]["length_s"] == pytest.approx(r["target_s"], rel=0.25)


def test_analytic_and_monte_carlo_lengths_agree_for_b_within_25_percent(mems_plan):
    # measured: B to +-25 % planned at 96.5 min, 96 seeds' median +-27.0 %, implies 120 min (+24 %; 48 seeds at
    # 97.6 min: +10 %); the plan without the smaller plausible models in its union gave 85.6 min, where the seeds
    # imply 2.1 h (+47 %)
    r = mems_plan.terms["B"]
    assert r["mc"]["length_s"] == pytest.approx(r["target_s"], rel=0.25)


def test_recording_the_planned_length_gives_the_promised_width_and_coverage(mems_plan):
    # with 12 seeds the median width scatters by about 1.25 / sqrt(12) of its spread; coverage >= 9 of 12
    # (true 95 %: 8 or fewer in 12 has probability 0.002)
    for t in ("N", "B"):
        mc = mems_plan.terms[t]["mc"]
        assert mc["n_seeds"] == SEEDS and mc["resolved_fraction"] >= 0.9
        # the seeds' scatter of the median: ~3 % of the width for N, ~5 % for B (48-seed spread)
        assert mc["median_width"] <= (1.1 if t == "N" else 1.15) * mems_plan.terms[t]["target"], t
        assert mc["coverage"] >= 0.75, t
    assert mems_plan.seeds == list(range(1, SEEDS + 1))


def test_the_length_for_most_records_is_checked_by_monte_carlo(mems_plan):
    """``share_s``: the length at which 80 % of the records reach the target (the expected width times the 80 % /
    median ratio of the fit's rules on linearised Gaussian records, plan.spread).  Measured with 48 seeds
    (docs/plan.md): see the table there (before: the closed-form spread, B 2.24 h, 36 of 48 reach +-25 %)."""
    for t in ("N", "B"):
        r = mems_plan.terms[t]
        assert r["share"] == 0.8 and 1.05 * r["target_s"] < r["share_s"] < 2.5 * r["target_s"], t
        ms = r["mc_share"]
        assert ms["n_seeds"] == SEEDS and ms["met_fraction"] >= 7 / 12, t
        assert ms["met_fraction"] >= r["mc"]["met_fraction"], t
    r, line = mems_plan.terms["B"], mems_plan.lines()[1]  # the length to record first, then the median record's
    assert line.startswith(f"B to ±{100 * r['target']:.3g} %: {fmt_length(r['share_s'])} for 80 % of records "
                           f"(Allan fit; {round(r['mc_share']['met_fraction'] * SEEDS)} of {SEEDS} seeds reach ")
    assert f"; the median record: {fmt_length(r['target_s'])} (Allan fit)" in line and "; Allan Monte-Carlo " in line


def test_the_share_union_holds_models_some_records_find_plausible():
    """RLG-like gyro at 1 Hz, 1 612 647 samples (18.7 d): the model without K is just outside the plausible window
    at the expected curve, so the median record's union drops it (B +-19.7 %), but more than 20 % of records find
    it plausible, and the 80 % width keeps it (+-23.8 % before the spread).  Measured: 24 seeds there give a median
    of +-24.1 %."""
    m = parse_model("N=0.003 deg/sqrt(h), B=0.004 deg/h, K=0.002 deg/h^1.5", 1.0)
    median, most = analytic_widths(m, 1_612_647), analytic_widths(m, 1_612_647, share=0.8)
    assert median["B"]["rel_width"] < 0.21 and most["B"]["rel_width"] > 0.23


def test_b_interval_holds_the_plausible_model_without_k():
    """At 85.6 min K is not resolved, so the fit's union holds the model N+B (K dropped), whose B takes up part of
    K's rise.  Measured: the 48-seed Monte-Carlo median B width there is +-27.8 % (seeds 1-48); the plan gives
    +-26.1 % with that model in its union (threshold at the selected N+B's 12 degrees of freedom) and +-25.1 %
    (9.7 % optimistic) without it."""
    w = analytic_widths(parse_model(MEMS, 0.1), 51361)["B"]
    assert 0.255 <= w["rel_width"] <= 0.278
    assert not analytic_widths(parse_model(MEMS, 0.1), 51361)["K"]["resolved"]


def test_threshold_uses_the_selected_models_degrees_of_freedom():
    """RLG-like gyro at 1 Hz, N to +-5 % (about 2 h): B and K are invisible there, and the real fit selects N alone
    (11 taus, 10 degrees of freedom; 8 seeds); the plan's threshold uses the same model, not the true 3-term one."""
    m = parse_model(RLG, 1.0)
    w = analytic_widths(m, 7164)
    assert w["_fit"]["selected"] == "N" and w["_fit"]["dof"] == 10 and w["_fit"]["n_taus"] == 11
    assert 0.048 < w["N"]["rel_width"] < 0.0505
    long_ = analytic_widths(m, 1_328_400)["_fit"]
    assert long_["selected"] == "N+B+K" and long_["dof"] == long_["n_taus"] - 3


def test_share_ratio_reproduces_the_seed_spread():
    """The 80 % / median width ratio of the linearised fit: 1 at the median by construction; for the MEMS B at its
    planned length about the 48 seeds' 1.18 (real fits, docs/plan.md), for N (no union to vary) less."""
    from fogdrift.plan.spread import share_ratio

    m = parse_model(MEMS, 0.1)
    assert share_ratio(m, 57906, "B", 0.5, draws=100) == pytest.approx(1.0)
    rb = share_ratio(m, 57906, "B", 0.8, draws=200)
    rn = share_ratio(m, 12973, "N", 0.8, draws=200)
    assert 1.12 < rb < 1.3 and 1.04 < rn < 1.16 and rn < rb


def test_the_80_percent_length_is_the_fixed_point_of_the_spread(monkeypatch):
    """share_s solves L = crossing(w_share * ratio(L) * 1.03): the spread is taken at the length it is applied to,
    and the allowance for what the linearised records miss is on it (docs/plan.md, "The allowance").  The
    ratio falls with length (MEMS B: 1.216 at 57 906 samples, 1.137 at 106 415), so the two substitution passes of
    before (at the nearest half-octave grid point) stopped at 86 650 samples where the fixed point is 91 974 (90 578
    with the records' finite-record covariance; seeds 1-96 reach +-25 % there in 82, 1-600 in 473; docs/plan.md).
    A stand-in ratio (no records: exact)."""
    import fogdrift.plan.core as core
    from fogdrift.plan.spread import SPREAD_DRAWS

    calls = []

    def ratio(model, n, term, share, draws=SPREAD_DRAWS, seed=0):
        calls.append((n, draws))
        return 1.25 * (n / 57906.0) ** -0.15

    monkeypatch.setattr(core, "share_ratio", ratio)
    model = parse_model(MEMS, 0.1)
    plan = make_plan(model, {"B": 0.25}, estimators=("allan",))
    r = plan.terms["B"]
    assert calls[-1][1] == SPREAD_DRAWS >= 1600 and len(calls) <= 9
    assert r["share_ratio"] == pytest.approx(1.25 * (r["share_s"] / 0.1 / 57906.0) ** -0.15, rel=1e-3)
    assert 1.3 * r["target_s"] < r["share_s"] < 1.8 * r["target_s"]
    # the 80 % width: the share union's times the spread and the allowance, at every length of the grid
    i = min(range(len(plan.grid["length_s"])), key=lambda k: abs(plan.grid["length_s"][k] - r["share_s"]))
    union = analytic_widths(model, plan.grid["n_samples"][i], share=0.8)["B"]["rel_width"]
    assert core.SHARE_ALLOWANCE == pytest.approx(0.03)
    assert plan.grid["width_share"]["B"][i] == pytest.approx(union * r["share_ratio"] * 1.03, rel=1e-9)


def test_the_80_percent_length_is_found_when_the_first_step_overshoots_the_grid(monkeypatch):
    """The spread of a short record is wider than that of a long one: at the median record's length it may put the
    80 % width's crossing beyond 30 d while the fixed point lies within (RLG-like B, +-25 %: 15.4 d's spread gives
    no crossing, 29.6 d's gives one there).  A stand-in ratio of 10 at the median length falling as n^-0.45:
    the first step lands past the grid, the fixed point is near 10^6 samples; a ratio that stays at 10 has none."""
    import fogdrift.plan.core as core

    def ratio(model, n, term, share, draws=None, seed=0):
        return 10.0 * (n / 57906.0) ** -0.45

    monkeypatch.setattr(core, "share_ratio", ratio)
    model = parse_model(MEMS, 0.1)
    r = make_plan(model, {"B": 0.25}, estimators=("allan",)).terms["B"]
    assert r["share_s"] is not None and 3e5 < r["share_s"] / 0.1 < 5e6
    assert r["share_ratio"] == pytest.approx(ratio(model, r["share_s"] / 0.1, "B", 0.8), rel=2e-3)
    monkeypatch.setattr(core, "share_ratio", lambda *a, **k: 10.0)
    r = make_plan(model, {"B": 0.25}, estimators=("allan",)).terms["B"]
    assert r["share_s"] is None and r["target_s"] is not None
    assert make_plan(model, {"B": 0.25}, estimators=("allan",)).lines()[0].startswith(
        "B to ±25 %: not within 30 d for 80 % of records (Allan fit); the median record: ")


def test_model_curves_are_unbiased_with_the_estimators_scatter():
    """plan.spread.model_curves (the Allan curves the fit-rule check draws): each point's mean is the model's and
    its relative s.d. the estimators' sqrt(2 / nu) (4 000 draws at the MEMS B 80 % length, 86 650 samples: the
    long-tau points have nu ~ 3, where a Wilson-Hilferty draw centred at 1 instead of 1 - 2 / (9 nu) is 20 % high)."""
    from fogdrift.plan.spread import model_curves

    m, mu, nu, y = model_curves(parse_model(MEMS, 0.1), 86650, 4000, seed=1)
    r = y / mu
    se = r.std(axis=0) / math.sqrt(r.shape[0])
    assert m.size == 15 and nu[-1] < 5
    assert np.all(np.abs(r.mean(axis=0) - 1.0) < 4.0 * se)
    assert np.allclose(r.std(axis=0), np.sqrt(2.0 / nu), rtol=0.05)


def test_the_fits_own_rules_on_model_records_give_the_planned_80_percent_width():
    """The Allan fit itself (identify: selection, slope rules, union over the plausible models, chi2 widening) on
    Allan curves drawn from the model's sampling covariance (plan.spread.fit_rule_widths) at the MEMS B 80 % length
    (86 650 samples, where the plan's 80 % width is +-25 %): about 80 % of them reach +-25 % (400 draws: 78.7 %;
    the plan's linearised records hold the fit's rules).  Measured (docs/plan.md): the same fit on the real
    simulated records reaches it in 219 of seeds 1-300 (73 %), its median (+-22.4 %) as the model records' (+-22.7 %)
    but a longer upper tail -- the records' curves, not the fit's rules, differ."""
    from fogdrift.plan.spread import fit_rule_widths

    w = fit_rule_widths(parse_model(MEMS, 0.1), 86650, "B", draws=100)
    assert 0.21 < float(np.median(w)) < 0.245
    assert 0.7 <= float(np.mean(w <= 0.25)) <= 0.92


def test_rlg_n_analytic_and_monte_carlo_lengths_agree():
    """RLG-like N to +-5 % (1 Hz, ~1.8 h): measured with 24 seeds (docs/plan.md) the Monte-Carlo width implies a
    length within 25 % of the plan's (before the selected model's degrees of freedom: -28 %, 12 seeds)."""
    p = make_plan(parse_model(RLG, 1.0), {"N": 0.05}, monte_carlo=8, estimators=("allan",))
    r = p.terms["N"]
    assert r["mc"]["length_s"] == pytest.approx(r["target_s"], rel=0.25)
    assert r["mc"]["coverage"] >= 7 / 8 and r["mc_share"]["met_fraction"] >= 5 / 8


def test_stated_length_verdicts_match_the_monte_carlo(mems_plan):
    at = mems_plan.at_length
    assert at["terms"]["N"]["resolved"] and not at["terms"]["K"]["resolved"]
    assert at["mc"]["N"]["resolved_fraction"] >= 0.9 and at["mc"]["K"]["resolved_fraction"] <= 0.5
    lines = mems_plan.lines()
    assert lines[-1].startswith("a 60 min record resolves N to ±") and "K only as a bound" in lines[-1]
    json.dumps(mems_plan.to_dict())


# -- the command ------------------------------------------------------------------------------------------------
def test_cli_plan_writes_json_and_figure(tmp_path, monkeypatch):
    from typer.testing import CliRunner

    import fogdrift.plan.core as core
    from fogdrift.cli import _commands

    monkeypatch.setattr(core, "share_ratio", lambda *a, **k: 1.15)  # the 80 % length: tested above, costly here
    out = tmp_path / "p"
    res = CliRunner().invoke(_commands(), ["plan", "--model", MEMS, "--rate", "10", "--target", "N:5%,B:20%",
                                           "--length", "2h", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "N to ±5 %:" in res.output and "(Allan fit)" in res.output and "a 2 h record resolves N" in res.output
    d = json.loads((out / "plan.json").read_text())
    assert d["terms"]["B"]["target"] == 0.2 and d["terms"]["B"]["unit"] == "deg/h"
    assert d["terms"]["B"]["target_s"] > d["terms"]["B"]["resolved_s"] > 0
    assert d["terms"]["B"]["share_ratio"] == 1.15 and d["terms"]["B"]["share_s"] > d["terms"]["B"]["target_s"]
    assert "for 80 % of records (Allan fit)" in res.output and (out / "plan.png").stat().st_size > 1000


@pytest.mark.parametrize("args, words", [
    (["--model", MEMS], "needs the sample rate"), (["--model", "N=1 deg/furlong", "--rate", "10"], "unknown unit"),
    (["--model", MEMS, "--rate", "10", "--target", "R:5%"], "no R term"), ([], "either a pilot log"),
    (["--model", MEMS, "--rate", "10", "--length", "3 fortnights"], "unknown time unit")])
def test_cli_refusals_are_one_line(tmp_path, args, words):
    from typer.testing import CliRunner

    from fogdrift.cli import _commands

    res = CliRunner().invoke(_commands(), ["plan", *args, "--out", str(tmp_path / "p")])
    assert res.exit_code == 1
    text = res.output.strip()
    assert words in text and len(text.splitlines()) == 1, text


def test_model_file_takes_the_interval_from_the_records_signal_description(tmp_path):
    """A result whose fit states no dt_s: the interval is the record's signal.sampling, never a synonym beside it."""
    from fogdrift.io import from_array
    from fogdrift.plan import read_model_file

    record = json.loads(json.dumps(from_array([0.0] * 8, dt_s=0.25).to_rate(2.0).metadata()))
    axes = [{"name": "gz", "noise": {"terms": {"N": {"value": 0.1, "unit": "deg/sqrt(h)"}}}}]
    p = tmp_path / "allan.json"
    p.write_text(json.dumps({"record": {**record, "dt_s": 9.0}, "axes": axes}))
    m = read_model_file(p)
    assert m.dt_s == 0.5 and m.coefficients == {"N": 0.1}
    p.write_text(json.dumps({"record": {"dt_s": 0.5, "fs_hz": 2.0}, "axes": axes}))
    with pytest.raises(ConfigError) as ei:
        read_model_file(p)
    assert str(ei.value) == (f"{p}: the record states its sampling only as dt_s, fs_hz, not in 'signal.sampling' "
                             "where this fogdrift reads it; re-run the fogdrift command that wrote the file")
