"""Output safety: --out validated up front, atomic files, one run's files per folder, interruption bookkeeping.

Independent checks: the file system itself (os.listdir, stat, exists) and hand-written expectations.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from fogdrift import interrupt
from fogdrift.errors import ConfigError
from fogdrift.interrupt import Interrupted
from fogdrift.output import MANIFEST, TMP_PREFIX, OutputDir, atomic_path, check_out_dir


def listing(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


# ------------------------------------------------------------------------------------------
# Validation before any work
# ------------------------------------------------------------------------------------------
def test_out_that_is_a_file_is_refused(tmp_path):
    f = tmp_path / "report.html"
    f.write_text("x")
    with pytest.raises(ConfigError) as ei:
        check_out_dir(f)
    assert "exists and is not a folder" in str(ei.value) and str(ei.value).startswith("out= ")
    assert ei.value.render({"out": "--out"}).startswith(f"--out {f} exists")


def test_out_below_a_file_is_refused(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    with pytest.raises(ConfigError, match="is a file, not a folder"):
        check_out_dir(f / "sub" / "run")


def test_missing_parent_is_refused_unless_asked(tmp_path):
    target = tmp_path / "typo" / "run1"
    with pytest.raises(ConfigError, match="its parent folder .*typo does not exist"):
        check_out_dir(target)
    assert check_out_dir(target, create_parents=True) == target
    assert not (tmp_path / "typo").exists()  # validation creates nothing


def test_unwritable_folder_is_refused(tmp_path):
    if Path("/proc/self").is_dir():  # a mount nobody may create files in, root included
        with pytest.raises(ConfigError, match="cannot write in /proc"):
            check_out_dir("/proc/fogdrift-out")
    if os.geteuid() != 0:
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o500)
        try:
            with pytest.raises(ConfigError, match="cannot write in"):
                check_out_dir(ro / "run")
        finally:
            ro.chmod(0o700)


def test_validation_leaves_no_probe_file(tmp_path):
    check_out_dir(tmp_path)
    check_out_dir(tmp_path / "new")
    assert listing(tmp_path) == []


# ------------------------------------------------------------------------------------------
# Atomic files
# ------------------------------------------------------------------------------------------
def test_atomic_path_renames_only_a_complete_file(tmp_path):
    target = tmp_path / "a" / "b.json"
    with atomic_path(target) as tmp:
        assert tmp.parent == target.parent and tmp.name.startswith(TMP_PREFIX) and tmp.suffix == ".json"
        tmp.write_text("{}")
        assert not target.exists()
    assert target.read_text() == "{}"
    with pytest.raises(ValueError):
        with atomic_path(target) as tmp:
            tmp.write_text('{"half":')
            raise ValueError("writer failed")
    assert target.read_text() == "{}"  # the old complete file is untouched
    assert listing(tmp_path) == ["a", "a/b.json"]


def test_numpy_and_matplotlib_writers_keep_the_extension(tmp_path):
    import numpy as np
    from fogdrift.report import pyplot, save_figure

    with atomic_path(tmp_path / "s.npz") as tmp:
        np.savez(tmp, x=np.arange(3))
    with np.load(tmp_path / "s.npz") as z:
        assert z["x"].tolist() == [0, 1, 2]
    plt = pyplot()
    fig, _ = plt.subplots()
    save_figure(fig, tmp_path / "f.png")
    assert (tmp_path / "f.png").read_bytes()[:4] == b"\x89PNG"
    assert listing(tmp_path) == ["f.png", "s.npz"]


# ------------------------------------------------------------------------------------------
# One run's files per folder
# ------------------------------------------------------------------------------------------
def _run(folder, names, command="test", **kw):
    with OutputDir(folder, command=command, **kw) as out:
        for n in names:
            with atomic_path(folder / n) as tmp:
                tmp.write_text(n)
    return out


def test_a_run_replaces_the_previous_runs_files(tmp_path):
    folder = tmp_path / "out"
    first = _run(folder, ["a.json", "b.csv", "figures/f1.png", "figures/f2.png"])
    assert first.written == ["a.json", "b.csv", "figures/f1.png", "figures/f2.png"]
    doc = json.loads((folder / MANIFEST).read_text())
    assert doc["complete"] is True and doc["files"] == first.written and doc["dirs"] == ["figures"]
    (folder / "notes.txt").write_text("mine")  # a file fogdrift did not write
    second = _run(folder, ["a.json"])
    assert listing(folder) == sorted([MANIFEST, "a.json", "notes.txt"])  # stale files and the empty folder gone
    assert sorted(second.removed) == ["a.json", "b.csv", "figures/f1.png", "figures/f2.png"]
    assert json.loads((folder / MANIFEST).read_text())["files"] == ["a.json"]
    # the same run twice writes the same names (deterministic), nothing accumulates
    _run(folder, ["a.json", "b.csv"])
    _run(folder, ["a.json", "b.csv"])
    assert listing(folder) == sorted([MANIFEST, "a.json", "b.csv", "notes.txt"])


def test_inputs_and_paths_outside_are_never_removed(tmp_path):
    folder = tmp_path / "out"
    _run(folder, ["separation.csv", "x.json"])
    outside = tmp_path / "keep.txt"
    outside.write_text("keep")
    doc = json.loads((folder / MANIFEST).read_text())
    doc["files"] += ["../keep.txt", str(outside), "", 7]  # a tampered manifest
    (folder / MANIFEST).write_text(json.dumps(doc))
    # separation.csv is this run's input and a file of the previous run, which a run there replaces: refused at
    # the start, before any work, nothing touched (issue 36)
    with pytest.raises(ConfigError, match=r"holds the files of an earlier 'fogdrift test' run, which this run "
                                          r"would replace, and separation.csv among them is an input of this run"):
        _run(folder, ["y.json"], protect=[folder / "separation.csv"])
    assert listing(folder) == sorted([MANIFEST, "separation.csv", "x.json"])
    _run(folder, ["y.json"])
    assert outside.read_text() == "keep"
    assert listing(folder) == sorted([MANIFEST, "y.json"])


def test_nothing_is_touched_before_the_first_write(tmp_path):
    folder = tmp_path / "out"
    _run(folder, ["a.json"])
    with pytest.raises(Interrupted):
        with OutputDir(folder, command="test") as out:
            raise Interrupted()  # e.g. Ctrl-C during the analysis
    assert listing(folder) == sorted([MANIFEST, "a.json"])
    assert out.summary() == f"nothing was written to {folder} (the earlier run's files there are unchanged)"
    with OutputDir(tmp_path / "new", command="test") as fresh:
        pass
    assert not (tmp_path / "new").exists() and fresh.summary() == f"nothing was written to {tmp_path / 'new'}"


def test_interrupted_run_lists_what_was_and_was_not_written(tmp_path):
    folder = tmp_path / "out"
    try:
        with OutputDir(folder, command="test") as out:
            out.expect("a.json", "b.csv", "c.png")
            with atomic_path(folder / "a.json") as tmp:
                tmp.write_text("{}")
            interrupt.request()  # Ctrl-C while the next file is written
            with atomic_path(folder / "b.csv") as tmp:
                tmp.write_text("never")
    except Interrupted:
        pass
    finally:
        interrupt.reset()
    assert listing(folder) == sorted([MANIFEST, "a.json"])
    assert json.loads((folder / MANIFEST).read_text())["complete"] is False
    assert out.summary() == (f"wrote 1 complete file(s) to {folder}: a.json; not written: b.csv, c.png; "
                             "no partial file left")


def test_interruption_during_a_write_leaves_no_partial_file(tmp_path):
    folder = tmp_path / "out"
    with pytest.raises(Interrupted):
        with OutputDir(folder, command="test"):
            with atomic_path(folder / "big.csv") as tmp:
                tmp.write_text("half of it")
                raise Interrupted()
    assert listing(folder) == [MANIFEST]


def test_abort_from_another_thread_stops_renames(tmp_path):
    folder = tmp_path / "out"
    with pytest.raises(RuntimeError, match="closed after an interruption"):
        with OutputDir(folder, command="test") as out:
            with atomic_path(folder / "a.json") as tmp:
                tmp.write_text("{}")
                out.abort()  # the watchdog: temporaries removed, no rename after this
    assert listing(folder) == [MANIFEST]


def test_dead_processes_temporaries_are_removed(tmp_path):
    folder = tmp_path / "out"
    folder.mkdir()
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead_pid = int(dead.stdout)
    (folder / f"{TMP_PREFIX}{dead_pid}-allan.png").write_text("half")
    (folder / f"{TMP_PREFIX}{os.getppid()}-other.png").write_text("a running process is writing it")
    _run(folder, ["a.json"])
    assert listing(folder) == sorted([MANIFEST, "a.json", f"{TMP_PREFIX}{os.getppid()}-other.png"])


def test_the_manifest_lists_a_file_before_it_appears(tmp_path, monkeypatch):
    """Each rename of a finished temporary file into place happens after the manifest on disk lists it (a run killed
    between the two leaves a listed file absent, which a later run skips, never a file no manifest records); a
    rename that fails takes the entry back.  Also on a re-run whose previous file is moved aside first."""
    import fogdrift.output as output

    folder = tmp_path / "out"
    seen = []
    real = os.replace

    def replace(src, dst):
        if Path(src).name.startswith(TMP_PREFIX) and Path(dst).name != MANIFEST:
            listed = json.loads((folder / MANIFEST).read_text())["files"]
            seen.append((Path(dst).name, Path(dst).name in listed, Path(dst).exists()))
        return real(src, dst)

    monkeypatch.setattr(output.os, "replace", replace)
    for run in range(2):                                   # the second run moves the first run's a.txt aside
        with OutputDir(folder, command="test") as out:
            for name in ("a.txt", "b.txt"):
                with out.file(name) as tmp:
                    tmp.write_text(f"{name} {run}")
            out.complete = True
    assert seen == [("a.txt", True, False), ("b.txt", True, False)] * 2
    assert (folder / "a.txt").read_text() == "a.txt 1"

    def failing(src, dst):
        if Path(src).name.startswith(TMP_PREFIX) and Path(dst).name != MANIFEST:
            raise OSError(28, "No space left on device")
        return real(src, dst)

    monkeypatch.setattr(output.os, "replace", failing)
    with pytest.raises(Exception):
        with OutputDir(tmp_path / "full", command="test") as out:
            with out.file("c.txt") as tmp:
                tmp.write_text("c")
    doc = json.loads((tmp_path / "full" / MANIFEST).read_text()) if (tmp_path / "full" / MANIFEST).exists() else {}
    assert "c.txt" not in doc.get("files", [])
