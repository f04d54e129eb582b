"""Issue 25: the heading evaluation forecasts all origins of a drift model in one ``forecast_many`` call.

The batched path must give the per-origin loop's angle errors (each row cut to its own longest horizon), fall
back to that loop when the batched call raises a FogdriftError, and leave models without the method (or whose
subclass overrides ``forecast`` alone) on the per-origin path.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from fogdrift.errors import DataFormatError
from fogdrift.evaluation import heading as heading_mod
from fogdrift.evaluation import heading_errors
from fogdrift.models import Persistence
from fogdrift.models.causal_predictor import causal_weights
from fogdrift.models.grey import GM11

DT = 1.0
W = 64
HORIZONS = (60.0, 600.0, 1500.0)


def _rate(n=3300, seed=25):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * DT
    # slow drift + wander + white noise [deg/h]
    return 4.0 + 0.3 * np.sin(2 * np.pi * t / 2400.0) + np.cumsum(rng.normal(0, 0.01, n)) + rng.normal(0, 0.4, n)


def _grey(r):
    return GM11(mode="rolling", window=8).fit(r[:600] - np.mean(r[:600]) + 2.0)


def _run(r, models, *, batched=True, monkeypatch=None):
    if not batched:
        monkeypatch.setattr(heading_mod, "_batched_forecasts", lambda models, calib: {})
    res = heading_errors(r, DT, models, causal_window=W, horizons_s=HORIZONS, calib_s=300.0, step_s=300.0)
    if not batched:
        monkeypatch.undo()
    return res


class SpyGM11(GM11):
    """Counts the calls of each path."""

    n_many = 0
    n_single = 0

    def forecast_many(self, h, histories):
        type(self).n_many += 1
        return super().forecast_many(h, histories)

    def forecast(self, h, *, history=None):
        type(self).n_single += 1
        return super().forecast(h, history=history)


class RaisingGM11(GM11):
    def forecast_many(self, h, histories):
        raise DataFormatError("no batch today")


class OffsetGM11(GM11):
    """Overrides forecast only: the inherited forecast_many would not stand for it."""

    def forecast(self, h, *, history=None):
        return super().forecast(h, history=history) + 0.5


def _copy(cls, model):
    out = cls.__new__(cls)
    out.__dict__.update(model.__dict__)
    return out


def test_batched_equals_per_origin_loop(monkeypatch):
    r = _rate()
    m = _grey(r)
    models = {"grey": m, "persistence": Persistence().fit([0.0])}
    new = _run(r, models)
    old = _run(r, models, batched=False, monkeypatch=monkeypatch)
    # the last horizon does not fit after the late origins: NaN there, and rows cut to a shorter h_max
    assert np.isnan(new.errors["grey"][:, -1]).any() and np.isfinite(new.errors["grey"][:, -1]).any()
    for label in old.errors:
        assert_allclose(new.errors[label], old.errors[label], rtol=1e-12, atol=0, equal_nan=True)
    assert [r_.to_dict() for r_ in new.rows] == [r_.to_dict() for r_ in old.rows]
    assert new.notes == old.notes


def test_batched_matches_hand_computed_angle_error():
    """Independent of both code paths: bias = window mean, causal drift by explicit FIR, one forecast per origin,
    E = sum(r - b - f) dt / 3600, at the first origin and at the last (whose longest horizon is shorter)."""
    r = _rate()
    m = _grey(r)
    res = _run(r, {"grey": m})
    g = causal_weights(W, "db2", 4, "symmetric")
    w_cal = 300
    for i in (0, res.origins_s.size - 1):
        t0 = int(round(res.origins_s[i] / DT))
        win = r[t0 - w_cal:t0]
        b = win.mean()
        zc = win - b
        c = np.array([zc[k:k + W] @ g for k in range(zc.size - W + 1)])
        for j, h in enumerate(HORIZONS):
            H = int(h / DT)
            if t0 + H > r.size:
                assert np.isnan(res.errors["grey"][i, j])
                continue
            f = m.forecast(H, history=c)
            ref = np.sum(r[t0:t0 + H] - b - f) * DT / 3600.0
            assert_allclose(res.errors["grey"][i, j], ref, rtol=1e-9, atol=1e-12)


def test_one_batched_call_per_model():
    r = _rate()
    spy = _copy(SpyGM11, _grey(r))
    SpyGM11.n_many = SpyGM11.n_single = 0
    res = _run(r, {"spy": spy})
    assert res.origins_s.size > 5
    assert SpyGM11.n_many == 1
    assert SpyGM11.n_single == 0


def test_fallback_when_batched_call_raises(monkeypatch):
    r = _rate()
    base = _grey(r)
    raising = _copy(RaisingGM11, base)
    new = _run(r, {"grey": raising})
    old = _run(r, {"grey": base}, batched=False, monkeypatch=monkeypatch)
    assert_allclose(new.errors["grey"], old.errors["grey"], rtol=1e-12, atol=0, equal_nan=True)
    assert not any("grey" in n for n in new.notes)


def test_subclass_overriding_forecast_only_keeps_its_forecast(monkeypatch):
    r = _rate()
    base = _grey(r)
    off = _copy(OffsetGM11, base)
    assert heading_mod._batch_forecaster(off) is None
    assert heading_mod._batch_forecaster(base) is not None
    new = _run(r, {"off": off, "grey": base})
    old = _run(r, {"off": off, "grey": base}, batched=False, monkeypatch=monkeypatch)
    assert_allclose(new.errors["off"], old.errors["off"], rtol=1e-12, atol=0, equal_nan=True)
    # the offset changes the errors (0.5 deg/h over 60 s = 0.5 * 60 / 3600 deg): it was not batched away
    assert_allclose(new.errors["grey"][:, 0] - new.errors["off"][:, 0], 0.5 * 60.0 / 3600.0, rtol=1e-6)


def test_rate_models_are_not_batched():
    class RateModel:
        input_kind = "rate"

        def forecast_many(self, h, histories):  # pragma: no cover - must not be called
            raise AssertionError("called")

    assert heading_mod._batch_forecaster(RateModel()) is None
    assert heading_mod._batch_forecaster(Persistence().fit([0.0])) is None


def test_failing_model_still_reported(monkeypatch):
    """A model whose forecasts fail on both paths is dropped with the same note as before."""
    r = _rate()
    unfitted = GM11(mode="rolling", window=8)
    new = _run(r, {"grey": unfitted})
    old = _run(r, {"grey": unfitted}, batched=False, monkeypatch=monkeypatch)
    assert "grey" not in new.errors
    assert new.notes == old.notes
    assert any(n.startswith("grey: no forecast") for n in new.notes)


@pytest.mark.parametrize("mode", ["whole"])
def test_whole_mode_grey_identical(mode, monkeypatch):
    r = _rate()
    m = GM11(mode=mode).fit(r[:600] - np.mean(r[:600]) + 2.0)
    new = _run(r, {"grey": m})
    old = _run(r, {"grey": m}, batched=False, monkeypatch=monkeypatch)
    assert_allclose(new.errors["grey"], old.errors["grey"], rtol=1e-12, atol=0, equal_nan=True)
