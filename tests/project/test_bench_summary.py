"""bench/run_all.py's one table: every benchmark's JSON becomes rows with ratio = peer time / fogdrift time."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture()
def run_all(tmp_path, monkeypatch):
    spec = importlib.util.spec_from_file_location("fogdrift_bench_run_all", ROOT / "bench" / "run_all.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    monkeypatch.setattr(mod, "OUT", tmp_path)
    return mod


def test_rows_and_ratios_from_each_benchmark(run_all, tmp_path):
    (tmp_path / "allan.json").write_text(json.dumps({"rows": [
        {"size": 1e8, "tool": "fogdrift exact adev", "n_tau": 95, "wall_s": 2.0, "ratio": 40.0, "max_rel_diff": 1e-12},
        {"size": 1e8, "tool": "allantools oadev", "n_tau": 95, "wall_s": 80.0, "ratio": 1.0, "max_rel_diff": 0.0}]}))
    (tmp_path / "lifting.json").write_text(json.dumps({"rows": [
        {"n": 1e6, "pywt_s": 3.0, "numba_s": 0.5, "numba_peak_x": 2.0, "pywt_peak_x": 9.0,
         "max_abs_diff_vs_pywt": 1e-13}]}))
    (tmp_path / "readers.json").write_text(json.dumps({"rows": [["csv.gz", 40.0, 0.5, 80.0, 2.0, 20.0]]}))
    (tmp_path / "cli.json").write_text(json.dumps({"rows": [
        {"case": "allan", "fogdrift_s": 2.0, "rss_mb": 300.0, "peer": "allantools", "peer_s": 6.0, "ratio": 3.0,
         "target": "ratio >= 5", "met": False}]}))
    rows = {(r["bench"], r["case"]): r for r in run_all.summary_rows()}
    allan = rows[("allan", "fogdrift exact adev 1e+08, 95 tau")]
    assert allan["peer_s"] == pytest.approx(80.0) and allan["ratio"] == 40.0
    assert ("allan", "allantools oadev 1e+08, 95 tau") not in rows           # the peer is not its own row
    lift = rows[("lifting", "separate numba 1e+06")]
    assert lift["ratio"] == pytest.approx(6.0)                               # pywt 3.0 s / fogdrift 0.5 s
    assert not any(c.startswith("separate numba_peak") for _, c in rows)     # *_peak_x keys are not timings
    assert rows[("readers", "csv.gz (40 MB)")]["ratio"] == pytest.approx(4.0)
    assert rows[("command", "allan")]["target"].endswith("(NOT met)")


def test_missing_files_give_an_empty_table(run_all, capsys):
    assert run_all.summary_rows() == []
    run_all.print_summary()
    assert "| bench | case |" in capsys.readouterr().out
