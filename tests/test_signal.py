"""The signal description (issue 21 item 1) and complete results (item 6): one rule per test.

Each fact about the numbers is made once and read back: the unit is parsed once per load, the decimation
factor decided once per run and read back by the bundle and the CLI, the lifting level and causal window
stored on the model axis where the pipeline decides them.  Independent references: the causal window from the
documented rule ``min(max(round(T_w / dt), (L - 1) 2^J), n_train)`` computed here by hand; scales from the
unit definitions (1 deg/s = 3600 deg/h).
"""

from __future__ import annotations

import json
import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift import units
from fogdrift.bundle import load_bundle, seal_manifest, write_bundle
from fogdrift.errors import ConfigError, ModelFileError
from fogdrift.io import from_array, load
from fogdrift.io import record as io_record
from fogdrift.pipeline import AnalysisAxis, AnalysisConfig, AllanAxis, ModelAxis, run_models
from fogdrift.signal import Channel, Sampling, SignalDescription, record_sampling, record_units
from fogdrift.simulate import simulate

runner = CliRunner()


def _csv(tmp_path, header="t_s,gz[deg/s]", n=400, dt=0.01, name="log.csv"):
    rng = np.random.default_rng(3)
    rows = [header] + [f"{k * dt:.6f},{v:.9f}" for k, v in enumerate(rng.normal(0.0, 1e-3, n))]
    p = tmp_path / name
    p.write_text("\n".join(rows) + "\n")
    return p


# -- made once by io --------------------------------------------------------------------------------------------
def test_load_describes_where_rate_and_unit_came_from(tmp_path):
    rec = load(_csv(tmp_path))
    smp, (ch,) = rec.signal.sampling, rec.signal.channels
    assert (smp.dt_source, smp.time_column, smp.time_unit, smp.time_unit_source) == ("time column", "t_s", "s",
                                                                                    "header")
    assert smp.dt_s == pytest.approx(0.01, rel=1e-9) and smp.block_average_factor == 1
    assert (ch.name, ch.quantity, ch.unit_as_read, ch.unit_source, ch.declared_unit) == (
        "gz", "angular_rate", "deg/s", "header", "deg/s")
    assert ch.scale_to_internal == 3600.0 and ch.internal_unit == "deg/h"
    meta = rec.metadata()["signal"]
    assert meta["sampling"]["dt_source"] == "time column" and meta["channels"][0]["unit_source"] == "header"
    assert json.loads(json.dumps(meta)) == meta  # JSON-ready


def test_rate_and_unit_options_are_recorded_as_options(tmp_path):
    p = tmp_path / "x.txt"
    p.write_text("\n".join(str(v) for v in range(50)) + "\n")
    rec = load(p, rate_hz=50.0, unit="inc:arcsec")
    assert rec.signal.sampling.dt_source == "rate option" and rec.signal.sampling.time_column is None
    ch = rec.signal.channels[0]
    assert ch.unit_source == "option" and ch.unit.kind == "increment"
    assert ch.scale_to_internal == pytest.approx(50.0)  # 1 arcsec per 20 ms = 50 deg/h


def test_the_unit_is_parsed_once_per_load(tmp_path, monkeypatch):
    calls = []
    real = units.parse_unit
    monkeypatch.setattr(units, "parse_unit", lambda *a, **k: calls.append(a) or real(*a, **k))
    load(_csv(tmp_path))  # declared in the header
    assert len(calls) == 1
    calls.clear()
    load(_csv(tmp_path, header="t_s,gz", name="b.csv"), unit="deg/s")  # given as an option
    assert len(calls) == 1


def test_description_follows_select_and_block_averaging():
    rec = from_array(np.ones((100, 2)), dt_s=0.01, unit="deg/s", axis_names=["gx", "gz"])
    low = rec.select("gz").to_rate(25.0)
    assert low.signal.names == ("gz",)
    smp = low.signal.sampling
    assert smp.block_average_factor == 4 and smp.dt_s == pytest.approx(0.04) and smp.native_dt_s == 0.01
    assert smp.rate_hz == pytest.approx(25.0) and smp.native_rate_hz == pytest.approx(100.0)


def test_a_description_that_does_not_match_the_record_is_refused():
    rec = from_array(np.ones(10), dt_s=0.01, unit="deg/s")
    wrong = SignalDescription(Sampling(dt_s=0.02, dt_source="argument"), rec.signal.channels)
    with pytest.raises(ConfigError, match="signal does not describe this record: dt_s"):
        io_record.GyroRecord(data_internal=rec.rate_dph, dt_s=0.01, axis_names=("axis0",), source="<array>",
                             input_unit="deg/s", scale_to_internal=3600.0, signal=wrong)


