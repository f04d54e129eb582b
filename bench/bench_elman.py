"""Benchmark: Elman and grey-Elman training time on 10^4 and 10^5 drift samples.

Run: ``.venv/bin/python bench/bench_elman.py [--sizes 10000 100000] [--seeds 16] [--json out.json]``

Setting: hidden 16, lags 4, defaults otherwise (Adam lr 1e-3, window 64, batch_size 2048,
sse loss, float32). Data: a seeded synthetic drift (exponential warm-up + slow oscillation
+ small bounded random walk, deg/h); the first 80 % is y_train, of which ``fit`` holds out the last
20 % chronologically for early stopping.

Stopping rule ("convergence"): stop after ``patience`` = 100 epochs without a relative
improvement of more than 0.01 % of the validation loss, or at ``epochs`` = 2000; the
best-validation parameters are kept. Wall time includes JIT compilation (each model class is
warmed up once on a tiny series first, so the figure is mostly steady-state training) and the
final pass that sets the forecast state.

The 16-model column trains 16 seeds at once with ``fit_many`` (``jax.vmap`` over seeds);
"ratio" is its wall time over the single-model wall time. Each model keeps its own stopping
epoch; the batch runs until the last one stops. Timings are not asserted anywhere.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

import jax
import numpy as np

from fogdrift.models.elman import Elman, GreyElman, fit_many
from fogdrift.models import Persistence


def synthetic_drift(n: int, seed: int = 0) -> np.ndarray:
    """Warm-up (tau 300 samples) + oscillation (period 250 samples) + bounded walk [deg/h].

    The walk is AR(1) with phi = 0.995 and step sd 0.002 deg/h (stationary sd 0.02 deg/h), so
    the test block stays inside the training range at every n.
    """
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    e = rng.normal(0.0, 0.002, n)
    walk = np.empty(n)
    acc = 0.0
    for i in range(n):
        acc = 0.995 * acc + e[i]
        walk[i] = acc
    return 0.5 * (1.0 - np.exp(-k / 300.0)) + 0.2 * np.sin(2 * np.pi * k / 250.0) + walk


def _rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


def _print_row(r):
    many = f"{r['many_wall_s']:.1f} | {r['ratio']:.2f}" if "many_wall_s" in r else "- | -"
    print(f"| {r['n']} | {r['model']} | {r['epochs']} ({r['best_epoch']}) | {r['wall_s']:.1f} | "
          f"{r['final_val_loss']:.4g} | {r['test_rmse_dph']:.4g} / {r['persistence_rmse_dph']:.4g} | {many} |",
          flush=True)


def run(sizes, n_seeds, hidden=16, lags=4):
    rows = []
    for cls in (Elman, GreyElman):  # warm-up compiles on a tiny series (shapes differ; cost noted)
        cls(hidden=hidden, lags=lags, epochs=2).fit(synthetic_drift(600))
    for n in sizes:
        y = synthetic_drift(n)
        n_train = int(0.8 * n)
        y_train, y_test = y[:n_train], y[n_train:]
        persist = _rmse(Persistence().fit(y_train).predict(y_test, history=y_train), y_test)
        for cls in (Elman, GreyElman):
            model = cls(hidden=hidden, lags=lags)
            t0 = time.perf_counter()
            model.fit(y_train)
            wall = time.perf_counter() - t0
            test_rmse = _rmse(model.predict(y_test, history=y_train), y_test)
            row = {"n": n, "model": model.label, "epochs": model.n_epochs_, "best_epoch": model.best_epoch_,
                   "wall_s": wall, "final_val_loss": float(model.val_curve_[model.best_epoch_]),
                   "test_rmse_dph": test_rmse, "persistence_rmse_dph": persist}
            if n_seeds:
                t0 = time.perf_counter()
                many = fit_many(model, y_train, seeds=range(n_seeds))
                row["many_wall_s"] = time.perf_counter() - t0
                row["many_epochs_max"] = max(m.n_epochs_ for m in many)
                row["ratio"] = row["many_wall_s"] / wall
            rows.append(row)
            _print_row(row)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    ap.add_argument("--seeds", type=int, default=16, help="models for the fit_many column (0: skip)")
    ap.add_argument("--json", default=None, help="also write the rows and machine info to this file")
    args = ap.parse_args()
    dev = jax.devices()[0]
    info = {"jax": jax.__version__, "backend": jax.default_backend(), "device": str(dev),
            "cpu_count": os.cpu_count(), "machine": platform.machine(), "python": platform.python_version()}
    print(f"JAX {info['jax']} backend={info['backend']} device={info['device']} cpus={info['cpu_count']}")
    print()
    print(f"| n | model | epochs (best) | wall s | final val loss (sse, z) | test RMSE / persistence [deg/h] "
          f"| {args.seeds}-model wall s | ratio |")
    print("|---|---|---|---|---|---|---|---|", flush=True)
    rows = run(args.sizes, args.seeds)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"machine": info, "rows": rows}, fh, indent=2)


if __name__ == "__main__":
    main()
