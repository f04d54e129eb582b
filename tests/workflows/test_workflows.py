"""The command workflows (:mod:`fogdrift.workflows`): the CLI and ``fogdrift batch`` run the same functions, and a
Python user gets the same result objects and files."""

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
    assert sorted(WORKFLOWS) == ["allan", "analyze", "export", "model", "noise", "separate"]
    with pytest.raises(ConfigError, match="no workflow"):
        workflow("plot")


def _files(folder, names):
    return {n: (folder / n).read_bytes() for n in names}


def test_separate_and_model_the_cli_writes_what_the_workflow_writes(tmp_path):
    """``fogdrift separate`` and ``fogdrift model`` are their workflows plus printing: the files a Python user writes
    with ``run_<cmd>`` + ``write_<cmd>`` are the CLI's, byte for byte (the JSON, CSV and NPZ; one axis, 1 Hz)."""
    import fogdrift

    y = simulate(2**12, 1.0, arw_dprh=0.05, bias_instability_dph=0.5, seed=4)
    path = tmp_path / "g.npy"
    np.save(path, y)
    rec = load(path, unit="deg/h", rate_hz=1.0)
    for cmd, extra, names in (
            ("separate", [], ["separation.json", "separation.csv", "separation_table.csv"]),
            ("model", ["--models", "persistence,ar"], ["metrics.json", "bundle/manifest.json"])):
        res = runner.invoke(app, [cmd, str(path), "--unit", "deg/h", "--rate", "1", *extra, "--out",
                                  str(tmp_path / f"cli_{cmd}")])
        assert res.exit_code == 0, res.output + repr(res.exception)
        cfg = fogdrift.pipeline.AnalysisConfig(**({"models": ("persistence", "ar")} if cmd == "model" else {}))
        run = getattr(fogdrift, f"run_{cmd}")(rec, cfg)
        assert run.factor == 1 and [a.name for a in run.axes] == ["col0"] and run.findings == []
        getattr(fogdrift, f"write_{cmd}")(run, tmp_path / f"py_{cmd}")
        cli, py = _files(tmp_path / f"cli_{cmd}", names), _files(tmp_path / f"py_{cmd}", names)
        for n in names:
            if n.endswith(".json"):   # the run's own times and paths aside
                a, b = (json.loads(x) for x in (cli[n], py[n]))
                for d in (a, b):
                    d.pop("created_utc", None), d.pop("seal_sha256", None), d.pop("source", None)
                    for ax in d.get("axes", []):
                        ax.pop("fit_seconds", None)
                assert a == b, n
            else:
                assert cli[n] == py[n], n


def test_export_the_cli_writes_what_the_workflow_writes(tmp_path):
    """``fogdrift export LOG`` is ``run_export`` + ``write_export``: the same target files and allan.json."""
    import fogdrift

    path = _log(tmp_path)
    res = runner.invoke(app, ["export", str(path), "--unit", "deg/h", "--rate", "100", "--target", "kalibr,json",
                              "--out", str(tmp_path / "cli")])
    assert res.exit_code == 0, res.output + repr(res.exception)
    run = fogdrift.run_export(load(path, unit="deg/h", rate_hz=100.0), targets="kalibr,json")
    assert run.targets == ["kalibr", "json"] and run.fit is not None and run.context.rate_hz == 100.0
    files = fogdrift.write_export(run, tmp_path / "py")
    assert sorted(files) == ["allan", "json", "kalibr"]
    for name in ("imu.yaml", "allan.csv"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "py" / name).read_bytes(), name
    a, b = (json.loads((tmp_path / d / "allan.json").read_text()) for d in ("cli", "py"))
    assert a == b


def test_separate_and_model_runs_share_one_base():
    """The two runs at the modelling rate are one dataclass (record, config, factor, axes, findings) under two names,
    and ``analyze`` decides its configuration and factor with the same helper."""
    import dataclasses

    from fogdrift.workflows import analyze as wf_analyze
    from fogdrift.workflows._modelled import ModelledRun, modelling
    from fogdrift.workflows.model import ModelRun
    from fogdrift.workflows.separate import SeparateRun

    names = [f.name for f in dataclasses.fields(ModelledRun)]
    assert names == ["record", "config", "factor", "axes", "findings"]
    for cls in (SeparateRun, ModelRun):
        assert issubclass(cls, ModelledRun) and [f.name for f in dataclasses.fields(cls)] == names
    assert wf_analyze.modelling is modelling
