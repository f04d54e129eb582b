"""Benchmark (issue 35): short commands where users feel them, as alternating A/B pairs of fresh processes.

Each case is a pair of command lines, *rival* (the old way) and *fogdrift* (this tree), run alternately for
``--rounds`` rounds (the order flips every round, so a load change hits both); the figure is the median of the
per-round ratios rival / fogdrift, printed with the load average before and after.  Nothing here is a test: the
suite asserts rules (what is imported, which variables are set), never a time.

Cases:

* ``blas``: ``fogdrift allan`` on ADIS16405 session 1 with OpenBLAS on every core (``OPENBLAS_NUM_THREADS=<cores>``,
  what a command did before) against the default (one BLAS thread, set by ``fogdrift.cli.main``).
* ``stats``: ``import fogdrift.pipeline`` (this tree) with and without ``scipy.stats`` imported first: what the
  noise fit's move from ``scipy.stats`` to ``scipy.special`` (``noise.distributions``) saves an importer.
* ``csv``: reading ADIS16405 session 1 (CSV.gz, 10^6 rows x 4) in this process: ``numpy.loadtxt`` (``FAST_CSV =
  False``) against the fast path (pyarrow's reader, one thread), alternating; also checks the arrays are equal bit
  for bit.
* ``floor``: the start-up floor of the stack the commands stand on, as a fresh process (Python; NumPy, typer and
  rich; numba imported and one cached kernel called; matplotlib drawing one small log-log PNG on Agg; SciPy's
  ``optimize`` and ``special``), against ``fogdrift allan --help``, ``allan`` and ``noise`` on ADIS16405 session 1:
  what a command costs beyond the floor is fogdrift's own (reading, checks, statistics, fits, figure, files).
* ``base``: any command, this tree against another source tree (``--base DIR``, e.g. ``git archive <commit> src |
  tar -x -C DIR``), both under the same environment: ``--cmd 'allan {ADIS1} --unit deg/s'``.

Usage::

    python bench/bench_startup.py [--rounds 5] [--cases blas,stats,csv,floor] [--base DIR --cmd '...']
"""

from __future__ import annotations

import argparse
import os
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / "src"
ADIS1 = Path(os.environ.get("FOGDRIFT_ADIS", ROOT.parent / "shared/data/adis16405_static")) / "adis16405_imu1.csv.gz"
RLG = ROOT / "data/psins_lasergyro_rlg/psins_lasergyro_rlg.csv.gz"


def _load() -> str:
    a = os.getloadavg()
    return f"{a[0]:.1f} {a[1]:.1f} {a[2]:.1f}"


