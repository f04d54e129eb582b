"""``fogdrift noise`` (GMWM / Allan) and ``analyze --noise-method gmwm`` end to end.

Independent references: the WV the command writes is half the overlapping Allan variance at tau = scale (Haar
MODWT identity, checked against allantools); the published SMAC KVH DSP-1750 table reproduced exactly after the
deg/s -> deg/h conversion, and its white-noise coefficient N = 0.003094 deg/sqrt(h) (GMWM notes §8).
"""

from __future__ import annotations

import csv
import gzip
import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app

runner = CliRunner()
SMAC = Path("/work/shared/data/smac_fog_reference_curves/smac_wvar_gyro_reference.csv.gz")
needs_smac = pytest.mark.skipif(not SMAC.exists(), reason="shared SMAC reference curves not available")


def _ok(result):
    assert result.exit_code == 0, result.output + repr(result.exception)
    return result.output


def _csv(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_noise_gmwm_on_the_bundled_rlg(bundled_path, bundled_record, tmp_path):
    allantools = pytest.importorskip("allantools")
    _ok(runner.invoke(app, ["noise", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--segments", "whole",
                            "--out", str(tmp_path)]))  # the whole record, so the WV is that of the whole gz
    assert {p.name for p in tmp_path.iterdir()} >= {"noise.json", "wvar.csv", "noise.png"}
    doc = json.loads((tmp_path / "noise.json").read_text())
    assert doc["method"] == "gmwm" and doc["units"]["wvar"] == "(deg/h)^2"
    (ax,) = doc["axes"]
    sel = ax["selection"]
    assert ax["name"] == "gz" and ax["selected"] == sel["selected"]
    assert [c["model"] for c in sel["candidates"]][:2] == ["WN", "WN+RW"]  # every candidate, with WIC and reasons
    assert all(np.isfinite(c["wic"]) and (c["passed"] or c["reasons"]) for c in sel["candidates"])
    # the RLG's 2.75-Hz line (67 deg/h) dominates the short scales: they are excluded for it, named by frequency
    assert sel["excluded"] and all("no candidate explains" in e["reason"] or "spectral line at 2.748 Hz" in e["reason"]
                                   for e in sel["excluded"])
    assert any(e.get("line_share") for e in sel["excluded"]) and ax["spectral_lines"]
    assert "over-rejects" in ax["j_statistic"]["caveat"] and ax["j_statistic"]["df"] >= 1
    n = sel["ieee"]["terms"]["N_dprh"]
    assert n["unit"] == "deg/sqrt(h)" and n["lo95"] < n["value"] < n["hi95"]
    # wvar.csv: nu^2(scale) = AVAR_overlapping(tau = scale) / 2 (independent: allantools)
    rows = _csv(tmp_path / "wvar.csv")
    scale = np.array([float(r["scale_s"]) for r in rows])
    wv = np.array([float(r["wvar_dph2"]) for r in rows])
    x = np.asarray(bundled_record.axis("gz"), dtype=float)
    m = np.rint(scale[:6] / bundled_record.dt_s / 2).astype(int)  # Haar width 2^j = two averages of 2^(j-1)
    _, adev, _, _ = allantools.oadev(x, rate=1.0 / bundled_record.dt_s, data_type="freq", taus=m * bundled_record.dt_s)
    np.testing.assert_allclose(wv[:6], adev**2 / 2, rtol=1e-9)
    used = np.array([r["used"] == "1" for r in rows])
    assert used.sum() == len(sel["levels_used"]) and not used[0]


@needs_smac
def test_noise_on_the_published_kvh_curve(tmp_path):
    # the table's unit column is only 'unit_inferred' (README there: KVH deg/s): --unit states it
    result = runner.invoke(app, ["noise", "--curve", str(SMAC), "--sensor", "kvh1750", "--columns", "x",
                                 "--unit", "deg/s", "--out", str(tmp_path), "--json"])
    _ok(result)
    doc = json.loads(result.stdout)  # --json: stdout is the JSON alone
    assert doc == json.loads((tmp_path / "noise.json").read_text())
    (ax,) = doc["axes"]
    n = ax["selection"]["ieee"]["terms"]["N_dprh"]["value"]
    assert abs(n / 0.003094 - 1.0) < 0.05  # GMWM notes §8
    with gzip.open(SMAC, "rt") as fh:
        pub = [float(r["wvar"]) for r in csv.DictReader(fh) if r["sensor_key"] == "kvh1750" and r["axis"] == "x"]
    rows = _csv(tmp_path / "wvar.csv")
    np.testing.assert_allclose([float(r["wvar_dph2"]) for r in rows], np.array(pub) * 3600.0**2, rtol=1e-12)


@needs_smac
def test_curve_table_with_several_sensors_needs_sensor(tmp_path):
    result = runner.invoke(app, ["noise", "--curve", str(SMAC), "--out", str(tmp_path)])
    assert result.exit_code == 1 and "--sensor" in result.output and "Traceback" not in result.output


@pytest.mark.parametrize("model, fragment", [("WN+XX", "unknown component 'XX'"), ("", "pass --model"),
                                             ("WN+WN", "repeats WN")])
def test_bad_model_string_is_one_line_naming_the_flag(bundled_path, tmp_path, model, fragment):
    result = runner.invoke(app, ["noise", str(bundled_path), "--unit", "deg/h", "--model", model,
                                 "--out", str(tmp_path)])
    assert result.exit_code == 1, result.output
    lines = [ln for ln in result.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and fragment in lines[0], result.output
    assert "--model" in lines[0] or model == "WN+WN"
    assert not (tmp_path / "noise.json").exists()


@pytest.mark.slow
def test_fixed_model_and_allan_method(bundled_path, tmp_path):
    _ok(runner.invoke(app, ["noise", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--model",
                            "qn+arw", "--out", str(tmp_path / "g")]))
    sel = json.loads((tmp_path / "g" / "noise.json").read_text())["axes"][0]["selection"]
    assert sel["selected"] == "QN+WN" and [c["model"] for c in sel["candidates"]] == ["QN+WN"]
    _ok(runner.invoke(app, ["noise", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--method", "allan",
                            "--out", str(tmp_path / "a")]))
    doc = json.loads((tmp_path / "a" / "noise.json").read_text())
    assert doc["method"] == "allan" and "N" in doc["axes"][0]["noise"]["terms"]
    result = runner.invoke(app, ["noise", str(bundled_path), "--unit", "deg/h", "--method", "allan", "--robust",
                                 "--out", str(tmp_path / "b")])
    assert result.exit_code == 1 and "--method gmwm" in result.output


def test_neither_or_both_inputs_refused(bundled_path, tmp_path):
    result = runner.invoke(app, ["noise", "--out", str(tmp_path)])
    assert result.exit_code == 1 and "--curve" in result.output


@pytest.mark.slow
def test_analyze_noise_method_gmwm_end_to_end(bundled_path, tmp_path):
    _ok(runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--models",
                            "persistence", "--noise-method", "gmwm", "--out", str(tmp_path / "an")]))
    doc = json.loads((tmp_path / "an" / "analysis.json").read_text())
    assert doc["config"]["noise_method"] == "gmwm"
    g = doc["axes"][0]["gmwm"]
    # the same analysis as 'fogdrift noise' on the same axis
    _ok(runner.invoke(app, ["noise", str(bundled_path), "--unit", "deg/h", "--columns", "gz",
                            "--out", str(tmp_path / "n")]))
    ref = json.loads((tmp_path / "n" / "noise.json").read_text())["axes"][0]
    assert g["selected"] == ref["selected"]
    assert g["selection"]["ieee"]["terms"]["N_dprh"]["value"] == pytest.approx(
        ref["selection"]["ieee"]["terms"]["N_dprh"]["value"], rel=1e-9)
    html = (tmp_path / "an" / "report.html").read_text()
    assert "Noise model by GMWM" in html and g["selected"] in html
    # the first screen's headline is the GMWM model's, with the Allan N beside it as a cross-check
    head = doc["report_summary"]["noise"]
    assert head["headers"][0] == "whole record, native rate (GMWM)"
    rows = {r[0]: r[1] for r in head["rows"]}
    n_ref = ref["selection"]["ieee"]["terms"]["N_dprh"]
    check = rows["cross-check: GMWM vs Allan fit"]
    b = rows["B bias instability [deg/h]"]  # one B, named by its rule; a bound carries no interval
    assert rows["selected noise model (WIC)"].startswith(ref["selected"] + " (checks ")
    if ref["no_result"]:  # no candidate passed (the RLG's gz): no model value anywhere, the WV's own bound
        assert rows["N angle random walk [deg/√h]"].startswith("– (< ") and b.startswith("no result")
        assert check.startswith("N: neither estimator has a result") or check.startswith(("N is consistent",
                                                                                           "N differs"))
        assert " B: GMWM has no result" in check
    else:
        assert rows["N angle random walk [deg/√h]"].startswith(f"{n_ref['value']:.4g} [{n_ref['lo95']:.3g}, ")
        assert check.startswith("N agrees") or check.startswith("N differs")  # agreement, or why not, in words
        assert (" B agrees" in check) or (" B differs" in check) or (" B cannot be compared" in check)
        assert "min of the model's ADEV" in b or "flicker term" in b
        assert not (b.startswith("<") and "[" in b.split("(")[0])
    result = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--models", "persistence",
                                 "--noise-method", "kalman", "--out", str(tmp_path / "bad")])
    assert result.exit_code == 1 and "--noise-method" in result.output


