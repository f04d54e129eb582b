"""The default scheduler of ``fogdrift batch`` (issue 35): the serial loop for small work, a local Dask cluster where
its start-up pays (fogdrift.fleet.schedule) -- the rule, without timing."""

from __future__ import annotations

import gzip

import numpy as np
import pytest

from fogdrift.fleet import run_batch, runner
from fogdrift.fleet.schedule import DASK_MIN_BYTES, choose, usable_cores, work_bytes

ADIS = 5 * 23_076_943          # the five ADIS16405 sessions, uncompressed gzip CSV
BENCH = 20 * 44_200_000        # bench_fleet.py's 20 CSV logs of 10^6 x 3 samples


@pytest.mark.parametrize("n_files, n_bytes, cores, dask, workers", [
    (5, ADIS, 2, False, 1),               # the ADIS sessions: serial (the local cluster was 1.6-2.3x slower)
    (20, BENCH, 2, True, 2),              # 880 MB: the local cluster, 2 workers (1.45x faster)
    (20, BENCH, 1, False, 1),             # one usable core: nothing runs side by side
    (1, 10 * DASK_MIN_BYTES, 8, False, 1),  # one file
    (3, DASK_MIN_BYTES, 8, True, 3),      # at the threshold: Dask, no more workers than files
    (3, DASK_MIN_BYTES - 1, 8, False, 1),
    (40, 4 * DASK_MIN_BYTES, 16, True, 16),
])
def test_the_rule(n_files, n_bytes, cores, dask, workers):
    c = choose(n_files, n_bytes, cores)
    assert (c.dask, c.workers) == (dask, workers)
    assert c.reason and "\n" not in c.reason


def test_usable_cores_are_the_affinity(monkeypatch):
    monkeypatch.setattr("os.sched_getaffinity", lambda pid: {3}, raising=False)
    assert usable_cores() == 1


def test_work_bytes_reads_the_gzip_size(tmp_path):
    text = b"t_s,gx\n" + b"".join(b"%d,0.05\n" % k for k in range(50_000))
    gz = tmp_path / "a.csv.gz"
    gz.write_bytes(gzip.compress(text))
    npy = tmp_path / "b.npy"
    np.save(npy, np.zeros(1000))
    bag = tmp_path / "bag"
    bag.mkdir()
    (bag / "metadata.yaml").write_text("x" * 10)
    (bag / "bag_0.db3").write_bytes(b"y" * 90)
    assert gz.stat().st_size < len(text)
    assert work_bytes([gz, npy, bag, tmp_path / "missing.csv"]) == len(text) + npy.stat().st_size + 100


def _logs(tmp_path, n):
    rng = np.random.default_rng(35)
    paths = []
    for k in range(n):
        p = tmp_path / f"u{k}.npy"
        np.save(p, rng.normal(size=2000))
        paths.append(p)
    return paths


SETTINGS = {"load": {"unit": "deg/h", "rate_hz": 100.0}}


def test_small_work_runs_serial_and_says_why(tmp_path):
    res = run_batch(_logs(tmp_path, 2), tmp_path / "o", settings=SETTINGS, page=False)
    assert res.scheduler.startswith("serial (in-process loop; chosen: 0 MB of input, less than the 268 MB")
    assert res.n_ok == 2


@pytest.mark.parametrize("scheduler, workers, big, expected", [
    (None, None, True, (None, 2)),        # large work: the local cluster, min(cores, files) workers
    (None, 3, False, (None, 3)),          # --workers asks for the local cluster whatever the size
    ("local", None, False, (None, None)),  # so does --scheduler local (workers: its own default)
    ("tcp://127.0.0.1:8786", None, False, ("tcp://127.0.0.1:8786", None)),
])
def test_which_runs_on_dask(tmp_path, monkeypatch, scheduler, workers, big, expected):
    seen = []

    def fake_dask(tasks, sched, n, done):
        seen.append((sched, n))
        for i, t in enumerate(tasks):
            done(i, runner.run_file(t))
        return "stand-in"

    monkeypatch.setattr(runner, "_run_dask", fake_dask)
    monkeypatch.setattr(runner, "usable_cores", lambda: 2)
    if big:
        monkeypatch.setattr(runner, "work_bytes", lambda paths: DASK_MIN_BYTES)
    res = run_batch(_logs(tmp_path, 3), tmp_path / "o", settings=SETTINGS, page=False, scheduler=scheduler,
                    workers=workers)
    assert seen == [expected] and res.scheduler == "stand-in"


def test_the_help_and_the_docs_name_the_threshold():
    from pathlib import Path

    import fogdrift.cli.batch as cli_batch

    text = f"{DASK_MIN_BYTES / 1e6:.0f} MB"
    assert text in Path(cli_batch.__file__).read_text()
    docs = Path(__file__).resolve().parents[2] / "docs"
    for name in ("fleets.md", "formats.md", "reference/cli.md"):
        assert text in (docs / name).read_text(), name
