"""Benchmark: whole commands end to end (new processes, warm disk and numba caches), against issue 25's targets.

Each command runs in its own process under ``/usr/bin/time`` (wall time and peak RSS); the numba caches are
warmed by one small ``allan`` run first.  Rows:

* ``allan`` on a 10^7-sample float64 ``.npy`` (--taus 100, deg/h, 100 Hz) **beside allantools**: a process
  that loads the same file and calls ``allantools.oadev(y, rate=100, data_type="freq", taus=<fogdrift's taus>)``
  (its in-process call time is printed too); the ratio is the allantools process's wall time over fogdrift's.
* ``allan``, ``noise``, ``analyze`` on ADIS16405 session 1 (``--unit deg/s``, 10^6 samples x 3 axes);
  ``compensate`` of session 2 with the bundle analyze wrote; ``make demo``'s analyze on the bundled RLG.
* reading the ADIS16405 session 1 CSV.gz (10^6 rows x 4 columns) with ``fogdrift.io.load`` (in process,
  imports excluded).

``--quick``: 10^6 samples for the allantools row, and no analyze / compensate / demo rows.

Usage::

    python bench/bench_cli.py [--quick] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
ADIS = Path(os.environ.get("FOGDRIFT_ADIS", ROOT.parent / "shared/data/adis16405_static"))
RLG = ROOT / "data/psins_lasergyro_rlg/psins_lasergyro_rlg.csv.gz"
DEMO_ARGS = ["--unit", "deg/h", "--train-fraction", "0.4", "--val-fraction", "0.1", "--calibration", "150",
             "--origin-step", "30", "--horizons", "30,60"]
#: Issue 25's targets [s] (end to end, warm caches).
TARGETS = {"allan": 3.0, "noise": 8.0, "compensate": 20.0, "analyze": 60.0, "demo": 20.0, "csv.gz read": 1.0}

ALLANTOOLS_CHILD = """
import sys, time, json
t0 = time.perf_counter()
import numpy as np, allantools
y = np.load(sys.argv[1]); taus = np.load(sys.argv[2])
t1 = time.perf_counter()
allantools.oadev(y, rate=100.0, data_type="freq", taus=taus)
print(json.dumps({"call_s": time.perf_counter() - t1, "import_load_s": t1 - t0}))
"""

READ_CHILD = """
import sys, time, json
from fogdrift.io import load
t0 = time.perf_counter()
rec = load(sys.argv[1], unit="deg/s")
print(json.dumps({"read_s": time.perf_counter() - t0, "shape": list(rec.rate_dph.shape)}))
"""


def _timed(cmd, env=None) -> dict:
    """Run ``cmd`` under /usr/bin/time; wall [s], peak RSS [MB], return code and the last stdout line."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as tf:
        t0 = time.perf_counter()
        proc = subprocess.run(["/usr/bin/time", "-f", "%e %M", "-o", tf.name, *cmd], capture_output=True, text=True,
                              env=env)
        wall = time.perf_counter() - t0
        text = Path(tf.name).read_text().split()
    rss = float(text[-1]) / 1024.0 if text else float("nan")
    last = proc.stdout.strip().splitlines()[-1] if proc.stdout.strip() else ""
    if proc.returncode:
        print(f"  exit {proc.returncode}: {' '.join(map(str, cmd))}\n{proc.stderr[-2000:]}", file=sys.stderr)
    return {"wall_s": wall, "peak_rss_mb": rss, "rc": proc.returncode, "stdout_last": last}


