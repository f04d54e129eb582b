"""Benchmark: Haar wavelet variance and a full GMWM model selection.

Part 1 - WV of 1e8 samples (default; ``--wv-size``) against ``fogdrift.allan.allan_variance``
(exact overlapping estimator) at the matching octave averaging factors ``m = 2^(j-1)``, on the
same seeded white + random-walk data, timed one after the other in the same process.  The numba
kernels of allan_variance are warmed up first.  Both results are compared: ``nu2_j = AVAR(m)/2``.
The classical WV is computed through ``allan_variance`` (one home for the second-difference
sums), so the ratio shows the WV's own overhead (input checks, eta3 intervals).

Part 2 - ``select_model`` with the default candidate set on 1e7 simulated samples (WN + RW + GM,
dt = 0.01 s), with the time split into: the WV pyramid, the covariance quadrature (building the
SDF-independent plan once, then each evaluation), and the rest (starting values and
least-squares fits of the 11 candidates, checks, IEEE reading).

Part 3 (``--solver``) - the GMWM optimiser: every ``_Problem.solve`` call that ``analyse_gmwm`` makes on each axis
of a log (default ADIS16405 session 1, deg/s) is recorded, then replayed in this process by SciPy's
``least_squares`` (``_Problem.solve_scipy``, the old solver) and by the compiled solver (``_Problem.solve``,
:mod:`fogdrift.gmwm.solver`), alternately for ``--rounds`` rounds (the order flips every round); printed: the median
of the per-round ratios, the load average before and after, and how far the results are apart (objective relative
difference, converged flags).  The compiled solver is warmed up (compiled or loaded from numba's cache) first.
Parts 1 and 2 are skipped with ``--solver``.

Usage::

    python bench/bench_gmwm.py [--wv-size 1e8] [--sel-size 1e7] [--json out.json]
    python bench/bench_gmwm.py --solver [--log PATH --unit deg/s] [--rounds 5]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import time
import warnings
from pathlib import Path

import numpy as np

ADIS1 = (Path(os.environ.get("FOGDRIFT_ADIS", Path(__file__).resolve().parents[2] / "shared/data/adis16405_static"))
         / "adis16405_imu1.csv.gz")


def _data(n: int, seed: int = 12345) -> np.ndarray:
    rng = np.random.default_rng(seed)
    y = rng.standard_normal(n)
    y += 1e-3 * np.cumsum(rng.standard_normal(n))
    y += 10.0
    return y


def bench_wv(n: int) -> dict:
    from fogdrift.allan import allan_variance
    from fogdrift.gmwm import haar_wvar

    warm = _data(10_000)
    allan_variance(warm, 0.01, taus=[0.01, 0.02])
    haar_wvar(warm, 0.01)
    y = _data(n)
    t0 = time.perf_counter()
    wv = haar_wvar(y, 0.01)
    t_wv = time.perf_counter() - t0
    taus = 0.01 * 2.0 ** (wv.level - 1)
    t0 = time.perf_counter()
    av = allan_variance(y, 0.01, taus=taus)
    t_av = time.perf_counter() - t0
    rel = float(np.max(np.abs(wv.nu2_dph2 / (av.avar_dph2 / 2.0) - 1.0)))
    return {"n": n, "levels": len(wv), "wv_s": t_wv, "allan_octave_s": t_av, "ratio_allan_over_wv": t_av / t_wv,
            "max_rel_diff_nu2_vs_avar_half": rel}


def bench_selection(n: int) -> dict:
    from fogdrift.gmwm import covariance, haar_wvar, select_model, simulate_latent

    beta = 1e-3
    u = -math.expm1(-beta)
    theta = [1.0, 1e-7, beta, 0.05 * u * (2 - u)]
    x = simulate_latent("WN+RW+GM", theta, n, seed=7)
    timing = {"plan_build_s": 0.0, "plan_builds": 0, "cov_eval_s": 0.0, "cov_evals": 0}
    orig_plan, orig_gram = covariance._plan, covariance.filter_gram

    def plan(*a, **k):
        hits = orig_plan.cache_info().hits
        t = time.perf_counter()
        out = orig_plan(*a, **k)
        if orig_plan.cache_info().hits == hits:
            timing["plan_build_s"] += time.perf_counter() - t
            timing["plan_builds"] += 1
        return out

    def gram(*a, **k):
        t = time.perf_counter()
        out = orig_gram(*a, **k)
        timing["cov_eval_s"] += time.perf_counter() - t
        timing["cov_evals"] += 1
        return out

    covariance._plan, covariance.filter_gram = plan, gram
    try:
        t0 = time.perf_counter()
        wv = haar_wvar(x, 0.01)
        t_wv = time.perf_counter() - t0
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sel = select_model(wv)
        t_sel = time.perf_counter() - t0
    finally:
        covariance._plan, covariance.filter_gram = orig_plan, orig_gram
    t_cov = timing["cov_eval_s"]  # includes the plan builds
    return {
        "n": n, "levels": len(wv), "wv_s": t_wv, "selection_s": t_sel, "total_s": t_wv + t_sel,
        "covariance_s": t_cov, "plan_build_s": timing["plan_build_s"], "plan_builds": timing["plan_builds"],
        "covariance_evals": timing["cov_evals"], "fits_and_rest_s": t_sel - t_cov,
        "selected": sel.selected, "excluded_levels": [e.level for e in sel.excluded],
        "n_dprh": sel.ieee.terms["N_dprh"].value,
    }


def _recorded_solves(log, unit):
    """``[(problem, start, budget)]`` of every ``_Problem.solve`` that ``analyse_gmwm`` makes on each axis of
    ``log`` (the whole record of each axis)."""
    from fogdrift.gmwm import estimator
    from fogdrift.gmwm.analysis import analyse_gmwm
    from fogdrift.io import load

    rec = load(log, unit=unit)
    calls = []
    real = estimator._Problem.solve

    def record(self, z0, max_nfev=2000):
        calls.append((self, np.array(z0, dtype=np.float64), max_nfev))
        return real(self, z0, max_nfev)

    estimator._Problem.solve = record
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for name in rec.axis_names:
                analyse_gmwm(name, rec.axis(name), rec.dt_s)
    finally:
        estimator._Problem.solve = real
    return calls


def bench_solver(log, unit, rounds) -> dict:
    calls = _recorded_solves(log, unit)
    p, z, n = calls[0]
    p.solve(z, n)  # compile or load the compiled solver

    def run(compiled):
        t = time.perf_counter()
        out = [(pr.solve if compiled else pr.solve_scipy)(z0, nf) for pr, z0, nf in calls]
        return time.perf_counter() - t, out

    load0 = os.getloadavg()[0]
    ratios, t_old, t_new = [], [], []
    for r in range(rounds):
        order = (False, True) if r % 2 == 0 else (True, False)
        res = {}
        for compiled in order:
            res[compiled] = run(compiled)
        t_old.append(res[False][0])
        t_new.append(res[True][0])
        ratios.append(res[False][0] / res[True][0])
    load1 = os.getloadavg()[0]
    old, new = res[False][1], res[True][1]
    rel = [abs(a[1] - b[1]) / abs(b[1]) if b[1] else abs(a[1]) for a, b in zip(new, old)]
    both = [r for r, a, b in zip(rel, new, old) if a[2] and b[2]]
    return {"log": str(log), "solves": len(calls), "rounds": rounds, "scipy_s": statistics.median(t_old),
            "compiled_s": statistics.median(t_new), "ratio_median": statistics.median(ratios),
            "ratio_min": min(ratios), "ratio_max": max(ratios), "load_before": load0, "load_after": load1,
            "max_rel_dq": max(rel), "max_rel_dq_converged": max(both) if both else 0.0,
            "converged_flag_differs": sum(a[2] != b[2] for a, b in zip(new, old)),
            "bit_identical": sum(a[1] == b[1] and np.array_equal(a[0], b[0]) for a, b in zip(new, old))}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wv-size", default="1e8", help="samples for the WV vs Allan timing (default 1e8)")
    ap.add_argument("--sel-size", default="1e7", help="samples for the model selection (default 1e7)")
    ap.add_argument("--json", default=None, help="also write the results (and machine info) to this file")
    ap.add_argument("--solver", action="store_true", help="part 3 only: SciPy's least_squares vs the compiled solver")
    ap.add_argument("--log", default=str(ADIS1), help="log for --solver (default ADIS16405 session 1)")
    ap.add_argument("--unit", default="deg/s", help="its rate unit (default deg/s)")
    ap.add_argument("--rounds", type=int, default=5, help="alternating rounds for --solver (default 5)")
    args = ap.parse_args(argv)
    import numba
    import scipy

    info = {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__,
            "numba": numba.__version__, "cpu": platform.processor() or platform.machine(),
            "cpus": os.cpu_count()}
    out = {"machine": info}
    if args.solver:
        sv = bench_solver(args.log, args.unit, args.rounds)
        out["solver"] = sv
        print(f"GMWM optimiser, {sv['solves']} solves of analyse_gmwm on {Path(sv['log']).name} (every axis), "
              f"{sv['rounds']} alternating rounds: least_squares {sv['scipy_s']:.2f} s, compiled "
              f"{sv['compiled_s']:.2f} s, ratio {sv['ratio_median']:.1f}x ({sv['ratio_min']:.1f}-{sv['ratio_max']:.1f}); "
              f"load {sv['load_before']:.1f} -> {sv['load_after']:.1f}; max relative objective difference "
              f"{sv['max_rel_dq']:.1e} (converged runs {sv['max_rel_dq_converged']:.1e}), converged flag differs in "
              f"{sv['converged_flag_differs']}, bit-identical {sv['bit_identical']}")
        if args.json:
            with open(args.json, "w") as fh:
                json.dump(out, fh, indent=2)
        return out
    wvr = bench_wv(int(float(args.wv_size)))
    out["wv_vs_allan"] = wvr
    print(f"WV of {wvr['n']:.0e} samples ({wvr['levels']} levels): {wvr['wv_s']:.2f} s; "
          f"allan_variance at the same {wvr['levels']} octave m: {wvr['allan_octave_s']:.2f} s; "
          f"ratio allan/WV = {wvr['ratio_allan_over_wv']:.2f}; max |nu2/(AVAR/2) - 1| = "
          f"{wvr['max_rel_diff_nu2_vs_avar_half']:.1e}")
    sr = bench_selection(int(float(args.sel_size)))
    out["selection"] = sr
    print(f"select_model (default candidates) on {sr['n']:.0e} samples, {sr['levels']} levels: "
          f"total {sr['total_s']:.2f} s = WV {sr['wv_s']:.2f} s + covariance {sr['covariance_s']:.2f} s "
          f"({sr['covariance_evals']} evaluations, {sr['plan_builds']} plan builds {sr['plan_build_s']:.2f} s) "
          f"+ fits/checks {sr['fits_and_rest_s']:.2f} s; selected {sr['selected']}, excluded {sr['excluded_levels']}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=2)
    return out


if __name__ == "__main__":
    main()
