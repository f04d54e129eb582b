"""Every verdict sentence and table cell of :mod:`fogdrift.evaluation.verdicts`, pinned on hand-built rows
(issue 24, round 2 of mutation testing: the survivors were wording, branch and number-format mutants).

The rows are built so that each branch of the sentences is taken once: the headline when nothing ran, when no
horizon can be judged (with and without overlapping origins), "none" over three horizons, "mixed" by the artefact
check, "reduces" with a clean check, the best of two reducing models; the ADEV caveat with each artefact state and
the heading's worth; the per-horizon sentences when too few origins count; the artefact sentences and tables.
The expected strings were read against the rule they state (:func:`~fogdrift.evaluation.verdicts.judge`,
the module docstrings) before being pinned.
"""

from __future__ import annotations

import math
from types import SimpleNamespace as NS

import numpy as np
import pytest

from fogdrift.evaluation.heading import heading_row
from fogdrift.evaluation.verdicts import (Verdict, adev_caveat, artefact_table, artefact_verdict, causal_verdict,
                                          compensation_verdicts, heading_table, paper_measure_verdict,
                                          heading_verdict, headline_verdict, independent_origins, judge, table2_marks,
                                          table2_verdict)
from fogdrift.evaluation.verdicts import _f, _pct


def _row(m, h, rms, ratio, better=0, worse=0, n=30, n_origins=None, sigma=None, inside=None):
    return NS(model=m, horizon_s=h, n_origins=n_origins or n, rms_deg=rms, ratio_to_bias=ratio, n_independent=n,
              better_independent=better, worse_independent=worse, wins_vs_bias=0.5, predicted_sigma_deg=sigma,
              inside_sigma=inside)


def _heading(rows, horizons, step=300.0, axis="gx"):
    return NS(axis=axis, calib_s=300.0, step_s=step, horizons_s=horizons, rows=rows)


# the mixed / reduces case: Kalman reduces at 60 and 600 s, AR(p) at 60 s only and worsens at 600 s
TWO = [_row("constant bias", 60.0, 1.0, 1.0), _row("AR(p)", 60.0, 0.7, 0.7, 20, 10),
       _row("Kalman", 60.0, 0.8, 0.8, 20, 10), _row("constant bias", 600.0, 8.0, 1.0),
       _row("AR(p)", 600.0, 9.0, 1.125, 10, 20), _row("Kalman", 600.0, 6.0, 0.75, 20, 10)]
FLAGGED = NS(rows=[NS(model="Kalman", flagged_hz=(0.001, 0.002)), NS(model="AR(p)", flagged_hz=())])
CLEAN = NS(rows=[NS(model="Kalman", flagged_hz=()), NS(model="AR(p)", flagged_hz=())])


def test_headline_not_run():
    v = headline_verdict(None, axis="gy", reason="the held-out block is shorter than one calibration")
    assert v.to_dict() == {"kind": "headline", "lines": [
        "gy: heading error not evaluated (the held-out block is shorter than one calibration); no compensation "
        "verdict."], "data": {"outcome": "undetermined", "model": None,
                              "reason": "the held-out block is shorter than one calibration"}}
    assert headline_verdict(None, axis="gy").lines == ["gy: heading error not evaluated (not run); no compensation "
                                                       "verdict."]


def test_headline_undetermined_names_the_non_overlapping_count_when_origins_overlap():
    """17 origins 60 s apart at a 600-s horizon are 2 independent ones: the sentence says so (it said '17
    calibration origin(s) ... need 10', which reads as enough).  9 origins at 60 s: no overlap, no second count."""
    rows = [heading_row("constant bias", np.ones(17), np.ones(17), horizon_s=600.0, step_s=60.0)]
    v = headline_verdict(_heading(rows, (600.0,), step=60.0))
    assert v.lines == ["gx: cannot judge whether any model reduces the heading error: the held-out block gives 17 "
                       "calibration origin(s), 2 of them with non-overlapping horizons, at 600 s (300-s calibrations "
                       "every 60 s; need 10)."]
    assert v.data == {"outcome": "undetermined", "model": None, "judged_horizons_s": []}
    rows = [heading_row("constant bias", np.ones(9), np.ones(9), horizon_s=60.0, step_s=60.0)]
    v = headline_verdict(_heading(rows, (60.0,), step=60.0), min_origins=10)
    assert v.lines == ["gx: cannot judge whether any model reduces the heading error: the held-out block gives 9 "
                       "calibration origin(s) at 60 s (300-s calibrations every 60 s; need 10)."]
    assert headline_verdict(_heading(rows, (60.0,), step=60.0), min_origins=9).data["outcome"] == "none"


