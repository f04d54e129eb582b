"""The one verdict rule (:func:`fogdrift.evaluation.verdicts.judge`) and what hangs on it.

A model *reduces* the heading error only when its RMS is at least 5 % below constant bias's AND it is better at
MORE THAN HALF of the origins whose horizon windows do not overlap; *worsens* is the mirror image; a diverged
forecast is "diverges" and never a reduction.  The independent references are hand-built errors and rows whose
counts are known by construction; each test names the one-line bug it catches.  The compensate tests run the
command on a small simulated bundle: its own training log (same SHA-256) gets the not-held-out warning, the
artefact check runs by default, and the stored JSON has no unrendered ``{opt:`` marker.
"""

from __future__ import annotations

import json
import math
import re
from types import SimpleNamespace as NS

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.evaluation import headline_verdict
from fogdrift.evaluation.heading import HeadingResult, heading_errors, heading_row
from fogdrift.evaluation.verdicts import (adev_caveat, diverges, heading_table, heading_verdict, independent_origins,
                                          independent_subset, judge, one_step_lines, table2_verdict)


def _errors(n, better_at, big=1.01, small=0.1):
    """Constant bias errs 1 deg at every origin; the model errs ``small`` at ``better_at`` and ``big`` elsewhere."""
    e = np.full(n, big)
    e[list(better_at)] = small
    return e, np.ones(n)


def _result(rows, step_s=300.0, horizons=(600.0,)):
    base = [heading_row("constant bias", np.ones(r.n_origins), np.ones(r.n_origins), horizon_s=r.horizon_s,
                        step_s=step_s) for r in rows]
    return NS(axis="gz", calib_s=300.0, step_s=step_s, horizons_s=horizons, rows=base + list(rows))


def _row(label, ratio, better, worse, n=12, h=600.0):
    return NS(model=label, horizon_s=h, n_origins=2 * n - 1, rms_deg=ratio, ratio_to_bias=ratio, wins_vs_bias=0.5,
              predicted_sigma_deg=None, inside_sigma=None, n_independent=n, better_independent=better,
              worse_independent=worse, median_abs_deg=ratio, p90_abs_deg=ratio)


# ---------------------------------------------------------------------------------------------------------------
# the rule on rows with known counts


def test_ratio_088_but_better_at_45_percent_is_not_a_reduction_and_says_the_count():
    """RMS -12 % but better at 9 of 20 non-overlapping origins (45 %): not "reduces"; the sentence gives the count.
    Catches: the rule reading only the ratio, or counting all (overlapping) origins."""
    v = heading_verdict(_result([_row("Kalman", 0.88, 9, 11, n=20)]))
    assert v.data["600.0"]["reduces"] == []
    assert "no model reduces" in v.lines[-1] and "better at only 9 of 20 non-overlapping origins" in v.lines[-1]
    assert judge(_row("Kalman", 0.88, 9, 11, n=20)).outcome == "not at most origins"


def test_ratio_088_better_at_60_percent_reduces():
    v = heading_verdict(_result([_row("Kalman", 0.88, 12, 8, n=20)]))
    assert v.data["600.0"]["reduces"] == ["Kalman"]
    assert v.lines[-1] == ("gz, 600 s: reduces the heading error: Kalman by 12 % (better at 12 of 20 non-overlapping "
                           "origins).")


@pytest.mark.parametrize("better, outcome", [(6, "not at most origins"), (7, "reduces")])
def test_exactly_half_is_not_most(better, outcome):
    """6 of 12 is half, not more than half.  Catches ``>=`` for ``>``."""
    assert judge(_row("m", 0.80, better, 12 - better)).outcome == outcome


@pytest.mark.parametrize("worse, outcome", [(6, "not at most origins"), (7, "worsens")])
def test_worsens_is_the_mirror_image(worse, outcome):
    """+12 % RMS worsens only when worse at more than half (catches the old ratio-only "worse" and ``>=``)."""
    j = judge(_row("m", 1.12, 12 - worse, worse))
    assert j.outcome == outcome and j.worsens == (outcome == "worsens")


