"""Monte-Carlo check of a plan: simulate the model at a record length with many seeds, run the real Allan fit on
each record (:func:`fogdrift.pipeline.analyse_allan` with the default configuration: the code path of
``fogdrift allan``, spectrum and Markov candidates included) and measure the interval width and coverage obtained.

Per term and length: the median relative 95 % half-width ``(hi95 - lo95) / (2 value)`` over the seeds that
resolved it, the fraction of seeds resolving it, the fraction meeting the target width, and the coverage (the
fraction of seeds whose interval holds the true value; an unresolved interval ``[0, hi]`` counts when ``hi`` is
above the truth).  The seeds are ``seed0, seed0 + 1, ...`` and are reported.
"""

from __future__ import annotations

import math
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool

import numpy as np

from ..pipeline import AnalysisConfig, analyse_allan
from ..simulate import simulate

__all__ = ["simulate_fits", "run_seeds", "summarise", "MC_MAX_SAMPLES"]

#: Longest record simulated (samples): the flicker simulator shapes 4 n points by FFT (about 64 n bytes).
MC_MAX_SAMPLES = 2**23


def _one(args):
    coefs, dt, n, seed, kw = args
    y = simulate(int(n), float(dt), seed=int(seed), **kw)
    fit = analyse_allan("mc", y, float(dt), AnalysisConfig()).noise
    return {t: (fit.terms[t].value, fit.terms[t].lo95, fit.terms[t].hi95, fit.terms[t].status) for t in coefs}


def simulate_fits(model, n_samples, seeds, workers: int = 1) -> list[dict]:
    """Fit ``len(seeds)`` simulated records of ``n_samples`` samples; one ``{term: (value, lo95, hi95, status)}``
    per seed (in seed order).  ``workers > 1``: that many processes."""
    if int(n_samples) > MC_MAX_SAMPLES:
        raise ValueError(f"{n_samples} samples is beyond the Monte-Carlo limit of {MC_MAX_SAMPLES}")
    jobs = [(model.terms, model.dt_s, int(n_samples), int(s), model.simulate_kwargs()) for s in seeds]
    return run_seeds(_one, jobs, workers)


def run_seeds(fn, jobs, workers: int = 1) -> list:
    """``[fn(job) for job in jobs]``, in order; ``workers > 1``: in that many processes.

    Fresh interpreters ("spawn"): a forked child of a process that already runs threads (numba, BLAS, a test
    runner's worker) can die on start; a pool that breaks anyway falls back to one process.  ``fn`` must be a
    module-level function (the pool pickles it by name).
    """
    if workers > 1 and len(jobs) > 1:
        try:
            with ProcessPoolExecutor(max_workers=int(workers), mp_context=multiprocessing.get_context("spawn")) as ex:
                return list(ex.map(fn, jobs))
        except BrokenProcessPool:
            pass
    return [fn(j) for j in jobs]


def summarise(model, fits, targets) -> dict:
    """Per term: ``median_width`` (relative half-width over the seeds that resolved it; inf when fewer than half
    did), ``resolved_fraction``, ``coverage``, ``met_fraction`` (width <= target; None without a target),
    ``n_seeds``."""
    out = {}
    for t in model.terms:
        truth = model.coefficients[t]
        widths, cover, res = [], 0, 0
        for f in fits:
            v, lo, hi, status = f[t]
            lo_ = 0.0 if lo is None else lo
            if hi is not None and lo_ <= truth <= hi:
                cover += 1
            if status == "resolved" and v and lo is not None and hi is not None:
                res += 1
                widths.append((hi - lo) / (2.0 * v))
            else:
                widths.append(math.inf)
        n = len(fits)
        w = np.asarray(widths)
        target = targets.get(t)
        out[t] = {"median_width": float(np.median(w)) if n else math.nan,
                  "resolved_fraction": res / n if n else math.nan, "coverage": cover / n if n else math.nan,
                  "met_fraction": None if target is None else float(np.mean(w <= target)), "n_seeds": n}
    return out