def test_headline_none_over_three_horizons_names_the_worse_model():
    rows = []
    for h, rms, ar in ((60.0, 1.0, 1.2), (600.0, 8.0, 1.125), (3600.0, 20.0, 1.05)):
        rows += [_row("constant bias", h, rms, 1.0), _row("AR(p)", h, rms * ar, ar, 5, 25),
                 _row("Kalman", h, rms * 0.97, 0.97, 20, 10)]
    v = headline_verdict(_heading(rows, (60.0, 600.0, 3600.0)))
    assert v.lines == ["gx: no model reduces the heading error by 5 % or more at most non-overlapping origins at 60, "
                       "600 or 3600 s after a 300-s calibration (constant bias leaves 1 / 8 / 20 deg RMS; worse: "
                       "AR(p))."]
    assert v.data == {"outcome": "none", "model": None, "judged_horizons_s": [60.0, 600.0, 3600.0], "reduces": {},
                      "worsens": {"AR(p)": [60.0, 600.0, 3600.0]}, "flagged_hz": {}, "diverges": {}}
    two = headline_verdict(_heading(rows[:6], (60.0, 600.0)))
    assert "at 60 or 600 s after" in two.lines[0]
    one = headline_verdict(_heading(rows[:2], (60.0,)))
    assert one.lines[0] == ("gx: no model reduces the heading error by 5 % or more at most non-overlapping origins "
                            "at 60 s after a 300-s calibration (constant bias leaves 1 deg RMS; worse: AR(p)).")


def test_headline_best_model_reduces_at_most_horizons_and_the_artefact_check_decides_mixed():
    """Kalman reduces at two horizons (AR(p) at one, by more): Kalman is the best, read at its largest reduction
    (600 s, -25 %); flagged by the artefact check -> mixed; clean -> reduces."""
    v = headline_verdict(_heading(TWO, (60.0, 600.0)), FLAGGED)
    assert v.lines == ["gx: Kalman reduces the heading error by 25 % at 600 s after a 300-s calibration (6 vs 8 deg "
                       "RMS, better at 20 of 30 non-overlapping origins) but removes real rate near 0.001, 0.002 Hz "
                       "(artefact check)."]
    assert v.data == {"outcome": "mixed", "model": "Kalman", "horizon_s": 600.0, "ratio_to_bias": 0.75,
                      "judged_horizons_s": [60.0, 600.0], "reduces": {"AR(p)": [60.0], "Kalman": [60.0, 600.0]},
                      "worsens": {"AR(p)": [600.0]}, "flagged_hz": {"Kalman": [0.001, 0.002]}, "diverges": {}}
    v = headline_verdict(_heading(TWO, (60.0, 600.0)), CLEAN)
    assert v.data["outcome"] == "reduces" and v.lines == [
        "gx: Kalman reduces the heading error by 25 % at 600 s after a 300-s calibration (6 vs 8 deg RMS, better at "
        "20 of 30 non-overlapping origins) and worsens it at no judged horizon (60, 600 s); artefact check clean."]


def test_headline_tie_on_horizons_goes_to_the_larger_reduction_and_worsening_is_mixed():
    """Both reduce at one horizon: AR(p) (-30 %) beats Kalman (-20 %); AR(p) worsens at 600 s -> mixed with the
    worse count."""
    rows = [_row("constant bias", 60.0, 1.0, 1.0), _row("AR(p)", 60.0, 0.7, 0.7, 20, 10),
            _row("Kalman", 60.0, 0.8, 0.8, 20, 10), _row("constant bias", 600.0, 8.0, 1.0),
            _row("AR(p)", 600.0, 9.0, 1.125, 10, 20), _row("Kalman", 600.0, 8.0, 1.0, 15, 15)]
    v = headline_verdict(_heading(rows, (60.0, 600.0)))
    assert v.data["model"] == "AR(p)" and v.data["outcome"] == "mixed"
    assert v.lines == ["gx: AR(p) reduces the heading error by 30 % at 60 s after a 300-s calibration (0.7 vs 1 deg "
                       "RMS, better at 20 of 30 non-overlapping origins) but worsens it by +12 % at 600 s (worse at 20 "
                       "of 30 non-overlapping origins)."]
    # a model that reduces at more horizons wins over a larger single reduction
    rows[5] = _row("Kalman", 600.0, 7.0, 0.875, 20, 10)
    assert headline_verdict(_heading(rows, (60.0, 600.0))).data["model"] == "Kalman"


