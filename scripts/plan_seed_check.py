"""How many simulated records reach the planned width at the plan's lengths (issue 34, docs/plan.md "80 % of records").

For one sensor class of docs/plan.md and one term: the plan's lengths (``make_plan(..., monte_carlo=0)``), then the
real Allan fit (``plan.montecarlo.simulate_fits``: ``fogdrift.pipeline.analyse_allan``, the path of ``fogdrift
allan``) on seeds ``--seeds`` at ``share_s`` (``--at share``, default) or ``target_s`` (``--at target``), and the
count of seeds whose relative 95 % half-width reaches the target, the coverage, the median and 80 % quantile of the
widths.  ``--records K``: also the fit's own rules on ``K`` Allan curves drawn from the model
(``plan.spread.fit_rule_widths``), the check of the linearisation.

    PYTHONPATH=src python scripts/plan_seed_check.py --sensor mems --term B --seeds 1-96 --workers 1 [--records 400]
"""

from __future__ import annotations

import argparse
import json
import math
import time

import numpy as np

from fogdrift.plan import make_plan, parse_model
from fogdrift.plan.core import _mc_length
from fogdrift.plan.montecarlo import simulate_fits, summarise
from fogdrift.plan.spread import fit_rule_widths

#: The three simulated classes of docs/plan.md: model text and sample interval [s].
SENSORS = {"mems": ("N=0.3 deg/sqrt(h), B=5 deg/h, K=20 deg/h^1.5", 0.1),
           "fog": ("N=0.04 deg/sqrt(h), B=0.08 deg/h, K=0.05 deg/h^1.5", 1.0),
           "rlg": ("N=0.003 deg/sqrt(h), B=0.004 deg/h, K=0.002 deg/h^1.5", 1.0)}
TARGETS = {"N": 0.05, "B": 0.25}


def _widths(fits, term):
    out = []
    for f in fits:
        v, lo, hi, status = f[term]
        out.append((hi - lo) / (2.0 * v) if status == "resolved" and v and lo is not None and hi is not None
                   else math.inf)
    return np.asarray(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sensor", choices=sorted(SENSORS), required=True)
    ap.add_argument("--term", choices=sorted(TARGETS), required=True)
    ap.add_argument("--seeds", default="1-48", help="first-last (inclusive)")
    ap.add_argument("--at", choices=("share", "target"), default="share")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--records", type=int, default=0, help="fit-rule records drawn from the model (0: none)")
    ap.add_argument("--json", default=None, help="write the per-seed fits and the summary here")
    a = ap.parse_args(argv)
    text, dt = SENSORS[a.sensor]
    model = parse_model(text, dt)
    target = TARGETS[a.term]
    t0 = time.time()
    plan = make_plan(model, {a.term: target}, monte_carlo=0, estimators=("allan",))
    r = plan.terms[a.term]
    length = r["share_s"] if a.at == "share" else r["target_s"]
    n = int(round(length / dt))
    s0, s1 = (int(x) for x in a.seeds.split("-"))
    seeds = list(range(s0, s1 + 1))
    print(f"{a.sensor} {a.term} ±{100 * target:g} %: target_s {r['target_s']:.6g} s, share_s {r['share_s']:.6g} s "
          f"(x{r['share_s'] / r['target_s']:.3f}, share_ratio {r['share_ratio']:.4f}); checking {a.at}_s = {n} "
          f"samples, seeds {s0}-{s1} (plan {time.time() - t0:.0f} s)", flush=True)
    t1 = time.time()
    fits = simulate_fits(model, n, seeds, workers=a.workers)
    s = summarise(model, fits, {a.term: target})[a.term]
    w = _widths(fits, a.term)
    met = int(np.sum(w <= target))
    print(f"  real fits: {met} / {len(seeds)} reach ±{100 * target:g} % ({100 * met / len(seeds):.1f} %), coverage "
          f"{round(s['coverage'] * len(seeds))} / {len(seeds)}, median ±{100 * np.median(w):.2f} %, q80 "
          f"±{100 * np.quantile(w, 0.8):.2f} % ({time.time() - t1:.0f} s)", flush=True)
    if a.at == "target":  # the length the seeds' median width implies, on the analytic curve's local slope
        implied = _mc_length(length, s["median_width"], target, plan.grid["length_s"], plan.grid["width"][a.term])
        if implied:
            print(f"  the seeds' median implies {implied:.6g} s ({100 * (implied / length - 1):+.1f} % of target_s)")
    out = {"sensor": a.sensor, "term": a.term, "target": target, "at": a.at, "n_samples": n,
           "target_s": r["target_s"], "share_s": r["share_s"], "share_ratio": r["share_ratio"], "seeds": seeds,
           "met": met, "summary": s, "fits": fits}
    if a.records:
        t2 = time.time()
        wr = fit_rule_widths(model, n, a.term, draws=a.records)
        print(f"  fit's rules on {a.records} model records: {100 * np.mean(wr <= target):.1f} % reach it, median "
              f"±{100 * np.median(wr):.2f} %, q80 ±{100 * np.quantile(wr, 0.8):.2f} % ({time.time() - t2:.0f} s)")
        out["records"] = {"draws": a.records, "met_fraction": float(np.mean(wr <= target)),
                          "median": float(np.median(wr)), "q80": float(np.quantile(wr, 0.8))}
    if a.json:
        with open(a.json, "w") as f:
            json.dump(out, f, default=lambda x: None if isinstance(x, float) and not math.isfinite(x) else str(x))


if __name__ == "__main__":
    main()
