"""Benchmark: the default noise identification against the classic five-term weighted least-squares fit.

For each real or simulated Allan curve the script times, in the same process, one after the other:

* ``fogdrift fit_noise`` - the default identification (model selection over 31 term subsets, model-based
  covariance, profile intervals over the plausible models, automatic short-tau exclusion);
* ``classic WLS-NNLS`` - the rival most tools use: sigma^2 = sum A_n tau^n with all five terms, rows weighted by
  sqrt(EDF/2) / sigma^2 (relative error, [Lv2015]), ``scipy.optimize.nnls``; no intervals, no selection.

It prints both wall times, their ratio (rival / fogdrift: below 1 means fogdrift is slower, which is expected:
it does far more), and N from each, so the price of the honest answer is visible.  numba kernels are warmed up
on a small curve first (compilation excluded).  The Allan curves are computed once, outside the timings.

Inputs: seeded simulations (white + flicker + rate random walk, 1e6 and 1e7 samples at 100 Hz) and, when the
shared data folder is present, the real logs (ADIS16405 imu1, deg/s; MTi-G, rad/s; the bundled RLG, deg/h).

Usage::

    python bench/bench_noise.py [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data"


def classic_fit(r):
    """All five terms, relative-error weights sqrt(EDF/2)/sigma^2, non-negative least squares."""
    from scipy.optimize import nnls

    tau, var = r.tau_s, r.var_dph2
    edf = np.asarray(r.edf, dtype=np.float64)
    X = np.stack([tau**-2, tau**-1, np.ones_like(tau), tau, tau**2], axis=1)
    w = np.sqrt(edf / 2.0) / var
    sc = np.linalg.norm(X * w[:, None], axis=0)
    a, _ = nnls(X * w[:, None] / sc, var * w)
    A = a / sc
    return float(np.sqrt(A[1]) / 60.0)  # N [deg/sqrt(h)] = sqrt(A_-1)/60


def curves():
    from fogdrift.allan import allan_variance
    from fogdrift.simulate import simulate

    out = []
    for n in (10**6, 10**7):
        x = simulate(n, 0.01, arw_dprh=0.02, bias_instability_dph=0.2, rrw_dphrh=0.4, seed=7)
        out.append((f"simulated {n:.0e} (N 0.02)", allan_variance(x, 0.01)))
    real = [("ADIS16405 imu1 gx", "adis16405_static/adis16405_imu1.csv.gz", "deg/s"),
            ("MTi-G gx", "mtig_cont_imu1/mtig_cont_imu1.csv.gz", "rad/s"),
            ("PSINS RLG gz", "psins_lasergyro_rlg/psins_lasergyro_rlg.csv.gz", "deg/h")]
    if SHARED.is_dir():
        from fogdrift.io import load

        for label, rel, unit in real:
            rec = load(SHARED / rel, unit=unit)
            name = "gz" if "RLG" in label else "gx"
            out.append((label, allan_variance(rec.axis(name), rec.dt_s)))
    return out


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    from fogdrift.allan import allan_variance
    from fogdrift.noise import fit_noise
    from fogdrift.simulate import simulate

    fit_noise(allan_variance(simulate(2**16, 0.01, arw_dprh=0.02, seed=1), 0.01))  # warm-up (numba)
    rows = []
    for label, r in curves():
        t0 = time.perf_counter()
        f = fit_noise(r)
        t_fd = time.perf_counter() - t0
        t0 = time.perf_counter()
        n_classic = classic_fit(r)
        t_cl = time.perf_counter() - t0
        rows.append(dict(curve=label, n_tau=int(r.tau_s.size), fogdrift_s=t_fd, classic_s=t_cl,
                         ratio=t_cl / t_fd, n_fogdrift=f.terms["N"].value, n_lo=f.terms["N"].lo95,
                         n_hi=f.terms["N"].hi95, n_classic=n_classic, selected="+".join(f.selected),
                         chi2_red=f.chi2_red, quality=f.quality))
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
          f"Python {platform.python_version()}, numpy {np.__version__}")
    print("| curve | n_tau | fogdrift fit_noise [s] | classic WLS-NNLS [s] | ratio | N fogdrift [deg/√h] | "
          "N classic | selected | χ²_red (quality) |")
    print("|---|---:|---:|---:|---:|---|---:|---|---|")
    for w in rows:
        print(f"| {w['curve']} | {w['n_tau']} | {w['fogdrift_s']:.3f} | {w['classic_s']:.4f} | {w['ratio']:.3g}x | "
              f"{w['n_fogdrift']:.4g} [{w['n_lo']:.3g}, {w['n_hi']:.3g}] | {w['n_classic']:.4g} | {w['selected']} | "
              f"{w['chi2_red']:.3g} ({w['quality']}) |")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