@pytest.mark.parametrize("ratio, outcome", [(0.951, "not material"), (0.95, "reduces"), (1.049, "not material"),
                                            (1.05, "worsens")])
def test_material_threshold_is_5_percent_on_both_sides(ratio, outcome):
    """Better (worse) at every origin, ratio at the 5 % edge.  Catches a sign or factor bug on MATERIAL."""
    better, worse = (12, 0) if ratio < 1 else (0, 12)
    assert judge(_row("m", ratio, better, worse)).outcome == outcome


def test_too_few_non_overlapping_origins_are_not_judged():
    assert judge(_row("m", 0.5, 9, 0, n=9)).outcome == "too few"
    assert judge(_row("m", 0.5, 10, 0, n=10)).outcome == "reduces"


# ---------------------------------------------------------------------------------------------------------------
# counting over the non-overlapping subset


def test_independent_subset_is_every_ceil_h_over_step_th_origin():
    """By hand: step 300 s, horizon 600 s -> every 2nd origin; 700 s -> every 3rd (ceil); step >= horizon -> all."""
    assert independent_subset(7, 300.0, 600.0).tolist() == [0, 2, 4, 6]
    assert independent_subset(7, 300.0, 700.0).tolist() == [0, 3, 6]
    assert independent_subset(5, 300.0, 60.0).tolist() == [0, 1, 2, 3, 4]
    for n, step, h in [(31, 300.0, 600.0), (21, 300.0, 3600.0), (30, 60.0, 600.0), (7, 300.0, 700.0), (1, 60.0, 600.0)]:
        assert independent_origins(n, step, h) == independent_subset(n, step, h).size


def test_overlapping_origins_are_counted_by_their_non_overlapping_subset():
    """24 origins 300 s apart, 600-s horizon: the non-overlapping ones are 0, 2, ..., 22 (12).  The model wins at
    every odd origin and at 5 even ones: 17 of 24 = 71 % of ALL origins, but only 5 of the 12 that count.
    Catches counting all origins (17 > 12) or the wrong subset (the odd ones: 12 of 12)."""
    e, eb = _errors(24, list(range(1, 24, 2)) + [0, 2, 4, 6, 8])
    r = heading_row("Kalman", e, eb, horizon_s=600.0, step_s=300.0)
    assert r.wins_vs_bias == pytest.approx(17 / 24)
    assert (r.n_independent, r.better_independent, r.worse_independent) == (12, 5, 7)
    assert r.ratio_to_bias < 0.95 and judge(r).outcome == "not at most origins"
    e2, _ = _errors(24, list(range(0, 24, 2))[:7])  # 7 of the 12 non-overlapping, none of the others
    r2 = heading_row("Kalman", e2, eb, horizon_s=600.0, step_s=300.0)
    assert r2.ratio_to_bias < 0.95 and r2.wins_vs_bias == pytest.approx(7 / 24) and judge(r2).outcome == "reduces"


def test_rows_of_a_real_evaluation_carry_the_counts():
    """heading_errors on white noise (origins every 60 s, horizons 60 and 600 s): the counts are over the subset."""
    from fogdrift.models import Persistence

    r = 3.0 + np.random.default_rng(1).normal(0.0, 6.0, 6000)
    res = heading_errors(r, 1.0, {"persistence": Persistence().fit(r[:10])}, causal_window=128, step_s=60.0,
                         horizons_s=(60.0, 600.0))
    for row in res.rows:
        assert row.n_independent == independent_origins(row.n_origins, 60.0, row.horizon_s)
        assert row.better_independent + row.worse_independent <= row.n_independent
    row = res.row("persistence", 600.0)
    sub = independent_subset(row.n_origins, 60.0, 600.0)
    e = np.abs(res.errors["persistence"][: row.n_origins, 1][sub])
    eb = np.abs(res.errors["constant bias"][: row.n_origins, 1][sub])
    assert row.better_independent == int(np.sum(e < eb)) and row.worse_independent == int(np.sum(e > eb))