def _run(argv: list[str], env: dict) -> float:
    t = time.perf_counter()
    proc = subprocess.run(argv, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    dt = time.perf_counter() - t
    if proc.returncode != 0:
        raise SystemExit(f"failed ({proc.returncode}): {shlex.join(argv)}\n{proc.stderr[-2000:]}")
    return dt


def _env(src: Path, **extra) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    env.update(PYTHONPATH=str(src), **extra)
    return env


def pairs(name: str, rival: tuple, mine: tuple, rounds: int) -> dict:
    """Alternating rounds of (argv, env) pairs; returns the medians and the median per-round ratio."""
    _run(*mine)  # warm the disk and numba caches once
    _run(*rival)
    a, b = [], []
    before = _load()
    for i in range(rounds):
        if i % 2 == 0:
            a.append(_run(*rival))
            b.append(_run(*mine))
        else:
            b.append(_run(*mine))
            a.append(_run(*rival))
    ratios = [x / y for x, y in zip(a, b)]
    row = {"case": name, "rival_s": statistics.median(a), "fogdrift_s": statistics.median(b),
           "ratio": statistics.median(ratios), "load": f"{before} -> {_load()}", "rounds": rounds}
    print(f"| {name} | {row['rival_s']:.2f} | {row['fogdrift_s']:.2f} | {row['ratio']:.2f}x | "
          f"{min(ratios):.2f}-{max(ratios):.2f} | {row['load']} |", flush=True)
    return row


#: The ``floor`` case's process: what every fogdrift command that reads a record imports and starts (kept apart
#: from fogdrift's own modules).  ``{folder}`` holds the kernel's module, cached by numba beside it.
FLOOR = """
import sys
sys.path.insert(0, {folder!r})
import numpy as np, typer, rich.console, numba
import floor_kernel
floor_kernel.total(np.ones(8))
import matplotlib
matplotlib.use("Agg")
from matplotlib.figure import Figure
from matplotlib.backends.backend_agg import FigureCanvasAgg
fig = Figure(figsize=(4, 3)); FigureCanvasAgg(fig); ax = fig.subplots(); ax.loglog([1, 10, 100], [1, 0.3, 0.2])
fig.savefig({png!r}, dpi=100)
import scipy.optimize, scipy.special
"""
FLOOR_KERNEL = """
import numba

@numba.njit(cache=True)
def total(a):
    s = 0.0
    for x in a:
        s += x
    return s
"""


def floor_pairs(rounds: int, out: Path) -> list[dict]:
    """The floor process against three short commands, alternating (see the module docstring)."""
    kernel = out / "floor_kernel.py"
    kernel.write_text(FLOOR_KERNEL)
    floor = ([sys.executable, "-c", FLOOR.format(folder=str(out), png=str(out / "floor.png"))], _env(SRC))
    rows = []
    for name, words in (("allan --help", ["allan", "--help"]),
                        ("allan ADIS imu1", ["allan", str(ADIS1), "--unit", "deg/s", "--out", str(out / "fa")]),
                        ("noise ADIS imu1", ["noise", str(ADIS1), "--unit", "deg/s", "--out", str(out / "fn")])):
        rows.append(pairs(f"stack floor vs fogdrift {name} (ratio: floor / command)", floor,
                          ([sys.executable, "-m", "fogdrift", *words], _env(SRC)), rounds))
    return rows


def csv_pairs(rounds: int) -> dict:
    sys.path.insert(0, str(SRC))
    import numpy as np

    from fogdrift.io.readers import text

    def read(fast: bool):
        text.FAST_CSV = fast
        table = text.open_table(ADIS1)
        t = time.perf_counter()
        data = table.read(set(range(table.n_fields)))
        return time.perf_counter() - t, data

    read(True)  # imports pyarrow once
    a, b, same = [], [], True
    before = _load()
    for i in range(rounds):
        for fast in ((False, True) if i % 2 == 0 else (True, False)):
            dt, _ = read(fast)
            (b if fast else a).append(dt)
        same &= np.array_equal(read(True)[1].view(np.int64), read(False)[1].view(np.int64)) if i == 0 else True
    ratios = [x / y for x, y in zip(a, b)]
    row = {"case": "read ADIS imu1 CSV.gz: loadtxt vs fast", "rival_s": statistics.median(a),
           "fogdrift_s": statistics.median(b), "ratio": statistics.median(ratios), "load": f"{before} -> {_load()}"}
    print(f"| {row['case']} (bit-identical: {same}) | {row['rival_s']:.2f} | {row['fogdrift_s']:.2f} | "
          f"{row['ratio']:.2f}x | {min(ratios):.2f}-{max(ratios):.2f} | {row['load']} |", flush=True)
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--cases", default="blas,stats")
    ap.add_argument("--base", type=Path, help="another source tree (holding fogdrift/) for the 'base' case")
    ap.add_argument("--cmd", default="allan {ADIS1} --unit deg/s", help="fogdrift arguments for the 'base' case")
    args = ap.parse_args(argv)
    py = sys.executable
    out = Path(tempfile.mkdtemp(prefix="fogdrift-bench-startup-"))
    print(f"{os.cpu_count()} cores, Python {sys.version.split()[0]}, load {_load()}\n")
    print("| case | rival s (median) | fogdrift s (median) | ratio (median of rounds) | ratio range | load |")
    print("|---|---:|---:|---:|---:|---|")
    cases = args.cases.split(",")
    if "blas" in cases:
        cmd = [py, "-m", "fogdrift", "allan", str(ADIS1), "--unit", "deg/s", "--out", str(out / "a")]
        pairs("allan ADIS imu1: all-core BLAS vs one thread",
              (cmd, _env(SRC, OPENBLAS_NUM_THREADS=str(os.cpu_count()))), (cmd, _env(SRC)), args.rounds)
    if "stats" in cases:
        pairs("import fogdrift.pipeline: with scipy.stats vs without",
              ([py, "-c", "import scipy.stats, fogdrift.pipeline"], _env(SRC)),
              ([py, "-c", "import fogdrift.pipeline"], _env(SRC)), args.rounds)
    if "csv" in cases:
        csv_pairs(args.rounds)
    if "floor" in cases:
        floor_pairs(args.rounds, out)
    if "base" in cases:
        if args.base is None:
            ap.error("the 'base' case needs --base DIR")
        words = shlex.split(args.cmd.format(ADIS1=ADIS1, RLG=RLG))
        cmd = [py, "-m", "fogdrift", *words, "--out", str(out / "b")]
        pairs(f"fogdrift {args.cmd}: {args.base} vs this tree", (cmd, _env(args.base.resolve())), (cmd, _env(SRC)),
              args.rounds)
    return 0


if __name__ == "__main__":
    sys.exit(main())