def _fogdrift(*args) -> list:
    return [sys.executable, "-m", "fogdrift", *map(str, args)]


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="10^6 samples beside allantools; no analyze/compensate/demo")
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    from fogdrift.allan import tau_grid

    rows = []
    env = {**os.environ, "COLUMNS": "100"}
    with tempfile.TemporaryDirectory(prefix="fogdrift-bench-cli-") as tmp:
        tmp = Path(tmp)
        n = 10**6 if args.quick else 10**7
        rng = np.random.default_rng(12345)
        y = rng.standard_normal(n) + 1e-3 * np.cumsum(rng.standard_normal(n)) + 10.0
        np.save(tmp / "y.npy", y)
        m = tau_grid(n, 0.01, 100)
        np.save(tmp / "taus.npy", m * 0.01)
        del y
        _timed(_fogdrift("allan", tmp / "y.npy", "--rate", 100, "--unit", "deg/h", "--taus", 20, "--out",
                         tmp / "warm"), env)                                      # numba caches
        fd = _timed(_fogdrift("allan", tmp / "y.npy", "--rate", 100, "--unit", "deg/h", "--taus", 100, "--out",
                              tmp / "a1"), env)
        at = _timed([sys.executable, "-c", ALLANTOOLS_CHILD, str(tmp / "y.npy"), str(tmp / "taus.npy")], env)
        call = json.loads(at["stdout_last"]) if at["stdout_last"].startswith("{") else {}
        rows.append(dict(case=f"allan {n:.0e} .npy, {m.size} tau (whole command)", fogdrift_s=fd["wall_s"], rc=fd["rc"] or at["rc"],
                         rss_mb=fd["peak_rss_mb"], peer="allantools oadev (process: import, load, call)",
                         peer_s=at["wall_s"], ratio=at["wall_s"] / fd["wall_s"], target="ratio >= 5",
                         met=at["wall_s"] / fd["wall_s"] >= 5,
                         note=f"allantools call alone {call.get('call_s', float('nan')):.2f} s"))
        imu1, imu2 = ADIS / "adis16405_imu1.csv.gz", ADIS / "adis16405_imu2.csv.gz"
        if imu1.exists():
            rd = _timed([sys.executable, "-c", READ_CHILD, str(imu1)], env)
            read_s = json.loads(rd["stdout_last"])["read_s"] if rd["stdout_last"].startswith("{") else float("nan")
            rows.append(dict(case="csv.gz read, ADIS imu1 (10^6 x 4)", fogdrift_s=read_s, rss_mb=rd["peak_rss_mb"],
                             target=f"<= {TARGETS['csv.gz read']} s", met=read_s <= TARGETS["csv.gz read"]))
            for name in ("allan", "noise"):
                r = _timed(_fogdrift(name, imu1, "--unit", "deg/s", "--out", tmp / name), env)
                rows.append(dict(case=f"{name}, ADIS imu1 (3 x 10^6)", fogdrift_s=r["wall_s"], rss_mb=r["peak_rss_mb"], rc=r["rc"],
                                 target=f"<= {TARGETS[name]} s", met=r["rc"] == 0 and r["wall_s"] <= TARGETS[name]))
            if not args.quick:
                r = _timed(_fogdrift("analyze", imu1, "--unit", "deg/s", "--out", tmp / "an"), env)
                rows.append(dict(case="analyze, ADIS imu1 (3 x 10^6)", fogdrift_s=r["wall_s"], rss_mb=r["peak_rss_mb"], rc=r["rc"],
                                 target=f"<= {TARGETS['analyze']} s", met=r["rc"] == 0 and r["wall_s"] <= 60))
                if imu2.exists() and (tmp / "an" / "bundle").exists():
                    r = _timed(_fogdrift("compensate", tmp / "an" / "bundle", imu2, "--unit", "deg/s", "--out", tmp / "comp"), env)
                    rows.append(dict(case="compensate, ADIS imu2 with imu1's bundle", fogdrift_s=r["wall_s"], rc=r["rc"],
                                     rss_mb=r["peak_rss_mb"], target=f"<= {TARGETS['compensate']} s",
                                     met=r["rc"] == 0 and r["wall_s"] <= TARGETS["compensate"]))
        if not args.quick and RLG.exists():
            r = _timed(_fogdrift("analyze", RLG, *DEMO_ARGS, "--out", tmp / "demo"), env)
            rows.append(dict(case="make demo (analyze, bundled RLG)", fogdrift_s=r["wall_s"], rss_mb=r["peak_rss_mb"], rc=r["rc"],
                             target=f"<= {TARGETS['demo']} s", met=r["rc"] == 0 and r["wall_s"] <= TARGETS["demo"]))
    load = os.getloadavg()
    print(f"load average after: {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}; {os.cpu_count()} cores\n")
    print("| case | fogdrift wall s | peak RSS MB | peer | peer s | ratio | target | met | note |")
    print("|---|---:|---:|---|---:|---:|---|---|---|")
    for r in rows:
        if r.get("rc"):
            r["note"] = (r.get("note", "") + f" FAILED: exit {r['rc']}").strip()
        ratio = f"{r['ratio']:.1f}x" if r.get("ratio") else "-"
        peer_s = f"{r['peer_s']:.2f}" if r.get("peer_s") else "-"
        print(f"| {r['case']} | {r['fogdrift_s']:.2f} | {r['rss_mb']:.0f} | {r.get('peer', '-')} | {peer_s} | "
              f"{ratio} | {r['target']} | {'yes' if r['met'] else 'NO'} | {r.get('note', '')} |")
    if args.json:
        Path(args.json).write_text(json.dumps({"load": load, "rows": rows}, indent=2))
    return rows


if __name__ == "__main__":
    main()