def test_the_record_reads_its_sampling_from_its_description_only():
    """``dt_s`` and ``block_average_factor`` are arguments of the record and properties of its ``signal``: one
    stored home.  Left out, they come from the description; a factor that disagrees with it is refused."""
    rec = from_array(np.ones(12), dt_s=0.01, unit="deg/s")
    low = rec.average_by(3)
    assert (low.dt_s, low.block_average_factor) == (low.signal.sampling.dt_s, 3) and low.dt_s == pytest.approx(0.03)
    again = io_record.GyroRecord(data_internal=low.rate_dph, axis_names=low.axis_names, source="<array>",
                                 input_unit="deg/s", scale_to_internal=3600.0, signal=low.signal)
    assert again.dt_s == low.dt_s and again.block_average_factor == 3
    assert "dt_s" not in vars(again) and "block_average_factor" not in vars(again)
    with pytest.raises(ConfigError, match="block_average_factor 3 vs 1"):
        io_record.GyroRecord(data_internal=low.rate_dph, axis_names=low.axis_names, source="<array>",
                             input_unit="deg/s", scale_to_internal=3600.0, signal=low.signal, block_average_factor=1)
    with pytest.raises(ConfigError, match="needs its sample interval"):
        io_record.GyroRecord(data_internal=low.rate_dph, axis_names=low.axis_names, source="<array>",
                             input_unit="deg/s", scale_to_internal=3600.0)


def test_description_round_trips_through_json_and_is_designed_for_specific_force():
    acc = Channel(name="ax", unit=units.parse_unit("mg", "specific_force"), unit_source="option",
                  declared_unit=None, scale_to_internal=9.80665e-3)
    d = SignalDescription(Sampling(dt_s=0.005, dt_source="rate option", native_dt_s=0.0025,
                                   block_average_factor=2), (acc,))
    back = SignalDescription.from_dict(json.loads(json.dumps(d.to_dict())))
    assert back == d and back.channels[0].internal_unit == "m/s^2"
    with pytest.raises(ConfigError, match="not block_average_factor 3"):
        Sampling(dt_s=0.005, dt_source="argument", native_dt_s=0.0025, block_average_factor=3)
    with pytest.raises(ConfigError, match="dt_source must be one of"):
        Sampling(dt_s=0.005, dt_source="guess")


# -- the one dt validator ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("kw", [{"rate_hz": 1e-300}, {"rate_hz": 1e300}, {"dt_s": 1e-300}, {"dt_s": 1e300}])
def test_absurd_sample_rates_are_one_line(tmp_path, kw):
    p = tmp_path / "x.txt"
    p.write_text("1\n2\n3\n")
    with pytest.raises(ConfigError) as ei:
        load(p, unit="deg/h", **kw)
    assert "\n" not in str(ei.value) and "between 1e-09" in str(ei.value)
    with pytest.raises(ConfigError, match="between 1e-09 s and 1e"):
        from_array([1.0, 2.0], dt_s=1e-300)


@pytest.mark.parametrize("rate", ["1e-300", "1e300"])
def test_cli_rate_absurd_is_one_line_naming_the_flag(tmp_path, rate):
    from fogdrift.cli import app

    p = tmp_path / "x.txt"
    p.write_text("\n".join(str(v) for v in range(64)) + "\n")
    res = runner.invoke(app, ["allan", str(p), "--rate", rate, "--unit", "deg/h", "--out", str(tmp_path / "o")])
    assert res.exit_code == 1
    text = res.output.strip()
    assert len(text.splitlines()) == 1 and "--rate" in text and "Traceback" not in text, res.output


# -- decided once, read back ------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def small():
    rate = simulate(3000, 0.5, arw_dprh=0.05, rrw_dphrh=0.5, bias_dph=2.0, seed=4)
    rec = from_array(rate, dt_s=0.5, unit="deg/h", axis_names=["gz"])
    cfg = AnalysisConfig(models=("ar", "persistence"), model_rate_hz=1.0, level=2, lags=3, causal_window_s=40.0)
    return rec, cfg


