"""``fogdrift compensate``: causal (future input never changes past output), chunk-size invariant (bit for bit),
the native-rate hold of the one-step prediction computed independently, bias re-estimation, and the refusals.

Independent references: the causal drift from :func:`fogdrift.lifting.causal_drift` on the whole series and the AR
prediction written out by hand; the same log compensated whole and in chunks of 1, 777 and 10007 samples; the
CSV re-read with :func:`fogdrift.io.load`.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.testing import assert_array_equal
from typer.testing import CliRunner

from fogdrift.bundle import write_bundle
from fogdrift.compensate import compensate_file
from fogdrift.errors import ConfigError, FogdriftWarning, InsufficientDataError
from fogdrift.io import from_array, load
from fogdrift.pipeline import AnalysisConfig, run_models
from fogdrift.simulate import simulate

FS = 10.0  # native rate [Hz]; models at 1 Hz (factor 10)
MODELS = ("grey-elman", "elman", "gm11", "ar", "kalman", "persistence")


def _rate(n, seed, bias=3.0):
    return np.column_stack([simulate(n, 1 / FS, arw_dprh=0.05, rrw_dphrh=2.0, bias_dph=bias + 5 * s, seed=seed + s)
                            for s in (0, 1)])


@pytest.fixture(scope="module")
def bundle_dir(tmp_path_factory):
    rec = from_array(_rate(60000, 1) / 3600.0, dt_s=1 / FS, unit="deg/s", axis_names=["gx", "gz"])
    cfg = AnalysisConfig(models=MODELS, epochs=20, hidden=4, lags=3, gm_window=8)
    out = tmp_path_factory.mktemp("bundle") / "bundle"
    write_bundle(out, run_models(rec, cfg), cfg, rec)
    return out


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    """The same new session as .npy (deg/s, no time column) and as CSV declaring deg/s."""
    d = tmp_path_factory.mktemp("logs")
    x = _rate(30007, 7, bias=4.0) / 3600.0
    np.save(d / "log.npy", x)
    t = np.arange(x.shape[0]) / FS
    np.savetxt(d / "log.csv", np.column_stack([t, x]), delimiter=",", header="t_s,gx[deg/s],gz[deg/s]", comments="",
               fmt="%.17g")
    return d, x


def _run(bundle_dir, path, out, **kw):
    kw.setdefault("heading", False)
    kw.setdefault("artefacts", False)  # on by default; these tests are about the streamed output
    kw.setdefault("figures", False)
    if str(path).endswith(".npy"):
        kw.setdefault("rate_hz", FS)
        kw.setdefault("unit", "deg/s")  # a .npy declares no unit
        kw.setdefault("axis_map", "col0=gx,col1=gz")
    return compensate_file(bundle_dir, path, out, **kw)


def _npz(out):
    with np.load(out / "compensated.npz") as z:
        return {k: z[k] for k in z.files}


@pytest.mark.parametrize("model", ["bias"] + list(MODELS))
@pytest.mark.parametrize("bias", ["keep", "re-estimate:200"])
def test_future_input_never_changes_past_output(bundle_dir, logs, tmp_path, model, bias):
    d, x = logs
    j = 12345  # not on a 1-s boundary
    other = x.copy()
    other[j:] = other[j:] * -3.0 + 0.01
    np.save(tmp_path / "changed.npy", other)
    kw = dict(model=model, bias=bias, formats=("npz",), segment=64)
    _run(bundle_dir, d / "log.npy", tmp_path / "a", **kw)
    _run(bundle_dir, tmp_path / "changed.npy", tmp_path / "b", **kw)
    a, b = _npz(tmp_path / "a"), _npz(tmp_path / "b")
    assert_array_equal(a["compensated"][:j], b["compensated"][:j])
    # the drift estimate of interval k uses samples < 10 k only: unchanged up to the interval holding sample j
    assert_array_equal(a["drift_estimate"][: (j // 10 + 1) * 10], b["drift_estimate"][: (j // 10 + 1) * 10])
    assert not np.array_equal(a["compensated"][j:], b["compensated"][j:])
    if model not in ("bias", "persistence"):
        assert np.any(a["drift_estimate"][: j] != 0.0)  # the model was active before the change


@pytest.mark.parametrize("model", ["kalman", "elman", "ar"])
def test_chunked_output_is_identical_to_whole_file(bundle_dir, logs, tmp_path, model):
    d, _ = logs
    runs = {}
    for src in ("log.npy", "log.csv"):
        for chunk in (1 << 22, 1, 777, 10007):
            if chunk == 1 and src == "log.csv":
                continue
            out = tmp_path / f"{src}_{chunk}"
            _run(bundle_dir, d / src, out, model=model, chunk_samples=chunk, segment=64, bias="re-estimate:100")
            runs[(src, chunk)] = (_npz(out), (out / "compensated.csv").read_bytes())
    for src in ("log.npy", "log.csv"):
        ref_npz, ref_csv = runs[(src, 1 << 22)]
        for (s, chunk), (npz, csv) in runs.items():
            if s != src:
                continue
            for key in ref_npz:
                assert_array_equal(npz[key], ref_npz[key], err_msg=f"{src} chunk {chunk} {key}")
            assert csv == ref_csv, f"{src} chunk {chunk}"
    # the .npy and the CSV hold the same numbers: same output
    assert_array_equal(runs[("log.npy", 1 << 22)][0]["compensated"], runs[("log.csv", 1 << 22)][0]["compensated"])


def test_default_segments_give_the_same_output_for_any_chunk(bundle_dir, tmp_path):
    """A log longer than one default segment (2**18 native samples at factor 10: 26214 intervals)."""
    x = _rate(270_000, 11) / 3600.0
    np.save(tmp_path / "long.npy", x)
    outs = []
    for chunk in (1 << 20, 65537):
        _run(bundle_dir, tmp_path / "long.npy", tmp_path / str(chunk), model="kalman", chunk_samples=chunk,
             formats=("npz",))
        outs.append(_npz(tmp_path / str(chunk)))
    for key in outs[0]:
        assert_array_equal(outs[0][key], outs[1][key])


def test_drift_estimate_is_the_held_one_step_ar_prediction(bundle_dir, logs, tmp_path):
    """Independent path: block means, causal drift of the whole series (lifting.causal_drift), AR by hand."""
    from fogdrift.bundle import load_bundle
    from fogdrift.lifting import causal_drift

    d, x = logs
    _run(bundle_dir, d / "log.npy", tmp_path, model="ar", formats=("npz", "csv"), segment=100)
    got = _npz(tmp_path)
    b = load_bundle(bundle_dir)
    for k, name in enumerate(("gx", "gz")):
        ax = b.axis(name)
        ar = ax.models["ar"]
        z = (x[: 30000, k] * 3600.0).reshape(-1, 10).mean(axis=1) - ax.bias_dph - ax.earth_rate_dph
        c = causal_drift(z, ax.causal_window, b.wavelet, level=ax.level, mode=b.mode)
        p = np.full(z.size + 1, np.nan)
        for j in range(ax.causal_window - 1 + ar.order_, z.size + 1):
            p[j] = ar.intercept_ + sum(ar.coef_[i] * c[j - 1 - i] for i in range(ar.order_))
        drift = got["drift_estimate"][:, k] * 3600.0  # output unit deg/s
        held = np.repeat(np.nan_to_num(p, nan=0.0), 10)[: x.shape[0]]
        np.testing.assert_allclose(drift, held, rtol=0, atol=1e-9 * np.abs(held).max())
        assert np.all(np.ptp(drift[:30000].reshape(-1, 10), axis=1) == 0)  # constant over each interval
        np.testing.assert_allclose(got["compensated"][:, k] * 3600.0, x[:, k] * 3600.0 - ax.bias_dph - drift,
                                   rtol=0, atol=1e-9)
    # the CSV says the same, in the log's unit, and fogdrift reads it back
    rec = load(tmp_path / "compensated.csv", columns="col0,col1")
    assert rec.input_unit == "deg/s"
    np.testing.assert_allclose(rec.rate_dph / 3600.0, got["compensated"], rtol=1e-11, atol=1e-15)
    assert_array_equal(got["t_s"], np.arange(x.shape[0]) * (1 / FS))
    assert list(got["axis_names"]) == ["col0", "col1"] and str(got["unit"]) == "deg/s"


def test_bias_re_estimation_is_stated_and_causal(bundle_dir, logs, tmp_path):
    from fogdrift.bundle import load_bundle

    d, x = logs
    res = _run(bundle_dir, d / "log.csv", tmp_path, model="ar", bias="re-estimate:200")
    b = load_bundle(bundle_dir)
    line = next(m for m in res.messages if m.startswith("bias:"))
    assert "RE-ESTIMATED on the first 200 s" in line and "200 samples at 1 Hz" in line
    for k, name in enumerate(("gx", "gz")):
        expected = x[:2000, k].mean() * 3600.0 - b.axis(name).earth_rate_dph
        assert res.summary["axes"][k]["bias_dph"] == pytest.approx(expected, rel=1e-12)
    got = _npz(tmp_path)
    # during the calibration window: the bundle's bias, no drift model
    assert_array_equal(got["drift_estimate"][:2000], 0.0)
    np.testing.assert_allclose(got["compensated"][:2000, 0] * 3600.0, x[:2000, 0] * 3600.0 - b.axis("gx").bias_dph,
                               atol=1e-9)
    with pytest.raises(InsufficientDataError, match="needs 5000 s"):
        _run(bundle_dir, d / "log.csv", tmp_path / "short", bias="re-estimate:5000")


def test_unit_rate_and_axis_mismatches_are_refused_unless_mapped(bundle_dir, logs, tmp_path):
    d, x = logs
    t = np.arange(x.shape[0]) / FS
    np.savetxt(tmp_path / "rad.csv", np.column_stack([t, np.deg2rad(x)]), delimiter=",",
               header="t_s,gx[rad/s],gz[rad/s]", comments="", fmt="%.17g")
    with pytest.raises(ConfigError) as info:
        _run(bundle_dir, tmp_path / "rad.csv", tmp_path / "o1")
    assert "declares unit rad/s" in info.value.render({"unit": "--unit"}) and "--unit rad/s" in \
        info.value.render({"unit": "--unit"})
    res = _run(bundle_dir, tmp_path / "rad.csv", tmp_path / "o2", unit="rad/s", model="ar")
    assert res.summary["signal"]["channels"][0]["unit_as_read"] == "rad/s"
    assert (tmp_path / "o2" / "compensated.csv").read_text().splitlines()[0].startswith("t_s,gx[rad/s],gz[rad/s]")
    ref = _run(bundle_dir, d / "log.csv", tmp_path / "o3", model="ar")
    np.testing.assert_allclose(np.rad2deg(_npz(tmp_path / "o2")["compensated"]), _npz(tmp_path / "o3")["compensated"],
                               rtol=1e-9)
    assert ref.summary["signal"]["channels"][0]["unit_as_read"] == "deg/s"

    np.savetxt(tmp_path / "fast.csv", np.column_stack([np.arange(x.shape[0]) / 20.0, x]), delimiter=",",
               header="t_s,gx[deg/s],gz[deg/s]", comments="", fmt="%.17g")
    with pytest.raises(ConfigError, match="accept_rate"):
        _run(bundle_dir, tmp_path / "fast.csv", tmp_path / "o4")
    res = _run(bundle_dir, tmp_path / "fast.csv", tmp_path / "o5", accept_rate=True, model="ar")
    assert res.summary["block_average_factor"] == 20 and any("x20" in m for m in res.messages)

    with pytest.raises(ConfigError, match="log axis 'col0' has no model in the bundle.*axis_map"):
        compensate_file(bundle_dir, d / "log.npy", tmp_path / "o6", rate_hz=FS, unit="deg/s", heading=False)
    with pytest.raises(ConfigError, match="both map to bundle axis 'gx'"):
        _run(bundle_dir, d / "log.npy", tmp_path / "o7", axis_map="col0=gx,col1=gx")
    res = _run(bundle_dir, d / "log.npy", tmp_path / "o8", columns="1", axis_map="col1=gz", model="ar")
    assert res.summary["axes"][0]["bundle_axis"] == "gz" and any("not in the log" in m for m in res.messages)
    with pytest.raises(ConfigError, match="not in the bundle; pass model= as one of"):
        _run(bundle_dir, d / "log.csv", tmp_path / "o9", model="lstm")


def test_summary_heading_table_and_figure(bundle_dir, logs, tmp_path):
    d, _ = logs
    res = compensate_file(bundle_dir, d / "log.csv", tmp_path, heading=True, calib_s=200.0, step_s=200.0,
                          horizons_s=(60.0, 600.0))
    doc = json.loads((tmp_path / "compensation.json").read_text())
    assert doc["model"] == "kalman"  # the default when the bundle has one
    assert {h["axis"] for h in doc["heading"]} == {"gx", "gz"}
    models = {r["model"] for r in doc["heading"][0]["rows"]}
    assert models == {"constant bias", "grey-Elman", "Elman", "GM(1,1)", "AR(p)", "Kalman", "persistence"}
    assert doc["verdicts"][0]["kind"] == "heading"
    assert (tmp_path / "compensation_allan.png").stat().st_size > 10_000
    rows = doc["axes"][0]["allan_before_after"]
    assert rows and all(r["adev_before_dph"] > 0 for r in rows)
    assert res.heading[0].row("Kalman", 60.0).inside_sigma is not None


def test_cli_compensate_prints_the_heading_table_and_refuses_in_one_line(bundle_dir, logs, tmp_path):
    from fogdrift.cli import app

    d, _ = logs
    runner = CliRunner()
    result = runner.invoke(app, ["compensate", str(bundle_dir), str(d / "log.csv"), "--model", "ar", "--calibration",
                                 "200", "--origin-step", "200", "--horizons", "60,600", "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    assert "heading error after a 200-s calibration" in result.output and "constant bias" in result.output
    assert "(unit deg/s, 10 Hz, models at 1 Hz)" in " ".join(result.output.split())  # the log's rate: its signal
    assert (tmp_path / "o" / "compensated.npz").exists()
    np.savetxt(tmp_path / "rad.csv", np.column_stack([np.arange(100) / FS, np.zeros(100)]), delimiter=",",
               header="t_s,gx[rad/s]", comments="")
    result = runner.invoke(app, ["compensate", str(bundle_dir), str(tmp_path / "rad.csv"), "--out", str(tmp_path)])
    assert result.exit_code == 1
    assert "--unit rad/s" in result.output and "Traceback" not in result.output
    assert len([ln for ln in result.output.splitlines() if ln.strip()]) <= 3


def test_csv_without_a_declared_unit_is_refused_suggesting_the_bundles(bundle_dir, logs, tmp_path):
    # the ADIS16405 and most logger CSVs declare no unit: compensate refuses to guess (not even the bundle's unit)
    # and suggests it; with --unit the result equals the same numbers in a CSV that declares that unit
    d, x = logs
    t = np.arange(x.shape[0]) / FS
    np.savetxt(tmp_path / "plain.csv", np.column_stack([t, x]), delimiter=",", header="t_s,gx,gz", comments="",
               fmt="%.17g")
    with pytest.raises(ConfigError) as info:
        _run(bundle_dir, tmp_path / "plain.csv", tmp_path / "o1", model="ar")
    assert "pass --unit deg/s (the bundle was trained on deg/s)" in info.value.render({"unit": "--unit"})
    assert not (tmp_path / "o1" / "compensated.csv").exists()
    res = _run(bundle_dir, tmp_path / "plain.csv", tmp_path / "o1", model="ar", unit="deg/s")
    assert res.summary["signal"]["channels"][0]["unit_as_read"] == "deg/s"
    ref = _run(bundle_dir, d / "log.csv", tmp_path / "o2", model="ar")
    np.testing.assert_array_equal(_npz(tmp_path / "o1")["compensated"], _npz(tmp_path / "o2")["compensated"])
    assert ref.summary["signal"]["channels"][0]["unit_as_read"] == "deg/s"
    # the deprecated spelling still works, with a warning
    with pytest.warns(FogdriftWarning, match="deprecated"):
        res = _run(bundle_dir, tmp_path / "plain.csv", tmp_path / "o3", model="bias", apply_unit="deg/s")
    assert res.summary["signal"]["channels"][0]["unit_as_read"] == "deg/s"
