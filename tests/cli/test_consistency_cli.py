"""``fogdrift consistency`` end to end on small simulated logs (the truth known)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app

runner = CliRunner()
DT = 0.1
N_DPRH = 0.5  # deg/sqrt(h)


def _write(path, seed, n=30_000):
    y = np.random.default_rng(seed).normal(0.0, 60.0 * N_DPRH / math.sqrt(DT), n) + 50.0
    np.savetxt(path, np.column_stack([np.arange(n) * DT, y]), delimiter=",", header="t_s,gz", comments="",
               fmt="%.6f")
    return path


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("cons")
    return [_write(d / f"s{i}.csv", i) for i in range(3)]


def test_consistency_with_given_components(logs, tmp_path):
    comps = tmp_path / "model.json"
    comps.write_text(json.dumps({"axes": {"gz": [{"kind": "white", "arw_dprh": N_DPRH / 2}]}}))  # N halved
    res = runner.invoke(app, ["consistency", str(logs[0]), "--unit", "deg/h", "--held-out", str(logs[1]),
                              "--held-out", str(logs[2]), "--components", str(comps), "--calibration", "20",
                              "--horizons", "5,20", "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    out = res.output
    assert "full model (model.json)" in out and "in 68 % band" in out
    assert "inflate the variances by λ" in out  # N halved: lambda about 4
    doc = json.loads((tmp_path / "o" / "consistency.json").read_text())
    assert doc["fogdrift_result"] == "consistency" and doc["horizons_s"] == [5.0, 20.0]
    full = doc["targets"][0]
    assert full["target"] == "full"
    for row in full["axes"]["gz"]["rows"]:
        # non-overlapping origins per log: floor((n - k - m) / s) + 1 (m, k, s in samples), two logs pooled
        assert row["n_origins"] == {5.0: 2 * 120, 20.0: 2 * 75}[row["horizon_s"]]
        assert 3.0 < row["inflation"]["68 %"]["lambda"] < 5.5
    # white-only model: the covering random walk is 0 and no target is skipped
    assert doc["covering_random_walk"]["gz"]["k_eff_dphrh"] == 0.0


def test_consistency_from_the_allan_fit_covers_white_noise(logs, tmp_path):
    res = runner.invoke(app, ["consistency", str(logs[0]), "--unit", "deg/h", "--held-out", str(logs[1]),
                              "--held-out", str(logs[2]), "--calibration", "20", "--horizons", "5,20",
                              "--out", str(tmp_path / "p")])
    assert res.exit_code == 0, res.output
    doc = json.loads((tmp_path / "p" / "consistency.json").read_text())
    rows = doc["targets"][0]["axes"]["gz"]["rows"]
    for row in rows:
        n = row["n_origins"]
        assert abs(row["coverage"]["68 %"] - 0.6827) < 4 * math.sqrt(0.68 * 0.32 / n)
    assert "to cover the bias wander over 60 s" in res.output


@pytest.mark.parametrize("extra, match", [
    ([], "give at least one --held-out log"),
    (["--held-out", "X", "--horizons", "5,-1"], "--horizons must be comma-separated numbers > 0"),
    (["--held-out", "X", "--calibration", "0"], "--calibration must be a number > 0"),
])
def test_consistency_bad_options_one_line(logs, tmp_path, extra, match):
    args = ["consistency", str(logs[0]), "--unit", "deg/h", "--out", str(tmp_path / "q")]
    args += [str(logs[1]) if a == "X" else a for a in extra]
    res = runner.invoke(app, args)
    assert res.exit_code == 1
    lines = [l for l in res.output.splitlines() if l.strip()]
    assert len(lines) == 1 and match in lines[0], res.output


def test_consistency_reads_an_export_json(logs, tmp_path):
    """The complete JSON of 'fogdrift export': gyro channels' state_space components; accel channels ignored."""
    exp = tmp_path / "export.json"
    exp.write_text(json.dumps({"fogdrift_export": "json", "channels": [
        {"name": "gz", "quantity": "gyro", "state_space": {"components": [{"kind": "white", "arw_dprh": N_DPRH}]}},
        {"name": "az", "quantity": "accel", "state_space": {"components": [{"kind": "white", "arw_dprh": 1.0}]}}]}))
    res = runner.invoke(app, ["consistency", str(logs[0]), "--unit", "deg/h", "--held-out", str(logs[1]),
                              "--components", str(exp), "--calibration", "20", "--horizons", "20",
                              "--out", str(tmp_path / "e")])
    assert res.exit_code == 0, res.output
    doc = json.loads((tmp_path / "e" / "consistency.json").read_text())
    assert doc["targets"][0]["axes"]["gz"]["components"] == [{"kind": "white", "arw_dprh": N_DPRH}]