@pytest.mark.parametrize("model, artefacts, want", [
    ("Kalman", FLAGGED, "gx: the lower long-τ ADEV of Kalman is not evidence: the artefact check shows it removes "
                        "real rate near 0.001, 0.002 Hz; what it is worth: heading error at 600 s 0.75 x constant "
                        "bias's (reduces)."),
    ("AR(p)", CLEAN, "gx: artefact check clean: AR(p) removes no injected real rate where its ADEV is lower; what it "
                     "is worth: heading error at 600 s 1.12 x constant bias's (worsens)."),
    ("GM(1,1)", CLEAN, "gx: the artefact check has no row for GM(1,1)."),
    ("Kalman", None, "gx: the lower long-τ ADEV of Kalman is not checked: the artefact check did not run; a causal "
                     "drift subtraction lowers it on any static log; what it is worth: heading error at 600 s 0.75 x "
                     "constant bias's (reduces)."),
    ("Kalman", NS(rows=[]), "gx: the artefact check has no row for Kalman; what it is worth: heading error at 600 s "
                            "0.75 x constant bias's (reduces)."),
])
def test_adev_caveat_with_the_heading_worth(model, artefacts, want):
    assert adev_caveat(model, artefacts, axis="gx", heading=_heading(TWO, (60.0, 600.0))) == want


def test_adev_caveat_worth_when_too_few_not_at_most_or_diverged():
    rows = [_row("constant bias", 600.0, 8.0, 1.0, n=12), _row("A", 600.0, 6.0, 0.75, 5, 7, n=12),
            _row("B", 600.0, math.inf, math.inf, 0, 12, n=12), _row("C", 600.0, 9.0, 1.125, 7, 5, n=12)]
    h = _heading(rows, (600.0,))
    assert adev_caveat("A", None, heading=h, why_not="--no-artefacts") == (
        "the lower long-τ ADEV of A is not checked: the artefact check did not run (--no-artefacts); a causal drift "
        "subtraction lowers it on any static log; what it is worth: heading error at 600 s 0.75 x constant bias's "
        "(better at only 5 of 12 non-overlapping origins).")
    assert adev_caveat("B", None, heading=h).endswith("what it is worth: heading error at 600 s diverges (diverges).")
    assert adev_caveat("C", None, heading=h).endswith("1.12 x constant bias's (worse at only 5 of 12 non-overlapping "
                                                      "origins).")
    few = _heading([_row("constant bias", 600.0, 8.0, 1.0, n=4), _row("A", 600.0, 6.0, 0.75, 4, 0, n=4)], (600.0,))
    assert adev_caveat("A", None, heading=few).endswith("0.75 x constant bias's (4 non-overlapping origins: too few "
                                                        "to judge).")