def test_decimation_factor_decided_once_and_read_back(small, monkeypatch, tmp_path):
    rec, cfg = small
    calls = []
    real = io_record.decimation_factor
    monkeypatch.setattr(io_record, "decimation_factor", lambda *a: calls.append(a) or real(*a))
    (ma,) = run_models(rec, cfg)
    assert calls == [(0.5, 1.0)] and ma.block_average_factor == 2
    calls.clear()
    (ma,) = run_models(rec, cfg, factor=2)  # the CLI hands the factor it decided: not decided again
    assert calls == []
    b = write_bundle(tmp_path / "bundle", [ma], cfg, rec)
    assert calls == [] and b.block_average_factor == 2 and load_bundle(b.path).block_average_factor == 2


def test_level_and_causal_window_are_stored_where_decided(small, tmp_path):
    rec, cfg = small
    (ma,) = run_models(rec, cfg)
    # db2 has filter length 4: reach (4 - 1) * 2**2 = 12 samples; 40 s at 1 s = 40; training 900 samples
    assert (ma.level, ma.causal_window) == (2, 40)
    d = ma.to_dict()
    assert (d["level"], d["causal_window"], d["causal_window_s"], d["block_average_factor"]) == (2, 40, 40.0, 2)
    back = load_bundle(write_bundle(tmp_path / "b", [ma], cfg, rec).path)
    assert (back.axis("gz").level, back.axis("gz").causal_window) == (2, 40)


