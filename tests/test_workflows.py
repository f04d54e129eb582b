"""The command workflows (:mod:`fogdrift.workflows`): the CLI and ``fogdrift batch`` run the same functions, and a
Python user gets the same result objects and files (issue 33, deliver 1)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.errors import ConfigError
from fogdrift.fleet.commands import run_allan_command, run_noise_command
from fogdrift.io import from_array, load
from fogdrift.simulate import simulate
from fogdrift.workflows import WORKFLOWS, workflow
from fogdrift.workflows import allan as wf_allan
from fogdrift.workflows import noise as wf_noise

runner = CliRunner()


def _log(tmp_path, seed=3):
    y = simulate(2**14, 0.01, arw_dprh=0.05, bias_instability_dph=0.5, seed=seed)
    path = tmp_path / "g.npy"
    np.save(path, y)
    return path


@pytest.mark.parametrize("name,cli_args,fleet", [
    ("allan", ["allan"], run_allan_command),
    ("noise", ["noise", "--model", "WN+FLICKER"], run_noise_command),
])
def test_the_cli_and_the_fleet_call_the_same_workflow(tmp_path, monkeypatch, name, cli_args, fleet):
    module = {"allan": wf_allan, "noise": wf_noise}[name]
    real = getattr(module, f"run_{name}")
    calls = []

    def spy(*args, **kwargs):
        calls.append(kwargs)
        return real(*args, **kwargs)

    monkeypatch.setattr(module, f"run_{name}", spy)
    path = _log(tmp_path)
    res = runner.invoke(app, [*cli_args, str(path), "--unit", "deg/h", "--rate", "100", "--out", str(tmp_path / "c")])
    assert res.exit_code == 0, res.output + repr(res.exception)
    record = load(path, unit="deg/h", rate_hz=100.0)
    settings = {"gmwm": {"model": "WN+FLICKER"}} if name == "noise" else {}
    (tmp_path / "f").mkdir()
    rows = fleet(record, settings, tmp_path / "f")
    assert len(calls) == 2 and rows and rows[0]["axis"] == record.axis_names[0]
    out_name = "allan.json" if name == "allan" else "noise.json"
    cli_doc = json.loads((tmp_path / "c" / out_name).read_text())
    fleet_doc = json.loads((tmp_path / "f" / out_name).read_text())
    assert cli_doc["axes"] == fleet_doc["axes"]


def test_a_python_user_runs_a_command_and_writes_its_files(tmp_path):
    rec = from_array(simulate(2**14, 0.01, arw_dprh=0.1, seed=1), dt_s=0.01, axis_names=["gz"])
    run = workflow("allan").run(rec)
    n = run.results[0].noise.terms["N"]
    assert n.lo95 < 0.1 < n.hi95 and run.screens["gz"]["stationary"] and run.findings == []
    files = workflow("allan").write(run, tmp_path)
    doc = json.loads(files["json"].read_text())
    assert doc["axes"][0]["name"] == "gz" and (tmp_path / "allan.png").is_file()
    assert sorted(WORKFLOWS) == ["allan", "analyze", "noise"]
    with pytest.raises(ConfigError, match="no workflow"):
        workflow("plot")