def test_per_horizon_sentences_when_too_few_origins_count_and_a_model_diverges():
    rows = [_row("constant bias", 60.0, 0.02, 1.0, n=9), _row("Kalman", 60.0, 0.018, 0.9, 6, 3, n=9, sigma=0.02,
                                                              inside=0.7),
            _row("GM(1,1)", 60.0, math.inf, math.inf, 0, 9, n=9),
            _row("constant bias", 600.0, 0.2, 1.0, n=2, n_origins=9),
            _row("Kalman", 600.0, 0.19, 0.95, 1, 1, n=2, n_origins=9, sigma=0.2, inside=0.6),
            _row("GM(1,1)", 600.0, math.nan, math.nan, 0, 2, n=2, n_origins=9)]
    h = _heading(rows, (60.0, 600.0), step=60.0, axis="gz")
    v = heading_verdict(h)
    assert v.lines == [
        "gz, 60 s after a 300-s calibration (9 origins): constant bias leaves 0.02 deg RMS; Kalman 0.018 deg (-10 %, "
        "better at 6 of 9 non-overlapping origins) [predicted 1-sigma 0.02 deg, 70 % of origins inside; ~68 % if "
        "calibrated]; GM(1,1) diverges.",
        "gz, 60 s: 9 origin(s) are too few to judge (need 10; use a longer held-out record or a smaller origin step); "
        "GM(1,1) diverges.",
        "gz, 600 s after a 300-s calibration (9 origins): constant bias leaves 0.2 deg RMS; Kalman 0.19 deg (-5 %, "
        "better at 1 of 2 non-overlapping origins) [predicted 1-sigma 0.2 deg, 60 % of origins inside; ~68 % if "
        "calibrated]; GM(1,1) diverges.",
        "gz, 600 s: 9 origin(s), 2 of them with non-overlapping horizons, are too few to judge (need 10; use a longer "
        "held-out record); GM(1,1) diverges."]
    assert v.data == {"60.0": {"reduces": [], "worsens": ["GM(1,1)"], "diverges": ["GM(1,1)"],
                               "constant_bias_rms_deg": 0.02, "too_few_origins": True, "n_independent": 9},
                      "600.0": {"reduces": [], "worsens": ["GM(1,1)"], "diverges": ["GM(1,1)"],
                                "constant_bias_rms_deg": 0.2, "too_few_origins": True, "n_independent": 2}}
    assert heading_table(h) == (
        ["model", "RMS 60 s [deg]", "/ bias 60 s", "RMS 600 s [deg]", "/ bias 600 s", "origins",
         "better / non-overlapping", "Kalman 1σ / inside"],
        [["constant bias", "0.02", "1", "0.2", "1", "9/9", "–", "–"],
         ["Kalman", "0.018", "0.9", "0.19", "0.95", "9/9", "6/9, 1/2", "0.02 / 70 %, 0.2 / 60 %"],
         ["GM(1,1)", "diverges", "diverges", "diverges", "diverges", "9/9", "0/9, 0/2", "–"]])


ART = NS(axis="gz", frequencies_hz=[0.001, 0.01], step_delays_s=(10.0, 100.0), rows=[
    NS(model="constant bias", gains={0.001: 1.0, 0.01: 1.0}, step_survival={10.0: 1.0, 100.0: 1.0}, ramp_survival=1.0,
       flagged_hz=()),
    NS(model="persistence", gains={0.001: 0.05, 0.01: 0.8}, step_survival={10.0: 0.9, 100.0: 0.2}, ramp_survival=0.0,
       flagged_hz=(0.001,)),
    NS(model="AR(p)", gains={0.001: 0.85, 0.01: 1.0}, step_survival={10.0: 1.0, 100.0: 0.95}, ramp_survival=0.97,
       flagged_hz=()),
    NS(model="Kalman", gains={0.001: 0.99, 0.01: 1.0}, step_survival={10.0: 1.0, 100.0: 1.0}, ramp_survival=1.0,
       flagged_hz=())])


def test_artefact_sentences_and_table():
    v = artefact_verdict(ART)
    assert v.lines == ["gz: persistence FLAGGED: its Allan 'improvement' near 0.001 Hz is removal of real rate (an "
                       "injected sinusoid keeps only 0.05 of its amplitude).",
                       "gz: AR(p) removes > 10 % of injected rate at 0.001 Hz (no Allan improvement claimed there)."]
    assert v.data == {"persistence": {"flagged_hz": [0.001], "removes_over_10pct_hz": [0.001, 0.01]},
                      "AR(p)": {"flagged_hz": [], "removes_over_10pct_hz": [0.001]},
                      "Kalman": {"flagged_hz": [], "removes_over_10pct_hz": []}}
    quiet = NS(axis="gz", frequencies_hz=[0.001], rows=[ART.rows[0], ART.rows[3]])
    assert artefact_verdict(quiet).lines == ["gz: no compensator removes more than 10 % of an injected signal."]
    assert artefact_table(ART) == (
        ["model", "0.001 Hz", "0.01 Hz", "step +10 s", "step +100 s", "ramp", "flagged [Hz]"],
        [["constant bias", "1", "1", "1", "1", "1", "–"], ["persistence", "0.05", "0.8", "0.9", "0.2", "0", "0.001"],
         ["AR(p)", "0.85", "1", "1", "0.95", "0.97", "–"], ["Kalman", "0.99", "1", "1", "1", "1", "–"]])