def test_candidate_tables_are_behind_details(tmp_path):
    """The default console is one table per axis and the verdict lines; --details adds the candidate table, J and
    every excluded scale (white noise, 2^14 samples: a fast, passing fit)."""
    x = np.random.default_rng(3).standard_normal(2**14)
    path = tmp_path / "w.csv"
    np.savetxt(path, np.c_[np.arange(x.size) * 0.01, x], delimiter=",", header="t_s,gz", comments="")
    plain = _ok(runner.invoke(app, ["noise", str(path), "--unit", "deg/h", "--out", str(tmp_path / "a")]))
    assert "why rejected" not in plain and "J = " not in plain and "--details lists the candidates" in plain
    full = _ok(runner.invoke(app, ["noise", str(path), "--unit", "deg/h", "--out", str(tmp_path / "b"), "--details"]))
    assert "why rejected" in full and "J = " in full and "--details lists" not in full
    # the files are the same either way
    a, b = (json.loads((tmp_path / d / "noise.json").read_text())["axes"][0]["selected"] for d in "ab")
    assert a == b


def test_noise_files_of_an_accelerometer_say_m_s2(tmp_path):
    """An accelerometer's noise.json and wvar.csv carry m/s^2: the units block, the WV columns, the B headline and
    the spectral lines (a 5 Hz tone) name no deg/h; a gyro's say deg/h (white noise plus a tone, 2^14 samples)."""
    n, dt = 2**14, 0.01
    x = np.random.default_rng(4).standard_normal(n) * 0.01 + 0.02 * np.sin(2 * np.pi * 5.0 * dt * np.arange(n))
    for name, unit, rate, two in (("az", "m/s^2", "m/s^2", "m2ps4"), ("gz", "deg/h", "deg/h", "dph2")):
        path = tmp_path / f"{name}.csv"
        np.savetxt(path, np.c_[np.arange(n) * dt, x], delimiter=",", header=f"t_s,{name}", comments="")
        _ok(runner.invoke(app, ["noise", str(path), "--unit", unit, "--out", str(tmp_path / name)]))
        doc = json.loads((tmp_path / name / "noise.json").read_text())
        assert doc["units"]["rate"] == rate and doc["units"]["wvar"] == f"({rate})^2"
        ax = doc["axes"][0]
        assert ax["spectral_lines"] and all(line.endswith(rate) for line in ax["spectral_lines"])
        assert rate in ax["b_headline_text"] and ("deg" in ax["b_headline_text"]) == (name == "gz")
        assert ax.get("quantity", "angular_rate") == ("specific_force" if name == "az" else "angular_rate")
        head = (tmp_path / name / "wvar.csv").read_text().splitlines()[0]
        assert head == f"axis,level,scale_s,wvar_{two},ci_lo95_{two},ci_hi95_{two},used,model_wvar_{two}"