# ---------------------------------------------------------------------------------------------------------------
# diverging forecasts


class _Runaway:
    """A drift model whose forecast is NaN (``kind="nan"``) or 1e30 deg/h (``"huge"``)."""

    input_kind = "drift"
    label = "runaway"

    def __init__(self, kind):
        self.kind = kind

    def forecast(self, n, history=None):
        if self.kind == "nan":
            return np.full(n, np.nan)
        return np.full(n, 1e30)


@pytest.mark.parametrize("kind", ["nan", "huge"])
def test_a_diverging_forecast_reads_diverges_and_never_reduces(kind):
    r = np.random.default_rng(2).normal(0.0, 6.0, 4000)
    res = heading_errors(r, 1.0, {"runaway": _Runaway(kind)}, causal_window=64, step_s=60.0, horizons_s=(60.0,))
    row = res.row("runaway", 60.0)
    j = judge(row, step_s=60.0)
    assert j.outcome == "diverges" and j.worsens and not j.reduces
    d = row.to_dict()
    assert d["diverges"] is True and (d["rms_deg"] is None if kind == "nan" else d["rms_deg"] > 1e27)
    v = heading_verdict(res)
    assert "runaway diverges" in v.lines[0] and "runaway" in v.data["60.0"]["diverges"]
    assert "runaway" not in v.data["60.0"]["reduces"]
    headers, rows = heading_table(res)
    cells = dict(zip(headers, next(x for x in rows if x[0] == "runaway")))
    assert cells["RMS 60 s [deg]"] == "diverges" and cells["/ bias 60 s"] == "diverges"
    hv = headline_verdict(res)
    assert hv.data["model"] != "runaway" and "runaway" in hv.data["diverges"]


def test_diverges_bound():
    """Non-finite, or above 1e3 x constant bias's RMS; 999 x is a (bad) number, not a divergence."""
    assert diverges(math.nan, math.nan) and diverges(math.inf, math.inf) and diverges(5e6, 4.8e5)
    assert not diverges(999.0, 999.0) and not diverges(0.5, 0.88)


# ---------------------------------------------------------------------------------------------------------------
# headline, table 2 flag, ADEV caveat


def test_headline_uses_the_same_rule_and_prints_the_count():
    res = _result([_row("Kalman", 0.88, 9, 11, n=20)])
    v = headline_verdict(res)
    assert v.data["outcome"] == "none", v.lines  # the old ratio-only rule said "reduces ... by 12 %"
    res = _result([_row("Kalman", 0.88, 15, 5, n=20)])
    v = headline_verdict(res)
    assert v.data["outcome"] == "reduces" and "better at 15 of 20 non-overlapping origins" in v.lines[0]


def test_table2_practical_flag_on_the_console():
    rows = [NS(label="Kalman: output - causal prediction (practical)", kind="practical", model="Kalman"),
            NS(label="Kalman: drift residual (paper)", kind="paper", model="Kalman"),
            NS(label="AR(p): output - causal prediction (practical)", kind="practical", model="AR(p)")]
    arte = NS(rows=[NS(model="Kalman", flagged_hz=(0.001, 0.002)), NS(model="AR(p)", flagged_hz=())])
    v = table2_verdict(rows, arte, axis="gx")
    assert len(v.lines) == 1 and '"Kalman: output - causal prediction (practical)" FLAGGED' in v.lines[0]
    assert "0.001, 0.002 Hz" in v.lines[0]
    assert table2_verdict(rows, None) is None
    assert table2_verdict(rows, NS(rows=[NS(model="Kalman", flagged_hz=())])) is None


