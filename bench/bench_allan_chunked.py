"""Benchmark: out-of-core Allan variance of 10^9 float32 samples from a file, against the in-memory engine.

Writes a seeded white-noise float32 ``.npy`` of ``--n`` samples (default 10^9, 4 GB) under ``--dir``
(default /tmp), then, each in a fresh process so that peak memory is its own:

* ``chunked`` - ``allan_variance_chunked(open_source(file), taus="octave")`` over the whole file;
* ``in-memory`` - ``allan_variance(np.load(file_1e8), dt, taus="octave")`` on the first ``--n-mem``
  samples (default 10^8) loaded into memory, its wall time scaled by ``n / n_mem`` (the estimator is
  O(N) per tau) for comparison;

and reports wall time, peak resident set size (``VmHWM`` of the child: imports and warm-up included, the
file's pages only while mapped) and, on the 10^8 prefix, that both give the same AVAR.  The big file is deleted at the end (``--keep`` keeps it).

Usage::

    python bench/bench_allan_chunked.py [--n 1e9] [--n-mem 1e8] [--dir /tmp] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

CHILD = r"""
import json, sys, time
import numpy as np

def vm_hwm_mb():
    # peak resident set of this process image (VmHWM; ru_maxrss would include the parent's peak at fork)
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024
    return float("nan")

mode, path, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
from fogdrift.allan import allan_variance
from fogdrift.allan.chunked import allan_variance_chunked
from fogdrift.io.chunked import open_source
# warm-up (numba compilation or cache load) on a small file, excluded from the timing
small = np.random.default_rng(0).normal(size=300_000).astype(np.float32)
np.save(path + ".warm.npy", small)
allan_variance_chunked(open_source(path + ".warm.npy", rate_hz=100.0, unit="deg/h"), chunk_samples=65536)
allan_variance(small, 0.01)
base = vm_hwm_mb()
t0 = time.perf_counter()
if mode == "chunked":
    r = allan_variance_chunked(open_source(path, rate_hz=100.0, unit="deg/h"))
else:
    y = np.load(path, mmap_mode="r")[:n]
    y = np.array(y)            # loaded into memory (float32, as the file)
    r = allan_variance(y, 0.01)
wall = time.perf_counter() - t0
peak = vm_hwm_mb()
print(json.dumps({"mode": mode, "n": n, "wall_s": wall, "peak_rss_mb": peak, "rss_before_mb": base,
                  "avar": r.avar_dph2.tolist(), "taus": len(r.tau_s)}))
"""


def _machine() -> dict:
    cpu = ""
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    mem = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    return {"cpu": cpu, "cores": os.cpu_count(), "memory_gib": round(mem, 1), "python": platform.python_version(),
            "numpy": np.__version__, "loadavg": os.getloadavg()}


def _write(path: Path, n: int, seed: int = 1) -> float:
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    mm = np.lib.format.open_memmap(path, mode="w+", dtype=np.float32, shape=(n,))
    step = 1 << 24
    for a in range(0, n, step):
        b = min(n, a + step)
        mm[a:b] = rng.normal(size=b - a).astype(np.float32)
    mm.flush()
    del mm
    return time.perf_counter() - t0


def _run(mode: str, path: Path, n: int) -> dict:
    out = subprocess.run([sys.executable, "-c", CHILD, mode, str(path), str(n)], capture_output=True, text=True,
                         check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=float, default=1e9)
    ap.add_argument("--n-mem", type=float, default=1e8)
    ap.add_argument("--dir", default="/tmp")
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--json")
    args = ap.parse_args()
    n, n_mem = int(args.n), int(args.n_mem)
    big = Path(args.dir) / f"fogdrift_bench_{n}.npy"
    prefix = Path(args.dir) / f"fogdrift_bench_{n_mem}.npy"
    print("machine:", json.dumps(_machine()), flush=True)
    try:
        print(f"writing {big} ({n * 4 / 1e9:.1f} GB): {_write(big, n):.1f} s", flush=True)
        np.save(prefix, np.load(big, mmap_mode="r")[:n_mem])
        small_chunked = _run("chunked", prefix, n_mem)
        small_mem = _run("memory", prefix, n_mem)
        same = small_chunked["avar"] == small_mem["avar"]
        big_chunked = _run("chunked", big, n)
    finally:
        if not args.keep:
            for p in (big, prefix, Path(str(big) + ".warm.npy"), Path(str(prefix) + ".warm.npy")):
                p.unlink(missing_ok=True)
    scale = n / n_mem
    rows = [
        ("chunked (out-of-core)", n, big_chunked["wall_s"], big_chunked["peak_rss_mb"]),
        ("chunked (out-of-core)", n_mem, small_chunked["wall_s"], small_chunked["peak_rss_mb"]),
        ("in-memory", n_mem, small_mem["wall_s"], small_mem["peak_rss_mb"]),
        (f"in-memory x{scale:g} (scaled)", n, small_mem["wall_s"] * scale, None),
    ]
    print(f"\npeak RSS after imports and warm-up, before the timed call: {big_chunked['rss_before_mb']:.0f} MB")
    print("\n| engine | samples | wall [s] | peak RSS [MB] |\n| --- | --- | --- | --- |")
    for name, size, wall, rss in rows:
        print(f"| {name} | {size:.0e} | {wall:.1f} | {'–' if rss is None else f'{rss:.0f}'} |")
    print(f"\nsame AVAR on the {n_mem:.0e} prefix (bit for bit): {same}; "
          f"taus: {big_chunked['taus']} (octave); in-memory needs ~{(8 * 2 + 4) * n / 1e9:.0f} GB at {n:.0e}")
    if args.json:
        Path(args.json).write_text(json.dumps({"machine": _machine(), "rows": rows, "same_avar": same}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
