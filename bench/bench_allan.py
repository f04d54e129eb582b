"""Benchmark: fogdrift Allan-family deviations against allantools.

For each size the script generates seeded white + random-walk rate data (float64), warms up
numba (compilation / cache load is excluded from the timings), then times in the same
process, one after the other:

* ``fogdrift exact``  - ``allan_variance(y, dt, taus=N_TAUS, estimator="overlapping", statistic=S)``
* ``fogdrift fast``   - ``allan_variance(..., estimator="fast")`` (Allan deviation only; every
  requested tau, strided start indices)
* ``allantools <f>`` - ``<f>(y, rate=1/dt, data_type="freq", taus=<fogdrift exact taus>)`` with
  ``<f>`` = ``oadev`` (``--statistic adev``, default), ``ohdev`` (``hdev``) or ``mdev`` (``mdev``)

Peak memory is the ``tracemalloc`` peak during the call, in MB, above what was allocated
before it (the input array is excluded).  NumPy reports its array allocations to
tracemalloc, so this counts the angle array and every temporary; the only untracked memory is
numba's per-block partial-sum array (n_blocks x n_tau doubles, about 1.2 MB at 10^8 samples
and 100 taus).  tracemalloc slows allocation-heavy code only per allocation, which is
negligible for these few large arrays.

"ratio" is allantools wall time / this tool's wall time (speed-up).  "max rel diff" compares
ADEV with allantools at the taus both computed with the same m.  The fast row also states how
many of its taus lie inside the exact estimator's 68 % confidence bounds.

Usage::

    python bench/bench_allan.py --sizes 1e6,1e7 --taus 100 [--statistic hdev] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
import tracemalloc

import numpy as np


def _measure(fn):
    tracemalloc.start()
    tracemalloc.reset_peak()
    base = tracemalloc.get_traced_memory()[0]
    t0 = time.perf_counter()
    out = fn()
    wall = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    return out, wall, peak / 1e6


def _data(n: int, seed: int = 12345) -> np.ndarray:
    rng = np.random.default_rng(seed)
    y = rng.standard_normal(n)
    y += 1e-3 * np.cumsum(rng.standard_normal(n))
    y += 10.0  # an offset, as a real gyro has
    return y


def main(argv=None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="1e6,1e7", help="comma-separated sample counts, e.g. 1e6,1e7,1e8")
    ap.add_argument("--taus", type=int, default=100, help="number of log-spaced taus (default 100)")
    ap.add_argument("--dt", type=float, default=0.01, help="sample interval in s")
    ap.add_argument("--statistic", default="adev", choices=("adev", "hdev", "mdev"),
                    help="Allan (vs oadev), overlapping Hadamard (vs ohdev) or modified Allan (vs mdev)")
    ap.add_argument("--skip-allantools", action="store_true", help="time fogdrift only")
    ap.add_argument("--json", default=None, help="also write the rows (and machine info) to this file")
    args = ap.parse_args(argv)
    sizes = [int(float(s)) for s in args.sizes.split(",") if s.strip()]

    import numba

    from fogdrift.allan import allan_variance

    stat = args.statistic
    rival = {"adev": "oadev", "hdev": "ohdev", "mdev": "mdev"}[stat]
    with_fast = stat == "adev"
    # warm-up: compile or load the numba kernels, import scipy.special
    warm = _data(10_000)
    allan_variance(warm, args.dt, taus=20, statistic=stat)
    if with_fast:
        allan_variance(warm, args.dt, taus=20, estimator="fast")

    info = {
        "python": platform.python_version(),
        "machine": platform.machine(),
        "processor": platform.processor() or "",
        "cpu_count": os.cpu_count(),
        "numba_threads": numba.get_num_threads(),
        "numpy": np.__version__,
        "numba": numba.__version__,
    }
    rows = []
    for n in sizes:
        y = _data(n)
        exact, t_ex, m_ex = _measure(lambda: allan_variance(y, args.dt, taus=args.taus, statistic=stat))
        timed = [("fogdrift exact", exact, t_ex, m_ex)]
        inside = 0
        if with_fast:
            fast, t_fa, m_fa = _measure(lambda: allan_variance(y, args.dt, taus=args.taus, estimator="fast"))
            timed.append(("fogdrift fast", fast, t_fa, m_fa))
            ex_at_fast = allan_variance(y, args.dt, taus=fast.tau_s)  # exact at fast's taus (untimed)
            inside = int(np.sum((fast.dev_dph >= ex_at_fast.dev_lo68_dph) & (fast.dev_dph <= ex_at_fast.dev_hi68_dph)))
        ref = None
        if not args.skip_allantools:
            import allantools

            func = getattr(allantools, rival)
            ref, t_at, m_at = _measure(
                lambda: func(y, rate=1.0 / args.dt, data_type="freq", taus=exact.tau_s)
            )

        def _cmp(res):
            if ref is None:
                return None
            m_ref = np.rint(np.asarray(ref[0]) / args.dt).astype(np.int64)
            common, i_res, i_ref = np.intersect1d(res.m, m_ref, return_indices=True)
            return float(np.max(np.abs(res.dev_dph[i_res] / np.asarray(ref[1])[i_ref] - 1.0)))

        for tool, res, wall, peak in timed:
            rows.append(dict(size=n, tool=f"{tool} {stat}", n_tau=len(res), wall_s=wall, peak_mb=peak,
                             ratio=None if ref is None else t_at / wall, max_rel_diff=_cmp(res),
                             note=f"{inside}/{len(res)} taus within exact 68 % CI" if tool.endswith("fast") else ""))
        if ref is not None:
            rows.append(dict(size=n, tool=f"allantools {rival}", n_tau=len(ref[0]), wall_s=t_at, peak_mb=m_at,
                             ratio=1.0, max_rel_diff=0.0, note=""))
        del y

    print(f"machine: {info}; input array: size x 8 bytes; dt = {args.dt} s; taus = {args.taus} log-spaced; "
          f"statistic = {stat}\n")
    print("| size | tool | n_tau | wall s | peak MB | ratio vs allantools | max rel diff vs allantools | note |")
    print("|---:|---|---:|---:|---:|---:|---:|---|")
    for r in rows:
        ratio = "-" if r["ratio"] is None else f"{r['ratio']:.1f}x"
        diff = "-" if r["max_rel_diff"] is None else f"{r['max_rel_diff']:.1e}"
        print(f"| {r['size']:.0e} | {r['tool']} | {r['n_tau']} | {r['wall_s']:.2f} | {r['peak_mb']:.0f} | "
              f"{ratio} | {diff} | {r['note']} |")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"machine": info, "rows": rows}, fh, indent=2)
    return rows


if __name__ == "__main__":
    main()