def test_adev_caveat_flagged_clean_and_not_run():
    flagged = NS(rows=[NS(model="Kalman", flagged_hz=(0.005,))])
    assert "is not evidence: the artefact check shows it removes real rate near 0.005 Hz" in adev_caveat("Kalman",
                                                                                                          flagged)
    assert "artefact check clean" in adev_caveat("Kalman", NS(rows=[NS(model="Kalman", flagged_hz=())]))
    assert "not checked" in adev_caveat("Kalman", None, why_not="--no-artefacts")


# ---------------------------------------------------------------------------------------------------------------
# compensate: training log, artefact check by default, rendered JSON


FS = 10.0


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """A bundle (AR and persistence) trained on a CSV log without a declared unit, and a second session."""
    from fogdrift.bundle import write_bundle
    from fogdrift.io import load
    from fogdrift.pipeline import AnalysisConfig, run_models
    from fogdrift.simulate import simulate

    d = tmp_path_factory.mktemp("trained")
    paths = []
    for seed in (1, 2):
        x = simulate(20000, 1 / FS, arw_dprh=0.05, rrw_dphrh=2.0, bias_dph=3.0, seed=seed) / 3600.0
        p = d / f"log{seed}.csv"
        np.savetxt(p, np.column_stack([np.arange(x.size) / FS, x]), delimiter=",", header="t_s,gz", comments="",
                   fmt="%.17g")
        paths.append(p)
    rec = load(paths[0], unit="deg/s")
    cfg = AnalysisConfig(models=("ar", "persistence"), lags=3)
    write_bundle(d / "bundle", run_models(rec, cfg), cfg, rec)
    return d / "bundle", paths[0], paths[1]