def test_table2_flags_only_practical_rows_of_flagged_models():
    rows = [NS(label="persistence: output - causal prediction (practical)", kind="practical", model="persistence"),
            NS(label="persistence: drift residual (paper)", kind="paper", model="persistence"),
            NS(label="AR(p): output - causal prediction (practical)", kind="practical", model="AR(p)"),
            NS(label="no model", kind="practical")]
    assert table2_marks(rows, ART) == {"persistence: output - causal prediction (practical)":
                                       "improvement partly removes real rate (artefact check: 0.001 Hz)"}
    v = table2_verdict(rows, ART)
    assert v.to_dict() == {"kind": "table2", "lines": [
        'Table 2 row "persistence: output - causal prediction (practical)" FLAGGED: improvement partly removes real '
        "rate (artefact check: 0.001 Hz); its lower noise figures are not evidence of a better gyro."],
        "data": {"marks": table2_marks(rows, ART)}}
    assert table2_verdict(rows, ART, axis="gz").lines[0].startswith('gz: Table 2 row "persistence')


def test_judgement_texts_and_number_formats():
    j = judge(_row("m", 600.0, 0.88, 0.88, 9, 3, n=12))
    assert (j.change(), j.counts(), j.counts("worse", True)) == (
        "-12 %", "better at 9 of 12 non-overlapping origins", "worse at only 3 of 12 non-overlapping origins")
    assert judge(_row("m", 600.0, math.inf, math.inf, 0, 12, n=12)).change() == "diverges"
    bare = judge(NS(horizon_s=600.0, n_origins=17, rms_deg=0.5, ratio_to_bias=0.5), step_s=300.0)
    assert bare.counts() == "better at ? of 9 non-overlapping origins (not counted)"
    assert Verdict("x", ["a"], {"k": 1}).to_dict() == {"kind": "x", "lines": ["a"], "data": {"k": 1}}
    assert [_pct(x) for x in (None, math.nan, 10, 12.34, 1.0, 1.004, 0.996, 0.88, 1.12)] == [
        "n/a", "n/a", "x10", "x12.3", "±0 %", "±0 %", "±0 %", "-12 %", "+12 %"]
    assert [_f(x) for x in (None, math.inf, 0, 1e4, 1e-3, 9.99e-4, 0.1234, -2e-5)] == [
        "n/a", "n/a", "0", "1.00e+04", "0.001", "9.99e-04", "0.123", "-2.00e-05"]
    assert _f(0.123456, 2) == "0.12" and _f(12345.0, 2) == "1.2e+04"


def _metrics(skill, rmse, rmse_p):
    return NS(skill=skill, rmse_dph=rmse, rmse_persistence_dph=rmse_p, to_dict=lambda: {"rmse_dph": rmse})


def test_causal_and_paper_measure_sentences():
    """Skill > 0 beats persistence (NaN skill does not); the paper's measure is labelled as such and says n/a
    where persistence's RMSE is 0."""
    ma = NS(name="gz", causal_metrics={"persistence": _metrics(0.0, 1.0, 1.0), "AR(p)": _metrics(0.12, 0.88, 1.0),
                                       "Kalman": _metrics(-0.05, 1.05, 1.0),
                                       "GM(1,1)": _metrics(math.nan, math.nan, 1.0)},
            metrics={"persistence": _metrics(0.0, 1.0, 1.0), "AR(p)": _metrics(0.3, 0.7, 1.0),
                     "Kalman": _metrics(0.1, 0.9, 0.0)})
    c = causal_verdict(ma)
    assert c.lines == ["gz: against the causal drift (what a real-time compensator sees), one-step skill vs "
                       "persistence: AR(p) 0.12; Kalman -0.05; GM(1,1) n/a.",
                       "gz: AR(p) beat persistence on the causal target."]
    assert c.data["AR(p)"] == {"skill": 0.12, "rmse_dph": 0.88, "rmse_persistence_dph": 1.0}
    assert "persistence" not in c.data
    p = paper_measure_verdict(ma)
    assert p.to_dict() == {"kind": "paper", "lines": [
        "gz: paper's measure (one step ahead, target = non-causal wavelet drift; not a compensation result): AR(p) "
        "RMSE -30 % vs persistence; Kalman RMSE n/a vs persistence."],
        "data": {"AR(p)": {"rmse_dph": 0.7}, "Kalman": {"rmse_dph": 0.9}}}
    none = NS(name="gz", causal_metrics={"persistence": _metrics(0.0, 1.0, 1.0), "Kalman": _metrics(-0.05, 1.05, 1.0)},
              metrics={"persistence": _metrics(0.0, 1.0, 1.0)})
    assert causal_verdict(none).lines[1] == "gz: no model beats persistence on the causal target."
    assert paper_measure_verdict(none).lines == ["gz: paper's measure (one step ahead, target = non-causal wavelet "
                                                 "drift; not a compensation result): persistence only."]
    only = NS(name="gz", causal_metrics={"persistence": _metrics(0.0, 1.0, 1.0)}, metrics={})
    assert causal_verdict(only).to_dict() == {"kind": "causal", "lines": ["Only persistence was run."], "data": {}}
    assert compensation_verdicts() == []
    assert [v.kind for v in compensation_verdicts(model_axis=ma)] == ["causal", "paper"]
    h = _heading(TWO, (60.0, 600.0))
    vs = compensation_verdicts(heading=h, artefacts=ART, model_axis=ma)
    assert [v.kind for v in vs] == ["heading", "artefacts", "causal", "paper"]
    assert vs[0].lines == heading_verdict(h).lines and vs[1].lines == artefact_verdict(ART).lines