def test_consistency_from_the_gmwm_model(logs, tmp_path):
    res = runner.invoke(app, ["consistency", str(logs[0]), "--unit", "deg/h", "--method", "gmwm", "--held-out",
                              str(logs[1]), "--calibration", "20", "--horizons", "20", "--out", str(tmp_path / "g")])
    assert res.exit_code == 0, res.output
    doc = json.loads((tmp_path / "g" / "consistency.json").read_text())
    assert doc["model_source"].startswith("the GMWM model of")
    white = [c for c in doc["targets"][0]["axes"]["gz"]["components"] if c["kind"] == "white"]
    assert white and white[0]["arw_dprh"] == pytest.approx(N_DPRH, rel=0.05)
    res = runner.invoke(app, ["consistency", str(logs[0]), "--unit", "deg/h", "--method", "kalman", "--held-out",
                              str(logs[1]), "--out", str(tmp_path / "h")])
    assert res.exit_code == 1 and "--method must be 'allan' or 'gmwm'" in res.output


def test_verdict_line_rules():
    """Inflation is asked for only when some row under-covers beyond counting error; the factor is the largest λ."""
    from types import SimpleNamespace

    from fogdrift.evaluation.consistency import verdict_line
    from fogdrift.evaluation.consistency import CoverageRow

    def res(*infl):
        rows = [CoverageRow(float(h), 100, 1.0, 1.0, {}, {"68 %": i}) for h, i in enumerate(infl, 1)]
        return SimpleNamespace(axes={"gx": {"rows": rows}})

    assert "no inflation needed: the model covers" in verdict_line(res((0.8, 0.6, 1.0), (0.9, 0.7, 1.1)), "gx")
    assert "within counting error" in verdict_line(res((1.3, 0.9, 1.8), (0.9, 0.7, 1.1)), "gx")
    line = verdict_line(res((1.2, 1.05, 1.4), (1.6, 0.9, 2.5)), "gx")
    assert "inflate the variances by λ = 1.6 (2 s" in line and "beyond counting error at 1 s" in line
    assert "multiply N, K, σ by 1.26" in line


def test_summary_cell_follows_the_verdict_rule():
    from types import SimpleNamespace

    from fogdrift.evaluation.consistency import summary_cell
    from fogdrift.evaluation.consistency import CoverageRow

    def res(*infl):
        rows = [CoverageRow(float(h), 100, 1.0, 1.0, {}, {"68 %": i}) for h, i in enumerate(infl, 1)]
        return SimpleNamespace(axes={"gx": {"rows": rows}})

    assert summary_cell(res((1.3, 0.9, 1.8)), "gx") == "none (largest 1.3)"
    assert summary_cell(res((1.2, 1.05, 1.4), (1.6, 0.9, 2.5)), "gx") == "1.6 [0.9, 2.5]"


def test_model_text_in_the_channel_units():
    from fogdrift.cli.consistency import _model_text

    comps = [{"kind": "white", "arw_dprh": 1e-4}, {"kind": "gauss_markov", "tc_s": 10.0, "sigma_dph": 0.002}]
    assert _model_text(comps) == "N 0.0001 deg/√h, GM σ 0.002 deg/h T_c 10 s"
    # m/s^2 in place of deg/h: (m/s^2) sqrt(h) = 3600 m/s/sqrt(h)
    assert _model_text(comps, "accel") == "VRW 0.36 m/s/√h, GM σ 0.002 m/s² T_c 10 s"


