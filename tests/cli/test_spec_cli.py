"""``fogdrift noise --spec``: the datasheet comparison on the console and in spec.json; bad specs as one line."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def white_log(tmp_path_factory):
    """White noise of N = 1 deg/sqrt(h) = 60 (deg/h) sqrt(s): per 0.1-s sample 60/sqrt(0.1) deg/h."""
    d = tmp_path_factory.mktemp("speclog")
    dt = 0.1
    y = np.random.default_rng(7).normal(0.0, 60.0 / math.sqrt(dt), 40_000)  # deg/h: N = 1 deg/sqrt(h)
    p = d / "white.csv"
    np.savetxt(p, np.column_stack([np.arange(y.size) * dt, y]), delimiter=",", header="t_s,gx", comments="",
               fmt="%.6f")
    return p


def _run(args):
    return runner.invoke(app, args)


def test_noise_allan_spec_pass_fail_and_json(white_log, tmp_path):
    spec = tmp_path / "s.json"
    # N = 1 deg/sqrt(h): passes 1.5 deg/sqrt(h) (= 90 deg/h/sqrt(Hz)), fails 0.5 deg/sqrt(h)
    spec.write_text(json.dumps({"sensor": "test part", "gyro": {"arw": "90 deg/h/sqrt(Hz)"}}))
    res = _run(["noise", str(white_log), "--unit", "deg/h", "--method", "allan", "--spec", str(spec),
                "--out", str(tmp_path / "a")])
    assert res.exit_code == 0, res.output
    assert "datasheet comparison: test part" in res.output and "pass" in res.output
    assert "B compared: the IEEE-952 reading B_min" in res.output
    doc = json.loads((tmp_path / "a" / "spec.json").read_text())
    (j,) = doc["judgements"]
    assert j["channel"] == "gx" and j["item"] == "arw" and j["verdict"] == "pass" and j["limit_canonical"] == 1.5
    spec.write_text(json.dumps({"gyro": {"arw": "0.5 deg/sqrt(h)"}}))
    res = _run(["noise", str(white_log), "--unit", "deg/h", "--method", "allan", "--spec", str(spec),
                "--out", str(tmp_path / "b")])
    assert res.exit_code == 0, res.output
    assert json.loads((tmp_path / "b" / "spec.json").read_text())["judgements"][0]["verdict"] == "fail"


def test_noise_spec_unitless_is_one_line_before_any_work(white_log, tmp_path):
    spec = tmp_path / "bad.json"
    spec.write_text('{"gyro": {"arw": 2}}')
    res = _run(["noise", str(white_log), "--unit", "deg/h", "--spec", str(spec), "--out", str(tmp_path / "c")])
    assert res.exit_code == 1
    lines = [l for l in res.output.splitlines() if l.strip()]
    assert len(lines) == 1 and "has no unit" in lines[0] and "Traceback" not in res.output
    assert not (tmp_path / "c" / "noise.json").exists()
