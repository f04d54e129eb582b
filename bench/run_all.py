"""Run every benchmark in sequence (each in its own process, so peak memory is not shared) and print their
markdown tables. ``make bench`` calls this; results and the machine go into ``bench/RESULTS.md`` by hand.

Usage::

    python bench/run_all.py            # full sizes: up to 10^8 samples in memory, 10^9 out of core (~35 min)
    python bench/run_all.py --quick    # 10^6 and 10^7 only
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="skip the 10^8-sample cases")
    args = ap.parse_args()
    sizes = "1e6,1e7" if args.quick else "1e6,1e7,1e8"
    out = HERE / "_out"
    out.mkdir(exist_ok=True)
    jobs = [
        ["bench_allan.py", "--sizes", sizes, "--taus", "100", "--json", str(out / "allan.json")],
        ["bench_lifting.py", "--sizes", sizes, "--json", str(out / "lifting.json")],
        ["bench_elman.py", "--json", str(out / "elman.json")],
        ["bench_compensate.py", "--sizes", sizes, "--json", str(out / "compensate.json")],
        ["bench_noise.py", "--json", str(out / "noise.json")],
        ["bench_gmwm.py", "--wv-size", "1e7" if args.quick else "1e8", "--sel-size", "1e6" if args.quick else "1e7",
         "--json", str(out / "gmwm.json")],
        ["bench_readers.py", "--samples", "1e5" if args.quick else "1e6", "--json", str(out / "readers.json")],
        ["bench_fleet.py", *(["--files", "6", "--samples", "2e5"] if args.quick else []),
         "--json", str(out / "fleet.json")],
        # full size: a 4 GB file in /tmp and ~9 min
        ["bench_allan_chunked.py", *(["--n", "1e8", "--n-mem", "1e7"] if args.quick else []),
         "--json", str(out / "allan_chunked.json")],
    ]
    status = 0
    for job in jobs:
        print(f"\n## {' '.join(job)}\n", flush=True)
        status |= subprocess.call([sys.executable, str(HERE / job[0]), *job[1:]])
    return status


if __name__ == "__main__":
    sys.exit(main())