def test_consistency_on_accelerometer_logs_is_velocity(tmp_path):
    """An accelerometer log (unit g): velocity errors in m/s, the white noise covered, the sentence names
    accelerometer_random_walk."""
    paths = []
    for i in range(2):
        y = np.random.default_rng(40 + i).normal(-1.0, 0.002 / math.sqrt(DT), 30_000)  # g; 2 mg sqrt(s)
        p = tmp_path / f"acc{i}.csv"
        np.savetxt(p, np.column_stack([np.arange(y.size) * DT, y]), delimiter=",", header="t_s,az", comments="",
                   fmt="%.8f")
        paths.append(p)
    res = runner.invoke(app, ["consistency", str(paths[0]), "--unit", "g", "--held-out", str(paths[1]),
                              "--calibration", "20", "--horizons", "5,20", "--out", str(tmp_path / "o")])
    if res.exit_code != 0 and "unknown unit 'g'" in res.output:
        pytest.skip("accelerometer units not read by this tree's loader")
    assert res.exit_code == 0, res.output
    doc = json.loads((tmp_path / "o" / "consistency.json").read_text())
    assert doc["quantities"] == {"az": "accel"}
    rows = doc["targets"][0]["axes"]["az"]["rows"]
    assert all(r["unit"] == "m/s" for r in rows)
    # white specific force of 2 mg sqrt(s) = 0.0196 m/s/sqrt(s): sigma_pred at 20 s = 0.0196 sqrt(20 + 20) m/s
    assert rows[1]["sigma_pred"] == pytest.approx(0.002 * 9.80665 * math.sqrt(40.0), rel=0.1)
    for r in rows:
        assert abs(r["coverage"]["68 %"] - 0.6827) < 4 * math.sqrt(0.68 * 0.32 / r["n_origins"])
    assert "velocity error" in res.output and "accelerometer_random_walk" in res.output


def test_horizon_no_log_reaches_is_one_line_with_flags(logs, tmp_path):
    res = runner.invoke(app, ["consistency", str(logs[0]), "--unit", "deg/h", "--held-out", str(logs[1]),
                              "--calibration", "20", "--horizons", "5,5000", "--out", str(tmp_path / "q")])
    assert res.exit_code == 1
    lines = [l for l in res.output.splitlines() if l.strip() and not l.startswith(("consistency", "gz:", "held"))]
    assert any("horizon(s) 5000 s" in l and "shorten --horizons or --calibration" in l for l in lines), res.output
    assert "Traceback" not in res.output


def test_training_log_as_held_out_is_warned(logs, tmp_path):
    res = runner.invoke(app, ["consistency", str(logs[0]), "--unit", "deg/h", "--held-out", str(logs[0]),
                              "--calibration", "20", "--horizons", "20", "--out", str(tmp_path / "w")])
    assert res.exit_code == 0, res.output
    assert "is the training log itself (same SHA-256): its coverage is no held-out evidence" in res.output


def test_a_held_out_log_declaring_another_unit_is_refused_not_read_through_unit(tmp_path):
    """``--unit deg/s`` is the training log's; a held-out log whose header declares ``gz[rad/s]`` was read as deg/s
    (every angle error 57x small, "no inflation needed": issue 36).  Now one line naming the file, the column and
    both units, before any fit; a held-out log declaring the same unit passes."""
    from fogdrift.io import load
    from fogdrift.workflows.consistency import check_declared_units

    rng = np.random.default_rng(3)
    t = np.arange(6000) * 0.1
    train, held, same = tmp_path / "train.csv", tmp_path / "held.csv", tmp_path / "same.csv"
    np.savetxt(train, np.c_[t, 0.01 * rng.standard_normal(t.size)], delimiter=",", header="t_s,gz", comments="")
    np.savetxt(held, np.c_[t, 2e-4 * rng.standard_normal(t.size)], delimiter=",", header="t_s,gz[rad/s]", comments="")
    np.savetxt(same, np.c_[t, 0.01 * rng.standard_normal(t.size)], delimiter=",", header="t_s,gz[deg/s]", comments="")
    res = runner.invoke(app, ["consistency", str(train), "--unit", "deg/s", "--held-out", str(held), "--out",
                              str(tmp_path / "o")])
    assert res.exit_code == 1 and "Traceback" not in res.output
    err = [ln for ln in res.output.splitlines() if ln.startswith("error:")]
    assert len(err) == 1 and "held.csv" in err[0] and "'rad/s'" in err[0] and "--unit 'deg/s'" in err[0], res.output
    assert not (tmp_path / "o" / "consistency.json").exists()
    check_declared_units(load(same, unit="deg/s"), "same.csv")  # the same unit: nothing to refuse