def test_headline_without_counts_uses_the_origin_step_and_the_given_thresholds():
    """Rows without counts (a bundle written before them): 30 origins 60 s apart at 600 s are 3 independent ones,
    so nothing is judged, and the ADEV caveat says so; ``material`` and ``min_origins`` reach every judgement."""
    rows = [NS(model="constant bias", horizon_s=600.0, n_origins=30, rms_deg=8.0, ratio_to_bias=1.0),
            NS(model="Kalman", horizon_s=600.0, n_origins=30, rms_deg=4.0, ratio_to_bias=0.5)]
    h = _heading(rows, (600.0,), step=60.0)
    v = headline_verdict(h)
    assert v.kind == "headline" and v.data["outcome"] == "undetermined"
    assert "gives 30 calibration origin(s), 3 of them with non-overlapping horizons, at 600 s" in v.lines[0]
    assert adev_caveat("Kalman", None, heading=h).endswith("heading error at 600 s 0.5 x constant bias's (3 "
                                                           "non-overlapping origins: too few to judge).")
    six = [_row("constant bias", 60.0, 1.0, 1.0, n=6), _row("Kalman", 60.0, 0.8, 0.8, 5, 1, n=6)]
    assert headline_verdict(_heading(six, (60.0,)), min_origins=5).data["outcome"] == "reduces"
    assert headline_verdict(_heading(six, (60.0,))).data["outcome"] == "undetermined"
    v = headline_verdict(_heading(six, (60.0,)), material=0.6, min_origins=5)
    assert v.kind == "headline" and v.data["outcome"] == "none" and v.lines == [
        "gx: no model reduces the heading error by 60 % or more at most non-overlapping origins at 60 s after a "
        "300-s calibration (constant bias leaves 1 deg RMS)."]


def test_headline_of_a_model_worse_at_two_horizons_and_flagged_lists_everything():
    rows = [_row("constant bias", 60.0, 1.0, 1.0), _row("Kalman", 60.0, 0.45, 0.45, 20, 10),
            _row("AR(p)", 60.0, 1.1, 1.1, 5, 25), _row("GM(1,1)", 60.0, 1.2, 1.2, 5, 25),
            _row("constant bias", 600.0, 8.0, 1.0), _row("Kalman", 600.0, 9.6, 1.2, 10, 20),
            _row("AR(p)", 600.0, 8.0, 1.0, 15, 15), _row("GM(1,1)", 600.0, 8.0, 1.0, 15, 15),
            _row("constant bias", 3600.0, 20.0, 1.0), _row("Kalman", 3600.0, math.inf, math.inf, 0, 30),
            _row("AR(p)", 3600.0, 20.0, 1.0, 15, 15), _row("GM(1,1)", 3600.0, 20.0, 1.0, 15, 15)]
    h = _heading(rows, (60.0, 600.0, 3600.0))
    v = headline_verdict(h, NS(rows=[NS(model="Kalman", flagged_hz=(0.001,))]))
    assert v.kind == "headline" and v.data["outcome"] == "mixed"
    assert v.lines == ["gx: Kalman reduces the heading error by 55 % at 60 s after a 300-s calibration (0.45 vs 1 "
                       "deg RMS, better at 20 of 30 non-overlapping origins) but worsens it by +20 % at 600 s (worse "
                       "at 20 of 30 non-overlapping origins), diverges at 3600 s and removes real rate near 0.001 Hz "
                       "(artefact check)."]
    only = headline_verdict(_heading([rows[0], rows[1]], (60.0,)))
    assert only.kind == "headline" and only.lines == [
        "gx: Kalman reduces the heading error by 55 % at 60 s after a 300-s calibration (0.45 vs 1 deg RMS, better "
        "at 20 of 30 non-overlapping origins) and worsens it at no judged horizon (60 s); artefact check not run."]
    none = headline_verdict(_heading([rows[0], rows[2], rows[3]], (60.0,)))
    assert none.kind == "headline" and none.lines[0].endswith("(constant bias leaves 1 deg RMS; worse: AR(p), "
                                                              "GM(1,1)).")
    assert headline_verdict(None).lines == [": heading error not evaluated (not run); no compensation verdict."]
    assert headline_verdict(NS(axis="gq", calib_s=300.0, step_s=300.0, horizons_s=(60.0,),
                               rows=[rows[1]])).lines[0].startswith("gq: cannot judge")
    nobase = headline_verdict(NS(axis="gq", calib_s=300.0, step_s=300.0, horizons_s=(60.0,), rows=[rows[1]]))
    assert "gives 0 calibration origin(s) at 60 s" in nobase.lines[0] and nobase.kind == "headline"


