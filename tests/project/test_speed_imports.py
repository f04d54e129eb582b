"""What a command imports is part of its start-up time (issue 25: ``fogdrift allan`` >= 3 s on ADIS imu1, of
which ~2 s imports).  GMWM (``fogdrift.gmwm``: its estimator pulls scipy.optimize's least squares, its simulator
scipy.signal, ~0.5 s) is loaded only where a GMWM model is fitted: ``fogdrift noise``, ``analyze --noise-method
gmwm``, ``consistency``, ``batch``.

Each check runs in a fresh interpreter (``sys.modules`` of this process already holds everything).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import fogdrift

#: The source tree of the fogdrift under test: a probe imports it, not whatever copy the interpreter has installed
#: (an editable install may point at another checkout).
_SRC = str(Path(fogdrift.__file__).resolve().parents[1])


#: Runs the code in argv[1], then prints the sorted names of the loaded fogdrift/scipy modules as JSON.
_PROBE = r"""
import json, sys
code = sys.argv[1]
sys.argv = json.loads(sys.argv[2])
try:
    exec(code)
except SystemExit as exc:
    if exc.code not in (0, None):
        raise
print(json.dumps(sorted(m for m in sys.modules if m.startswith(("fogdrift", "scipy")))))
"""


def _modules(code: str, argv=()) -> set:
    proc = subprocess.run([sys.executable, "-c", _PROBE, code, json.dumps(list(argv))], capture_output=True,
                          text=True, timeout=600, env={"COLUMNS": "200", "PATH": "/usr/bin:/bin", "PYTHONPATH": _SRC})
    assert proc.returncode == 0, proc.stderr[-3000:]
    return set(json.loads(proc.stdout.strip().splitlines()[-1]))


def _gmwm(mods) -> list:
    return sorted(m for m in mods if m == "fogdrift.gmwm" or m.startswith("fogdrift.gmwm."))


def test_importing_the_pipeline_loads_no_gmwm():
    mods = _modules("import fogdrift.pipeline")
    assert "fogdrift.pipeline" in mods
    assert _gmwm(mods) == []
    assert "scipy.signal" not in mods  # was imported through gmwm.simulate


def test_importing_the_noise_fit_loads_no_scipy_stats():
    """Issue 35: the noise fit's chi-squared and t quantiles come from scipy.special (noise.distributions), so
    importing the pipeline, the noise package or the Allan noise identification does not load scipy.stats (0.3-0.6 s).
    The spectrum's Welch is written on scipy.fft: scipy.signal (which loads scipy.stats itself) stays out too."""
    mods = _modules("import fogdrift.pipeline, fogdrift.noise.identify, fogdrift.noise.spectral")
    assert "fogdrift.noise.identify" in mods
    assert "scipy.stats" not in mods
    assert "scipy.signal" not in mods


def test_the_gmwm_path_still_loads_it_on_use():
    """``run_analysis(noise_method='gmwm')`` imports GMWM where it is used (the deferred import is reached)."""
    import fogdrift.pipeline as pipeline

    src = open(pipeline.__file__, encoding="utf-8").read()
    assert "from ..gmwm.analysis import analyse_gmwm" in src.split("def run_analysis", 1)[1]
    mods = _modules("import fogdrift.pipeline\nfrom fogdrift.gmwm.analysis import analyse_gmwm")
    assert "fogdrift.gmwm.estimator" in mods
    # GMWM's chi-squared and normal laws come from scipy.special (noise.distributions): no scipy.stats (1.2 s of
    # a `fogdrift noise` profile); least_squares (scipy.optimize) is imported only by the fallback that calls it
    assert "scipy.stats" not in mods


@pytest.fixture(scope="module")
def small_npy(tmp_path_factory):
    path = tmp_path_factory.mktemp("speed-imports") / "y.npy"
    np.save(path, np.random.default_rng(3).standard_normal(4096))
    return path


def test_allan_command_loads_no_gmwm(small_npy, tmp_path):
    argv = ["fogdrift", "allan", str(small_npy), "--rate", "100", "--unit", "deg/h", "--out", str(tmp_path / "a")]
    mods = _modules("from fogdrift.cli import main\nmain()", argv)
    assert "fogdrift.cli.allan" in mods
    assert _gmwm(mods) == []
    # the command reads the spectrum (noise.spectral's Welch on scipy.fft) without scipy.signal's 0.9 s of imports
    assert "fogdrift.noise.spectral" in mods and "scipy.fft" in mods
    assert "scipy.signal" not in mods and "scipy.stats" not in mods


def test_run_freezes_the_imported_objects_only_while_the_command_runs(tmp_path):
    """cli._app.run freezes the objects that exist when a command starts out of the cyclic GC (full collections
    during the command skip the imported modules) and unfreezes them when it ends, normally or on an error."""
    import gc
    from pathlib import Path

    import typer

    from fogdrift.cli._app import run
    from fogdrift.errors import ConfigError

    gc.unfreeze()
    with run("allan", tmp_path / "a", default_out=Path("out/allan")):
        assert gc.get_freeze_count() > 1000
        garbage = []
        garbage.append(garbage)  # a cycle made during the command is still collected there
        del garbage
        assert gc.collect() >= 1
    assert gc.get_freeze_count() == 0
    with pytest.raises(typer.Exit):
        with run("allan", tmp_path / "b", default_out=Path("out/allan")):
            raise ConfigError("bad setting")
    assert gc.get_freeze_count() == 0


def test_the_allan_workflow_and_its_cli_load_no_html_report():
    """``fogdrift allan`` writes its JSON, CSV and PNG without the HTML report's module (report.html, with the
    evaluation verdicts and the report's sections); ``fogdrift.report.write_report`` still imports it on use."""
    mods = _modules("import fogdrift.workflows.allan, fogdrift.cli.allan")
    assert "fogdrift.report.files" in mods
    assert "fogdrift.report.html" not in mods and "fogdrift.evaluation" not in mods
    mods = _modules("from fogdrift.report import write_report\nassert write_report.__module__ == 'fogdrift.report.html'")
    assert "fogdrift.report.html" in mods
