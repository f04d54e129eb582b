"""The compiled lifting kernels are served by numba's on-disk cache in every new process.

As closures inside a factory they could not be: the cache index key hashes the closure cells, which
differ in every process, so each ``fogdrift`` run compiled them again (4-8 s) and wrote a new cache
file.  Checked here as rules: no kernel is a closure, each has a disk cache, and a second fresh
process that runs every kernel (fused and step-by-step, both modes) loads all of them and saves none.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from fogdrift.lifting import _kernels, _numba

KERNELS = ("step", "split", "merge", "fwd_blocks", "inv_blocks", "fwd_blocks_serial", "inv_blocks_serial", "fwd_block",
           "inv_block", "apply_steps_local", "step_local", "bmap")

_RUN_ALL = """
import numpy as np
from fogdrift import lifting as L
x = np.random.default_rng(0).standard_normal(70000)
for mode in L.MODES:
    L.separate(x, "db2", 4, mode)          # fused block kernels, parallel at level 1, serial further down
    L.separate(x[:500], "db4", 3, mode)    # step / split / merge kernels
"""


@pytest.mark.parametrize("name", KERNELS)
def test_kernel_is_module_level_and_disk_cached(name):
    disp = getattr(_numba, name)
    assert disp.py_func.__closure__ is None, f"{name} closes over variables: numba cannot reuse its cache"
    assert type(disp._cache).__name__ == "FunctionCache", f"{name} has no disk cache"


def test_factory_returns_the_module_level_kernels():
    assert _kernels._numba_kernels() == (_numba.step, _numba.split, _numba.merge, _numba.fwd_blocks,
                                         _numba.inv_blocks, _numba.fwd_blocks_serial, _numba.inv_blocks_serial)


def test_second_process_loads_every_kernel_and_compiles_none():
    env = dict(os.environ, NUMBA_DEBUG_CACHE="1")
    logs = [
        subprocess.run([sys.executable, "-c", _RUN_ALL], env=env, capture_output=True, text=True, check=True).stdout
        for _ in range(2)
    ]
    mine = [line for line in logs[1].splitlines() if "lifting" in line and "_numba." in line]
    loaded = {line.split("_numba.")[1].split("-")[0] for line in mine if line.startswith("[cache] data loaded")}
    assert {"step", "split", "merge", "fwd_blocks", "inv_blocks", "fwd_blocks_serial", "inv_blocks_serial"} <= loaded, \
        logs[1]
    assert not [line for line in mine if "saved" in line], logs[1]


@pytest.mark.parametrize("mode", ["periodization", "symmetric"])
@pytest.mark.parametrize("n", [2048, 40_001, 70_000])
def test_serial_and_parallel_block_drivers_are_bit_identical(monkeypatch, n, mode):
    # the same blocks and arithmetic in both drivers: which one runs must not change a single bit
    from fogdrift import lifting as L
    from fogdrift.lifting import _drift

    x = np.random.default_rng(n).standard_normal(n)
    scheme = L.get_wavelet("db4")
    out = {}
    for name, min_blocks in (("parallel", 0), ("serial", 10**9)):
        monkeypatch.setattr(_drift, "_PARALLEL_MIN_BLOCKS", min_blocks)
        drift, noise = np.empty(n), np.empty(n)
        _drift._fused_drift(x, scheme, 5, mode == "periodization", drift, noise)
        out[name] = drift, noise
    np.testing.assert_array_equal(out["parallel"][0], out["serial"][0])
    np.testing.assert_array_equal(out["parallel"][1], out["serial"][1])
    ref = _drift._drift_ref(x, scheme, 5, mode == "periodization")
    np.testing.assert_allclose(out["serial"][0], ref, rtol=0, atol=1e-13 * max(1.0, np.abs(ref).max()))
