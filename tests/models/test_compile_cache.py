"""``fogdrift.models.compile_cache``: the networks' XLA programs kept on disk between processes, the same numbers
from a cached program as from a fresh compile, and the user's own JAX cache setting left alone."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from fogdrift.models.compile_cache import ENV, cache_dir, host_tag

SCRIPT = """
import json, numpy as np
from fogdrift.models.elman import Elman
y = np.sin(np.arange(300) / 9.0) + np.random.default_rng(3).normal(0, 0.05, 300)
m = Elman(lags=3, hidden=4, epochs=15, patience=5, seed=1).fit(y[:200])
print(json.dumps([float(v) for v in m.predict(y[200:])]))
"""


def _run(env_extra: dict, tmp_path: Path):
    env = {k: v for k, v in os.environ.items() if k not in (ENV, "JAX_COMPILATION_CACHE_DIR")}
    env.update(env_extra, PYTHONPATH=str(Path(__file__).resolve().parents[2] / "src"))
    r = subprocess.run([sys.executable, "-c", SCRIPT], env=env, cwd=tmp_path, capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    line = r.stdout.strip().splitlines()[-1]
    assert len(json.loads(line)) == 100
    return line  # the predictions' reprs: equal texts are equal bits


def test_cache_dir_rules(monkeypatch, tmp_path):
    tag = host_tag()
    assert cache_dir({ENV: str(tmp_path)}) == tmp_path / tag
    assert cache_dir({ENV: ""}) is None and cache_dir({ENV: " 0 "}) is None
    assert cache_dir({"XDG_CACHE_HOME": str(tmp_path)}) == tmp_path / "fogdrift" / "jax" / tag
    monkeypatch.setenv("HOME", str(tmp_path))
    assert cache_dir({}) == tmp_path / ".cache" / "fogdrift" / "jax" / tag


def test_each_processor_has_its_own_folder():
    """Programs compiled for one processor's instruction set are never offered to another one."""
    epyc = "processor : 0\nmodel name : AMD EPYC\nflags : fpu sse2 avx2 avx512f\n"
    assert host_tag(epyc) == host_tag(epyc + epyc.replace("processor : 0", "processor : 1"))  # one tag per machine
    assert host_tag(epyc) != host_tag(epyc.replace(" avx512f", ""))  # another feature set
    assert host_tag(epyc) != host_tag(epyc.replace("AMD EPYC", "Intel Xeon"))  # another model
    assert host_tag(epyc) == host_tag(epyc.replace("processor : 0", "processor : 7"))  # not the core's number


@pytest.mark.slow
def test_a_second_process_loads_the_programs_and_predicts_the_same_bits(tmp_path):
    root = tmp_path / "cache"
    folder = root / host_tag()
    cold = _run({ENV: str(root)}, tmp_path)
    written = sorted(p.name for p in folder.iterdir())
    assert any("forward" in n for n in written), written  # the network's forward pass among the programs kept
    assert ".lockfile" in written  # a bounded cache: JAX reads and writes its entries under a file lock
    warm = _run({ENV: str(root)}, tmp_path)
    assert warm == cold
    off = _run({ENV: "0", "XDG_CACHE_HOME": str(tmp_path / "xdg")}, tmp_path)
    assert off == cold and not (tmp_path / "xdg").exists()


@pytest.mark.slow
def test_the_users_own_jax_cache_is_kept(tmp_path):
    mine, ours = tmp_path / "mine", tmp_path / "ours"
    _run({"JAX_COMPILATION_CACHE_DIR": str(mine), "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS": "0", ENV: str(ours)},
         tmp_path)
    assert not ours.exists() and mine.is_dir() and any(mine.iterdir())