def test_cli_model_decides_the_factor_once(tmp_path, monkeypatch):
    from fogdrift.cli import app

    calls = []
    real = io_record.decimation_factor
    monkeypatch.setattr(io_record, "decimation_factor", lambda *a: calls.append(a) or real(*a))
    x = simulate(4000, 0.5, arw_dprh=0.05, rrw_dphrh=0.5, bias_dph=2.0, seed=5)
    p = tmp_path / "g.csv"
    p.write_text("t_s,gz[deg/h]\n" + "".join(f"{k * 0.5:.3f},{v:.9f}\n" for k, v in enumerate(x)))
    res = runner.invoke(app, ["model", str(p), "--models", "persistence", "--level", "2", "--out",
                              str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    assert calls == [(0.5, 1.0)]
    assert "1 Hz (2 Hz block-averaged in blocks of 2)" in res.output


# -- the bundle carries the description; hostile manifests are one line -------------------------------------------
@pytest.fixture(scope="module")
def bundle_dir(tmp_path_factory):
    rate = simulate(3000, 0.5, arw_dprh=0.05, rrw_dphrh=0.5, bias_dph=2.0, seed=4)
    rec = from_array(rate / 3600.0, dt_s=0.5, unit="deg/s", axis_names=["gz"])
    cfg = AnalysisConfig(models=("persistence",), model_rate_hz=1.0, level=2, lags=3, causal_window_s=40.0)
    out = tmp_path_factory.mktemp("sb") / "bundle"
    write_bundle(out, run_models(rec, cfg), cfg, rec)
    return out


def _edited(bundle_dir, tmp_path, edit):
    import shutil

    d = tmp_path / "edited"
    shutil.copytree(bundle_dir, d)
    doc = json.loads((d / "manifest.json").read_text())
    edit(doc)
    (d / "manifest.json").write_text(json.dumps(seal_manifest(doc)))
    return d


def test_bundle_carries_the_signal_description(bundle_dir):
    b = load_bundle(bundle_dir)
    ch = b.signal.channel("gz")
    assert (ch.unit_as_read, ch.scale_to_internal, ch.unit_source) == ("deg/s", 3600.0, "argument")
    assert b.signal.sampling.dt_s == 0.5


def _v2_without_signal(d):
    """The manifest in the format-2 layout without a description: the intervals as native_dt_s and model_dt_s, the
    unit as input_unit."""
    sig = d.pop("signal")
    dt, k = sig["sampling"]["dt_s"], d["block_average_factor"]
    d.update(format_version=2, native_dt_s=dt, native_rate_hz=1 / dt, model_dt_s=k * dt, model_rate_hz=1 / (k * dt),
             input_unit=sig["channels"][0]["unit_as_read"], rate_unit_internal="deg/h")


def test_format_2_bundle_without_a_description_still_loads(bundle_dir, tmp_path):
    b = load_bundle(_edited(bundle_dir, tmp_path, _v2_without_signal))
    assert b.signal.sampling.dt_source == "bundle" and b.signal.channel("gz").unit_as_read == "deg/s"
    assert (b.native_dt_s, b.model_dt_s, b.block_average_factor) == (0.5, 1.0, 2)


def test_format_3_bundle_without_a_description_is_refused(bundle_dir, tmp_path):
    with pytest.raises(ModelFileError) as ei:
        load_bundle(_edited(bundle_dir, tmp_path, lambda d: d.pop("signal")))
    assert str(ei.value).endswith("manifest.json: signal: missing (the training log's signal description holds the "
                                  "bundle's sampling and unit)")


@pytest.mark.parametrize("edit, where", [
    (lambda d: d["axes"][0].update(causal_window=10**12), "causal_window: expected at most"),
    (lambda d: d["axes"][0].update(bias_dph=1e300), "bias_dph: expected |bias_dph|"),
    (lambda d: d["signal"]["sampling"].update(dt_s=1e-300, native_dt_s=1e-300), "signal: dt_s"),
    (lambda d: d.update(block_average_factor=10**12), "block_average_factor: the modelling interval"),
    (lambda d: d.update(block_average_factor=0), "block_average_factor: expected an integer >= 1"),
    (lambda d: d.update(latitude_deg=400.0), "latitude_deg"),
    (lambda d: d.update(input_unit="rad/s"), "input_unit: 'rad/s' is not the unit of signal.channels ['gz']"),
    (lambda d: d["signal"]["channels"][0].update(unit_as_read="furlong/s"), "signal: unknown"),
    (lambda d: d["signal"]["sampling"].update(dt_source="magic"), "signal: dt_source"),
])
def test_absurd_bundle_fields_are_refused_in_one_line(bundle_dir, tmp_path, edit, where):
    with pytest.raises(ModelFileError) as ei:
        load_bundle(_edited(bundle_dir, tmp_path, edit))
    assert where in str(ei.value) and "\n" not in str(ei.value)


def test_bundle_argument_that_is_a_file_is_one_line(bundle_dir, tmp_path):
    f = tmp_path / "not_a_bundle.csv"
    f.write_text("1\n")
    with pytest.raises(ModelFileError, match="is a file; expected a bundle directory"):
        load_bundle(f)
    assert load_bundle(bundle_dir / "manifest.json").axis_names == ("gz",)


# -- item 6: one validation point, results complete when built -----------------------------------------------------
def test_validate_checks_without_mutating():
    cfg = AnalysisConfig(models=("AR", "ar", "Persistence"))
    v = cfg.validate()
    assert cfg.models == ("AR", "ar", "Persistence") and v.models == ("ar", "persistence")
    assert v.validate() is v


@pytest.mark.parametrize("bad, opt", [
    (dict(wavelet="db99"), "wavelet"), (dict(mode="wrap"), "mode"), (dict(training="sgd"), "training"),
    (dict(estimator="fancy"), "estimator"), (dict(terms=("N", "X")), "terms"), (dict(level=0), "level"),
    (dict(level="high"), "level"), (dict(taus="weekly"), "taus"), (dict(fit_tau_s=(10.0, 1.0)), "fit_tau_s"),
    (dict(gm_window=2), "gm_window"), (dict(model_rate_hz=float("inf")), "model_rate_hz"),
    (dict(model_rate_hz=1e300), "model_rate_hz"), (dict(causal_window_s=float("nan")), "causal_window_s"),
    (dict(latitude_deg=10.0, earth_axes={"gz": "sideways"}), "axis orientation"), (dict(seed=1.5), "seed"),
    (dict(train_fraction="most"), "train_fraction"), (dict(val_fraction=None), "val_fraction"),
    (dict(lags="4"), "lags"), (dict(latitude_deg="north"), "latitude"),
    (dict(earth_axes={"gz": "up"}), "without a latitude; pass latitude_deg="),
])
def test_validate_checks_every_setting(bad, opt):
    with pytest.raises(ConfigError, match=opt):
        AnalysisConfig(**bad).validate()


def test_result_fields_are_typed_not_object():
    for cls in (AllanAxis, AnalysisAxis, ModelAxis):
        assert all("object" not in str(t) for t in cls.__annotations__.values()), cls.__annotations__
    assert AnalysisAxis.__annotations__["evaluation"] == "AxisEvaluation | None"
    assert AnalysisAxis.__annotations__["gmwm"] == "GmwmAxis | None"


def test_noise_fit_built_complete_with_outliers():
    from fogdrift.pipeline import analyse_allan

    x = np.random.default_rng(0).normal(0.0, 1.0, 4096)
    x[100] = 50.0
    from fogdrift.outliers import treat_outliers

    treated, report = treat_outliers(x, "clip")
    ax = analyse_allan("gz", treated, 1.0, AnalysisConfig(), outliers=report)
    assert ax.outliers is report and ax.noise.outliers == report.to_dict() and report.count >= 1


def test_models_have_one_validation_hook():
    import fogdrift.models.ar
    import fogdrift.models.grey
    import fogdrift.models.kalman  # noqa: F401  (the subclasses below)
    from fogdrift.models.base import DriftModel

    def subclasses(c):
        return [c] + [s for k in c.__subclasses__() for s in subclasses(k)]

    classes = subclasses(DriftModel)
    assert len(classes) >= 4
    for cls in classes:
        assert callable(cls._validate)
        assert not hasattr(cls, "_validate_params") and not hasattr(cls, "_check_params"), cls


@pytest.mark.parametrize("args, flag", [(["--gm-window", "2"], "--gm-window"), (["--fit-taus", "10:1"], "--fit-taus"),
                                        (["--taus", "weekly"], "--taus"), (["--wavelet", "db99"], "db99")])
def test_cli_analyze_refuses_a_bad_setting_in_one_line_before_reading(tmp_path, args, flag):
    from fogdrift.cli import app

    missing = tmp_path / "never_read.csv"  # the settings are refused before the file is opened
    missing.write_text("t_s,gz[deg/h]\n0,1\n")
    res = runner.invoke(app, ["analyze", str(missing), *args, "--out", str(tmp_path / "o")])
    assert res.exit_code == 1 and len(res.output.strip().splitlines()) == 1 and flag in res.output, res.output


def test_separation_axis_is_complete_when_built():
    from fogdrift.pipeline import run_separation

    x = simulate(2000, 1.0, arw_dprh=0.05, rrw_dphrh=0.5, bias_dph=3.0, seed=1)
    (sep,) = run_separation(from_array(x, dt_s=1.0), AnalysisConfig(model_rate_hz=None, level=2))
    assert sep.mean_removed_dph == pytest.approx(float(np.mean(x)), rel=1e-12) and sep.level == 2
    assert abs(float(np.mean(sep.rate_dph))) < 1e-9  # the mean stored is the one removed


def test_cli_analyze_decides_the_factor_once_and_echoes_the_sources(tmp_path, monkeypatch):
    from fogdrift.cli import app

    calls = []
    real = io_record.decimation_factor
    monkeypatch.setattr(io_record, "decimation_factor", lambda *a: calls.append(a) or real(*a))
    x = simulate(4000, 0.5, arw_dprh=0.05, rrw_dphrh=0.5, bias_dph=2.0, seed=6)
    p = tmp_path / "g.csv"
    p.write_text("t_s,gz\n" + "".join(f"{k * 0.5:.3f},{v / 3600.0:.12f}\n" for k, v in enumerate(x)))
    res = runner.invoke(app, ["analyze", str(p), "--unit", "deg/s", "--models", "persistence", "--level", "2",
                              "--no-heading", "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    assert calls == [(0.5, 1.0)]
    assert "(dt 0.5 s from time column 't_s'); units: rate deg/s (--unit), time s (declared in the header)" in res.output
    doc = json.loads((tmp_path / "o" / "bundle" / "manifest.json").read_text())
    assert doc["block_average_factor"] == 2 and doc["signal"]["channels"][0]["unit_source"] == "option"


@pytest.mark.parametrize("field, value", [("scale_to_internal", "big"), ("scale_to_internal", None),
                                          ("scale_to_internal", -1.0), ("quantity", "pressure"),
                                          ("unit_as_read", 5), ("unit_source", ["x"])])
def test_a_damaged_channel_is_one_config_error(field, value):
    d = from_array([1.0, 2.0], dt_s=0.01, unit="deg/s").signal.to_dict()
    d["channels"][0][field] = value
    with pytest.raises(ConfigError):
        SignalDescription.from_dict(d)


def test_cli_apply_to_echo_names_the_flag_that_gave_the_unit(tmp_path):
    from fogdrift.cli import app

    for name, seed, scale, header in (("a.csv", 7, 1.0 / 3600.0, "t_s,gz[deg/s]"), ("b.csv", 8, 1.0, "t_s,gz")):
        x = simulate(4000, 0.5, arw_dprh=0.05, rrw_dphrh=0.5, bias_dph=2.0, seed=seed)
        (tmp_path / name).write_text(header + "\n" + "".join(f"{k * 0.5:.3f},{v * scale:.12f}\n"
                                                             for k, v in enumerate(x)))
    res = runner.invoke(app, ["analyze", str(tmp_path / "a.csv"), "--apply-to", str(tmp_path / "b.csv"),
                              "--apply-unit", "deg/h", "--models", "persistence", "--level", "2", "--no-heading",
                              "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    assert "a.csv: 4000 samples" in res.output and "units: rate deg/s (declared in the header)" in res.output
    assert "b.csv: 4000 samples" in res.output and "units: rate deg/h (--apply-unit)" in res.output


# -- a result document's record block: its sampling is read from signal.sampling, through one function ----------
def test_record_sampling_reads_the_signal_and_never_its_synonyms():
    meta = json.loads(json.dumps(from_array([1.0, 2.0, 3.0, 4.0], dt_s=0.01).to_rate(50.0).metadata()))
    smp = record_sampling(meta)
    assert (smp.dt_s, smp.rate_hz, smp.native_rate_hz, smp.block_average_factor) == (0.02, 50.0, 100.0, 2)
    # a block that repeats the sampling beside its signal: the synonyms are not read
    synonyms = {"dt_s": 9.0, "fs_hz": 1 / 9.0, "native_fs_hz": 3.0, "block_average_factor": 7}
    assert record_sampling({**meta, **synonyms}) == smp


def test_record_sampling_refuses_the_synonyms_alone_in_one_line():
    with pytest.raises(ConfigError) as ei:
        record_sampling({"dt_s": 0.04, "block_average_factor": 4}, "run/allan.json: the record")
    assert str(ei.value) == ("run/allan.json: the record states its sampling only as dt_s, block_average_factor, not "
                             "in 'signal.sampling' where this fogdrift reads it; re-run the fogdrift command that "
                             "wrote the file")
    with pytest.raises(ConfigError, match=r"^the model_record's signal\.sampling: dt_source must be one of"):
        record_sampling({"signal": {"sampling": {"dt_s": 0.5, "dt_source": "guess"}}}, "the model_record")
    with pytest.raises(ConfigError, match=r"^the record's signal: expected an object; got list$"):
        record_sampling({"signal": [1]})
    assert record_sampling({"n_samples": 3}) is None and record_sampling(None) is None


#: The unit keys a record block wrote beside its signal description, with values that contradict it.
_UNIT_SYNONYMS = {"input_unit": "rad/s", "declared_units": ["rad/s"], "scale_to_dph": 1.0, "rate_unit": "m/s^2",
                  "scale_to_internal": 7.0, "internal_unit": "m/s^2"}


def test_record_units_read_the_signal_and_never_the_old_keys():
    rec = from_array([0.1, 0.2, 0.3], dt_s=0.01, unit="deg/s", axis_names=["gz"])
    meta = json.loads(json.dumps(rec.metadata()))
    u = record_units(meta)
    assert (u.input_unit, u.declared_units, u.scale_to_internal, u.internal_unit, u.all_gyro) == \
        ("deg/s", (None,), 3600.0, "deg/h", True)
    assert u.channels == rec.signal.channels
    # a block that repeats the units beside its signal (and contradicts it): the old keys are not read
    assert record_units({**meta, **_UNIT_SYNONYMS}) == u


def test_record_units_refuse_the_old_keys_alone_in_one_line():
    with pytest.raises(ConfigError) as ei:
        record_units({"input_unit": "deg/s", "scale_to_dph": 3600.0, "rate_unit": "deg/h"},
                     "run/allan.json: the record")
    assert str(ei.value) == ("run/allan.json: the record states its units only as input_unit, scale_to_dph, "
                             "rate_unit, not in 'signal.channels' where this fogdrift reads them; re-run the fogdrift "
                             "command that wrote the file")
    with pytest.raises(ConfigError, match=r"^the model_record's signal.channels: expected a list of one or more"):
        record_units({"signal": {"sampling": {}}}, "the model_record")
    with pytest.raises(ConfigError, match=r"^the record's signal.channels: unknown unit 'furlong/s'"):
        record_units({"signal": {"channels": [{"name": "gz", "quantity": "angular_rate", "unit_as_read": "furlong/s",
                                               "unit_source": "option", "scale_to_internal": 1.0}]}})
    assert record_units({"n_samples": 3}) is None and record_units(None) is None
