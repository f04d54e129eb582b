"""``fogdrift batch --spec FILE``: the datasheet comparison in every summary row and counted on the console.

A 2-file batch (serial scheduler) over one gyro log and one accelerometer log of known white noise:

* gyro: 0.04 deg/s per sample at 100 Hz -> N = 0.04 * 3600 * sqrt(0.01) / 60 = 0.24 deg/sqrt(h);
* accelerometer: 0.0034 g per sample -> N = 0.0034 * 9.80665 * sqrt(0.01) * 60 = 0.200 m/s/sqrt(h).

The limits are chosen so that each verdict is decided by hand:

* gyro arw 0.5 deg/sqrt(h): pass (0.24, its interval a few % wide);
* gyro bias_instability 2 deg/h: cannot tell (white noise: the ADEV still falls at the longest tau, so B_min is an
  upper bound only, and that bound, ~4-7 deg/h on these 80-s logs, is above 2: a bound can never show a fail);
* accel vrw 0.1 m/s/sqrt(h): fail (0.2, interval far above 0.1);
* accel bias_instability 0.2 mg = 1.96e-3 m/s^2: pass (an upper bound of ~110-170 ug, below 200 ug).

A gyro row judged against the accelerometer section (or the reverse) would carry spec_vrw / spec_arw where it
must not, and a g not converted to m/s^2 would move the accelerometer verdicts: both are asserted.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.fleet import read_summary, run_batch
from fogdrift.fleet.runner import settings_sha256
from fogdrift.fleet.summary import spec_count_lines, spec_counts

SPEC = {"sensor": "test part", "gyro": {"arw": "0.5 deg/sqrt(h)", "bias_instability": "2 deg/h"},
        "accel": {"vrw": "0.1 m/s/sqrt(h)", "bias_instability": "0.2 mg"}}
UNIT = "gyro=deg/s,accel=g"


def _write(path, names, data, dt=0.01):
    lines = ["t_s," + ",".join(names)]
    lines += [",".join([repr(k * dt)] + [repr(float(v)) for v in row]) for k, row in enumerate(data)]
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    rng = np.random.default_rng(5)
    n = 8000
    d = tmp_path_factory.mktemp("specwire") / "in"
    d.mkdir()
    _write(d / "imu.csv", ["gx", "gy", "gz"], rng.normal(0.0, 0.04, (n, 3)) + [0.4, -0.4, -0.3])
    _write(d / "imu_accel.csv", ["ax", "ay", "az"], rng.normal(0.0, 0.0034, (n, 3)) + [0.0, 0.0, -1.0])
    return d


@pytest.fixture(scope="module")
def spec_file(folder):
    p = folder.parent / "part.json"
    p.write_text(json.dumps(SPEC))
    return p


def _check_rows(rows):
    rows = {r["axis"]: r for r in rows}
    assert set(rows) == {"gx", "gy", "gz", "ax", "ay", "az"}
    for a in ("gx", "gy", "gz"):
        r = rows[a]
        assert r["quantity"] == "angular_rate"
        assert (r["spec_arw"], r["spec_bias_instability"], r["spec_vrw"]) == ("pass", "cannot tell", None), a
        assert "within the limit 0.5 deg/sqrt(h)" in r["spec_arw_why"]
        assert "only an upper bound" in r["spec_bias_instability_why"]
        assert r["b_min_bound_only"] is True and r["b_min_dph"] > 2.0     # why it cannot tell
    for a in ("ax", "ay", "az"):
        r = rows[a]
        assert r["quantity"] == "specific_force"
        assert (r["spec_vrw"], r["spec_bias_instability"], r["spec_arw"]) == ("fail", "pass", None), a
        assert "exceeds the limit 0.1 m/s/sqrt(h)" in r["spec_vrw_why"]
        assert r["N_lo95_mps_rh"] > 0.1                                    # the fail, by the row's own interval
        assert r["b_min_ug"] < 200.0                                       # the pass: 0.2 mg = 200 ug
        assert "0.00196 m/s^2" in r["spec_bias_instability_why"]           # 0.2 mg in m/s^2 (9.80665e-3 * 0.2)


def test_batch_cli_spec_columns_and_counts(folder, spec_file, tmp_path):
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["batch", str(folder), "--glob", "*.csv", "--unit", UNIT, "--scheduler", "serial",
                                   "--spec", str(spec_file), "--out", str(out)], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    text = " ".join(res.output.split())
    assert "datasheet comparison: test part (part.json)" in text
    assert "gyro arw: 3 pass, 0 fail, 0 cannot tell (of 3 axes)" in text
    assert "gyro bias_instability: 0 pass, 0 fail, 3 cannot tell (of 3 axes)" in text
    assert "accel vrw: 0 pass, 3 fail, 0 cannot tell (of 3 axes)" in text
    assert "accel bias_instability: 3 pass, 0 fail, 0 cannot tell (of 3 axes)" in text
    assert "B compared: the IEEE-952 reading B_min" in text
    _check_rows(read_summary(out / "summary.parquet"))
    # the spec is part of the settings: a changed limit recomputes, the same spec skips
    res = CliRunner().invoke(app, ["batch", str(folder), "--glob", "*.csv", "--unit", UNIT, "--scheduler", "serial",
                                   "--spec", str(spec_file), "--out", str(out)], env={"COLUMNS": "200"})
    assert res.exit_code == 0 and "2 unchanged (skipped)" in " ".join(res.output.split()), res.output
    assert "gyro arw: 3 pass" in " ".join(res.output.split())          # cached rows keep their verdicts


def test_batch_gmwm_rows_judged_by_their_own_section(folder, tmp_path):
    res = run_batch([folder], tmp_path / "out", command="noise", settings={"load": {"unit": UNIT}, "spec": SPEC},
                    pattern="*.csv", scheduler="serial")
    assert (res.n_files, res.n_ok, res.n_error) == (2, 2, 0), [r.get("error") for r in res.rows]
    _check_rows(res.rows)
    assert spec_counts(res.rows)[("accel", "vrw")] == {"pass": 0, "fail": 3, "cannot tell": 0}


def test_bad_spec_is_one_line_before_any_work(folder, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("gyro:\n  arw: 2\n")   # no unit
    out = tmp_path / "out"
    res = CliRunner().invoke(app, ["batch", str(folder), "--glob", "*.csv", "--unit", UNIT, "--scheduler", "serial",
                                   "--spec", str(bad), "--out", str(out)], env={"COLUMNS": "200"})
    assert res.exit_code == 1
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and "has no unit" in lines[0] and "Traceback" not in res.output
    assert not (out / "summary.parquet").exists() and not any(out.glob("imu*"))
    # the library refuses it too, before any file is read
    from fogdrift.errors import ConfigError

    with pytest.raises(ConfigError, match="unknown gyro item"):
        run_batch([folder], tmp_path / "lib", settings={"spec": {"gyro": {"noise": "1 deg/sqrt(h)"}}},
                  pattern="*.csv", scheduler="serial")


def test_no_spec_keeps_the_settings_hash():
    """Without --spec the settings carry no spec key: earlier batches' folders stay valid (the hash of
    ``{"load": {}, "gaps": "error", "analysis": {...}}`` is what it was)."""
    from fogdrift.cli._spec import spec_settings
    from fogdrift.spec import parse_spec

    base = {"load": {}, "gaps": "error", "analysis": {"taus": "octave"}}
    assert settings_sha256("allan", base) == settings_sha256("allan", json.loads(json.dumps(base)))
    limits = parse_spec(SPEC)
    plain = spec_settings(limits, "part.json")
    assert plain == {"source": "part.json", **SPEC}                  # the file's mapping back, limits as written
    assert [(l.kind, l.item, l.value) for l in parse_spec(plain)["limits"]] == \
        [(l.kind, l.item, l.value) for l in limits["limits"]]
    assert settings_sha256("allan", {**base, "spec": plain}) != settings_sha256("allan", base)


def test_spec_counts_by_hand():
    rows = [{"quantity": "angular_rate", "spec_arw": "pass", "spec_bias_instability": "fail"},
            {"quantity": "angular_rate", "spec_arw": "cannot tell", "spec_bias_instability": "fail"},
            {"quantity": "specific_force", "spec_vrw": "pass", "spec_bias_instability": "pass"},
            {"quantity": "angular_rate", "status": "error", "spec_arw": "pass"},       # error rows: not counted
            {"quantity": None, "spec_arw": None}]                                    # nothing judged
    c = spec_counts(rows)
    assert c == {("gyro", "arw"): {"pass": 1, "fail": 0, "cannot tell": 1},
                 ("gyro", "bias_instability"): {"pass": 0, "fail": 2, "cannot tell": 0},
                 ("accel", "vrw"): {"pass": 1, "fail": 0, "cannot tell": 0},
                 ("accel", "bias_instability"): {"pass": 1, "fail": 0, "cannot tell": 0}}
    assert spec_count_lines(rows)[0] == "gyro arw: 1 pass, 0 fail, 1 cannot tell (of 2 axes)"
    assert spec_count_lines(rows)[2] == "accel vrw: 1 pass, 0 fail, 0 cannot tell (of 1 axis)"
    assert spec_count_lines([]) == []
