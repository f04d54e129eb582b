"""The console entry point imports a command's module only when that command runs (issue 25, CLI start-up).

``fogdrift allan --help`` used to import every command module, and through ``batch`` the fleet, the noise package
and scipy.  :func:`fogdrift.cli.main` now registers commands lazily; the top-level help still lists every command
with the same help text as the eagerly built application.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

import fogdrift

#: The source tree of the fogdrift under test: a probe imports it, not whatever copy the interpreter has installed
#: (an editable install may point at another checkout).
_SRC = str(Path(fogdrift.__file__).resolve().parents[1])


#: Runs main() with the given argv and prints, as JSON, the exit code, stdout and the fogdrift/scipy modules loaded.
_PROBE = r"""
import io, json, sys, contextlib
argv = json.loads(sys.argv[1])
sys.argv = ["fogdrift", *argv]
from fogdrift.cli import main
buf = io.StringIO()
code = 0
with contextlib.redirect_stdout(buf):
    try:
        main()
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
mods = sorted(m for m in sys.modules if m.startswith(("fogdrift", "scipy")))
import os
blas = {v: os.environ.get(v) for v in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
print(json.dumps({"code": code, "out": buf.getvalue(), "modules": mods, "blas": blas}))
"""


def _probe(*argv, env=None):
    proc = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(list(argv))], capture_output=True, text=True,
                          timeout=300, env={"COLUMNS": "200", "PATH": "/usr/bin:/bin", "PYTHONPATH": _SRC, **(env or {})})
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout.strip().splitlines()[-1]), proc.stderr


def test_allan_help_imports_no_other_command():
    res, _ = _probe("allan", "--help")
    assert res["code"] == 0
    assert "--taus" in res["out"]
    mods = set(res["modules"])
    assert "fogdrift.cli.allan" in mods
    # (cli.allan takes --spec's option from the light cli.noise module: allowed; the heavy imports are not)
    for absent in ("fogdrift.cli.batch", "fogdrift.cli.compensate", "fogdrift.cli.model", "fogdrift.cli.analyze",
                   "fogdrift.fleet", "fogdrift.noise", "fogdrift.gmwm", "scipy"):
        assert absent not in mods, f"{absent} imported by 'fogdrift allan --help'"


def test_noise_help_works_lazily():
    res, _ = _probe("noise", "--help")
    assert res["code"] == 0
    assert "--model" in res["out"]
    assert "fogdrift.cli.batch" not in res["modules"]


def test_top_level_help_lists_every_command_with_its_help():
    from typer.main import get_command

    from fogdrift.cli import COMMAND_MODULES, app

    eager = get_command(app)
    assert set(eager.commands) == set(COMMAND_MODULES)  # a new command must be added to COMMAND_MODULES
    res, _ = _probe("--help")
    assert res["code"] == 0
    lines = res["out"].splitlines()
    listed = lines[lines.index("Commands:") + 1:]
    names = [ln.split()[0] for ln in listed if ln.strip()]
    assert names == list(COMMAND_MODULES)
    for ln in listed:
        if not ln.strip():
            continue
        name, text = ln.split(None, 1)
        short = eager.commands[name].get_short_help_str(limit=len(text))
        assert text.strip() == short.strip(), name


def test_unknown_command_is_a_usage_error():
    res, err = _probe("alan")
    assert res["code"] == 2
    assert "No such command 'alan'" in err


@pytest.mark.parametrize("name", ["batch", "separate"])
def test_lazy_command_matches_the_eager_one(name):
    from typer.main import get_command

    from fogdrift.cli import app

    eager = get_command(app).commands[name]
    res, _ = _probe(name, "--help")
    assert res["code"] == 0
    for param in eager.params:
        for opt in param.opts:
            if opt.startswith("--"):
                assert opt in res["out"], (name, opt)


def test_a_command_runs_blas_on_one_thread_unless_the_user_chose():
    """Issue 35: OpenBLAS's threads thrash on a busy machine (the CLI's matrices are small), so ``main()`` sets
    ``OPENBLAS_NUM_THREADS``/``MKL_NUM_THREADS`` to 1 before NumPy loads; a count the user set is kept."""
    res, _ = _probe("allan", "--help")
    assert res["blas"] == {"OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    res, _ = _probe("allan", "--help", env={"OPENBLAS_NUM_THREADS": "3"})
    assert res["blas"]["OPENBLAS_NUM_THREADS"] == "3"


def test_one_blas_thread_changes_nothing_once_numpy_is_loaded(monkeypatch):
    """Called in a process that already imported NumPy (a test, a notebook) it cannot act, so it leaves the
    environment (what child processes inherit) alone."""
    import numpy  # noqa: F401

    from fogdrift.cli import BLAS_THREAD_VARS, one_blas_thread

    for var in BLAS_THREAD_VARS:
        monkeypatch.delenv(var, raising=False)
    assert one_blas_thread() is False
    assert all(var not in __import__("os").environ for var in BLAS_THREAD_VARS)
