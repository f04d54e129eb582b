"""CLI reader options: --temperature (console line and the JSON field), --layout/--scale/--header-bytes for raw
binary, --topic for a bag, and a missing option shown as its CLI flag."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app

runner = CliRunner()


def _ok(result):
    assert result.exit_code == 0, result.output + repr(result.exception)
    return result.output


def test_allan_reports_temperature_range_and_drift(tmp_path):
    rng = np.random.default_rng(3)
    n = 4000
    lines = ["t_s,gz,temp"] + [f"{i / 10:.1f},{float(v)!r},{20 + i / 1000:.3f}" for i, v in enumerate(rng.normal(size=n))]
    p = tmp_path / "log.csv"
    p.write_text("\n".join(lines) + "\n")
    out = _ok(runner.invoke(app, ["allan", str(p), "--unit", "deg/h", "--temperature", "temp",
                                   "--out", str(tmp_path / "o")]))
    assert "temperature 20.00 to 24.00 deg C (range 4.00), drift +3.96 deg C" in out
    doc = json.loads((tmp_path / "o" / "allan.json").read_text())
    t = doc["record"]["temperature"]
    assert t["range_c"] == pytest.approx(3.999) and t["slope_c_per_h"] == pytest.approx(36.0)
    assert [a["name"] for a in doc["axes"]] == ["gz"]


def test_raw_binary_through_cli_flags(tmp_path):
    rng = np.random.default_rng(4)
    rec = np.zeros(5000, dtype=[("seq", "<u4"), ("gz", "<i4")])
    rec["seq"] = np.arange(5000)
    rec["gz"] = rng.integers(-100, 100, size=5000)
    p = tmp_path / "log.raw"
    p.write_bytes(b"\x00" * 32 + rec.tobytes())
    args = ["allan", str(p), "--layout", "<u4 seq, <i4 gz", "--header-bytes", "32", "--rate", "100",
            "--out", str(tmp_path / "o")]
    result = runner.invoke(app, args)
    assert result.exit_code == 1 and "raw binary declares no unit; pass --unit" in result.output
    _ok(runner.invoke(app, args + ["--unit", "inc:arcsec", "--scale", "0.01"]))
    doc = json.loads((tmp_path / "o" / "allan.json").read_text())
    assert doc["record"]["n_samples"] == 5000
    assert doc["record"]["signal"]["channels"][0]["scale_to_internal"] == pytest.approx(100.0)


def test_bag_topic_flag(tmp_path):
    pytest.importorskip("rosbags")
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "io"))  # the bag writer of tests/io/test_io_rosbag.py
    from test_io_rosbag import T0_NS, write_bag

    w = np.random.default_rng(5).normal(scale=1e-4, size=(3000, 3))
    write_bag(tmp_path / "b.bag", 1, w, T0_NS + np.arange(3000, dtype=np.int64) * 10_000_000, extra_imu=True)
    result = runner.invoke(app, ["allan", str(tmp_path / "b.bag"), "--out", str(tmp_path / "o")])
    assert result.exit_code == 1 and "or --topic, got: /imu/data" in result.output
    _ok(runner.invoke(app, ["allan", str(tmp_path / "b.bag"), "--topic", "/imu/raw", "--columns", "gz",
                            "--out", str(tmp_path / "o")]))
    doc = json.loads((tmp_path / "o" / "allan.json").read_text())
    ch = doc["record"]["signal"]["channels"][0]
    assert ch["unit_as_read"] == "rad/s"
    assert ch["scale_to_internal"] == pytest.approx(180 / math.pi * 3600)


def test_analyze_report_shows_rate_and_temperature(tmp_path):
    # a log with a temperature column: the report's Recording section has the rate + temperature figure
    # (its PNG written through the atomic outputs) and the range/drift line computed from the column
    rng = np.random.default_rng(5)
    n = 20_000
    lines = ["t_s,gz,temp"] + [f"{i / 10:.1f},{float(v)!r},{20 + i / 5000:.4f}"
                               for i, v in enumerate(rng.normal(size=n) + np.linspace(0, 3, n))]
    p = tmp_path / "log.csv"
    p.write_text("\n".join(lines) + "\n")
    _ok(runner.invoke(app, ["analyze", str(p), "--unit", "deg/h", "--temperature", "temp", "--models",
                            "persistence", "--no-heading", "--sensor", "LAB FOG #3", "--out", str(tmp_path / "o")]))
    html = (tmp_path / "o" / "report.html").read_text()
    # --sensor: named on the first screen and in analysis.json (a log does not carry it)
    doc = json.loads((tmp_path / "o" / "analysis.json").read_text())
    assert doc["report_summary"]["recording"]["sensor"] == "LAB FOG #3" and "LAB FOG #3" in html
    assert "<h3>Temperature</h3>" in html
    # by hand: 20 + i/5000 at 10 Hz -> 20.00 to 24.00 deg C over 2000 s = 0.556 h, slope 7.2 deg C/h
    assert "temperature 20.00 to 24.00 deg C (range 4.00)" in html and "(slope +7.200 deg C/h)" in html
    png = tmp_path / "o" / "figures" / "fig_temperature.png"
    assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list((tmp_path / "o").rglob("*.tmp*"))