def test_gmwm_without_a_passing_candidate_prints_true_bounds_not_values():
    """No candidate passes: the table holds no model value, only the bounds the measured WV itself sets, and they
    hold the truth of a white-noise record with a slow oscillation no candidate describes."""
    from fogdrift.gmwm.analysis import GmwmAxis, ieee_rows
    from fogdrift.gmwm import haar_wvar, select_model
    import warnings

    dt, n_true = 0.01, 0.05  # deg/sqrt(h): white noise of sigma^2 = (60 N)^2 / dt per sample
    x = np.random.default_rng(1).standard_normal(2**16) * 60.0 * n_true / np.sqrt(dt)
    x = x + 30.0 * np.sin(np.arange(x.size) * 0.02)  # a slow oscillation (period 3.1 s): no candidate has it
    wv = haar_wvar(x, dt)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sel = select_model(wv, ["WN", "QN+WN"])
    ax = GmwmAxis("x", wv, sel)
    assert not sel.passed_checks
    rows = {r[0]: r for r in ieee_rows(ax)}
    assert all(isinstance(r[1], str) and r[2] is None and r[3] is None for r in rows.values())
    assert rows["B"][1] == "no result"
    b = ax.data_bounds()
    assert rows["N"][1] == f"< {b['N']:.4g}" and b["N"] >= n_true
    terms = ax.ieee_terms()
    assert terms["N"].status == "no_fit" and terms["N"].hi95 == b["N"]
