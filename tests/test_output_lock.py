"""One run per output folder at a time, a lock that a crashed run does not leave stuck, and inputs never replaced
by outputs (fogdrift.output)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import time

import pytest

from fogdrift.errors import ConfigError
from fogdrift.output import LOCK, MANIFEST, OutputDir

# A run that writes three files tagged with its name, holding the folder between the first and the others until
# the file `release` appears (so that two runs started together really overlap; a hang guard of 60 s only).
RUN = textwrap.dedent("""
    import os, sys, time
    from pathlib import Path
    from fogdrift.errors import ConfigError
    from fogdrift.output import OutputDir
    out, tag, release = Path(sys.argv[1]), sys.argv[2], Path(sys.argv[3])
    try:
        with OutputDir(out, command="allan") as od:
            with od.file("allan.json") as tmp:
                tmp.write_text(tag)
            Path(str(release) + "." + tag).write_text("holding")
            deadline = time.monotonic() + 60
            while not release.exists() and time.monotonic() < deadline:
                time.sleep(0.01)
            for name in ("allan.csv", "allan.png"):
                with od.file(name) as tmp:
                    tmp.write_text(tag)
    except ConfigError as exc:
        print(str(exc), file=sys.stderr)
        sys.exit(1)
""")


def _start(out, tag, release):
    return subprocess.Popen([sys.executable, "-c", RUN, str(out), tag, str(release)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


@pytest.mark.parametrize("exists", [True, False])
def test_two_runs_into_one_folder_one_refuses_naming_the_other(tmp_path, exists):
    refused = 0
    for trial in range(10):
        out = tmp_path / f"out{trial}"
        if exists:
            out.mkdir()
        release = tmp_path / f"release{trial}"
        procs = {tag: _start(out, tag, release) for tag in ("A", "B")}
        holding = lambda: [t for t in procs if (tmp_path / f"release{trial}.{t}").exists()]  # noqa: E731
        deadline = time.monotonic() + 60  # hang guard only
        while not holding() and all(p.poll() is None for p in procs.values()) and time.monotonic() < deadline:
            time.sleep(0.005)
        # whichever holds the folder waits for `release`: the other, started at the same time, must be refused
        for tag, p in procs.items():
            if tag not in holding():
                p.wait(timeout=60)
        release.write_text("go")
        for p in procs.values():
            p.wait(timeout=60)
        codes = {tag: p.returncode for tag, p in procs.items()}
        assert sorted(codes.values()) == [0, 1], (codes, {t: p.stderr.read() for t, p in procs.items()})
        winner = next(t for t, c in codes.items() if c == 0)
        loser = next(t for t, c in codes.items() if c == 1)
        err = procs[loser].stderr.read()
        assert f"'fogdrift allan' (process {procs[winner].pid}, started" in err and "is writing there now" in err
        # nothing mixed: every file is the winner's, the manifest is complete, the lock is gone
        assert {n: (out / n).read_text() for n in ("allan.json", "allan.csv", "allan.png")} == \
            dict.fromkeys(("allan.json", "allan.csv", "allan.png"), winner)
        assert json.loads((out / MANIFEST).read_text())["complete"] is True
        assert not (out / LOCK).exists()
        refused += 1
    assert refused == 10


def test_a_killed_run_does_not_leave_the_folder_locked(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    code = ("import os, sys; from fogdrift.output import OutputDir\n"
            "od = OutputDir(sys.argv[1], command='allan').__enter__()\n"
            "with od.file('a.txt') as t: t.write_text('x')\n"
            "os.kill(os.getpid(), 9)\n")
    proc = subprocess.run([sys.executable, "-c", code, str(out)], capture_output=True, timeout=60)
    assert proc.returncode == -9 and (out / LOCK).exists()  # the file stays, the lock died with the process
    with OutputDir(out, command="allan") as od:
        with od.file("a.txt") as tmp:
            tmp.write_text("y")
    assert (out / "a.txt").read_text() == "y" and not (out / LOCK).exists()


def test_the_watchdogs_exit_leaves_no_lock_file_of_any_folder_of_the_run(tmp_path):
    # the CLI's watchdog ends a run that did not stop in time with os._exit: the kernel drops the locks, but the
    # lock files stayed (a batch's folder and the file's folder inside it: issue 36); every active folder's goes
    code = ("import sys; from pathlib import Path; from fogdrift.output import OutputDir; from fogdrift.cli import _app\n"
            "root = Path(sys.argv[1])\n"
            "batch = OutputDir(root, command='batch allan').__enter__()\n"
            "with batch.file('started.txt') as t: t.write_text('1')\n"
            "one = OutputDir(root / 'a.npy', command='batch allan', create_parents=True).__enter__()\n"
            "with one.file('allan.json') as t: t.write_text('{}')\n"
            "writing = one.file('allan.csv')\n"
            "writing.__enter__().write_text('half of it')\n"
            "assert (root / %r).exists() and (root / 'a.npy' / %r).exists()\n"
            "_app.emergency_exit()\n") % (LOCK, LOCK)
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-c", code, str(out)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 130, proc.stderr
    assert proc.stderr.startswith("interrupted: wrote 1 complete file(s) to "), proc.stderr
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*")) == [
        MANIFEST, "a.npy", f"a.npy/{MANIFEST}", "a.npy/allan.json", "started.txt"]  # no lock, no temporary file


def test_a_second_run_in_the_same_process_is_refused_and_the_first_finishes(tmp_path):
    with OutputDir(tmp_path, command="allan") as first:
        with pytest.raises(ConfigError, match=rf"'fogdrift allan' \(process {os.getpid()}, started .*is writing"):
            with OutputDir(tmp_path, command="noise"):
                pass
        with first.file("x.txt") as tmp:
            tmp.write_text("1")
    with OutputDir(tmp_path, command="noise") as second:  # free again
        with second.file("y.txt") as tmp:
            tmp.write_text("2")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([MANIFEST, "y.txt"])


def test_an_output_never_replaces_an_input(tmp_path):
    log = tmp_path / "allan.csv"
    log.write_text("t_s,gz\n0,1\n")
    with OutputDir(tmp_path, command="allan", protect=[log]) as od:
        with pytest.raises(ConfigError, match="would replace the input file"):
            with od.file("allan.csv") as tmp:
                tmp.write_text("output")
        with od.file("allan.json") as tmp:
            tmp.write_text("{}")
    assert log.read_text() == "t_s,gz\n0,1\n"
    # the same input reached through a symbolic link to it is protected too
    link = tmp_path / "link.csv"
    link.symlink_to(log)
    with OutputDir(tmp_path, command="allan", protect=[link]) as od:
        with pytest.raises(ConfigError, match="would replace the input file"):
            with od.file("allan.csv") as tmp:
                tmp.write_text("output")
    assert log.read_text() == "t_s,gz\n0,1\n"
