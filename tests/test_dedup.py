"""Issue 21 item 3 (no copies): the facts written once are read from their one home, and the joins still hold.

Each test checks a rule against an independent value (hashlib on the file's bytes, the IEEE-952 Allan laws
written out by hand, the stored level/window of the pipeline) and fails on the plausible one-line bug of the
join it covers.
"""

from __future__ import annotations

import hashlib
import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.bundle import load_bundle, write_bundle
from fogdrift.io import from_array
from fogdrift.pipeline import AnalysisConfig, run_analysis, run_models
from fogdrift.simulate import simulate

BOGUS = r"$\bogus{$"  # matplotlib would parse it as (bad) mathtext when the figure is drawn


@pytest.fixture(scope="module")
def small():
    rate = simulate(3000, 0.5, arw_dprh=0.05, rrw_dphrh=0.5, bias_dph=2.0, seed=4)
    rec = from_array(rate, dt_s=0.5, unit="deg/h", axis_names=["gz"])
    cfg = AnalysisConfig(models=("persistence",), model_rate_hz=1.0, level=2, lags=3, causal_window_s=40.0)
    return rec, cfg


def test_bundle_model_hashes_are_the_sha256_of_the_file_bytes(small, tmp_path):
    rec, cfg = small
    b = write_bundle(tmp_path / "b", run_models(rec, cfg), cfg, rec)
    doc = json.loads((b.path / "manifest.json").read_text())
    entry = doc["axes"][0]["models"]["persistence"]
    for ext in ("json", "npz"):
        raw = (b.path / f"{entry['file']}.{ext}").read_bytes()
        assert entry["sha256"][ext] == hashlib.sha256(raw).hexdigest()
    assert load_bundle(b.path).axis("gz").level == 2  # and the bundle still loads (its check uses the same hash)


def test_bundle_manifest_and_model_json_are_strict(small, tmp_path):
    """NaN/inf never reach a written JSON file as the non-standard NaN/Infinity tokens."""
    rec, cfg = small
    b = write_bundle(tmp_path / "b", run_models(rec, cfg), cfg, rec)
    for p in [b.path / "manifest.json", *b.path.rglob("*.json")]:
        text = p.read_text()
        json.loads(text, parse_constant=lambda c: pytest.fail(f"{p.name}: non-standard JSON constant {c}"))

    from fogdrift.models import Persistence, save_model

    m = Persistence().fit(np.arange(50.0))
    meta, arrays = m._get_state()
    m._get_state = lambda: ({**meta, "extra": float("nan"), "big": np.float64("inf")}, arrays)
    json_path, _ = save_model(m, tmp_path / "m")
    doc = json.loads(json_path.read_text(), parse_constant=lambda c: pytest.fail(f"model JSON holds {c}"))
    assert doc["state"]["extra"] is None and doc["state"]["big"] is None


def test_discretize_uses_the_allan_laws_of_the_term_table():
    """The Allan coefficients A_n of Q, N, B, K, R from one value X each: 3X², X², (2 ln2/π)X², X²/3, X²/2."""
    from fogdrift.noise.processes import flicker, quantization
    from fogdrift.noise.terms import TERM_TABLE, TERMS

    assert TERMS == ("Q", "N", "B", "K", "R")
    by_hand = {"Q": 3.0, "N": 1.0, "B": 2.0 * math.log(2.0) / math.pi, "K": 1.0 / 3.0, "R": 0.5}
    for name in TERMS:
        assert TERM_TABLE[name].avar_coefficient == pytest.approx(by_hand[name], rel=1e-15)
    # the rows the state-space model and the exports read are the same objects
    assert TERM_TABLE["B"] is flicker.TERM and TERM_TABLE["Q"] is quantization.TERM
    assert quantization.TERM.to_unit == pytest.approx(4.8481368110953599, rel=1e-15)


