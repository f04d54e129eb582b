"""Digest of every command's output on the shared logs and the bundled record, to compare two versions of fogdrift.

Runs ``allan``, ``noise`` and ``analyze`` (as the README runs them) into ``OUT/<case>/`` with the fogdrift found on
``sys.path`` (set ``PYTHONPATH`` to a checkout's ``src``), then writes ``OUT/digest.json``: per output file, the
SHA-256 of its content with the run-dependent fields blanked (wall-clock seconds, the output path) and every float
to 12 significant digits; the run manifests (timestamps, versions) are not compared.  Compare two
digests with ``--compare A.json B.json``: it prints the files that differ and exits 1 if any does.

    PYTHONPATH=old/src python scripts/output_digest.py /tmp/old
    PYTHONPATH=src python scripts/output_digest.py /tmp/new
    python scripts/output_digest.py --compare /tmp/old/digest.json /tmp/new/digest.json
"""

from __future__ import annotations

import hashlib
import json
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "data"
#: (case, command line after "fogdrift") -- the logs every version has.
CASES = [
    ("rlg_allan", ["allan", "data/psins_lasergyro_rlg/psins_lasergyro_rlg.csv.gz", "--unit", "deg/h"]),
    ("rlg_noise", ["noise", "data/psins_lasergyro_rlg/psins_lasergyro_rlg.csv.gz", "--unit", "deg/h"]),
    ("imu1_allan", ["allan", str(SHARED / "adis16405_static/adis16405_imu1.csv.gz"), "--unit", "deg/s"]),
    ("imu1_noise", ["noise", str(SHARED / "adis16405_static/adis16405_imu1.csv.gz"), "--unit", "deg/s"]),
    ("romy_allan", ["allan", str(SHARED / "romy_teleseism_1hz/romy_teleseism_1hz.csv.gz"), "--unit", "rad/s"]),
    ("rlg_analyze", ["analyze", "data/psins_lasergyro_rlg/psins_lasergyro_rlg.csv.gz", "--unit", "deg/h"]),
]
#: JSON keys whose values depend on the run, not on the method (wall-clock seconds, paths, versions).
VOLATILE = {"wall_s", "elapsed_s", "fit_seconds", "seconds", "created", "created_utc", "started_utc", "finished_utc",
            "out", "output", "out_dir", "fogdrift_version", "versions", "duration_s_wall", "seal_sha256"}
#: Significant digits a float is compared to: the last bits of a BLAS reduction depend on its thread count and the
#: CPU, not on the method.
DIGITS = 12


def _clean(obj):
    if isinstance(obj, dict):
        return {k: (None if k in VOLATILE else _clean(v)) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_clean(v) for v in obj]
    if isinstance(obj, float):
        return float(f"{obj:.{DIGITS}g}")
    return obj


def _digest(path: Path) -> str:
    data = path.read_bytes()
    if path.suffix == ".json":
        data = json.dumps(_clean(json.loads(data)), sort_keys=True).encode()
    elif path.suffix in (".html", ".png", ".pdf"):
        return "-"  # rendered pictures and pages: their numbers are the JSON's
    return hashlib.sha256(data).hexdigest()


def run(out: Path) -> dict:
    out.mkdir(parents=True, exist_ok=True)
    digest = {}
    for case, args in CASES:
        if not Path(args[1]).is_absolute() and not (ROOT / args[1]).is_file():
            continue
        if Path(args[1]).is_absolute() and not Path(args[1]).is_file():
            continue
        target = out / case
        cmd = [sys.executable, "-m", "fogdrift", *args, "--out", str(target), "--json"]
        res = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
        digest[f"{case}/exit"] = str(res.returncode)
        digest[f"{case}/stdout.json"] = hashlib.sha256(json.dumps(_clean(json.loads(res.stdout)), sort_keys=True)
                                                       .encode()).hexdigest() if res.returncode == 0 else res.stderr
        for f in sorted(p for p in target.rglob("*") if p.is_file() and p.name != ".fogdrift-manifest.json"):
            digest[f"{case}/{f.relative_to(target)}"] = _digest(f)
    (out / "digest.json").write_text(json.dumps(digest, indent=1, sort_keys=True))
    return digest


def compare(a: Path, b: Path) -> int:
    da, db = json.loads(a.read_text()), json.loads(b.read_text())
    bad = sorted(k for k in set(da) | set(db) if da.get(k) != db.get(k))
    for k in bad:
        print(f"differs: {k}")
    print(f"{len(set(da) | set(db)) - len(bad)} identical, {len(bad)} different")
    return 1 if bad else 0


USAGE = "usage: output_digest.py OUT_FOLDER | output_digest.py --compare A/digest.json B/digest.json"

if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["--compare"] and len(args) == 3:
        sys.exit(compare(Path(args[1]), Path(args[2])))
    if len(args) != 1 or args[0].startswith("-"):  # never an output folder named like an option
        sys.exit(USAGE)
    run(Path(args[0]))
