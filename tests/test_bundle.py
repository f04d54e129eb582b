"""Model bundle: a round trip gives identical predictions and settings; every refusal is one clear error.

Independent checks: the causal window and level recomputed from the pipeline's documented rule, the SHA-256 of
the training file from :mod:`hashlib`, the split times from the record's t0 and interval.
"""

from __future__ import annotations

import hashlib
import json
import shutil

import numpy as np
import pytest
from numpy.testing import assert_array_equal
from typer.testing import CliRunner

from fogdrift.bundle import BUNDLE_FORMAT_VERSION, load_bundle, write_bundle
from fogdrift.errors import ModelFileError
from fogdrift.io import from_array
from fogdrift.pipeline import AnalysisConfig, run_models
from fogdrift.simulate import simulate


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """A 2-axis record at 10 Hz, models at 1 Hz: AR, GM(1,1), Kalman, persistence."""
    rate = np.column_stack([
        simulate(60000, 0.1, arw_dprh=0.05, rrw_dphrh=1.0, bias_dph=3.0, seed=s) for s in (1, 2)])
    rec = from_array(rate / 3600.0, dt_s=0.1, unit="deg/s", axis_names=["gx", "gz"])
    cfg = AnalysisConfig(models=("ar", "gm11", "kalman", "persistence"), latitude_deg=45.0, earth_axes={"gz": "up"})
    axes = run_models(rec, cfg)
    out = tmp_path_factory.mktemp("b") / "bundle"
    bundle = write_bundle(out, axes, cfg, rec)
    return rec, cfg, axes, bundle, out


def test_round_trip_same_settings_and_predictions(fitted):
    rec, cfg, axes, bundle, out = fitted
    back = load_bundle(out)
    assert back.axis_names == ("gx", "gz")
    assert back.input_unit == "deg/s" and back.native_dt_s == 0.1 and back.model_dt_s == 1.0
    assert back.block_average_factor == 10 and back.wavelet == "db2" and back.mode == "symmetric"
    assert back.latitude_deg == 45.0 and back.format_version == BUNDLE_FORMAT_VERSION
    assert back.model_names == ("gm11", "ar", "kalman", "persistence")
    split = back.training["split"]
    assert split["test"]["t_s"] == [4800.0, 6000.0] and split["test"]["samples"] == [4800, 6000]
    for ma in axes:
        ax = back.axis(ma.name)
        assert ax.bias_dph == ma.bias_dph and ax.earth_rate_dph == ma.earth_rate_dph
        assert ax.level == 4
        assert ax.causal_window == 128  # max(round(128 s / 1 s), (4 - 1) * 2**4) with 3600 training samples
        assert "training block" in ax.bias_method
        A = ax.noise_model["allan"]["A"]
        assert len(A) == 5 and A[1] > 0  # white noise identified
        assert ax.noise_model["gmwm"] is None
        assert ax.noise_model["kalman_components"] == ma.fitted["Kalman"].components_
        e, f = ma.split["test"]
        z = ma.rate_dph[e:f]
        for name, model in ax.models.items():
            orig = next(m for m in ma.fitted.values() if type(m) is type(model))
            assert_array_equal(model.predict(z, history=ma.rate_dph[:e]), orig.predict(z, history=ma.rate_dph[:e]))
    assert back.axis("gz").earth_orientation == "up" and back.axis("gx").earth_orientation is None
    assert back.axis("gz").earth_rate_dph == pytest.approx(10.635640, abs=1e-5)  # method notes §6 table


