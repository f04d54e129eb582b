"""Inputs are sacred (issue 36): no run removes or replaces a file it read or a file it did not write, and a
previous run's files are replaced only once the new run is complete.

Independent checks: the file system itself (listing, contents), never the module's own bookkeeping.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift import interrupt
from fogdrift.cli import app
from fogdrift.errors import ConfigError
from fogdrift.interrupt import Interrupted
from fogdrift.output import BACKUP_PREFIX, LOCK, MANIFEST, OutputDir, recover

runner = CliRunner()


def listing(folder):
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


def contents(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def _write(od, names, tag):
    for n in names:
        with od.file(n) as tmp:
            tmp.write_text(f"{tag}:{n}")


def _previous_run(folder, command="model"):
    with OutputDir(folder, command=command) as od:
        _write(od, ["a.json", "b.csv", "figures/f1.png", "bundle/manifest.json", "bundle/ar.json"], "first")
    return contents(folder)


# ------------------------------------------------------------------------------------------
# A previous run's files are replaced only once the new run is complete
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("how", ["interrupted", "error"])
def test_a_rerun_that_does_not_finish_leaves_the_earlier_output_as_it_was(tmp_path, how):
    folder = tmp_path / "out"
    before = _previous_run(folder)
    try:
        with OutputDir(folder, command="model") as od:
            od.expect("a.json", "b.csv", "c.txt")
            _write(od, ["a.json", "c.txt", "bundle/manifest.json", "new/deep.png"], "second")
            assert (folder / "a.json").read_text() == "second:a.json"  # written in place while it runs
            if how == "interrupted":
                interrupt.request()
                _write(od, ["b.csv"], "second")
            raise ValueError("the fit failed")
    except (Interrupted, ValueError):
        pass
    finally:
        interrupt.reset()
    assert contents(folder) == before  # every earlier file back, byte for byte, the manifest included
    assert listing(folder) == sorted(set(before) | {"bundle", "figures"})  # no new folder, no backup, no lock
    assert json.loads((folder / MANIFEST).read_text())["complete"] is True
    assert od.summary() == (f"nothing was kept in {folder}: the earlier run's files there are unchanged (the 4 "
                            "file(s) this run had written were taken back, a folder holds one complete run)")


def test_a_complete_rerun_replaces_the_earlier_files_and_leaves_no_backup(tmp_path):
    folder = tmp_path / "out"
    _previous_run(folder)
    with OutputDir(folder, command="model") as od:
        _write(od, ["a.json", "c.txt"], "second")
        assert (folder / "b.csv").exists()  # the earlier run's other files stay until the run is complete
    assert listing(folder) == sorted([MANIFEST, "a.json", "c.txt"])
    assert (folder / "a.json").read_text() == "second:a.json"
    assert sorted(od.removed) == ["a.json", "b.csv", "bundle/ar.json", "bundle/manifest.json", "figures/f1.png"]


def test_the_watchdogs_abort_takes_the_run_back(tmp_path):
    folder = tmp_path / "out"
    before = _previous_run(folder)
    with pytest.raises(RuntimeError, match="closed after an interruption"):
        with OutputDir(folder, command="model") as od:
            _write(od, ["a.json", "z.txt"], "second")
            t = threading.Thread(target=od.abort)  # the CLI's watchdog, from another thread
            t.start()
            t.join()
            _write(od, ["b.csv"], "second")
    assert contents(folder) == before


def test_a_run_killed_outright_is_taken_back_by_the_next_one(tmp_path):
    folder = tmp_path / "out"
    before = _previous_run(folder)
    code = ("import os, sys; from fogdrift.output import OutputDir\n"
            "od = OutputDir(sys.argv[1], command='model').__enter__()\n"
            "for n in ('a.json', 'bundle/ar.json', 'q.txt'):\n"
            "    with od.file(n) as t: t.write_text('killed')\n"
            "os.kill(os.getpid(), 9)\n")
    proc = subprocess.run([sys.executable, "-c", code, str(folder)], capture_output=True, timeout=120)
    assert proc.returncode == -9
    assert (folder / "a.json").read_text() == "killed" and any(p.name.startswith(BACKUP_PREFIX)
                                                               for p in folder.iterdir())
    with OutputDir(folder, command="allan"):  # the next run: the killed one is taken back at its start
        pass
    assert contents(folder) == before
    assert recover(folder) is False  # nothing left to do


def test_a_new_folder_keeps_the_complete_files_of_an_interrupted_run(tmp_path):
    folder = tmp_path / "new"
    with pytest.raises(Interrupted):
        with OutputDir(folder, command="allan") as od:
            _write(od, ["allan.json"], "only")
            raise Interrupted()
    assert listing(folder) == [MANIFEST, "allan.json"]  # nothing earlier to keep: its complete files stay


# ------------------------------------------------------------------------------------------
# Refused before any work
# ------------------------------------------------------------------------------------------
def test_a_folder_whose_previous_files_include_an_input_folder_is_refused(tmp_path):
    folder = tmp_path / "out"
    before = _previous_run(folder)
    with pytest.raises(ConfigError, match=r"holds the files of an earlier 'fogdrift model' run, which this run "
                                          r"would replace, and bundle/manifest.json among them is an input"):
        with OutputDir(folder, command="compensate", protect=[folder / "bundle"]):
            raise AssertionError("refused before the body runs")
    assert contents(folder) == before and not (folder / LOCK).exists()
    # an input folder above the output folder (a batch over logs/ into logs/out) protects nothing in it
    with OutputDir(folder, command="batch allan", protect=[tmp_path]) as od:
        _write(od, ["summary.parquet"], "batch")


def test_a_users_own_file_is_never_replaced(tmp_path):
    (tmp_path / "log.csv").write_text("t_s,gz[deg/s]\n")
    (tmp_path / "allan.json").write_text("mine")
    with pytest.raises(ConfigError, match=r"the output allan.json would replace .*allan.json, a file fogdrift "
                                          r"did not write"):
        od = OutputDir(tmp_path, command="allan", protect=[tmp_path / "log.csv"])
        od.expect("allan.json", "allan.csv")
        with od:  # refused at the start: the expected names
            raise AssertionError("refused before the body runs")
    with OutputDir(tmp_path, command="allan") as od:  # a name not announced: refused at its write
        with pytest.raises(ConfigError, match="a file fogdrift did not write"):
            _write(od, ["allan.json"], "ours")
    assert (tmp_path / "allan.json").read_text() == "mine"


def test_two_runs_started_into_the_same_new_folder_the_second_is_refused(tmp_path):
    folder = tmp_path / "new"
    with OutputDir(folder, command="allan") as first:  # the first has not written anything yet
        assert folder.is_dir() and (folder / LOCK).exists()
        with pytest.raises(ConfigError, match=r"'fogdrift allan' \(process \d+, started .*is writing there now"):
            with OutputDir(folder, command="noise"):
                pass
        _write(first, ["allan.json"], "first")
    assert listing(folder) == [MANIFEST, "allan.json"]
    with OutputDir(tmp_path / "never", command="allan"):  # a run that writes nothing leaves no folder
        pass
    assert not (tmp_path / "never").exists()


def test_wildcard_inputs_are_protected(tmp_path):
    folder = tmp_path / "out"
    with OutputDir(folder, command="x") as od:
        _write(od, ["a.csv"], "x")
    with pytest.raises(ConfigError, match="a.csv among them is an input"):
        with OutputDir(folder, command="batch", protect=[str(folder / "*.csv")]):
            pass


# ------------------------------------------------------------------------------------------
# The commands
# ------------------------------------------------------------------------------------------
def _log(path, n=4000, fs=10.0):
    rng = np.random.default_rng(3)
    t = np.arange(n) / fs
    np.savetxt(path, np.column_stack([t, rng.normal(0, 0.01, n)]), delimiter=",", header="t_s,gz[deg/s]",
               comments="", fmt="%.9g")
    return path


def _one_line(result, *fragments):
    assert result.exit_code == 1, result.output
    text = result.output.strip()
    assert len(text.splitlines()) == 1 and text.startswith("error: "), text
    for f in fragments:
        assert f in text, text


def test_compensate_into_the_folder_of_the_bundle_is_refused(tmp_path):
    d = tmp_path / "model_out"
    before = _previous_run(d)
    log = _log(tmp_path / "new.csv")
    res = runner.invoke(app, ["compensate", str(d / "bundle"), str(log), "--out", str(d)])
    _one_line(res, "--out", "an input of this run", "choose another output folder")
    assert contents(d) == before


def test_consistency_with_components_in_its_out_folder_is_refused(tmp_path):
    d = tmp_path / "noise_out"
    with OutputDir(d, command="noise") as od:
        _write(od, ["noise.json", "noise_model.json"], "noise")
    before = contents(d)
    log, held = _log(tmp_path / "train.csv"), _log(tmp_path / "held.csv")
    res = runner.invoke(app, ["consistency", str(log), "--held-out", str(held), "--components",
                              str(d / "noise_model.json"), "--out", str(d)])
    _one_line(res, "noise_model.json among them is an input of this run")
    assert contents(d) == before


def test_allan_into_the_folder_of_its_log_and_a_users_allan_json(tmp_path):
    log = _log(tmp_path / "log.csv")
    (tmp_path / "allan.json").write_text("my own notes")
    before = contents(tmp_path)
    res = runner.invoke(app, ["allan", str(log), "--out", str(tmp_path)])
    _one_line(res, "allan.json, a file fogdrift did not write")
    assert contents(tmp_path) == before and listing(tmp_path) == ["allan.json", "log.csv"]


def test_export_never_replaces_a_result_it_reads(tmp_path):
    d = tmp_path / "o"
    with OutputDir(d, command="allan") as od:
        _write(od, ["allan.json"], "allan")
    before = contents(d)
    res = runner.invoke(app, ["export", "--gyro", str(d / "allan.json"), "--out", str(d)])
    _one_line(res, "allan.json among them is an input of this run")
    assert contents(d) == before


def test_an_interrupted_allan_rerun_keeps_the_earlier_output(tmp_path, monkeypatch):
    import fogdrift.report.figures as report

    log = _log(tmp_path / "log.csv")
    out = tmp_path / "o"
    first = runner.invoke(app, ["allan", str(log), "--out", str(out)])
    assert first.exit_code == 0, first.output
    before = contents(out)
    assert {"allan.json", "allan.csv", "allan.png", MANIFEST} <= set(before)

    def ctrl_c(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(report, "save_figure", ctrl_c)  # Ctrl-C as the figure is written (after allan.json)
    second = runner.invoke(app, ["allan", str(log), "--out", str(out)])
    assert second.exit_code == 130, second.output
    assert "the earlier run's files there are unchanged" in second.output and "were taken back" in second.output
    assert contents(out) == before
    assert not any(n.startswith((BACKUP_PREFIX, ".fogdrift-tmp-", LOCK)) for n in os.listdir(out))
