"""Benchmark: the fused exact-ADEV kernel against the memory floor, the angle-array kernel and allantools.

One process, interleaved rounds.  Each round at ``--size`` samples (seeded white + random walk + a tone +
an offset, float64), octave grid, overlapping ADEV, times one after the other:

* ``floor``      -- one compiled parallel pass that reads the rate once and sums it (4 accumulators per block):
  the least time any exact estimator needs to see every sample once; ``np.sum`` beside it;
* ``angle array`` -- ``allan_variance(y, dt, taus="octave")`` with the fused kernel switched off (the angle
  array of N + 1 points, then the per-tau kernel: the engine before the fused kernel);
* ``fused``      -- ``allan_variance(y, dt, taus="octave")`` (the fused kernel: the angle never stored);
* ``allantools`` -- ``allantools.oadev(y, rate=1/dt, data_type="freq", taus=<the same taus>)`` at
  ``--allantools-size`` samples (default 10^7; at ``--size`` itself the same array and the round's
  ``fused`` run are compared; allantools then needs about 24 bytes per sample), beside ``fused`` at that size.

The fused kernel reads the rate ``3 + L`` times (the mean, the block offsets, the near window, one stream
per long lag; L = 10 at 10^8 on the octave grid), so ``(3 + L) x floor`` is its traffic floor.  Every figure
is printed with ``os.getloadavg()`` (1 min) taken right after it; the summary gives the median of the
per-round ratios.  The fused and angle-array sums are checked equal bit for bit.

``--fresh K`` adds K alternating pairs of fresh processes that each make one call (angle array, then fused)
on the same seeded data after loading the numba cache: the case of a script or a CLI run, where the angle
array's 8 (N + 1) bytes are page-faulted in by that call (in the interleaved rounds above the process has
freed and re-allocated such arrays before, which makes the angle-array path cheaper).  Wall time of the call,
load, and the peak RSS of the process (``VmHWM``) are printed.

Usage::

    python bench/bench_allan_fused.py --size 1e8 --rounds 3 [--allantools-size 1e7] [--fresh 3]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import time

import numpy as np


def _data(n: int, seed: int = 12345) -> np.ndarray:
    """White noise + random walk + a tone + an offset [deg/h], built 2^22 samples at a time (no temporaries of
    the record's size, so the peak RSS of a fresh process is the record plus what the call itself allocates)."""
    rng = np.random.default_rng(seed)
    y = np.empty(n)
    walk = 0.0
    step = 1 << 22
    for lo in range(0, n, step):
        hi = min(n, lo + step)
        w = 1e-3 * np.cumsum(rng.standard_normal(hi - lo)) + walk
        walk = float(w[-1])
        y[lo:hi] = rng.standard_normal(hi - lo) + w + 0.5 * np.sin(2e-4 * np.arange(lo, hi)) + 10.0
    return y


def _floor_kernel():
    import numba

    @numba.njit(parallel=True, cache=False)
    def read_once(y, block):
        nb = (y.size + block - 1) // block
        tot = np.zeros(nb)
        for ib in numba.prange(nb):
            lo = ib * block
            hi = min(y.size, lo + block)
            a0 = a1 = a2 = a3 = 0.0
            i = lo
            while i + 3 < hi:
                a0 += y[i]
                a1 += y[i + 1]
                a2 += y[i + 2]
                a3 += y[i + 3]
                i += 4
            while i < hi:
                a0 += y[i]
                i += 1
            tot[ib] = (a0 + a1) + (a2 + a3)
        return tot.sum()

    return read_once


def _timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0, os.getloadavg()[0]


def _peak_rss_gb() -> float:
    """Peak RSS of this process's memory image in GB (``VmHWM``; ``ru_maxrss`` would carry the parent's peak
    across fork and exec)."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024 / 1e9
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6


def _once(mode: str, n: int, dt: float) -> None:
    """One call in this (fresh) process: ``mode`` "array" (fused kernel off) or "fused"; prints one line."""
    from fogdrift.allan import _kernels as K
    from fogdrift.allan import allan_variance

    allan_variance(_data(K.FUSED_MIN + 10, seed=1), dt, taus="octave")  # load the numba cache
    y = _data(n)
    if mode == "array":
        K.fused_lags = lambda n_, m_: None
    r, wall, load = _timed(lambda: allan_variance(y, dt, taus="octave"))
    rss = _peak_rss_gb()
    print(f"{mode} {wall:.3f} {load:.2f} {rss:.3f} {r.avar_dph2.sum()!r}", flush=True)


def _fresh(pairs: int, n: int, dt: float) -> None:
    print(f"\nfresh processes, one call each at N = {n:.0e} (octave grid):\n")
    print("| pair | angle array s | fused s | angle array / fused | peak RSS angle array GB | peak RSS fused GB | "
          "same sums |")
    print("|---:|---|---|---:|---:|---:|---|")
    ratios = []
    for k in range(pairs):
        got = {}
        for mode in ("array", "fused"):
            out = subprocess.run([sys.executable, __file__, "--once", mode, "--size", str(n), "--dt", str(dt)],
                                 capture_output=True, text=True, check=True).stdout.split()
            got[mode] = (float(out[1]), float(out[2]), float(out[3]), out[4])
        (ta, la, ra, sa), (tf, lf, rf, sf) = got["array"], got["fused"]
        ratios.append(ta / tf)
        print(f"| {k + 1} | {ta:.2f} (load {la:.1f}) | {tf:.2f} (load {lf:.1f}) | {ta / tf:.2f}x | {ra:.2f} | "
              f"{rf:.2f} | {sa == sf} |", flush=True)
    print(f"\nmedian angle array / fused over fresh pairs: {statistics.median(ratios):.2f}x")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="1e8")
    ap.add_argument("--fresh", type=int, default=0, help="pairs of fresh one-call processes (0: none)")
    ap.add_argument("--once", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--allantools-size", default="1e7", help="0 to skip allantools")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--dt", type=float, default=0.01)
    args = ap.parse_args(argv)
    n = int(float(args.size))
    n_at = int(float(args.allantools_size))
    if args.once:
        return _once(args.once, n, args.dt)

    import numba

    from fogdrift.allan import _kernels as K
    from fogdrift.allan import allan_variance, tau_grid

    read_once = _floor_kernel()
    warm = _data(K.FUSED_MIN + 1000)
    allan_variance(warm, args.dt, taus="octave")
    read_once(warm, 65536)
    real_lags = K.fused_lags

    def angle_array(y):
        K.fused_lags = lambda n_, m_: None
        try:
            return allan_variance(y, args.dt, taus="octave")
        finally:
            K.fused_lags = real_lags

    y = _data(n)
    y_at = (y if n_at == n else _data(n_at, seed=7)) if n_at else None
    m = tau_grid(n, args.dt, "octave")
    lags = real_lags(n, m)
    n_reads = 3 + (0 if lags is None else lags.size)
    print(f"N = {n:.0e}, octave grid ({m.size} taus), numba threads {numba.get_num_threads()}, cpus {os.cpu_count()}; "
          f"fused reads the rate {n_reads} times; allantools at N = {n_at:.0e}\n")
    print("| round | floor (1 read) s | np.sum s | angle array s | fused s | fused / floor | fused / "
          f"({n_reads} x floor) | angle array / fused | fused at {n_at:.0e} s | allantools at {n_at:.0e} s | "
          "allantools / fused | bit-equal |")
    print("|---:|---|---|---|---|---:|---:|---:|---|---|---:|---|")
    ratios = {"floor": [], "traffic": [], "old": [], "at": []}
    for r in range(args.rounds):
        _, t_fl, l_fl = _timed(lambda: read_once(y, 65536))
        _, t_np, l_np = _timed(lambda: np.sum(y))
        old, t_old, l_old = _timed(lambda: angle_array(y))
        new, t_new, l_new = _timed(lambda: allan_variance(y, args.dt, taus="octave"))
        equal = bool(np.array_equal(old.avar_dph2, new.avar_dph2))
        del old
        at_cells = "- | - | -"
        if n_at:
            if n_at == n:  # the fused run above is the one compared
                small, t_sm, l_sm = new, t_new, l_new
            else:
                small, t_sm, l_sm = _timed(lambda: allan_variance(y_at, args.dt, taus="octave"))
            import allantools

            _, t_at, l_at = _timed(lambda: allantools.oadev(y_at, rate=1.0 / args.dt, data_type="freq",
                                                             taus=small.tau_s))
            ratios["at"].append(t_at / t_sm)
            at_cells = f"{t_sm:.3f} (load {l_sm:.1f}) | {t_at:.2f} (load {l_at:.1f}) | {t_at / t_sm:.1f}x"
        ratios["floor"].append(t_new / t_fl)
        ratios["traffic"].append(t_new / (n_reads * t_fl))
        ratios["old"].append(t_old / t_new)
        print(f"| {r + 1} | {t_fl:.3f} (load {l_fl:.1f}) | {t_np:.3f} (load {l_np:.1f}) | {t_old:.2f} (load "
              f"{l_old:.1f}) | {t_new:.2f} (load {l_new:.1f}) | {t_new / t_fl:.1f}x | "
              f"{t_new / (n_reads * t_fl):.2f}x | {t_old / t_new:.2f}x | {at_cells} | {equal} |", flush=True)
    med = {k: (statistics.median(v) if v else float("nan")) for k, v in ratios.items()}
    print(f"\nmedians of the per-round ratios: fused / floor {med['floor']:.1f}x, fused / ({n_reads} x floor) "
          f"{med['traffic']:.2f}x, angle array / fused {med['old']:.2f}x, allantools / fused at {n_at:.0e} "
          f"{med['at']:.1f}x")
    if args.fresh:
        del y, y_at
        _fresh(args.fresh, n, args.dt)


if __name__ == "__main__":
    main()