def test_evaluated_analysis_returns_a_new_result_and_reads_the_stored_window(small, monkeypatch):
    from fogdrift.evaluation import analysis as ev_mod

    rec, cfg = small
    res = run_analysis(rec, cfg)
    seen = []
    real = ev_mod.heading_errors

    def spy(*a, **kw):
        seen.append((kw["level"], kw["causal_window"]))
        return real(*a, **kw)

    monkeypatch.setattr(ev_mod, "heading_errors", spy)
    out = ev_mod.evaluated_analysis(res, artefacts=False, step_s=200.0, horizons_s=(60.0,))
    ma = res.axes[0].models
    assert (ma.level, ma.causal_window) == (2, 40)  # 40 s at the 1 Hz modelling rate
    assert seen == [(2, 40)]  # read from the ModelAxis, not recomputed
    assert res.axes[0].evaluation is None  # the given result is not changed
    assert out is not res and out.axes[0] is not res.axes[0]
    ev = out.axes[0].evaluation
    assert ev.axis == "gz" and ev.settings["origin_step_s"] == 200.0 and ev.settings["artefacts"] is False
    assert out.to_dict()["axes"][0]["evaluation"]["axis"] == "gz"
    assert ev_mod.evaluations(out) == [ev]  # the list the CLI prints, read from the new result


def test_compensate_figure_draws_a_mathtext_column_name_as_written(tmp_path):
    from fogdrift.cli import app

    fs = 2.0
    x = simulate(6000, 1 / fs, arw_dprh=0.05, rrw_dphrh=1.0, bias_dph=3.0, seed=2)
    rec = from_array(x[:, None], dt_s=1 / fs, unit="deg/h", axis_names=[BOGUS])
    cfg = AnalysisConfig(models=("persistence",), model_rate_hz=1.0, level=2)
    write_bundle(tmp_path / "bundle", run_models(rec, cfg), cfg, rec)
    y = simulate(3000, 1 / fs, arw_dprh=0.05, rrw_dphrh=1.0, bias_dph=3.0, seed=3)
    log = tmp_path / "log.csv"
    log.write_text(f"t_s,{BOGUS}[deg/h]\n" + "".join(f"{k / fs:.3f},{v:.9f}\n" for k, v in enumerate(y)))
    res = CliRunner().invoke(app, ["compensate", str(tmp_path / "bundle"), str(log), "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    assert "Traceback" not in res.output
    assert (tmp_path / "o" / "compensation_allan.png").stat().st_size > 1000


def test_gmwm_ieee_terms_are_noise_terms_and_map_to_the_same_fleet_columns():
    """One IEEE-term type: GMWM's reading is a NoiseTerm (name, unit of the term table, reason), and N of white
    noise of known ARW comes back in deg/sqrt(h) (0.1 deg/sqrt(h) = 6 deg/h sqrt(s): sigma = 6/sqrt(dt) deg/h)."""
    from fogdrift.fleet.commands import ieee_columns
    from fogdrift.gmwm.analysis import GmwmTerm, analyse_gmwm
    from fogdrift.noise import NoiseTerm, TERM_UNITS

    dt = 0.1
    x = np.random.default_rng(3).standard_normal(2**15) * (6.0 / math.sqrt(dt))
    ax = analyse_gmwm("gx", x, dt, model="WN")
    terms = ax.ieee_terms()
    assert GmwmTerm is NoiseTerm and list(terms) == ["Q", "N", "B", "K", "R"]
    for name, t in terms.items():
        assert isinstance(t, NoiseTerm) and t.name == name and t.unit == TERM_UNITS[name]
    n = terms["N"]
    assert n.status == "resolved" and n.reason == "" and n.lo95 < 0.1 < n.hi95
    assert n.value == pytest.approx(0.1, rel=0.03)
    assert terms["K"].status == "absent" and terms["K"].value is None and "not in the selected GMWM model" in terms["K"].reason
    row = ieee_columns(terms, {})
    assert row["N_dprh"] == pytest.approx(n.value) and row["K_status"] == "absent"