def test_independent_origins_of_no_origins_and_table_cells_with_more_digits():
    assert independent_origins(0, 60.0, 600.0) == 0 and independent_origins(-1, 600.0, 60.0) == 0
    r = NS(model="m", gains={0.001: 0.8537}, step_survival={10.0: 0.1234}, ramp_survival=0.9876,
           flagged_hz=(0.001, 0.002))
    assert artefact_table(NS(frequencies_hz=[0.001], step_delays_s=(10.0,), rows=[r]))[1] == [
        ["m", "0.85", "0.12", "0.99", "0.001, 0.002"]]
    # a row without a kind is not a practical row
    rows = [NS(label="Kalman row", model="Kalman")]
    assert table2_marks(rows, NS(rows=[NS(model="Kalman", flagged_hz=(0.001,))])) == {}


def test_judged_horizon_sentence_lists_reductions_by_size_the_unsure_and_the_worse():
    """One judged horizon (10 independent origins, exactly the minimum), every outcome of judge at once."""
    rows = [_row("constant bias", 60.0, 1.0, 1.0, n=10), _row("A", 60.0, 0.8, 0.8, 6, 4, n=10),
            _row("B", 60.0, 0.5, 0.5, 8, 2, n=10), _row("C", 60.0, 0.9, 0.9, 4, 6, n=10),
            _row("D", 60.0, 1.1, 1.1, 6, 4, n=10), _row("E", 60.0, 1.3, 1.3, 2, 8, n=10),
            _row("F", 60.0, 1.2, 1.2, 3, 7, n=10), _row("G", 60.0, math.nan, math.nan, 0, 10, n=10),
            _row("H", 60.0, 1.0, 1.0, 5, 5, n=10)]
    v = heading_verdict(_heading(rows, (60.0,), step=None, axis="gz"))
    assert v.kind == "heading" and v.lines[-1] == (
        "gz, 60 s: reduces the heading error: B by 50 % (better at 8 of 10 non-overlapping origins), A by 20 % (better "
        "at 6 of 10 non-overlapping origins); C -10 % but better at only 4 of 10 non-overlapping origins; D +10 % but "
        "worse at only 4 of 10 non-overlapping origins; worse: E (+30 %, worse at 8 of 10 non-overlapping origins), F "
        "(+20 %, worse at 7 of 10 non-overlapping origins), G diverges.")
    assert v.data["60.0"]["reduces"] == ["B", "A"] and v.data["60.0"]["worsens"] == ["E", "F", "G"]
    assert v.data["60.0"]["counts"]["D"] == {"better": 6, "worse": 4, "n_independent": 10,
                                             "outcome": "not at most origins"}
    v = heading_verdict(_heading(rows[:4], (60.0,), step=None, axis="gz"), material=0.3)
    assert v.lines[-1] == "gz, 60 s: reduces the heading error: B by 50 % (better at 8 of 10 non-overlapping origins)."
    v = heading_verdict(_heading(rows[:2], (60.0,), step=None, axis="gz"), material=0.6)
    assert v.lines[-1] == ("gz, 60 s: no model reduces the heading error (60 % or more lower RMS and better at most "
                           "non-overlapping origins).")
    assert heading_verdict(_heading(rows[:2], (60.0,), step=None), min_origins=11).data["60.0"]["too_few_origins"]


