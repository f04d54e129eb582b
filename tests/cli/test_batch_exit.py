"""``fogdrift batch`` exits non-zero when a file failed (the other files' results are still written)."""

from __future__ import annotations

import numpy as np
from typer.testing import CliRunner

from fogdrift.cli import app


def _inputs(tmp_path):
    d = tmp_path / "in"
    d.mkdir()
    rng = np.random.default_rng(3)
    for k in range(2):
        t = np.arange(4000) * 0.01
        (d / f"unit{k}.csv").write_text("t_s,gz[deg/h]\n" + "".join(f"{a:.2f},{float(b)!r}\n" for a, b in
                                                                      zip(t, rng.normal(size=t.size))))
    (d / "broken.csv").write_text("t_s,gz[deg/h]\n0.00,1.0\n0.01,nan\n0.02,2.0\n")
    return d


def test_a_failed_file_makes_the_exit_code_1_and_allow_failures_0(tmp_path):
    d = _inputs(tmp_path)
    res = CliRunner().invoke(app, ["batch", str(d), "--glob", "*.csv", "--command", "allan", "--scheduler", "serial",
                                   "--out", str(tmp_path / "o")])
    assert res.exit_code == 1, res.output
    assert "2 done" in res.output and "1 failed" in res.output and "broken.csv" in res.output
    assert "exit code 1: 1 of 3 files failed" in res.output and "Traceback" not in res.output
    assert (tmp_path / "o" / "summary.parquet").is_file()
    assert (tmp_path / "o" / "unit0.csv" / "allan.json").is_file()
    res = CliRunner().invoke(app, ["batch", str(d), "--glob", "*.csv", "--command", "allan", "--scheduler", "serial",
                                   "--allow-failures", "--out", str(tmp_path / "o2")])
    assert res.exit_code == 0, res.output


def test_all_files_ok_exit_0(tmp_path):
    d = _inputs(tmp_path)
    (d / "broken.csv").unlink()
    res = CliRunner().invoke(app, ["batch", str(d), "--glob", "*.csv", "--command", "allan", "--scheduler", "serial",
                                   "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output


def test_inputs_that_would_share_an_output_folder_are_refused(tmp_path):
    d = _inputs(tmp_path)
    (d / "broken.csv").unlink()
    (d / "unit 0.csv").write_text((d / "unit0.csv").read_text())
    (d / "unit_0.csv").write_text((d / "unit0.csv").read_text())
    res = CliRunner().invoke(app, ["batch", str(d), "--glob", "*.csv", "--command", "allan", "--scheduler", "serial",
                                   "--out", str(tmp_path / "o")])
    assert res.exit_code != 0 and "Traceback" not in res.output
    assert "'unit 0.csv' and 'unit_0.csv' would share the output folder 'unit_0.csv'" in res.output
    assert not (tmp_path / "o" / "unit_0.csv").exists()
