"""Benchmark: ``fogdrift batch`` (allan) over generated logs, local Dask cluster against a serial loop.

Generates ``--files`` seeded CSV logs (default 20) of ``--samples`` samples (default 10^6) at 100 Hz with
three axes (white + random-walk rate noise, deg/h), then runs in the same process, one after the other:

* ``serial`` - ``run_batch(..., scheduler="serial")``: the files one after the other in this process
  (numba's own threads still parallelise the Allan kernel inside each file);
* ``dask``   - ``run_batch(..., workers=N)``: a local cluster of N worker processes (default: the cores),
  each single-threaded, cluster start-up included;
* ``running`` - the same on a cluster started (and warmed up on two files) beforehand, as with
  ``--scheduler``: the compute alone;

into separate output folders (no skipping), checks that both summaries hold the same numbers, and prints
the wall times and the speed-up with the machine's description and load.

Usage::

    python bench/bench_fleet.py [--files 20] [--samples 1e6] [--workers 2] [--dir /tmp/fogdrift_fleet]
    python bench/bench_fleet.py --adis [--rounds 3]

``--adis``: ``fogdrift batch`` (the command line, one process per run) on the five ADIS16405 sessions
(``/work/shared/data/adis16405_static/adis16405_imu{1..5}.csv.gz --unit deg/s``), the default scheduler against
``--scheduler serial`` and ``--scheduler local`` (the default before issue 35), in alternating order each round,
the load average printed with every run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import sys
import time
from pathlib import Path

import numpy as np


def _machine() -> dict:
    cpu = ""
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    mem = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    return {"cpu": cpu, "cores": os.cpu_count(), "memory_gib": round(mem, 1), "python": platform.python_version(),
            "loadavg_1_5_15": os.getloadavg()}


def _generate(folder: Path, files: int, samples: int) -> list[Path]:
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for k in range(files):
        rng = np.random.default_rng(1000 + k)
        rate = rng.normal(scale=5.0, size=(samples, 3)) + np.cumsum(rng.normal(scale=0.01, size=(samples, 3)), axis=0)
        t = np.arange(samples) / 100.0
        p = folder / f"unit{k:02d}.csv"
        np.savetxt(p, np.column_stack([t, rate]), delimiter=",", header="t_s,gx[deg/h],gy[deg/h],gz[deg/h]", comments="",
                   fmt="%.9g")
        out.append(p)
    return out


ADIS = [f"/work/shared/data/adis16405_static/adis16405_imu{k}.csv.gz" for k in range(1, 6)]


def _adis(rounds: int, root: Path) -> int:
    """The default scheduler against serial and local on the five ADIS sessions, through the command line."""
    import subprocess

    print("machine:", json.dumps(_machine()), flush=True)
    runs = {"default": [], "serial": ["--scheduler", "serial"], "local": ["--scheduler", "local"]}
    times: dict[str, list[float]] = {k: [] for k in runs}
    names = list(runs)
    for r in range(rounds):
        order = names[r % 3:] + names[:r % 3]
        for name in order:
            out = root / f"{name}{r}"
            load = os.getloadavg()[0]
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-m", "fogdrift", "batch", *ADIS, "--unit", "deg/s", *runs[name],
                                   "--out", str(out)], capture_output=True, text=True)
            wall = time.perf_counter() - t0
            line = next((ln for ln in proc.stdout.splitlines() if " files on " in ln), proc.stderr[-300:])
            times[name].append(wall)
            print(f"round {r + 1} {name:8s} {wall:6.1f} s  load {load:.2f}->{os.getloadavg()[0]:.2f}  rc "
                  f"{proc.returncode}  {line}", flush=True)
            shutil.rmtree(out, ignore_errors=True)
    print("\n| scheduler | runs [s] | median [s] |\n| --- | --- | --- |")
    for name, ts in times.items():
        print(f"| {name} | {' / '.join(f'{t:.1f}' for t in ts)} | {sorted(ts)[len(ts) // 2]:.1f} |")
    ratios = [d / s for d, s in zip(times["default"], times["serial"])]
    print(f"\ndefault / serial per round: {' '.join(f'{x:.2f}' for x in ratios)}; local / serial: "
          f"{' '.join(f'{l / s:.2f}' for l, s in zip(times['local'], times['serial']))}; load after: {os.getloadavg()}")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--adis", action="store_true", help="the five ADIS sessions: default vs serial vs local")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--files", type=int, default=20)
    ap.add_argument("--samples", type=float, default=1e6)
    ap.add_argument("--workers", type=int, default=os.cpu_count())
    ap.add_argument("--dir", default="/tmp/fogdrift_fleet")
    ap.add_argument("--json")
    args = ap.parse_args()
    root = Path(args.dir)
    shutil.rmtree(root, ignore_errors=True)
    if args.adis:
        return _adis(args.rounds, root)
    from fogdrift.fleet import run_batch

    t0 = time.perf_counter()
    files = _generate(root / "logs", args.files, int(args.samples))
    print(f"generated {len(files)} logs of {int(args.samples)} samples x 3 axes in {time.perf_counter() - t0:.1f} s",
          flush=True)
    print("machine:", json.dumps(_machine()), flush=True)
    # warm-up: numba compilation / cache load in this process (the serial loop), excluded from the timing
    run_batch(files[:1], root / "warm", scheduler="serial", page=False)
    t0 = time.perf_counter()
    serial = run_batch(files, root / "serial", scheduler="serial")
    t_serial = time.perf_counter() - t0
    t0 = time.perf_counter()
    dask = run_batch(files, root / "dask", workers=args.workers)
    t_dask = time.perf_counter() - t0
    # the same on a cluster started beforehand (as with --scheduler): the compute without the start-up
    from distributed import LocalCluster

    from fogdrift.fleet.runner import _worker_env

    t0 = time.perf_counter()
    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None, env=_worker_env(args.workers)) as cluster:
        t_start = time.perf_counter() - t0
        run_batch(files[:2], root / "warm2", scheduler=cluster.scheduler_address, page=False)   # workers' numba
        t0 = time.perf_counter()
        run_batch(files, root / "dask2", scheduler=cluster.scheduler_address)
        t_running = time.perf_counter() - t0
    key = [(r["file"], r["axis"]) for r in serial.rows]
    same = all(a["N_dprh"] == b["N_dprh"] and a["file"] == b["file"] for a, b in zip(serial.rows, dask.rows))
    print("\n| run | files | wall [s] | per file [s] |\n| --- | --- | --- | --- |")
    print(f"| serial loop (in process) | {len(files)} | {t_serial:.1f} | {t_serial / len(files):.2f} |")
    print(f"| {dask.scheduler} (start-up included) | {len(files)} | {t_dask:.1f} | {t_dask / len(files):.2f} |")
    print(f"| running cluster of {args.workers} workers (started in {t_start:.1f} s, warmed up) | {len(files)} | "
          f"{t_running:.1f} | {t_running / len(files):.2f} |")
    print(f"\nspeed-up serial / dask: {t_serial / t_dask:.2f}x with start-up, {t_serial / t_running:.2f}x on a running "
          f"cluster (target >= 1.7x on 2 cores); "
          f"same N in both summaries: {same} ({len(key)} rows); load after: {os.getloadavg()}")
    if args.json:
        Path(args.json).write_text(json.dumps({"machine": _machine(), "serial_s": t_serial, "dask_s": t_dask,
                                               "dask_running_s": t_running, "speedup": t_serial / t_dask,
                                               "speedup_running": t_serial / t_running, "same": same}, indent=1))
    shutil.rmtree(root, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
