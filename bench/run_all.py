"""Run every benchmark in sequence (each in its own process, so peak memory is not shared), then print ONE
table of ratios of all rows: fogdrift against its peers (allantools, PyWavelets, the readers' libraries, the
classic slope fit, serial loops) and the whole commands against issue 25's targets.  ``make bench`` calls
this; results and the machine go into ``bench/RESULTS.md`` by hand.

Usage::

    python bench/run_all.py            # full sizes: up to 10^8 samples in memory, 10^9 out of core (~40 min)
    python bench/run_all.py --quick    # 10^6 and 10^7 only, no analyze/compensate/demo rows (~5 min)
    python bench/run_all.py --summary  # only the table, from the JSON files of the last run (bench/_out)
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
OUT = HERE / "_out"


def _jobs(quick: bool) -> list[list[str]]:
    sizes = "1e6,1e7" if quick else "1e6,1e7,1e8"
    return [
        ["bench_allan.py", "--sizes", sizes, "--taus", "100", "--json", str(OUT / "allan.json")],
        ["bench_lifting.py", "--sizes", sizes, "--json", str(OUT / "lifting.json")],
        ["bench_elman.py", "--json", str(OUT / "elman.json")],
        ["bench_compensate.py", "--sizes", sizes, "--json", str(OUT / "compensate.json")],
        ["bench_noise.py", "--json", str(OUT / "noise.json")],
        ["bench_gmwm.py", "--wv-size", "1e7" if quick else "1e8", "--sel-size", "1e6" if quick else "1e7",
         "--json", str(OUT / "gmwm.json")],
        ["bench_readers.py", "--samples", "1e5" if quick else "1e6", "--json", str(OUT / "readers.json")],
        ["bench_fleet.py", *(["--files", "6", "--samples", "2e5"] if quick else []), "--json", str(OUT / "fleet.json")],
        # full size: a 4 GB file in /tmp and ~9 min
        ["bench_allan_chunked.py", *(["--n", "1e8", "--n-mem", "1e7"] if quick else []),
         "--json", str(OUT / "allan_chunked.json")],
        ["bench_cli.py", *(["--quick"] if quick else []), "--json", str(OUT / "cli.json")],
    ]


def _read(name: str):
    path = OUT / name
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def _row(bench, case, fd_s, peer="", peer_s=None, ratio=None, target="", note=""):
    return {"bench": bench, "case": case, "fogdrift_s": fd_s, "peer": peer, "peer_s": peer_s, "ratio": ratio,
            "target": target, "note": note}


def summary_rows() -> list[dict]:
    """One row per measured case, from the JSON files the benchmarks wrote (missing files are skipped)."""
    rows = []
    d = _read("allan.json")
    for r in (d or {}).get("rows", []):
        if r["tool"].startswith("fogdrift") and r.get("ratio"):
            rows.append(_row("allan", f"{r['tool']} {r['size']:.0e}, {r['n_tau']} tau", r["wall_s"], "allantools oadev",
                             r["wall_s"] * r["ratio"], r["ratio"], ">= 30x at 1e8 (exact)" if "exact" in r["tool"] else "",
                             f"max rel diff {r['max_rel_diff']:.1e}"))
    d = _read("lifting.json")
    for r in (d or {}).get("rows", []):
        ours = [k[:-2] for k in r if k.endswith("_s") and k != "pywt_s"]
        for k in ours:
            rows.append(_row("lifting", f"separate {k} {r['n']:.0e}", r[f"{k}_s"], "PyWavelets swt/iswt",
                             r["pywt_s"], r["pywt_s"] / r[f"{k}_s"], "",
                             f"max |diff| {r.get('max_abs_diff_vs_pywt', float('nan')):.1e}"))
    d = _read("noise.json")
    for r in d or []:
        rows.append(_row("noise fit", r["curve"], r["fogdrift_s"], "classic slope fit", r["classic_s"], r["ratio"]))
    d = _read("gmwm.json")
    if d:
        w = d.get("wv_vs_allan", {})
        if w:
            rows.append(_row("gmwm", f"wavelet variance {w['n']:.0e}", w["wv_s"], "allan_variance (octave)",
                             w["allan_octave_s"], w["ratio_allan_over_wv"]))
        s = d.get("selection", {})
        if s:
            rows.append(_row("gmwm", f"model selection {s['n']:.0e}", s["total_s"], note=f"selected {s['selected']}"))
    d = _read("readers.json")
    for r in (d or {}).get("rows", []):
        name, mb, t_fd, _, t_lib, _ = r
        rows.append(_row("readers", f"{name} ({mb:.0f} MB)", t_fd, "its library", t_lib,
                         None if not t_lib else t_lib / t_fd))
    d = _read("fleet.json")
    if d:
        rows.append(_row("batch", "Dask local vs serial loop", d["dask_s"], "serial loop", d["serial_s"], d["speedup"]))
        rows.append(_row("batch", "running cluster vs serial loop", d["dask_running_s"], "serial loop", d["serial_s"],
                         d["speedup_running"]))
    d = _read("compensate.json")
    for r in d or []:
        rows.append(_row("compensate stream", f"{r['model']} {r['size']:.0e} .npy", r["wall_s"],
                         note=f"peak RSS {r['peak_rss_mb']:.0f} MB"))
    d = _read("allan_chunked.json")
    if d:
        for name, size, wall, rss in d.get("rows", []):
            rows.append(_row("allan out-of-core", f"{name} {size:.0e}", wall,
                             note="" if rss is None else f"peak RSS {rss:.0f} MB"))
    d = _read("elman.json")
    for r in (d or {}).get("rows", []):
        if r.get("ratio"):
            rows.append(_row("elman", f"{r['model']} {r['n']:.0e}", r["many_wall_s"] / r["ratio"], "",
                             None, None, "", f"many models / one: {r['ratio']:.2f}x"))
    d = _read("cli.json")
    for r in (d or {}).get("rows", []):
        rows.append(_row("command", r["case"], r["fogdrift_s"], r.get("peer", ""), r.get("peer_s"), r.get("ratio"),
                         r["target"] + (" (met)" if r["met"] else " (NOT met)")
                         + (f"; FAILED: exit {r['rc']}" if r.get("rc") else ""),
                         f"peak RSS {r['rss_mb']:.0f} MB" + (f"; {r['note']}" if r.get("note") else "")))
    return rows


def print_summary() -> None:
    rows = summary_rows()
    load = os.getloadavg()
    print(f"\n## All rows (ratio = peer time / fogdrift time; load average now {load[0]:.1f} {load[1]:.1f} "
          f"{load[2]:.1f} on {os.cpu_count()} cores)\n")
    print("| bench | case | fogdrift s | peer | peer s | ratio | target | note |")
    print("|---|---|---:|---|---:|---:|---|---|")
    for r in rows:
        peer_s = "-" if r["peer_s"] is None else f"{r['peer_s']:.2f}"
        ratio = "-" if r["ratio"] is None else f"{r['ratio']:.1f}x"
        print(f"| {r['bench']} | {r['case']} | {r['fogdrift_s']:.2f} | {r['peer'] or '-'} | {peer_s} | {ratio} | "
              f"{r['target'] or '-'} | {r['note']} |")


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="skip the 10^8-sample cases and the long commands")
    ap.add_argument("--summary", action="store_true", help="only print the table from the last run's JSON files")
    args = ap.parse_args()
    OUT.mkdir(exist_ok=True)
    status = 0
    if not args.summary:
        for job in _jobs(args.quick):
            print(f"\n## {' '.join(job)}\n", flush=True)
            status |= subprocess.call([sys.executable, str(HERE / job[0]), *job[1:]])
    print_summary()
    return status


if __name__ == "__main__":
    sys.exit(main())
