"""fogdrift batch: the five ADIS16405 sessions on a local Dask cluster (summary.parquet queried with DuckDB and
pandas, per-file outputs identical to the single command), failures as rows, re-runs that skip unchanged files,
an existing cluster given by address, and the fleet page naming a simulated outlier.

Independent checks: the single ``fogdrift allan`` command's own JSON; DuckDB's and pandas' Parquet readers;
a simulated fleet whose odd unit has a known, 3x larger white noise.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.errors import ConfigError
from fogdrift.fleet import COLUMNS, read_summary, run_batch
from fogdrift.io import load
from fogdrift.fleet import commands as fleet_commands

duckdb = pytest.importorskip("duckdb")
pd = pytest.importorskip("pandas")
pytest.importorskip("distributed")

ADIS = Path("/work/shared/data/adis16405_static")
SHARED = ADIS if ADIS.is_dir() else Path(__file__).resolve().parents[3] / "shared" / "data" / "adis16405_static"
runner = CliRunner()


def _csv(path: Path, x, dt=0.01):
    t = np.arange(len(x)) * dt
    path.write_text("t_s,gz[deg/h]\n" + "".join(f"{a:.2f},{float(b)!r}\n" for a, b in zip(t, x)))
    return path


@pytest.mark.slow
@pytest.mark.skipif(not SHARED.is_dir(), reason="needs the shared ADIS16405 recordings")
def test_done_when_adis_batch_on_local_dask_cluster(tmp_path):
    files = sorted(str(p) for p in SHARED.glob("adis16405_imu?.csv.gz"))  # the gyros; *_accel files are in g
    assert len(files) == 5
    out = tmp_path / "fleet"
    res = runner.invoke(app, ["batch", *files, "--unit", "deg/s", "--command", "allan", "--workers", "2",
                              "--out", str(out)])
    assert res.exit_code == 0, res.output + repr(res.exception)
    assert "5 files on local Dask cluster, 2 worker processes" in res.output
    q = duckdb.sql(f"SELECT file, axis, status, N_dprh, N_lo95_dprh, N_hi95_dprh, sha256, duration_s, rate_hz "
                   f"FROM '{out / 'summary.parquet'}' ORDER BY file, axis").fetchall()
    assert len(q) == 15 and {r[2] for r in q} == {"ok"}
    assert [r[1] for r in q[:3]] == ["gx", "gy", "gz"]
    readme = (SHARED / "README.md").read_text()
    for r in q:
        assert r[6] in readme                                   # SHA-256 of each file as its README lists it
        assert r[7] == pytest.approx(10_000.0) and r[8] == pytest.approx(100.0)
        assert r[4] <= r[3] <= r[5] and 1.5 < r[3] < 3.5      # ARW ~2.4 deg/sqrt(h) (data README)
    frame = pd.read_parquet(out / "summary.parquet")
    assert list(frame.columns) == [c[0] for c in COLUMNS] and len(frame) == 15
    # each file's folder holds what `fogdrift allan` writes, with the same numbers
    single = tmp_path / "single"
    res = runner.invoke(app, ["allan", files[0], "--unit", "deg/s", "--out", str(single)])
    assert res.exit_code == 0, res.output
    batch_doc = json.loads((out / "adis16405_imu1.csv.gz" / "allan.json").read_text())
    single_doc = json.loads((single / "allan.json").read_text())
    # the record screen's eigen-decompositions round in the last bit differently in a Dask worker's BLAS: its
    # numbers agree to 1e-12, its decisions (intervals, segments) exactly
    for a, b in zip(batch_doc["axes"], single_doc["axes"]):
        sa, sb = a.pop("screen"), b.pop("screen")
        assert {k: sa[k] for k in ("intervals", "quiet_segments", "segments_used", "stationary")} == \
            {k: sb[k] for k in ("intervals", "quiet_segments", "segments_used", "stationary")}
        assert np.allclose(sa["levels"], sb["levels"], rtol=1e-12) and sa["edf"] == pytest.approx(sb["edf"], rel=1e-12)
    assert batch_doc == single_doc
    page = (out / "fleet.html").read_text()
    assert "<h1>fogdrift fleet: allan over 5 files</h1>" in page and "data:image/png;base64," in page
    assert not re.search(r"(src|href)=\"https?:", page)        # self-contained
    # a second run skips every file: same SHA-256 and settings
    res = runner.invoke(app, ["batch", *files, "--unit", "deg/s", "--workers", "2", "--out", str(out)])
    assert "0 done, 5 unchanged (skipped), 0 failed" in res.output
    assert {r["status"] for r in read_summary(out / "summary.parquet")} == {"cached"}


def test_failures_are_rows_and_reruns_skip_only_unchanged(tmp_path):
    rng = np.random.default_rng(11)
    d = tmp_path / "in"
    d.mkdir()
    for k in range(3):
        _csv(d / f"unit{k}.csv", rng.normal(size=4000))
    (d / "broken.csv").write_text("t_s,gz[deg/h]\n0.00,1.0\n0.01,nan\n0.02,2.0\n")
    (d / "notes.txt").write_text("not a log\n")
    out = tmp_path / "out"
    settings = {"load": {"unit": "deg/h"}}
    res = run_batch([d], out, settings=settings, pattern="*.csv", scheduler="serial")
    assert (res.n_files, res.n_ok, res.n_error) == (4, 3, 1)
    bad = [r for r in res.rows if r["status"] == "error"]
    assert len(bad) == 1 and bad[0]["file"] == "broken.csv"
    assert re.search(r"DataFormatError: .*broken\.csv:3:gz: non-finite value", bad[0]["error"])
    assert bad[0]["axis"] is None and bad[0]["sha256"]
    got = duckdb.sql(f"SELECT status, count(*) FROM '{out / 'summary.parquet'}' GROUP BY status ORDER BY status")
    assert got.fetchall() == [("error", 1), ("ok", 3)]

    _csv(d / "unit1.csv", rng.normal(size=4000))                   # changed file: recomputed
    res = run_batch([d], out, settings=settings, pattern="*.csv", scheduler="serial")
    status = {r["file"]: r["status"] for r in res.rows}
    assert status == {"broken.csv": "error", "unit0.csv": "cached", "unit1.csv": "ok", "unit2.csv": "cached"}
    res = run_batch([d], out, settings={**settings, "analysis": {"taus": "decade"}}, pattern="*.csv",
                    scheduler="serial")                               # changed settings: all recomputed
    assert res.n_ok == 3 and res.n_cached == 0


def test_unexpected_exception_is_a_row_not_cached(tmp_path, monkeypatch):
    def explode(record, settings, out_dir):
        raise RuntimeError("boom")

    monkeypatch.setitem(fleet_commands.COMMANDS, "explode", fleet_commands.CommandSpec("explode", explode))
    f = _csv(tmp_path / "a.csv", np.zeros(100) + np.arange(100))
    for _ in range(2):                                               # retried, not cached
        res = run_batch([f], tmp_path / "o", command="explode", scheduler="serial", page=False)
        assert res.rows[0]["status"] == "error" and res.rows[0]["error"] == "RuntimeError: boom"
    assert "RuntimeError: boom" in (tmp_path / "o" / "a.csv" / "error.txt").read_text()
    assert not (tmp_path / "o" / "a.csv" / "batch.json").exists()


@pytest.mark.slow
def test_existing_cluster_by_address(tmp_path, monkeypatch):
    from distributed import LocalCluster

    from fogdrift.fleet import runner

    rng = np.random.default_rng(12)
    files = [_csv(tmp_path / f"g{k}.csv", rng.normal(size=3000)) for k in range(2)]
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None,
                      protocol="tcp://", host="127.0.0.1") as cluster:
        res = run_batch(files, tmp_path / "o", scheduler=cluster.scheduler_address, page=False)
    assert res.scheduler.startswith("Dask cluster at tcp://") and res.n_ok == 2
    monkeypatch.setattr(runner, "CONNECT_TIMEOUT_S", 1.0)            # nothing listens on port 9
    with pytest.raises(ConfigError, match="cannot reach the Dask scheduler"):
        run_batch(files, tmp_path / "o2", scheduler="tcp://127.0.0.1:9", page=False)


def test_fleet_page_names_the_odd_unit(tmp_path):
    rng = np.random.default_rng(13)
    files = []
    for k in range(7):
        sigma = 3.0 if k == 4 else 1.0                # unit 4: three times the white noise (3x N)
        files.append(_csv(tmp_path / f"u{k}.csv", rng.normal(scale=sigma, size=20_000)))
    res = run_batch(files, tmp_path / "o", scheduler="serial", settings={"analysis": {"terms": ["N"]}})
    n = {r["file"]: r["N_dprh"] for r in res.rows}
    assert n["u4.csv"] == pytest.approx(3 * np.median(list(n.values())), rel=0.1)
    page = res.page_path.read_text()
    outlier_table = page.split("<h2>Outliers</h2>")[1].split("<h2>")[0]
    assert "<td>u4.csv</td>" in outlier_table and outlier_table.count("<tr>") == 2   # header + u4 only


def test_bad_settings_fail_before_any_work(tmp_path):
    f = _csv(tmp_path / "a.csv", np.arange(10.0))
    with pytest.raises(ConfigError, match=r"unknown batch command 'nois'"):
        run_batch([f], tmp_path / "o", command="nois")
    with pytest.raises(ConfigError, match=r"unknown load settings \['colums'\]"):
        run_batch([f], tmp_path / "o", settings={"load": {"colums": "gz"}})
    with pytest.raises(ConfigError, match=r"is a folder; pass glob="):
        run_batch([tmp_path], tmp_path / "o")
    assert not (tmp_path / "o").exists()


@pytest.mark.slow
def test_analyze_batch_rows_carry_the_verdict(tmp_path):
    rng = np.random.default_rng(14)
    n = 40_000                                                      # 4000 s at 10 Hz
    drift = np.cumsum(rng.normal(scale=0.05, size=n))
    f = _csv(tmp_path / "a.csv", drift + rng.normal(size=n), dt=0.1)
    settings = {"analysis": {"models": ["ar", "persistence"], "model_rate_hz": 1.0, "level": 2}}
    res = run_batch([f], tmp_path / "o", command="analyze", settings=settings, scheduler="serial")
    row = res.rows[0]
    assert row["status"] == "ok", row["error"]
    assert row["verdict"].startswith(f"{row['axis']}: paper's measure (one step ahead") and "AR(p) RMSE" in row["verdict"]
    doc = json.loads((tmp_path / "o" / "a.csv" / "analysis.json").read_text())
    ev = doc["axes"][0]["evaluation"]                                # as `fogdrift analyze` stores it
    assert row["compensation_outcome"] == ev["headline"]["data"]["outcome"]
    assert row["compensation_outcome"] in ("reduces", "mixed", "none", "undetermined")
    assert (tmp_path / "o" / "a.csv" / "report.html").is_file()
    assert (tmp_path / "o" / "a.csv" / "bundle").is_dir()
    block = load(tmp_path / "o" / "a.csv" / "compensated_test_gz.csv")      # as `fogdrift analyze` writes it
    assert block.n_samples > 100
    assert json.loads((tmp_path / "o" / "a.csv" / "analysis.json").read_text())["sha256"] == row["sha256"]


@pytest.mark.slow
def test_noise_command_gmwm_rows_against_the_simulated_white_noise(tmp_path):
    # white noise of sd s deg/h at 100 Hz: N = s * sqrt(dt) / 60 deg/sqrt(h) (IEEE-952 angle random walk)
    rng = np.random.default_rng(15)
    sd = [10.0, 10.0, 30.0]
    files = []
    for k, s in enumerate(sd):
        p = tmp_path / f"u{k}.npy"
        np.save(p, rng.normal(0.0, s, 40_000))
        files.append(str(p))
    out = tmp_path / "o"
    res = runner.invoke(app, ["batch", *files, "--unit", "deg/h", "--rate", "100", "--command", "noise",
                              "--scheduler", "serial", "--out", str(out)])
    assert res.exit_code == 0, res.output
    got = duckdb.sql(f"SELECT file, N_dprh, N_lo95_dprh, N_hi95_dprh, N_status, noise_model, statistic "
                     f"FROM '{out / 'summary.parquet'}' ORDER BY file").fetchall()
    assert [g[0] for g in got] == ["u0.npy", "u1.npy", "u2.npy"]
    for (_, n, lo, hi, status, model, stat), s in zip(got, sd):
        assert n == pytest.approx(s * 0.1 / 60.0, rel=0.03) and lo < s * 0.1 / 60.0 < hi
        assert status == "resolved" and "WN" in model and stat == "wvar"
    assert {"noise.json", "wvar.csv", "noise.png", "batch.json"} <= {p.name for p in (out / "u0.npy").iterdir()}
    assert (out / "fleet.html").is_file()


def test_noise_command_passes_model_scales_and_robust_like_fogdrift_noise(tmp_path):
    # the batch row and files must be those of `fogdrift noise` with the same --model/--scales/--robust
    rng = np.random.default_rng(21)
    x = rng.normal(0.0, 10.0, 20_000) + np.cumsum(rng.normal(0.0, 0.05, 20_000))
    f = tmp_path / "u.npy"
    np.save(f, x)
    opts = ["--model", "WN+RW", "--scales", "8", "--robust"]
    out = tmp_path / "b"
    res = runner.invoke(app, ["batch", str(f), "--unit", "deg/h", "--rate", "100", "--command", "noise", *opts,
                              "--scheduler", "serial", "--out", str(out)])
    assert res.exit_code == 0, res.output + repr(res.exception)
    single = tmp_path / "s"
    res = runner.invoke(app, ["noise", str(f), "--unit", "deg/h", "--rate", "100", *opts, "--out", str(single)])
    assert res.exit_code == 0, res.output + repr(res.exception)
    want = json.loads((single / "noise.json").read_text())
    got = json.loads((out / "u.npy" / "noise.json").read_text())
    assert got["axes"] == want["axes"]
    (row,) = duckdb.sql(f"SELECT noise_model, fit_n_points FROM '{out / 'summary.parquet'}'").fetchall()
    assert row[0] == "WN+RW" and row[1] <= 8
    assert [row[1]] == [len(u) for u in _levels_used(got)]  # the scales the fit used, no more
    manifest = json.loads((out / "u.npy" / "batch.json").read_text())
    assert manifest["settings"]["gmwm"] == {"model": "WN+RW", "levels": 8, "robust": True}


def _levels_used(noise_json) -> list:
    """Every ``levels_used`` list in a noise.json (one per axis): the scales its selected fit used."""
    found = []

    def walk(x):
        if isinstance(x, dict):
            for k, v in x.items():
                found.append(v) if k == "levels_used" else walk(v)
        elif isinstance(x, list):
            for v in x:
                walk(v)
    walk(noise_json)
    return found


def test_batch_noise_row_counts_only_the_scales_the_fit_used(tmp_path):
    # issue 36: a GMWM point count that includes the excluded scales passed every batch test.  WN+RW through a
    # 2-tap moving average (an output filter): the selection leaves out the leading scales (levels 1-3 of 14, as
    # in tests/test_rules_table_edges.py); the row's fit_n_points is the count of noise.json's levels_used
    from fogdrift.gmwm import simulate_latent

    x = simulate_latent("WN+RW", [1.0, 1e-5], 2**16, seed=8)
    f = tmp_path / "filtered.npy"
    np.save(f, np.convolve(x, [0.5, 0.5], mode="valid"))
    out = tmp_path / "b"
    res = runner.invoke(app, ["batch", str(f), "--unit", "deg/h", "--rate", "100", "--command", "noise", "--model",
                              "WN+RW", "--scheduler", "serial", "--out", str(out)])
    assert res.exit_code == 0, res.output + repr(res.exception)
    (used,) = _levels_used(json.loads((out / "filtered.npy" / "noise.json").read_text()))
    assert used == list(range(4, 15))  # 14 scales, the first 3 excluded
    (row,) = duckdb.sql(f"SELECT fit_n_points, fit_dof FROM '{out / 'summary.parquet'}'").fetchall()
    assert row == (len(used), len(used) - 2)  # 11 points, 2 parameters (WN, RW)


@pytest.mark.parametrize(("args", "message"), [
    (["--command", "allan", "--model", "WN+RW"], "--model, --scales and --robust are options of --command noise"),
    (["--command", "analyze", "--robust"], "--model, --scales and --robust are options of --command noise"),
    (["--command", "noise", "--model", "WN+XX"], "XX"),
    (["--command", "noise", "--scales", "0"], "--scales must be an integer >= 1; got 0"),
])
def test_gmwm_options_refused_in_one_line_before_reading(tmp_path, args, message):
    out = tmp_path / "o"
    res = runner.invoke(app, ["batch", str(tmp_path / "missing.npy"), "--unit", "deg/h", "--rate", "100", *args,
                              "--scheduler", "serial", "--out", str(out)])
    assert res.exit_code != 0 and message in res.output, res.output
    assert "Traceback" not in res.output and not (out / "summary.parquet").exists()
