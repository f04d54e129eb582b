"""Benchmark: ``fogdrift compensate`` on large ``.npy`` logs, peak memory and wall time.

For each size the script writes a seeded one-axis float64 ``.npy`` log at 100 Hz in deg/h (white + random-walk
rate, streamed to disk in pieces so the generator itself stays small), builds a small bundle from a separate
simulated 2-h record at the same rate (models AR(4), Kalman and persistence; modelling rate 1 Hz), then runs
``compensate_file(bundle, log, out, model=..., formats=("npz",), heading=False)`` **in a fresh process** and
reports that process's peak resident set size (``ru_maxrss``, which counts every page the process touched,
file-backed pages included) and wall time.  The log is read from the file chunk by chunk and the NPZ written
row block by row block, so the peak should not grow with the size.

Usage::

    python bench/bench_compensate.py --sizes 1e6,1e7,1e8 [--model kalman] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

CHILD = r"""
import resource, sys, time, json
from fogdrift.compensate import compensate_file
t0 = time.perf_counter()
res = compensate_file(sys.argv[1], sys.argv[2], sys.argv[3], model=sys.argv[4], formats=("npz",), heading=False,
                      rate_hz=100.0, unit="deg/h")
wall = time.perf_counter() - t0
print(json.dumps({"wall_s": wall, "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
                  "n": res.summary["n_samples"]}))
"""


def write_log(path: Path, n: int, seed: int = 0) -> None:
    """n samples of white (6 deg/h per 10-ms sample) + random walk + 3 deg/h, written 10^7 at a time."""
    rng = np.random.default_rng(seed)
    with open(path, "wb") as fh:
        np.lib.format.write_array_header_1_0(fh, {"descr": "<f8", "fortran_order": False, "shape": (n,)})
        level = 3.0
        for lo in range(0, n, 10_000_000):
            k = min(10_000_000, n - lo)
            walk = level + np.cumsum(rng.normal(0.0, 1e-3, k))
            level = walk[-1]
            fh.write((walk + rng.normal(0.0, 6.0, k)).astype("<f8").tobytes())


def build_bundle(out: Path) -> None:
    from fogdrift.bundle import write_bundle
    from fogdrift.io import from_array
    from fogdrift.pipeline import AnalysisConfig, run_models
    from fogdrift.simulate import simulate

    rec = from_array(simulate(720_000, 0.01, arw_dprh=0.1, rrw_dphrh=2.0, bias_dph=3.0, seed=1), dt_s=0.01,
                     axis_names=["col0"])
    cfg = AnalysisConfig(models=("ar", "kalman", "persistence"))
    write_bundle(out, run_models(rec, cfg), cfg, rec)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="1e6,1e7")
    ap.add_argument("--model", default="kalman")
    ap.add_argument("--json")
    args = ap.parse_args()
    rows = []
    with tempfile.TemporaryDirectory(prefix="fogdrift-bench-") as tmp:
        tmp = Path(tmp)
        build_bundle(tmp / "bundle")
        for size in (int(float(s)) for s in args.sizes.split(",")):
            log = tmp / f"log_{size}.npy"
            t0 = time.perf_counter()
            write_log(log, size)
            gen = time.perf_counter() - t0
            proc = subprocess.run([sys.executable, "-c", CHILD, str(tmp / "bundle"), str(log), str(tmp / f"out_{size}"),
                                   args.model], capture_output=True, text=True)
            if proc.returncode:
                print(proc.stderr, file=sys.stderr)
                return 1
            res = json.loads(proc.stdout.strip().splitlines()[-1])
            res.update(size=size, file_mb=log.stat().st_size / 1e6, generate_s=gen, model=args.model)
            rows.append(res)
            log.unlink()
            for f in (tmp / f"out_{size}").iterdir():
                f.unlink()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, python "
          f"{platform.python_version()}")
    print("| samples | log file [MB] | model | wall [s] | peak RSS [MB] |")
    print("| ---: | ---: | --- | ---: | ---: |")
    for r in rows:
        print(f"| {r['size']:.0e} | {r['file_mb']:.0f} | {r['model']} | {r['wall_s']:.1f} | {r['peak_rss_mb']:.0f} |")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