def _compensate(bundle, log, out, *extra):
    from fogdrift.cli import app

    res = CliRunner().invoke(app, ["compensate", str(bundle), str(log), "--model", "ar", "--calibration", "200",
                                   "--origin-step", "200", "--horizons", "60", "--unit", "deg/s", "--out", str(out),
                                   *extra],
                             env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    return res.output, json.loads((out / "compensation.json").read_text())


def test_compensate_on_its_training_log_warns_and_runs_the_artefact_check_by_default(trained, tmp_path):
    bundle, train, other = trained
    out, doc = _compensate(bundle, train, tmp_path / "same")
    assert "bundle's own training log (same SHA-256)" in out and "NOT held-out" in out
    assert doc["held_out"] is False and doc["log_sha256"] == doc["bundle_training_sha256"]
    # the artefact check ran without being asked, and its caveat is on the console
    assert doc["artefacts"] and any(v["kind"] == "artefacts" for v in doc["verdicts"])
    assert "surviving fraction of injected signals" in out
    assert re.search(r"gz: (the lower long-τ ADEV of AR\(p\) is not evidence|artefact check clean)", out)
    out, doc = _compensate(bundle, other, tmp_path / "other")
    assert "training log" not in out and doc["held_out"] is True


def test_compensate_artefact_switches_and_rendered_json(trained, tmp_path):
    bundle, _, other = trained
    out, doc = _compensate(bundle, other, tmp_path / "off", "--no-artefacts")
    assert doc["artefacts"] == [] and "surviving fraction" not in out
    assert "not checked: the artefact check did not run (--no-artefacts)" in out
    out, doc = _compensate(bundle, other, tmp_path / "on", "--artefacts")
    assert doc["artefacts"]
    text = (tmp_path / "on" / "compensation.json").read_text()
    assert "{opt:" not in text
    assert "read as deg/s (--unit)" in text  # the CSV declares no unit: the note says where the unit came from


# ---------------------------------------------------------------------------------------------------------------
# CLI text: --models help, the paper's-measure label in `model`


@pytest.mark.parametrize("command", ["model", "analyze"])
def test_models_help_is_words_not_characters(command):
    from fogdrift.cli import app

    res = CliRunner().invoke(app, [command, "--help"], env={"COLUMNS": "200"})
    assert res.exit_code == 0
    text = " ".join(res.output.split())
    assert "kalman: Kalman filter on the rate" in text and "persistence: repeat the last value" in text
    assert "g; r; e" not in text


def test_model_labels_the_paper_measure(tmp_path):
    from fogdrift.cli import app
    from fogdrift.simulate import simulate

    x = simulate(6000, 1.0, arw_dprh=0.05, rrw_dphrh=2.0, bias_dph=3.0, seed=3)
    np.savetxt(tmp_path / "log.csv", np.column_stack([np.arange(x.size), x]), delimiter=",", header="t_s,gz",
               comments="", fmt="%.17g")
    res = CliRunner().invoke(app, ["model", str(tmp_path / "log.csv"), "--unit", "deg/h", "--models", "ar,persistence",
                                   "--out", str(tmp_path / "o")], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert "gz: paper's measure (one step ahead, target = non-causal wavelet drift; not a compensation result): AR(p) RMSE" in text
    assert "beat persistence one step ahead" not in text  # the unlabelled sentence is gone


def test_analysis_evaluation_carries_the_table2_flag_for_the_console():
    """evaluated_analysis adds the Table 2 flag as a verdict (printed by analyze --details through print_evaluation):
    persistence of the causal drift is a 128-s high-pass, flagged by the artefact check on a random-walk record."""
    from fogdrift.evaluation import evaluated_analysis, table2_marks
    from fogdrift.io import from_array
    from fogdrift.pipeline import AnalysisConfig, run_analysis
    from fogdrift.simulate import simulate

    x = simulate(20000, 1.0, arw_dprh=0.05, rrw_dphrh=20.0, bias_dph=3.0, seed=4)
    res = run_analysis(from_array(x[:, None], dt_s=1.0, unit="deg/h", axis_names=["gz"]),
                       AnalysisConfig(models=("persistence",), model_rate_hz=None))
    res = evaluated_analysis(res)
    (ev,) = [ax.evaluation for ax in res.axes]
    marks = table2_marks(res.axes[0].table2, ev.artefacts)
    assert list(marks) == ["persistence: output - causal prediction (practical)"]
    flag = next(v for v in ev.verdicts if v.kind == "table2")
    assert flag.data["marks"] == marks and "FLAGGED" in flag.lines[0] and "(practical)" in flag.lines[0]


def _one_step_axis(**models):
    """A model axis with constructed metrics: persistence RMSE 1.0 and MAE 0.8 deg/h."""
    metrics = {"persistence": NS(rmse_dph=1.0, mae_dph=0.8, rmse_persistence_dph=1.0)}
    for label, (rmse, mae) in models.items():
        metrics[label] = NS(rmse_dph=rmse, mae_dph=mae, rmse_persistence_dph=1.0)
    return NS(metrics=metrics)


def test_one_step_sentences_on_constructed_metrics():
    """The paper's one-step verdict: beat only when RMSE and MAE are both lower, MIXED when they disagree."""
    lines = one_step_lines(_one_step_axis(good=(0.9, 0.6), bad=(1.2, 0.9), mixed=(0.95, 0.85), mixed2=(1.1, 0.7)))
    assert lines[0] == ("good beat persistence one step ahead: RMSE 0.9 vs 1 deg/h (-10.0 %), "
                        "MAE 0.6 vs 0.8 deg/h (-25.0 %).")
    assert lines[1].startswith("bad did NOT beat persistence") and "(+20.0 %)" in lines[1] and "(+12.5 %)" in lines[1]
    assert lines[2].startswith("mixed gave a MIXED result against persistence")
    assert lines[3].startswith("mixed2 gave a MIXED result against persistence")
    assert lines[4] == "Lowest RMSE among learned models on the test block: good."
    assert one_step_lines(NS(metrics={"persistence": _one_step_axis().metrics["persistence"]})) == [
        "Only the persistence baseline was run."]
