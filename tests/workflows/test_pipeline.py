"""The pipeline's bookkeeping on small synthetic records with hand-computable results (issue 14).

What is checked here, each against values written by hand (never against the pipeline's own helpers):

- the chronological split indices, and that the test block does not start inside the validation block;
- that a model is fitted on the training block's drift only (validation drift passed separately);
- that scoring starts ``lags`` samples into the test block;
- the training-block bias and the Earth-rate sign for every ``earth_axes`` orientation
  (w_ie = 7.2921150e-5 rad/s, sensed rate w_ie (u_N cos L + u_U sin L));
- the modelling-rate rule (integer block averaging; 3 Hz on a 100 Hz record refused, nearest rates named);
- the model factory (registry names -> classes) and the verdict sentences (beat / did NOT beat / MIXED).

A spy drift model records what the pipeline feeds it and returns predictions chosen by the test, so the
expected metrics are exact numbers. Each test was shown to fail on a deliberate bug (docs/testing-rounds.md).
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

import fogdrift.pipeline as pipeline
from fogdrift.errors import ConfigError
from fogdrift.io import from_array
from fogdrift.lifting import separate
from fogdrift.pipeline import AnalysisConfig, run_models

W_IE_DPH = 7.2921150e-5 * 180.0 / math.pi * 3600.0  # WGS-84 Earth rate in deg/h, written out here


class Spy:
    """A drift model that records its inputs; predicts the truth except ``error`` added to the first ``bad``."""

    label = "spy"
    input_kind = "drift"

    def __init__(self, bad=0, error=0.0):
        self.bad, self.error, self.calls = bad, error, []

    def get_params(self):
        return {}

    def set_params(self, **params):
        return self

    def fit(self, y_train, y_val=None):
        self.calls.append(("fit", np.array(y_train), None if y_val is None else np.array(y_val)))
        return self

    def predict(self, y, *, history=None):
        y = np.asarray(y, dtype=float)
        self.calls.append(("predict", y.copy(), None if history is None else np.array(history)))
        out = y.copy()
        out[: self.bad] += self.error
        return out


def _record(n=400, dt_s=1.0, offset=0.0, seed=0):
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    x = offset + 0.5 * np.sin(2 * np.pi * k / 97.0) + 0.05 * rng.standard_normal(n)
    return from_array(x, dt_s=dt_s, unit="deg/h", axis_names=("gz",)), x


def _cfg(**kw):
    base = dict(model_rate_hz=None, level=2, lags=3, models=("ar",), causal_window_s=40.0)
    base.update(kw)
    return AnalysisConfig(**base)


@pytest.fixture
def spy(monkeypatch):
    model = Spy()
    monkeypatch.setattr(pipeline, "make_model", lambda name, cfg, progress=None, inputs=None: model)
    return model


# ---------------------------------------------------------------------------------------------------------
# split


@pytest.mark.parametrize("n, train, val, expected", [
    (100, 0.6, 0.2, {"train": [0, 60], "val": [60, 80], "test": [80, 100]}),
    (400, 0.5, 0.25, {"train": [0, 200], "val": [200, 300], "test": [300, 400]}),
    (10, 0.7, 0.0, {"train": [0, 7], "val": [7, 7], "test": [7, 10]}),
])
def test_split_indices_by_hand(n, train, val, expected):
    assert pipeline._split_indices(n, AnalysisConfig(train_fraction=train, val_fraction=val)) == expected


def test_blocks_fitted_and_scored_are_the_split_blocks(spy):
    rec, x = _record()
    (ma,) = run_models(rec, _cfg())
    assert ma.split == {"train": [0, 240], "val": [240, 320], "test": [320, 400]}
    rate = x - x[:240].mean()
    np.testing.assert_allclose(ma.rate_dph, rate, rtol=0, atol=1e-12)
    # each block is separated on its own: the drifts equal separate() of exactly that slice
    for block, (lo, hi) in ma.split.items():
        np.testing.assert_allclose(ma.drift_blocks[block], separate(rate[lo:hi], "db2", 2, mode="symmetric")[0],
                                   rtol=0, atol=1e-12)
    # the model is fitted once, on the training drift only, with the validation drift beside it
    fits = [c for c in spy.calls if c[0] == "fit"]
    assert len(fits) == 1
    np.testing.assert_array_equal(fits[0][1], ma.drift_blocks["train"])
    np.testing.assert_array_equal(fits[0][2], ma.drift_blocks["val"])
    # predictions on the test drift, history = training + validation drift (never test samples)
    pred = [c for c in spy.calls if c[0] == "predict"][0]
    np.testing.assert_array_equal(pred[1], ma.drift_blocks["test"])
    assert pred[1].size == 80
    np.testing.assert_array_equal(pred[2], np.concatenate([ma.drift_blocks["train"], ma.drift_blocks["val"]]))


# ---------------------------------------------------------------------------------------------------------
# scoring window


def test_scoring_starts_lags_into_the_test_block(monkeypatch):
    lags = 3
    model = Spy(bad=lags, error=100.0)  # perfect except huge errors on the first `lags` test samples
    monkeypatch.setattr(pipeline, "make_model", lambda name, cfg, progress=None, inputs=None: model)
    rec, _ = _record()
    (ma,) = run_models(rec, _cfg(lags=lags))
    assert ma.score_from == lags
    m = ma.metrics["spy"]
    assert m.rmse_dph == 0.0 and m.mae_dph == 0.0  # the bad samples are outside the scored window
    # persistence is scored over the same window: its RMSE by hand on drift[test][lags:]
    d = ma.drift_blocks["test"]
    expected = np.sqrt(np.mean(np.diff(d[lags - 1:]) ** 2))
    np.testing.assert_allclose(m.rmse_persistence_dph, expected, rtol=1e-12)


def test_one_bad_prediction_inside_the_window_is_scored(monkeypatch):
    # control for the test above: the same spy with lags=0 errors scored -> RMSE = 100 sqrt(k/n) by hand
    model = Spy(bad=4, error=100.0)
    monkeypatch.setattr(pipeline, "make_model", lambda name, cfg, progress=None, inputs=None: model)
    rec, _ = _record()
    (ma,) = run_models(rec, _cfg(lags=2))
    n_scored = 80 - 2
    np.testing.assert_allclose(ma.metrics["spy"].rmse_dph, 100.0 * math.sqrt(2 / n_scored), rtol=1e-12)


# ---------------------------------------------------------------------------------------------------------
# bias and Earth rate


@pytest.mark.parametrize("axis, projection", [
    ("up", lambda lat: math.sin(lat)),
    ("down", lambda lat: -math.sin(lat)),
    ("north", lambda lat: math.cos(lat)),
    ("south", lambda lat: -math.cos(lat)),
    ("east", lambda lat: 0.0),
    ((0.0, 1.0, 1.0), lambda lat: (math.cos(lat) + math.sin(lat)) / math.sqrt(2.0)),
], ids=["up", "down", "north", "south", "east", "north-up"])
@pytest.mark.parametrize("latitude", [30.0, -45.0])
def test_bias_and_earth_rate_sign(spy, axis, projection, latitude):
    b0 = 3.25  # the gyro's own bias [deg/h]
    earth = W_IE_DPH * projection(math.radians(latitude))
    rec, x = _record(offset=0.0)
    data = x + b0 + earth  # a static gyro senses its bias plus the Earth-rate component
    rec = from_array(data, dt_s=1.0, unit="deg/h", axis_names=("gz",))
    (ma,) = run_models(rec, _cfg(latitude_deg=latitude, earth_axes={"gz": axis}))
    np.testing.assert_allclose(ma.earth_rate_dph, earth, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(ma.bias_dph, b0 + x[:240].mean(), rtol=1e-12)
    # what the models see: the rate with Earth rate and training bias removed -> training mean 0
    np.testing.assert_allclose(ma.rate_dph, x - x[:240].mean(), rtol=0, atol=1e-12)


def test_no_latitude_no_earth_rate(spy):
    rec, x = _record(offset=-7.5)
    (ma,) = run_models(rec, _cfg())
    assert ma.earth_rate_dph == 0.0
    np.testing.assert_allclose(ma.bias_dph, x[:240].mean(), rtol=1e-12)


# ---------------------------------------------------------------------------------------------------------
# modelling rate


def test_model_rate_is_an_integer_block_average(spy):
    n = 4000
    rec, x = _record(n=n, dt_s=0.01)
    (ma,) = run_models(rec, _cfg(model_rate_hz=25.0))
    assert ma.dt_s == pytest.approx(0.04, rel=1e-12)
    averaged = x.reshape(-1, 4).mean(axis=1)  # 100 Hz -> 25 Hz: blocks of exactly 4 samples
    np.testing.assert_allclose(ma.rate_dph, averaged - averaged[:600].mean(), rtol=0, atol=1e-12)


def test_model_rate_that_does_not_divide_is_refused_with_the_nearest_rates(spy):
    rec, _ = _record(n=4000, dt_s=0.01)
    with pytest.raises(ConfigError) as err:
        run_models(rec, _cfg(model_rate_hz=3.0))
    msg = str(err.value)
    assert "3.03 Hz (/33)" in msg and "2.941 Hz (/34)" in msg and "model_rate_hz=" in msg


# ---------------------------------------------------------------------------------------------------------
# model factory


def test_model_factory_maps_registry_names_to_classes():
    from fogdrift.models.ar import AR
    from fogdrift.models.elman import Elman, GreyElman
    from fogdrift.models.grey import GM11
    from fogdrift.models.kalman import Kalman
    from fogdrift.models.persistence import Persistence

    expected = {"grey-elman": GreyElman, "elman": Elman, "gm11": GM11, "ar": AR, "kalman": Kalman,
                "persistence": Persistence}
    cfg = AnalysisConfig(lags=5)
    for name, cls in expected.items():
        assert type(pipeline.make_model(name, cfg)) is cls, name
    assert pipeline.make_model("ar", cfg).order == 5  # the AR order is the configured lags


def test_pipeline_fits_exactly_the_configured_models():
    rec, _ = _record()
    (ma,) = run_models(rec, _cfg(models=("persistence", "ar")))
    assert sorted(ma.fitted) == ["AR(p)", "persistence"]
    assert type(ma.fitted["AR(p)"]).__name__ == "AR"
    # persistence as a fitted model predicts the previous test drift sample (by definition)
    d = ma.drift_blocks["test"]
    np.testing.assert_array_equal(ma.predictions["persistence"][1:], d[:-1])
    assert ma.predictions["persistence"][0] == ma.drift_blocks["val"][-1]


# ---------------------------------------------------------------------------------------------------------
# found unasserted by the mutation run (docs/testing-rounds.md): the causal path, as-measured p0, block-size
# check, rate-input models, the factory call, config validation boundaries


def test_causal_path_window_wavelet_mode_and_history(spy):
    from fogdrift.lifting import causal_drift

    rec, x = _record(n=800, dt_s=0.5)
    cfg = _cfg(wavelet="haar", mode="periodization", causal_window_s=40.0)
    (ma,) = run_models(rec, cfg)
    rate = x - x[:480].mean()
    # window = causal_window_s / dt = 80 samples (haar level 2 reach 4 is shorter; training block 480 longer)
    causal = causal_drift(rate, 80, wavelet="haar", level=2, mode="periodization")
    np.testing.assert_array_equal(ma.causal_drift_dph, causal)
    for block, (lo, hi) in ma.split.items():
        np.testing.assert_array_equal(ma.drift_blocks[block],
                                      separate(rate[lo:hi], "haar", 2, mode="periodization")[0])
    calls = [c for c in spy.calls if c[0] == "predict"]
    assert len(calls) == 2
    np.testing.assert_array_equal(calls[1][1], causal[640:800])
    np.testing.assert_array_equal(calls[1][2], causal[:640][np.isfinite(causal[:640])])
    # causal metrics: the spy is perfect -> 0; persistence on the causal drift from its own history
    lags = cfg.lags
    m = ma.causal_metrics["spy"]
    assert m.rmse_dph == 0.0 and m.n == 160 - lags
    expected = np.sqrt(np.mean(np.diff(causal[640 + lags - 1:800]) ** 2))
    np.testing.assert_allclose(m.rmse_persistence_dph, expected, rtol=1e-12)
    np.testing.assert_array_equal(ma.causal_predictions["spy"], causal[640:800])


def test_p0_as_measured_adds_bias_and_earth_rate_back(spy):
    b0, lat = 40.0, 30.0
    earth = W_IE_DPH * math.sin(math.radians(lat))
    _, x = _record()
    rec = from_array(x + b0 + earth, dt_s=1.0, unit="deg/h", axis_names=("gz",))
    (ma,) = run_models(rec, _cfg(latitude_deg=lat, earth_axes={"gz": "up"}))
    lags, offset = 3, ma.bias_dph + earth
    y = ma.drift_blocks["test"][lags:] + offset
    pp = np.r_[ma.drift_blocks["val"][-1], ma.drift_blocks["test"][:-1]][lags:] + offset
    model_p0, persistence_p0 = ma.p0_as_measured["spy"]
    assert model_p0 == 100.0  # perfect predictions
    np.testing.assert_allclose(persistence_p0, 100.0 * (1.0 - np.mean(np.abs(y - pp) / np.abs(y))), rtol=1e-12)
    assert persistence_p0 < 100.0


@pytest.mark.parametrize("n, block, ok", [(60, None, True), (40, "val", False)])
def test_block_size_check_at_the_boundary(spy, n, block, ok):
    from fogdrift.errors import InsufficientDataError

    rec, _ = _record(n=n)
    # need = max((4 - 1) * 2**2, lags + 2) = 12: n = 60 gives blocks 36/12/12 (exactly enough), n = 40 -> 24/8/8
    if ok:
        (ma,) = run_models(rec, _cfg())
        assert ma.split["test"] == [48, 60]
        return
    with pytest.raises(InsufficientDataError) as err:
        run_models(rec, _cfg())
    assert (err.value.needed, err.value.got) == (12, 8) and f"the {block} block has 8 samples" in str(err.value)


def test_rate_input_models_see_the_rate_blocks(monkeypatch):
    model = Spy()
    model.input_kind = "rate"
    monkeypatch.setattr(pipeline, "make_model", lambda name, cfg, progress=None, inputs=None: model)
    rec, x = _record()
    (ma,) = run_models(rec, _cfg())
    rate = x - x[:240].mean()
    fit = [c for c in model.calls if c[0] == "fit"][0]
    np.testing.assert_array_equal(fit[1], rate[:240])
    np.testing.assert_array_equal(fit[2], rate[240:320])
    pred = [c for c in model.calls if c[0] == "predict"]
    assert len(pred) == 1  # causal by construction: one prediction serves both targets
    np.testing.assert_array_equal(pred[0][1], rate[320:400])
    np.testing.assert_array_equal(pred[0][2], rate[:320])
    assert ma.causal_predictions["spy"] is ma.predictions["spy"]


def test_factory_receives_name_settings_and_progress_and_records_fit_time(monkeypatch):
    seen = []

    def factory(name, cfg, progress=None, inputs=None):
        seen.append((name, cfg.level, cfg.lags, progress, inputs))
        return Spy()

    def progress(*args):
        pass

    monkeypatch.setattr(pipeline, "make_model", factory)
    rec, _ = _record()
    (ma,) = run_models(rec, _cfg(models=("ar",), level="auto"), progress=progress)
    from fogdrift.lifting import choose_level, level_scan

    rate = np.asarray(ma.rate_dph)
    level = int(choose_level(level_scan(rate, 1.0, wavelet="db2", mode="symmetric")))
    assert seen == [("ar", level, 3, progress, {"dt_s": 1.0})]   # the data's inputs, for the rows that declare them
    assert ma.name == "gz" and list(ma.fit_seconds) == ["spy"] and 0.0 <= ma.fit_seconds["spy"] < 60.0
    assert any(note.startswith("p0 is unstable near zero") for note in ma.notes)  # the drift crosses zero


def test_earth_rate_only_for_the_named_axis(spy):
    rng = np.random.default_rng(5)
    data = rng.standard_normal((400, 2)) + [1.0, 2.0]
    rec = from_array(data, dt_s=1.0, unit="deg/h", axis_names=("gx", "gz"))
    gx, gz = run_models(rec, _cfg(latitude_deg=45.0, earth_axes={"gz": "up"}))
    assert gx.earth_rate_dph == 0.0
    assert gz.earth_rate_dph == pytest.approx(W_IE_DPH * math.sqrt(0.5), rel=1e-12)
    with pytest.raises(ConfigError, match=r"Earth-rate axis \['gy'\] not in the record; its axes are \['gx', 'gz'\]"):
        run_models(rec, _cfg(latitude_deg=45.0, earth_axes={"gy": "up"}))


@pytest.mark.parametrize("kw, ok", [
    (dict(train_fraction=0.0), False), (dict(train_fraction=1.0), False), (dict(train_fraction=0.5), True),
    (dict(val_fraction=0.0), True), (dict(val_fraction=1.0), False), (dict(val_fraction=-0.1), False),
    (dict(train_fraction=0.6, val_fraction=0.4), False), (dict(train_fraction=0.6, val_fraction=0.39), True),
    (dict(train_fraction=0.9, val_fraction=0.05), True),
    (dict(model_rate_hz=0.0), False), (dict(model_rate_hz=0.5), True), (dict(model_rate_hz=None), True),
    (dict(lags=0), False), (dict(lags=1), True), (dict(hidden=0), False), (dict(hidden=1), True),
    (dict(epochs=0), False), (dict(epochs=1), True),
    (dict(causal_window_s=0.0), False), (dict(causal_window_s=0.5), True),
    (dict(latitude_deg=-90.0, earth_axes={"gz": "up"}), True), (dict(latitude_deg=90.0, earth_axes={"gz": "up"}), True),
    (dict(latitude_deg=-90.5, earth_axes={"gz": "up"}), False), (dict(latitude_deg=90.5, earth_axes={"gz": "up"}), False),
    (dict(latitude_deg=10.0), False),
])
def test_config_validation_boundaries(kw, ok):
    cfg = AnalysisConfig(**kw)
    if ok:
        assert cfg.validate() is cfg
    else:
        with pytest.raises(ConfigError):
            cfg.validate()


def test_config_to_dict_lists():
    d = AnalysisConfig(models=("ar", "persistence"), terms=("N", "B"), fit_tau_s=(1.0, None)).to_dict()
    assert d["models"] == ["ar", "persistence"] and d["terms"] == ["N", "B"] and d["fit_tau_s"] == [1.0, None]
    assert AnalysisConfig().to_dict()["terms"] is None