def test_rows_without_counts_in_the_per_horizon_sentences_and_table():
    rows = [NS(model="constant bias", horizon_s=600.0, n_origins=30, rms_deg=8.0, ratio_to_bias=1.0,
               predicted_sigma_deg=None),
            NS(model="K", horizon_s=600.0, n_origins=30, rms_deg=4.0, ratio_to_bias=0.5, predicted_sigma_deg=None)]
    h = _heading(rows, (600.0,), step=60.0, axis="gz")
    v = heading_verdict(h)
    assert v.lines == ["gz, 600 s after a 300-s calibration (30 origins): constant bias leaves 8 deg RMS; K 4 deg "
                       "(-50 %, better at ? of 3 non-overlapping origins (not counted)).",
                       "gz, 600 s: 30 origin(s), 3 of them with non-overlapping horizons, are too few to judge "
                       "(need 10; use a longer held-out record)."]
    assert heading_table(h)[1] == [["constant bias", "8", "1", "30", "–", "–"],
                                   ["K", "4", "0.5", "30", "?/3", "–"]]
    nan = NS(horizon_s=60.0, n_origins=12, rms_deg=0.0, ratio_to_bias=None, n_independent=12, better_independent=0,
             worse_independent=0)
    assert judge(nan).outcome == "n/a" and judge(nan).counts() == "better at 0 of 12 non-overlapping origins"
    assert judge(NS(horizon_s=60.0, n_origins=12, rms_deg=0.0)).outcome == "n/a"


def test_artefact_sentence_counts_only_gains_below_09_and_missing_gains_as_kept():
    art = NS(axis="gz", frequencies_hz=[0.001, 0.01], rows=[NS(model="A", gains={0.001: 0.9}, flagged_hz=()),
                                                             NS(model="B", gains={0.01: 0.89}, flagged_hz=())])
    v = artefact_verdict(art)
    assert v.kind == "artefacts" and v.lines == [
        "gz: B removes > 10 % of injected rate at 0.01 Hz (no Allan improvement claimed there)."]
    assert v.data == {"A": {"flagged_hz": [], "removes_over_10pct_hz": []},
                      "B": {"flagged_hz": [], "removes_over_10pct_hz": [0.01]}}


def test_the_short_headline_says_the_same_verdict_with_the_same_numbers():
    """The console's short form (Verdict.short): the outcome's numbers of the long sentence, without the protocol
    the console's heading states; never stored (to_dict is the long form)."""
    rows = []
    for h, rms, ar in ((60.0, 1.0, 1.2), (600.0, 8.0, 1.125)):
        rows += [_row("constant bias", h, rms, 1.0), _row("AR(p)", h, rms * ar, ar, 5, 25)]
    none = headline_verdict(_heading(rows, (60.0, 600.0)))
    assert none.short == "gx: no model gains 5 % or more at 60 / 600 s (constant bias: 1 / 8 deg RMS); worse: AR(p)."
    assert "short" not in none.to_dict() and none.to_dict()["lines"] == none.lines
    mixed = headline_verdict(_heading(TWO, (60.0, 600.0)), FLAGGED)
    assert mixed.short == ("gx: Kalman -25 % at 600 s (6 vs 8 deg RMS, better at 20 of 30 non-overlapping origins) "
                           "but removes real rate near 0.001, 0.002 Hz (artefact check).")
    clean = headline_verdict(_heading(TWO, (60.0, 600.0)), CLEAN)
    assert clean.short.startswith("gx: Kalman -25 % at 600 s (6 vs 8 deg RMS") and clean.short.endswith(
        "; worse nowhere; artefact check clean.")
    few = headline_verdict(_heading([heading_row("constant bias", np.ones(9), np.ones(9), horizon_s=60.0,
                                                 step_s=60.0)], (60.0,), step=60.0), min_origins=10)
    assert few.short.startswith("gx: cannot judge: 9 non-overlapping origin(s) at 60 s, 10 needed")
    assert headline_verdict(None, axis="gx", reason="--no-heading").short == ""  # the long line is short already
