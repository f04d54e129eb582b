"""Benchmark: lifting drift/noise separation vs PyWavelets.

For each size n, one separation ``drift, noise = fogdrift.lifting.separate(x, w, J)`` is
compared with the PyWavelets equivalent, done the way the method notes prescribe:
``c = pywt.wavedec(x, w, "periodization", J)``, then ``pywt.waverec`` once on
``[cA_J, 0, ..., 0]`` (drift) and once on ``[0, cD_J, ..., cD_1]`` (noise), both trimmed.

Wall time is the best of ``--repeat`` interleaved runs (after a warm-up that compiles the numba
kernels).  Peak memory is the tracemalloc peak of one extra run (NumPy's allocator reports
to tracemalloc; the numba kernels allocate only small block buffers, and their large
outputs are NumPy arrays), given as a multiple of the input array's size.

The ``numpy`` column runs the same lifting steps with the NumPy reference kernels
(step by step, no fusion): it is what justifies the numba kernels.

Usage::

    python bench/bench_lifting.py --sizes 1e6,1e7,1e8 [--wavelet db2] [--level 4]

``--wavelet`` takes any name of ``fogdrift.lifting.wavelist()`` (haar, db2, db4); each has a
PyWavelets counterpart of the same name (``LiftingScheme.pywt_name``).
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import platform
import time
import tracemalloc

import numpy as np
import pywt

from fogdrift import lifting


def _pywt_separate(x, wavelet, level):
    n = x.shape[0]
    wavelet = lifting.get_wavelet(wavelet).pywt_name
    c = pywt.wavedec(x, wavelet, mode="periodization", level=level)
    drift = pywt.waverec([c[0]] + [np.zeros_like(b) for b in c[1:]], wavelet, mode="periodization")[:n]
    noise = pywt.waverec([np.zeros_like(c[0])] + c[1:], wavelet, mode="periodization")[:n]
    return drift, noise


def _best_time(fn, repeat):
    best = float("inf")
    for _ in range(repeat):
        gc.collect()
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
        del out
    return best


def _peak_bytes(fn):
    gc.collect()
    tracemalloc.start()
    try:
        out = fn()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    del out
    return peak


def run(sizes, wavelet="db2", level=4, mode="periodization", repeat=3, backends=("numba", "numpy")):
    rows = []
    rng = np.random.default_rng(12345)
    warm = rng.standard_normal(20_000)
    for b in backends:  # compile / load the numba kernels outside the timings
        lifting._set_backend(b)
        lifting.separate(warm, wavelet, level, mode)
    for n in sizes:
        x = rng.standard_normal(n) + np.linspace(0.0, 5.0, n)
        row = {"n": n, "input_mb": x.nbytes / 2**20}
        # correctness guard: the benchmark compares like with like
        lifting._set_backend("numba")
        d, e = lifting.separate(x, wavelet, level, mode)
        pd, pe = _pywt_separate(x, wavelet, level)
        row["max_abs_diff_vs_pywt"] = float(max(np.abs(d - pd).max(), np.abs(e - pe).max()))
        del d, e, pd, pe
        # interleave the contenders so that a varying machine load hits them alike
        fns = {"pywt": lambda: _pywt_separate(x, wavelet, level)}
        for b in backends:
            fns[b] = (lambda b=b: (lifting._set_backend(b), lifting.separate(x, wavelet, level, mode))[1])
        best = {k: float("inf") for k in fns}
        for _ in range(repeat):
            for k, fn in fns.items():
                best[k] = min(best[k], _best_time(fn, 1))
        for k, fn in fns.items():
            row[f"{k}_s"] = best[k]
            row[f"{k}_peak_x"] = _peak_bytes(fn) / x.nbytes
        lifting._set_backend("numba")
        rows.append(row)
    return rows


def _table(rows, backends):
    head = ["n", "pywt [s]"]
    for b in backends:
        head += [f"lifting/{b} [s]", f"speed-up ({b})"]
    head += ["peak mem pywt [x input]"] + [f"peak mem {b} [x input]" for b in backends] + ["max |diff|"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = [f"{r['n']:.0e}", f"{r['pywt_s']:.4f}"]
        for b in backends:
            cells += [f"{r[f'{b}_s']:.4f}", f"{r['pywt_s'] / r[f'{b}_s']:.2f}x"]
        cells += [f"{r['pywt_peak_x']:.2f}"] + [f"{r[f'{b}_peak_x']:.2f}" for b in backends]
        cells += [f"{r['max_abs_diff_vs_pywt']:.1e}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--sizes", default="1e6,1e7", help="comma-separated sample counts, e.g. 1e6,1e7,1e8")
    p.add_argument("--wavelet", default="db2", choices=lifting.wavelist())
    p.add_argument("--level", type=int, default=4)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--backends", default="numba,numpy", help="lifting kernels to time")
    p.add_argument("--json", default=None, help="also write the rows and machine info to this file")
    args = p.parse_args(argv)
    sizes = [int(float(s)) for s in args.sizes.split(",") if s.strip()]
    backends = tuple(b.strip() for b in args.backends.split(",") if b.strip())
    rows = run(sizes, args.wavelet, args.level, repeat=args.repeat, backends=backends)
    info = {
        "machine": platform.machine(),
        "processor": platform.processor(),
        "cpus": os.cpu_count(),
        "loadavg": os.getloadavg(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "pywt": pywt.__version__,
        "wavelet": args.wavelet,
        "level": args.level,
        "mode": "periodization",
    }
    print(f"separation drift/noise, {args.wavelet}, level {args.level}, periodization; "
          f"best of {args.repeat}; {info['cpus']} CPUs, load {info['loadavg'][0]:.2f}")
    print()
    print(_table(rows, backends))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"info": info, "rows": rows}, fh, indent=2)


if __name__ == "__main__":
    main()