def test_training_input_is_described(fitted, tmp_path):
    rec, cfg, axes, _, _ = fitted
    path = tmp_path / "rec.npy"
    np.save(path, np.asarray(rec.rate_dph))
    from fogdrift.io import load

    loaded = load(path, rate_hz=10.0, unit="deg/h")
    axes2 = run_models(loaded, AnalysisConfig(models=("persistence",)))
    b = write_bundle(tmp_path / "bundle", axes2, AnalysisConfig(models=("persistence",)), loaded)
    doc = json.loads((tmp_path / "bundle" / "manifest.json").read_text())
    assert doc["training"]["sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
    assert doc["training"]["t_end_s"] == pytest.approx(6000.0) and doc["training"]["t0_s"] == 0.0
    assert doc["fogdrift_version"] and doc["settings"]["models"] == ["persistence"]
    assert b.path == tmp_path / "bundle"


def _copy(out, tmp_path):
    dst = tmp_path / "copy"
    shutil.copytree(out, dst)
    return dst, json.loads((dst / "manifest.json").read_text())


def _write(dst, doc, *, reseal=True):
    """Write an edited manifest; resealed by default, so that the structural checks behind the seal are tested."""
    from fogdrift.bundle import seal_manifest

    (dst / "manifest.json").write_text(json.dumps(seal_manifest(doc) if reseal else doc))


def test_newer_format_is_refused_with_a_clear_message(fitted, tmp_path):
    dst, doc = _copy(fitted[4], tmp_path)
    doc["format_version"] = BUNDLE_FORMAT_VERSION + 1
    doc["fogdrift_version"] = "9.9"
    _write(dst, doc)
    with pytest.raises(ModelFileError, match=rf"format version {BUNDLE_FORMAT_VERSION + 1} was written by "
                                             r"fogdrift 9.9.*upgrade fogdrift"):
        load_bundle(dst)


@pytest.mark.parametrize("edit, fragment", [
    (lambda d: d.pop("signal"), "signal: missing"),
    (lambda d: d.update(input_unit="furlong/s"), "input_unit: unknown unit"),
    (lambda d: d.update(block_average_factor=0), "block_average_factor"),
    (lambda d: d.update(block_average_factor=1.5), "block_average_factor: expected an integer"),
    (lambda d: d.update(wavelet="db9"), "wavelet"),
    (lambda d: d["axes"][0].update(level=9), "axes[0].level"),
    (lambda d: d["axes"][0].update(causal_window=1), "axes[0].causal_window"),
    (lambda d: d["axes"][1].update(name="gx"), "appears twice"),
    (lambda d: d["axes"][0]["models"]["ar"].update({"class": "GM11"}), "models.ar.class"),
    (lambda d: d["axes"][0]["models"].update(lstm=d["axes"][0]["models"]["ar"]), "unknown model 'lstm'"),
    (lambda d: d.update(format="something-else"), "not a fogdrift bundle"),
    (lambda d: d["axes"][0].update(bias_dph="3"), "axes[0].bias_dph: expected a finite number"),
])
def test_invalid_manifests_name_the_key(fitted, tmp_path, edit, fragment):
    dst, doc = _copy(fitted[4], tmp_path)
    edit(doc)
    _write(dst, doc)
    with pytest.raises(ModelFileError) as info:
        load_bundle(dst)
    assert fragment in str(info.value) and "manifest.json" in str(info.value)


def test_modified_or_missing_model_files_are_refused(fitted, tmp_path):
    dst, _ = _copy(fitted[4], tmp_path)
    path = dst / "gx" / "ar.json"
    doc = json.loads(path.read_text())
    doc["state"]["intercept_"] += 1.0
    path.write_text(json.dumps(doc))
    with pytest.raises(ModelFileError, match="SHA-256 differs"):
        load_bundle(dst)
    (dst / "gx" / "ar.npz").unlink()
    with pytest.raises(ModelFileError, match="missing"):
        load_bundle(dst)
    with pytest.raises(ModelFileError, match="manifest not found"):
        load_bundle(tmp_path / "nowhere")
    (dst / "manifest.json").write_text("{not json")
    with pytest.raises(ModelFileError, match="not valid JSON"):
        load_bundle(dst / "manifest.json")


def test_model_command_writes_a_loadable_bundle(bundled_path, tmp_path):
    from fogdrift.cli import app

    result = CliRunner().invoke(app, ["model", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--models", "ar,persistence",
                                      "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    b = load_bundle(tmp_path / "bundle")
    assert b.axis_names == ("gz",) and b.model_names == ("ar", "persistence")
    assert b.training["sha256"] == hashlib.sha256(bundled_path.read_bytes()).hexdigest()


# ------------------------------------------------------------------------------------------
# The bundle is verified whole (one seal over the manifest, which holds every file's SHA-256)
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("edit, what", [
    (lambda d: d["axes"][0].update(bias_dph=d["axes"][0]["bias_dph"] + 5000.0), "bias +5000 deg/h"),
    (lambda d: [c.update(unit_as_read="rad/s" if c["unit_as_read"] != "rad/s" else "deg/s")
                for c in d["signal"]["channels"]], "unit"),
    (lambda d: d["axes"][0].update(earth_rate_dph=d["axes"][0]["earth_rate_dph"] + 1.0), "Earth rate"),
    (lambda d: d["training"].update(sha256="0" * 64), "training SHA-256"),
    (lambda d: d["axes"][0]["models"]["ar"]["sha256"].update(json="0" * 64), "a file's hash"),
])
def test_any_edit_of_the_manifest_is_refused(fitted, tmp_path, edit, what):
    dst, doc = _copy(fitted[4], tmp_path)
    assert load_bundle(dst).axes  # the copy as written loads
    edit(doc)
    _write(dst, doc, reseal=False)
    with pytest.raises(ModelFileError, match="does not match its integrity seal") as info:
        load_bundle(dst)
    assert "manifest.json" in str(info.value) and "\n" not in str(info.value)


def test_an_unsealed_version_1_bundle_is_refused_with_advice(fitted, tmp_path):
    dst, doc = _copy(fitted[4], tmp_path)
    doc.pop("seal_sha256")
    doc["format_version"] = 1
    _write(dst, doc, reseal=False)
    with pytest.raises(ModelFileError, match="no integrity seal; re-create the bundle"):
        load_bundle(dst)


# ------------------------------------------------------------------------------------------
# The sampling is written once, in signal.sampling; a format-2 manifest (intervals beside it) is converted
# ------------------------------------------------------------------------------------------
def test_manifest_writes_the_sampling_once(fitted):
    rec, _, axes, _, out = fitted
    doc = json.loads((out / "manifest.json").read_text())
    assert doc["format_version"] == BUNDLE_FORMAT_VERSION == 3
    assert not {"native_dt_s", "native_rate_hz", "model_dt_s", "model_rate_hz"} & set(doc)
    assert [k for k in doc if "dt_s" in k or "rate_hz" in k] == []
    assert doc["block_average_factor"] == 10 and doc["signal"]["sampling"]["dt_s"] == 0.1
    back = load_bundle(out)
    # the intervals read back are the ones the run used, to the last bit
    assert back.native_dt_s == rec.dt_s and back.model_dt_s == axes[0].dt_s and back.block_average_factor == 10
    assert back.signal == rec.signal


def _as_format_2(doc):
    """``doc`` (format 3) in the format-2 layout, resealed: the intervals and rates beside signal.sampling, the
    unit beside signal.channels."""
    from fogdrift.bundle import seal_manifest

    dt, k = doc["signal"]["sampling"]["dt_s"], doc["block_average_factor"]
    old = {key: v for key, v in doc.items() if key != "seal_sha256"}
    old.update(format_version=2, native_dt_s=dt, native_rate_hz=1.0 / dt, model_dt_s=k * dt,
               model_rate_hz=1.0 / (k * dt), input_unit=doc["signal"]["channels"][0]["unit_as_read"],
               rate_unit_internal="deg/h")
    return seal_manifest(old)


def test_format_2_manifest_is_converted_on_reading(fitted, tmp_path):
    dst, doc = _copy(fitted[4], tmp_path)
    new = load_bundle(dst)
    (dst / "manifest.json").write_text(json.dumps(_as_format_2(doc)))
    old = load_bundle(dst)
    assert old.format_version == 2
    assert (old.native_dt_s, old.model_dt_s, old.block_average_factor) == (0.1, 1.0, 10)
    assert (old.native_dt_s, old.model_dt_s, old.signal, old.axis_names) == (new.native_dt_s, new.model_dt_s,
                                                                             new.signal, new.axis_names)


@pytest.mark.parametrize("edit, message", [
    (lambda d: d.update(model_dt_s=0.7), "block_average_factor: model_dt_s 0.7 is not 10 x native_dt_s 0.1"),
    (lambda d: d.update(native_dt_s=0.2, model_dt_s=2.0), "signal.sampling.dt_s: 0.1 differs from native_dt_s 0.2"),
    (lambda d: d.pop("native_dt_s"), "native_dt_s: missing"),
])
def test_format_2_intervals_that_disagree_are_refused_in_one_line(fitted, tmp_path, edit, message):
    from fogdrift.bundle import seal_manifest

    dst, doc = _copy(fitted[4], tmp_path)
    old = _as_format_2(doc)
    edit(old)
    (dst / "manifest.json").write_text(json.dumps(seal_manifest(old)))
    with pytest.raises(ModelFileError) as info:
        load_bundle(dst)
    assert str(info.value) == f"{dst / 'manifest.json'}: {message}"


def test_format_3_reads_the_interval_from_the_signal_only(fitted, tmp_path):
    """Format-2 keys left in a format-3 manifest are not read: the interval is signal.sampling's."""
    dst, doc = _copy(fitted[4], tmp_path)
    doc.update(native_dt_s=0.5, model_dt_s=5.0)
    _write(dst, doc)
    b = load_bundle(dst)
    assert (b.native_dt_s, b.model_dt_s) == (0.1, 1.0)


# ------------------------------------------------------------------------------------------
# The unit is written once, in signal.channels; input_unit beside it (format 2) is checked and dropped
# ------------------------------------------------------------------------------------------
def test_manifest_writes_the_unit_once(fitted):
    rec, _, _, _, out = fitted
    doc = json.loads((out / "manifest.json").read_text())
    assert not {"input_unit", "rate_unit_internal", "unit", "scale_to_dph"} & set(doc)
    assert [c["unit_as_read"] for c in doc["signal"]["channels"]] == ["deg/s", "deg/s"]
    back = load_bundle(out)
    assert back.input_unit == rec.input_unit == "deg/s" and back.signal == rec.signal


def test_format_2_unit_is_read_from_the_channels(fitted, tmp_path):
    """The converted manifest's unit is the channels' even where input_unit spells it otherwise (the unit it
    names is checked to be the same, then dropped)."""
    from fogdrift.bundle import seal_manifest

    dst, doc = _copy(fitted[4], tmp_path)
    old = _as_format_2(doc)
    assert old["input_unit"] == "deg/s"
    (dst / "manifest.json").write_text(json.dumps(seal_manifest(old)))
    b = load_bundle(dst)
    assert b.format_version == 2 and b.input_unit == "deg/s"


@pytest.mark.parametrize("version", [2, 3])
def test_an_input_unit_that_disagrees_with_the_channels_is_refused(fitted, tmp_path, version):
    from fogdrift.bundle import seal_manifest

    dst, doc = _copy(fitted[4], tmp_path)
    old = _as_format_2(doc) if version == 2 else {k: v for k, v in doc.items() if k != "seal_sha256"}
    old["input_unit"] = "rad/s"
    (dst / "manifest.json").write_text(json.dumps(seal_manifest(old)))
    with pytest.raises(ModelFileError) as info:
        load_bundle(dst)
    assert str(info.value).startswith(f"{dst / 'manifest.json'}: input_unit: 'rad/s' is not the unit of "
                                      "signal.channels ['gx', 'gz']")
    assert "\n" not in str(info.value)


def test_format_3_manifest_that_repeats_an_agreeing_unit_loads_the_same(fitted, tmp_path):
    dst, doc = _copy(fitted[4], tmp_path)
    new = load_bundle(dst)
    doc.update(input_unit="deg/s", rate_unit_internal="deg/h")
    _write(dst, doc)
    back = load_bundle(dst)
    assert (back.input_unit, back.signal, back.native_dt_s) == (new.input_unit, new.signal, new.native_dt_s)


def test_a_manifest_with_channels_in_two_units_is_refused(fitted, tmp_path):
    dst, doc = _copy(fitted[4], tmp_path)
    doc["signal"]["channels"][1].update(unit_as_read="rad/s")
    _write(dst, doc)
    with pytest.raises(ModelFileError, match=r"signal.channels: the channels are in 2 units \['deg/s', 'rad/s'\]"):
        load_bundle(dst)


@pytest.mark.parametrize("rel", ["/etc/passwd", "../outside/ar", "gx/../../outside/ar", "gx\\..\\..\\ar", ""])
def test_model_files_outside_the_bundle_are_refused(fitted, tmp_path, rel):
    out = tmp_path / "outside"
    dst, doc = _copy(fitted[4], tmp_path)
    shutil.copytree(dst / "gx", out)  # a valid model file outside the bundle, with matching hashes
    doc["axes"][0]["models"]["ar"]["file"] = rel
    _write(dst, doc)
    with pytest.raises(ModelFileError, match="is not a relative path inside the bundle|models.ar.file"):
        load_bundle(dst)


def test_non_finite_parameters_are_refused_at_load(fitted, tmp_path):
    dst, doc = _copy(fitted[4], tmp_path)
    npz = dst / "gx" / "ar.npz"
    with np.load(npz, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    arrays["coef_"] = np.full_like(arrays["coef_"], np.nan)
    np.savez(npz, **arrays)
    # hashes made consistent, as a careful editor would: the seal passes, the parameters do not
    from fogdrift.io.hashing import file_sha256

    doc["axes"][0]["models"]["ar"]["sha256"]["npz"] = file_sha256(npz)
    _write(dst, doc)
    with pytest.raises(ModelFileError, match="parameter 'coef_' of gx/ar holds NaN or inf"):
        load_bundle(dst)
