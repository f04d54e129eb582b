"""batch over a folder with one gyro and one accelerometer file: each read as what it is, in one summary."""

from __future__ import annotations

import numpy as np
import pytest

from fogdrift.fleet import read_summary, run_batch


def _write(path, names, data, dt=0.01):
    lines = ["t_s," + ",".join(names)]
    lines += [",".join([repr(k * dt)] + [repr(float(v)) for v in row]) for k, row in enumerate(data)]
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture()
def folder(tmp_path):
    rng = np.random.default_rng(5)
    n = 8000
    d = tmp_path / "in"
    d.mkdir()
    # gyro: white noise of 0.04 deg/s per sample at 100 Hz -> N = 0.04 * 3600 * sqrt(0.01) / 60 = 0.24 deg/sqrt(h)
    _write(d / "imu.csv", ["gx", "gy", "gz"], rng.normal(0.0, 0.04, (n, 3)) + [0.4, -0.4, -0.3])
    # accelerometer: 0.0034 g per sample -> N = 0.0034 * 9.80665 * sqrt(0.01) * 60 = 0.2 m/s/sqrt(h)
    _write(d / "imu_accel.csv", ["ax", "ay", "az"], rng.normal(0.0, 0.0034, (n, 3)) + [0.0, 0.0, -1.0])
    return d


def test_batch_reads_each_file_as_what_it_is(folder, tmp_path):
    out = tmp_path / "out"
    res = run_batch([folder], out, settings={"load": {"unit": "gyro=deg/s,accel=g"}}, pattern="*.csv",
                    scheduler="serial")
    assert (res.n_files, res.n_ok, res.n_error) == (2, 2, 0)
    rows = {r["axis"]: r for r in read_summary(out / "summary.parquet")}
    assert {a: rows[a]["quantity"] for a in rows} == {"gx": "angular_rate", "gy": "angular_rate",
                                                     "gz": "angular_rate", "ax": "specific_force",
                                                     "ay": "specific_force", "az": "specific_force"}
    for a in ("ax", "ay", "az"):   # the accelerometer's figures in its own columns, never in the deg/h ones
        r = rows[a]
        assert r["N_dprh"] is None and r["N_hi95_dprh"] is None and r["b_min_dph"] is None
        assert r["N_mps_rh"] == pytest.approx(0.2, rel=0.08)
        assert r["N_lo95_mps_rh"] <= r["N_mps_rh"] <= r["N_hi95_mps_rh"]
    for a in ("gx", "gy", "gz"):
        r = rows[a]
        assert r["N_mps_rh"] is None
        assert r["N_dprh"] == pytest.approx(0.24, rel=0.08)
    assert (out / "fleet.html").is_file() and "m/s/√h" in (out / "fleet.html").read_text()


def test_batch_with_a_rate_unit_refuses_the_accelerometer_file(folder, tmp_path):
    res = run_batch([folder], tmp_path / "out", settings={"load": {"unit": "deg/s"}}, pattern="*.csv",
                    scheduler="serial", page=False)
    bad = [r for r in res.rows if r["status"] == "error"]
    assert [r["file"] for r in bad] == ["imu_accel.csv"]
    assert "channel 'ax' is named as a specific-force (accelerometer) channel" in bad[0]["error"]
    assert res.n_ok == 1


def test_split_by_quantity_moves_and_converts_by_hand():
    from fogdrift.fleet.tasks import split_by_quantity
    from fogdrift.io import from_array

    rec = from_array(np.zeros((10, 2)), dt_s=0.01, unit="g",
                     axis_names=["ax", "ay"])
    rows = [{"axis": "ax", "N_dprh": 0.2, "N_lo95_dprh": 0.1, "N_hi95_dprh": 0.3, "B_dph": 1e-3, "b_min_dph": 2e-3}]
    (r,) = split_by_quantity(rec, rows)
    assert r["quantity"] == "specific_force" and "N_dprh" not in r and r["N_mps_rh"] == 0.2 and r["N_hi95_mps_rh"] == 0.3
    assert r["B_ug"] == 1e-3 and r["b_min_ug"] == 2e-3          # an Allan row is in ug already
    (r,) = split_by_quantity(rec, rows, b_in_mps2=True)          # a GMWM row: m/s^2 -> ug, 1 ug = 9.80665e-6 m/s^2
    assert r["B_ug"] == pytest.approx(101.97162, rel=1e-6) and r["b_min_ug"] == pytest.approx(203.94324, rel=1e-6)
    assert r["N_mps_rh"] == 0.2
