"""CLI: commands run on the bundled recording, write their files, and bad input gives one clear line."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app

runner = CliRunner()


def _ok(result):
    assert result.exit_code == 0, result.output + repr(result.exception)
    return result.output


def test_python_m_help():
    proc = subprocess.run([sys.executable, "-m", "fogdrift", "--help"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0
    for cmd in ("allan", "separate", "model", "analyze"):
        assert cmd in proc.stdout


#: Runs the code in $PROBE_CODE (``fogdrift --help``); at exit, after every atexit handler registered later, prints
#: whether the cyclic garbage collector's objects were frozen, and its thresholds at the start and then.
_GC_PROBE = r"""
import atexit, gc, json, os, sys
start = list(gc.get_threshold())
atexit.register(lambda: print(json.dumps([gc.get_freeze_count() > 0, start, list(gc.get_threshold())])))
sys.argv = ["fogdrift", "--help"]
exec(os.environ["PROBE_CODE"])
"""


@pytest.mark.parametrize("code, own", [("from fogdrift.cli import entry\nentry()", True),
                                       ("from fogdrift.cli import main\ntry:\n    main()\nexcept SystemExit:\n"
                                        "    pass", False)])
def test_only_the_entry_point_sets_the_collectors_policy(code, own):
    """The console script and ``python -m fogdrift`` run ``fogdrift.cli.entry``: the command under the process's
    collector thresholds (``GC_THRESHOLDS``), then the collector's objects frozen for the interpreter's exit (its
    full collections skipped); ``main()`` called in a process that goes on leaves the collector as it found it."""
    import os
    from pathlib import Path

    from fogdrift.cli import GC_THRESHOLDS

    proc = subprocess.run([sys.executable, "-c", _GC_PROBE], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PROBE_CODE": code})
    assert proc.returncode == 0 and "allan" in proc.stdout, proc.stderr[-2000:]
    frozen, start, end = json.loads(proc.stdout.strip().splitlines()[-1])
    assert frozen is own
    assert tuple(end) == (GC_THRESHOLDS if own else tuple(start))
    root = Path(__file__).resolve().parents[2]
    assert 'fogdrift = "fogdrift.cli:entry"' in (root / "pyproject.toml").read_text()
    assert "entry()" in (root / "src" / "fogdrift" / "__main__.py").read_text()


def test_allan_on_bundled_recording(bundled_path, tmp_path):
    # the whole record (the default fits the quiet segments the screen finds: tests/cli/test_segments_cli.py)
    out = _ok(runner.invoke(app, ["allan", str(bundled_path), "--unit", "deg/h", "--segments", "whole", "--out",
                                  str(tmp_path)]))
    for unit in ("µrad", "deg/√h", "deg/h^1.5", "deg/h²"):
        assert unit in out
    for axis in ("gx", "gy", "gz"):
        assert axis in out
    doc = json.loads((tmp_path / "allan.json").read_text())
    assert [a["name"] for a in doc["axes"]] == ["gx", "gy", "gz"]
    header = (tmp_path / "allan.csv").read_text().splitlines()[0]
    assert "tau_s" in header and "adev_dph" in header
    assert (tmp_path / "allan.png").stat().st_size > 10_000
    # the console table carries the IEEE B_min reading and the fit quality of each axis, as stored in the JSON
    assert "B [deg/h]" in out and "periodic / Markov" in out and "fit" in out
    for a in doc["axes"]:
        b = a["noise"]["b_min"]
        if b.get("value") is not None:
            assert f"{b['value']:.3g}" in out, (a["name"], b)
        assert a["noise"]["fit"]["quality"] in out
    # The JSON's ADEV at tau = 1 s matches the data README's sanity table (gz: 8.706 deg/h).
    gz = doc["axes"][2]["allan"]
    i = int(np.argmin(np.abs(np.asarray(gz["tau_s"]) - 1.28)))
    assert 5.0 < gz["adev_dph"][i] < 12.0


@pytest.mark.parametrize(
    "content, fragment",
    [
        ("t_s,gz\n0.0,1.0\n0.01,nan\n0.02,3.0\n", "bad.csv:3"),
        ("t_s,gz\n0.0,1.0\n0.01,abc\n0.02,3.0\n", "bad.csv:3"),
        ("t_s,gz\n0.0,1.0\n0.02,2.0\n0.01,3.0\n", "bad.csv:4"),
        ("", "bad.csv"),
    ],
)
def test_bad_input_is_one_clear_line(tmp_path, content, fragment):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    result = runner.invoke(app, ["allan", str(path), "--unit", "deg/h", "--out", str(tmp_path / "o")])
    assert result.exit_code == 1
    assert fragment in result.output
    assert "Traceback" not in result.output
    assert len([ln for ln in result.output.splitlines() if ln.strip()]) <= 3  # rich may wrap one line


def test_unknown_unit_and_level_are_config_errors(bundled_path, tmp_path):
    result = runner.invoke(app, ["allan", str(bundled_path), "--unit", "furlongs", "--out", str(tmp_path)])
    assert result.exit_code == 1 and "furlongs" in result.output
    result = runner.invoke(app, ["separate", str(bundled_path), "--unit", "deg/h", "--level", "x", "--out", str(tmp_path)])
    assert result.exit_code == 1 and "--level" in result.output


def test_separate_writes_series_figures_and_table(bundled_path, tmp_path):
    out = _ok(runner.invoke(app, ["separate", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--out", str(tmp_path)]))
    assert "drift" in out and "noise" in out
    with np.load(tmp_path / "separation.npz") as z:
        x, d, n = z["gz_input_dph"], z["gz_drift_dph"], z["gz_noise_dph"]
    np.testing.assert_allclose(d + n, x, rtol=0, atol=1e-12 * np.abs(x).max())
    assert x.size == 1847  # 184 718 samples at 100 Hz block-averaged to 1 Hz
    for name in ("separation.csv", "separation_table.csv", "fig5_drift_noise_gz.png", "fig6_allan_gz.png"):
        assert (tmp_path / name).exists()


def test_model_command_small(bundled_path, tmp_path):
    out = _ok(runner.invoke(app, ["model", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--models", "ar,gm11,persistence",
                                  "--out", str(tmp_path)]))
    assert "persistence" in out and "RMSE [deg/h]" in out
    doc = json.loads((tmp_path / "metrics.json").read_text())
    assert set(doc["axes"][0]["metrics_paper_target"]) >= {"persistence"}
    assert any(p.suffix == ".json" for p in (tmp_path / "models").iterdir())


def test_the_first_run_says_it_compiles_the_kernels_once_at_a_terminal(tmp_path, monkeypatch, capsys):
    """The first run on a machine compiles numba's kernels (the wait of a first `make demo`): a user at a terminal
    is told so, once; with a cached kernel, off a terminal or for `export` (no kernel), nothing is said."""
    from fogdrift.cli import _app

    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(type(_app.err_console), "is_terminal", property(lambda self: True))
    empty = tmp_path / "pkg"
    (empty / "allan" / "__pycache__").mkdir(parents=True)
    assert _app.first_run_note("allan", root=empty) is True
    assert "first run here: compiling the numerical kernels" in capsys.readouterr().err
    assert _app.first_run_note("export", root=empty) is False
    (empty / "allan" / "__pycache__" / "_kernels._sq2_py-97.py311.nbi").write_bytes(b"")
    assert _app.first_run_note("allan", root=empty) is False
    cache = tmp_path / "numba-cache"
    cache.mkdir()
    (cache / "k.nbi").write_bytes(b"")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(cache))
    assert _app.first_run_note("allan", root=tmp_path / "none") is False  # NUMBA_CACHE_DIR holds one
    monkeypatch.setattr(type(_app.err_console), "is_terminal", property(lambda self: False))
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    assert _app.first_run_note("allan", root=tmp_path / "none") is False  # a log or a pipe: not said
    assert capsys.readouterr().err == ""
