"""`analyze --apply-to`: its own units, axes matched by name, what it re-estimated said; the compensated test
block that `analyze` writes, checked against its definition."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.compensate.holdout import compensated_test_block
from fogdrift.io import from_array, load
from fogdrift.pipeline import AnalysisConfig, run_models
from fogdrift.simulate import simulate

ARGS = ["--models", "ar,persistence", "--epochs", "5"]


def _write(path, t, cols: dict):
    names = list(cols)
    data = np.column_stack([t] + [cols[n] for n in names])
    np.savetxt(path, data, delimiter=",", header=",".join(["t_s"] + names), comments="", fmt="%.15g")
    return path


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("apply")
    x = simulate(3000, dt_s=1.0, arw_dprh=0.5, rrw_dphrh=2.0, seed=3) + 7.5  # deg/h, with a bias
    y = simulate(3000, dt_s=1.0, arw_dprh=0.5, rrw_dphrh=2.0, seed=4) - 2.0
    t = np.arange(3000.0)
    a = _write(d / "a.csv", t, {"gz": x})
    b = _write(d / "b_degs.csv", t, {"gz": y / 3600.0})  # the second log in deg/s
    c = _write(d / "c_gx.csv", t, {"gx": y})
    return d, a, b, c, x, y


def test_apply_unit_is_the_second_logs_own(logs, tmp_path):
    d, a, b, _, x, y = logs
    res = CliRunner().invoke(app, ["analyze", str(a), "--unit", "deg/h", "--apply-to", str(b), "--apply-unit",
                                   "deg/s", *ARGS, "--out", str(tmp_path / "o"), "--json"])
    assert res.exit_code == 0, res.output
    import json

    doc = json.loads((tmp_path / "o" / "analysis.json").read_text())
    applied = doc["apply_to"]["axes"][0]["models"]["bias_dph"]
    # the training share of b is its first 60 %: its bias in deg/h (not deg/s, not the first log's)
    assert applied == pytest.approx(np.mean(y[:1800]), rel=1e-9)
    assert doc["axes"][0]["models"]["bias_dph"] == pytest.approx(np.mean(x[:1800]), rel=1e-9)


def test_apply_to_says_what_it_re_estimated(logs, tmp_path):
    d, a, b, _, x, y = logs
    res = CliRunner().invoke(app, ["analyze", str(a), "--unit", "deg/h", "--apply-to", str(b), "--apply-unit",
                                   "deg/s", *ARGS, "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    line = next(ln for ln in res.output.splitlines() if ln.startswith("--apply-to b_degs.csv"))
    assert "bias re-estimated" in line and f"{np.mean(y[:1800]):+.4g} deg/h" in line
    assert f"(fitted recording: {np.mean(x[:1800]):+.4g} deg/h)" in line


def test_apply_to_matches_axes_by_name(logs, tmp_path):
    d, a, _, c, _, _ = logs
    res = CliRunner().invoke(app, ["analyze", str(a), "--unit", "deg/h", "--apply-to", str(c), *ARGS,
                                   "--out", str(tmp_path / "o")])
    assert res.exit_code != 0
    line = res.output.strip().splitlines()[-1]
    assert "['gx'] have no fitted model" in line and "--columns" in line
    assert not (tmp_path / "o" / "analysis.json").exists()


def test_apply_unit_without_apply_to_is_refused(logs, tmp_path):
    _, a, *_ = logs
    res = CliRunner().invoke(app, ["analyze", str(a), "--unit", "deg/h", "--apply-unit", "deg/s", *ARGS,
                                   "--out", str(tmp_path / "o")])
    assert res.exit_code != 0 and "need --apply-to" in res.output


def test_compensated_test_block_by_definition():
    x = simulate(2000, dt_s=1.0, arw_dprh=0.5, rrw_dphrh=2.0, seed=5) + 3.0
    rec = dataclasses.replace(from_array(x, dt_s=1.0, axis_names=("gz",)), t0_s=100.0)
    [ma] = run_models(rec, AnalysisConfig(models=("persistence", "ar")))
    cols = compensated_test_block(ma, t0_s=rec.t0_s)
    e, f = ma.split["test"]
    assert_eq = np.testing.assert_allclose
    assert_eq(cols["t_s"], 100.0 + np.arange(e, f))
    assert_eq(cols["measured"], x[e:f], rtol=0, atol=1e-9)  # as measured: bias and Earth rate added back
    assert_eq(cols["bias"], x[e:f] - np.mean(x[: ma.split["train"][1]]), atol=1e-9)
    # persistence predicts the previous causal-drift sample: compensated = measured - bias - causal[k-1]
    causal = ma.causal_drift_dph
    expected = x[e:f] - ma.bias_dph - causal[e - 1:f - 1]
    assert_eq(cols["persistence"], expected, atol=1e-9)
    assert set(cols) == {"t_s", "measured", "bias", "persistence", "ar"}


def test_analyze_writes_a_loadable_compensated_test_block(logs, tmp_path):
    d, a, *_ = logs
    res = CliRunner().invoke(app, ["analyze", str(a), "--unit", "deg/h", *ARGS, "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    back = load(tmp_path / "o" / "compensated_test_gz.csv", columns=["measured", "ar", "persistence", "bias"])
    assert back.dt_s == 1.0 and back.n_samples == 600 and back.t0_s == 2400.0
    assert "compensated test block: compensated_test_gz.csv" in res.output
