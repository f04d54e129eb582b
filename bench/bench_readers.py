"""Benchmark: read speed of every fogdrift reader against the library's own bulk read of the same file.

For each format the script writes the same seeded data (``--samples`` samples x 3 axes, 100 Hz; bags and
miniSEED as the format stores them) with the format's own library, then times, best of ``--repeat``:

* ``fogdrift``: ``fogdrift.io.load(path, ...)`` -> GyroRecord in deg/h (parsing, checks, unit conversion,
  SHA-256 of the file);
* ``library``: the library's plain bulk read of the same numbers (``np.load``, ``np.fromfile``,
  ``np.loadtxt``, ``h5py`` slice, ``scipy.io.loadmat``, ``obspy.read``, rosbags iterate + deserialize).

MB/s is file size / wall time.  Bags hold ``--bag-messages`` Imu messages (default 2 * 10^5).

Usage::

    python bench/bench_readers.py [--samples 1e6] [--bag-messages 2e5] [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def _best(fn, repeat):
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _machine() -> dict:
    cpu = ""
    try:
        cpu = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(), "numpy": np.__version__,
            "loadavg": os.getloadavg()}


def _cases(d: Path, n: int, n_bag: int):
    """(name, path, fogdrift load kwargs, library read callable) for every format."""
    import h5py
    import scipy.io as sio

    from fogdrift.io import load

    rng = np.random.default_rng(7)
    t = np.arange(n) / 100.0
    g = rng.normal(size=(n, 3))
    cases = []

    np.save(d / "a.npy", np.column_stack([t, g]))
    cases.append(("npy", d / "a.npy", {"time_column": 0, "unit": "deg/h", "time_unit": "s"}, lambda p: np.array(np.load(p))))
    np.savez(d / "a.npz", t=t, gx=g[:, 0], gy=g[:, 1], gz=g[:, 2])
    cases.append(("npz", d / "a.npz", {"unit": "deg/h", "time_unit": "s"}, lambda p: {k: v for k, v in np.load(p).items()}))
    np.savetxt(d / "a.csv", np.column_stack([t, g]), delimiter=",", header="t_s,gx,gy,gz", comments="", fmt="%.9g")
    cases.append(("text (CSV)", d / "a.csv", {"unit": "deg/h"}, lambda p: np.loadtxt(p, delimiter=",", skiprows=1)))
    with h5py.File(d / "a.h5", "w") as f:
        f.create_dataset("imu/t", data=t)
        f.create_dataset("imu/gyro", data=g, chunks=(65536, 3))
    cases.append(("hdf5 (chunked group)", d / "a.h5", {"unit": "deg/h", "time_unit": "s"},
                  lambda p: [h5py.File(p, "r")["imu/gyro"][:], h5py.File(p, "r")["imu/t"][:]]))
    with h5py.File(d / "c.h5", "w") as f:
        f.create_dataset("rate", data=g)
    cases.append(("hdf5 (contiguous, memory-mapped)", d / "c.h5", {"rate_hz": 100.0, "unit": "deg/h"},
                  lambda p: h5py.File(p, "r")["rate"][:]))
    sio.savemat(d / "a.mat", {"imu": {"t": t, "gx": g[:, 0], "gy": g[:, 1], "gz": g[:, 2]}})
    cases.append(("mat v5", d / "a.mat", {"unit": "deg/h", "time_unit": "s"}, lambda p: sio.loadmat(p)))
    rec = np.zeros(n, dtype=[("seq", "<u4"), ("gx", "<i4"), ("gy", "<i4"), ("gz", "<i4")])
    rec["seq"] = np.arange(n)
    for k, c in enumerate(("gx", "gy", "gz")):
        rec[c] = (g[:, k] * 1e4).astype(np.int32)
    rec.tofile(d / "a.bin")
    cases.append(("raw binary", d / "a.bin", {"rate_hz": 100.0, "unit": "inc:arcsec",
                                              "reader_options": {"layout": "<u4 seq, <i4 gx, <i4 gy, <i4 gz",
                                                                 "scale": 1e-4}},
                  lambda p: np.fromfile(p, dtype=rec.dtype)))
    try:
        from obspy import Stream, Trace, UTCDateTime

        st = Stream()
        for k, ch in enumerate(("HJZ", "HJN", "HJE")):
            tr = Trace(np.ascontiguousarray(g[:, k]).astype(np.float32))
            tr.stats.update({"network": "XX", "station": "ROT", "channel": ch, "sampling_rate": 100.0,
                             "starttime": UTCDateTime(2024, 1, 1)})
            st += tr
        st.write(str(d / "a.mseed"), format="MSEED", encoding="FLOAT32")
        import obspy

        cases.append(("miniSEED (FLOAT32)", d / "a.mseed", {"unit": "rad/s"}, lambda p: obspy.read(str(p))))
    except ImportError:
        pass
    try:
        sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
        from test_io_rosbag import T0_NS, write_bag
        from rosbags.highlevel import AnyReader

        stamps = T0_NS + np.arange(n_bag, dtype=np.int64) * 10_000_000
        write_bag(d / "a.bag", 1, g[:n_bag], stamps)
        write_bag(d / "bag2", 2, g[:n_bag], stamps)

        def deser(p):
            with AnyReader([Path(p)]) as r:
                return [r.deserialize(raw, c.msgtype).angular_velocity.x for c, _, raw in r.messages()]

        cases.append(("ROS 1 bag", d / "a.bag", {}, deser))
        cases.append(("ROS 2 bag (sqlite3)", d / "bag2", {}, deser))
    except ImportError:
        pass
    return cases, load


def _size(p: Path) -> int:
    return sum(q.stat().st_size for q in p.rglob("*") if q.is_file()) if p.is_dir() else p.stat().st_size


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=float, default=1e6)
    ap.add_argument("--bag-messages", type=float, default=2e5)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json")
    args = ap.parse_args()
    d = Path(tempfile.mkdtemp(prefix="fogdrift_readers_"))
    try:
        cases, load = _cases(d, int(args.samples), int(args.bag_messages))
        print("machine:", json.dumps(_machine()), flush=True)
        rows = []
        for name, path, kwargs, lib in cases:
            load(path, **kwargs)                      # warm-up (imports, page cache)
            t_fd = _best(lambda: load(path, **kwargs), args.repeat)
            t_lib = _best(lambda: lib(path), args.repeat)
            mb = _size(path) / 1e6
            rows.append((name, mb, t_fd, mb / t_fd, t_lib, mb / t_lib))
        print("\n| format | file [MB] | fogdrift load [s] | fogdrift [MB/s] | library read [s] | library [MB/s] |"
              " ratio |\n| --- | --- | --- | --- | --- | --- | --- |")
        for name, mb, a, ra, b, rb in rows:
            print(f"| {name} | {mb:.1f} | {a:.3f} | {ra:.0f} | {b:.3f} | {rb:.0f} | {a / b:.2f} |")
        if args.json:
            Path(args.json).write_text(json.dumps({"machine": _machine(), "rows": rows}, indent=1))
    finally:
        shutil.rmtree(d, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
