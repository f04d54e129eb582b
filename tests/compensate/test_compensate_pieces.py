"""``fogdrift compensate`` pieces pinned rule by rule (issue 24, mutation round 3): the streaming engine, the log
source and its matching to a bundle, the streamed output writers and the compensated test block of ``analyze``.

Independent references, written out here: the Haar causal drift of a 2-sample window is the mean of the pair, so
with persistence the drift removed from modelling interval ``j`` is ``(z[j-2] + z[j-1]) / 2`` with
``z = block mean - bias - earth``; the Earth rate is Omega sin(phi) with Omega = 15.041067 deg/h (7.2921150e-5
rad/s) computed here; every result must be the same for input chunks of 1, 7, 64 samples and whole.
"""

from __future__ import annotations

import math
import os
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.compensate.engine import BIAS_ONLY, AxisPlan, StreamCompensator, _block_means, segment_blocks
from fogdrift.errors import ConfigError, DataFormatError, InsufficientDataError
from fogdrift.models import Persistence

#: Omega sin(30 deg) [deg/h], by hand: 7.2921150e-5 rad/s x 180/pi x 3600 = 15.041067 deg/h
EARTH_30 = 7.2921150e-5 * 180.0 / math.pi * 3600.0 * 0.5
CHUNKS = (1, 7, 64, None)  # None: the whole log in one push


def _axis(name="gz", bias=1.5, earth=0.0, model=True):
    models = {"persistence": Persistence().fit([0.0])} if model else {}
    return SimpleNamespace(name=name, bias_dph=bias, earth_rate_dph=earth, causal_window=2, level=1, models=models)


def _engine(axes, factor=3, model="persistence", **kw):
    plans = [AxisPlan(a.name, a, model) for a in axes]
    return StreamCompensator(plans, factor=factor, model_dt_s=kw.pop("model_dt_s", 1.0), wavelet="haar",
                             mode="periodization", **kw)


def _run(eng, x, chunk):
    x = np.asarray(x, dtype=float).reshape(len(x), -1)
    t = np.arange(x.shape[0]) * 0.25
    blocks = []
    step = x.shape[0] if chunk is None else chunk
    for lo in range(0, x.shape[0], step):
        blocks += eng.push(t[lo:lo + step], x[lo:lo + step])
    blocks += eng.finish()
    cat = {k: np.concatenate([getattr(b, k) for b in blocks]) for k in ("t_s", "rate_dph", "compensated_dph",
                                                                         "drift_dph")}
    cat["sigma"] = None if blocks[0].sigma_dph is None else np.concatenate([b.sigma_dph for b in blocks])
    assert_array_equal(cat["t_s"], t)
    assert_array_equal(cat["rate_dph"], x)
    return cat


def _persistence_reference(x, m, bias_total, extra=True):
    """Held drift [deg/h] per native sample: p[j] = (z[j-2] + z[j-1]) / 2, 0 where j < 2."""
    x = np.asarray(x, dtype=float)
    nb = x.size // m
    z = x[: nb * m].reshape(nb, m).mean(axis=1) - bias_total
    p = np.zeros(nb + 1)
    for j in range(2, nb + 1):
        p[j] = 0.5 * (z[j - 2] + z[j - 1])
    return np.repeat(p, m)[: x.size] if extra else np.repeat(p[:nb], m)[: x.size]


def _log(n=61, seed=0):
    rng = np.random.default_rng(seed)
    return 40.0 + np.cumsum(rng.normal(0.0, 0.3, n)) + 3.0 * np.sin(np.arange(n) / 5.0)


# ---------------------------------------------------------------------------------------------------------------
# the engine


def test_block_means_and_segment_sizes_by_hand():
    x = np.array([[1.0, 10.0], [2.0, 20.0], [3.0, 30.0], [4.0, 40.0], [5.0, 50.0], [6.0, 60.0], [7.0, 70.0]])
    assert_array_equal(_block_means(x, 2, 3), [[2.0, 20.0], [5.0, 50.0]])  # the 7th row is left out
    assert_array_equal(_block_means(x, 3, 2), [[1.5, 15.0], [3.5, 35.0], [5.5, 55.0]])
    assert_array_equal(_block_means(x, 7, 1), x)
    assert _block_means(x, 0, 4).shape == (0, 2)
    assert segment_blocks(1) == 262144 and segment_blocks(3) == 87381 and segment_blocks(1000) == 262
    assert segment_blocks(1024) == 256 and segment_blocks(1025) == 256 and segment_blocks(4096) == 256
    assert segment_blocks(np.int64(2)) == 131072 and segment_blocks(2.0) == 131072


def test_the_haar_window_is_the_mean_of_the_pair():
    from fogdrift.models.causal_predictor import causal_weights

    assert_allclose(causal_weights(2, "haar", 1, "periodization"), [0.5, 0.5], rtol=1e-12)


@pytest.mark.parametrize("chunk", CHUNKS)
@pytest.mark.parametrize("segment", (None, 4, 5))
def test_persistence_output_by_hand_with_the_earth_rate(chunk, segment):
    """z removes bias AND Earth rate; the output removes the bias and the drift only (the Earth rate stays)."""
    x = _log(61) + EARTH_30
    bias = 1.5
    eng = _engine([_axis(bias=bias, earth=EARTH_30)], factor=3, segment=segment)
    out = _run(eng, x, chunk)
    drift = _persistence_reference(x, 3, bias + EARTH_30)
    assert_allclose(out["drift_dph"][:, 0], drift, rtol=1e-12, atol=1e-9)
    assert_allclose(out["compensated_dph"][:, 0], x - bias - drift, rtol=1e-12, atol=1e-9)
    assert out["sigma"] is None and eng.has_sigma is False
    assert eng.n_in == 61 and eng.n_out == 61 and eng.n_axes == 1
    assert eng.first_active() == [6]  # interval 2 (native samples 6, 7, 8) is the first with a prediction
    assert eng.biases() == [(bias, bias + EARTH_30)]
    assert eng.re_estimated_bias_dph is None
    assert_allclose(eng.model_rate_series()[:, 0], x[:60].reshape(20, 3).mean(axis=1), rtol=1e-12)
    assert EARTH_30 == pytest.approx(15.041067 * 0.5, rel=1e-6)


def test_output_is_the_same_for_any_chunking_bit_for_bit():
    x = np.column_stack([_log(200, 1), _log(200, 2) - 7.0])
    runs = []
    for chunk in CHUNKS:
        eng = _engine([_axis("gx", 2.0, EARTH_30), _axis("gz", -1.0, -3.0)], factor=4, segment=3)
        runs.append(_run(eng, x, chunk))
    for r in runs[1:]:
        for k in ("compensated_dph", "drift_dph"):
            assert_array_equal(r[k], runs[0][k])
    for k, (bias, earth) in enumerate(((2.0, EARTH_30), (-1.0, -3.0))):
        d = _persistence_reference(x[:, k], 4, bias + earth)
        assert_allclose(runs[0]["drift_dph"][:, k], d, rtol=1e-12, atol=1e-9)
        assert_allclose(runs[0]["compensated_dph"][:, k], x[:, k] - bias - d, rtol=1e-12, atol=1e-9)


def test_bias_only_removes_the_bias_and_keeps_the_earth_rate():
    x = _log(20) + EARTH_30
    for model in (BIAS_ONLY, "persistence"):
        eng = _engine([_axis(bias=2.0, earth=EARTH_30)], factor=2, model=model)
        out = _run(eng, x, 7)
        if model == BIAS_ONLY:
            assert_array_equal(out["drift_dph"], 0.0)
            assert_allclose(out["compensated_dph"][:, 0], x - 2.0, rtol=1e-12)
            assert eng.first_active() == [0]
    assert AxisPlan("gz", _axis(), BIAS_ONLY).model is None
    ax = _axis()
    assert AxisPlan("gz", ax, "persistence").model is ax.models["persistence"]


@pytest.mark.parametrize("chunk", CHUNKS)
def test_last_incomplete_interval_gets_the_prediction_after_the_log(chunk):
    x = _log(23)  # 7 intervals of 3 and 2 samples more
    eng = _engine([_axis(bias=0.5)], factor=3)
    out = _run(eng, x, chunk)
    z = x[:21].reshape(7, 3).mean(axis=1) - 0.5
    assert_allclose(out["drift_dph"][21:, 0], 0.5 * (z[5] + z[6]), rtol=1e-12)
    assert_allclose(out["drift_dph"][:21, 0], _persistence_reference(x[:21], 3, 0.5), rtol=1e-12, atol=1e-12)
    assert eng.model_rate_series().shape == (7, 1)


@pytest.mark.parametrize("chunk", CHUNKS)
@pytest.mark.parametrize("segment", (None, 2, 3))
def test_bias_re_estimated_by_hand(chunk, segment):
    """bias=4 s at 1-s intervals: the mean of the first 4 block means minus the Earth rate; the bundle's bias and no
    drift model until then; the drift model's history starts at the log's first sample."""
    x = np.column_stack([_log(40, 3), _log(40, 4) + 20.0])
    axes = [_axis("gx", bias=9.0, earth=EARTH_30), _axis("gz", bias=-2.0, earth=0.0)]
    eng = _engine(axes, factor=2, bias=4.0, segment=segment)
    assert eng.n_cal == 4
    out = _run(eng, x, chunk)
    for k, (a, earth) in enumerate(zip(axes, (EARTH_30, 0.0))):
        means = x[:, k].reshape(20, 2).mean(axis=1)
        level = means[:4].mean()
        assert eng.re_estimated_bias_dph[k] == pytest.approx(level - earth, rel=1e-12)
        assert eng.biases()[k] == pytest.approx((level - earth, level), rel=1e-12)
        drift = _persistence_reference(x[:, k], 2, level)
        drift[:8] = 0.0  # calibrating
        assert_allclose(out["drift_dph"][:, k], drift, rtol=1e-12, atol=1e-9)
        expected = x[:, k] - np.where(np.arange(40) < 8, a.bias_dph, level - earth) - drift
        assert_allclose(out["compensated_dph"][:, k], expected, rtol=1e-12, atol=1e-9)
    assert eng.first_active() == [8, 8]


def test_bias_window_rounding_and_bias_only_first_active():
    assert _engine([_axis()], bias=2.4).n_cal == 2
    assert _engine([_axis()], bias=2.6).n_cal == 3
    assert _engine([_axis()], bias=0.2).n_cal == 1  # at least one interval
    assert _engine([_axis()], bias=6.0, model_dt_s=2.0).n_cal == 3
    assert _engine([_axis()], bias="3").n_cal == 3
    assert _engine([_axis()]).n_cal == 0
    eng = _engine([_axis(bias=5.0)], factor=2, model=BIAS_ONLY, bias=3.0)
    out = _run(eng, np.arange(20.0), 7)
    level = np.arange(20.0).reshape(10, 2).mean(axis=1)[:3].mean()
    assert eng.first_active() == [6]
    assert_allclose(out["compensated_dph"][:, 0], np.arange(20.0) - np.where(np.arange(20) < 6, 5.0, level))


def test_a_log_shorter_than_the_bias_window_is_refused_in_one_line():
    for n, chunk in ((9, None), (9, 2), (10, 3)):
        eng = _engine([_axis()], factor=2, bias=6.0)
        with pytest.raises(InsufficientDataError) as info:
            _run(eng, np.arange(float(n)), chunk)
        got = n // 2
        assert str(info.value) == (f"re-estimating the bias needs 6 s of the log; it has only {got} s (pass bias= "
                                   "keep or a shorter window)")
        assert info.value.needed == 6 and info.value.got == got
    eng = _engine([_axis()], factor=2, bias=5.0, model_dt_s=0.5)  # 10 intervals of 0.5 s
    with pytest.raises(InsufficientDataError, match="needs 5 s of the log; it has only 4.5 s"):
        _run(eng, np.arange(18.0), 4)
    for bias, first in (("keep", 0), (2.0, 2), (5.0, 5)):  # bias only, several segments: the first sample it acts
        eng = _engine([_axis()], factor=1, segment=4, model=BIAS_ONLY, bias=bias)  # on stays the first one
        _run(eng, np.arange(12.0), None)
        assert eng.first_active() == [first], bias
    eng = _engine([_axis()], factor=1, segment=4, bias=4.0)  # the window completes with the first segment:
    assert [b.t_s.size for b in eng.push(np.arange(4.0), np.arange(4.0).reshape(-1, 1))] == [4]  # emitted at once
    assert eng.re_estimated_bias_dph == [1.5]
    for chunk in (None, 2):  # the log ends exactly on a segment boundary, short of the window (finish: no rows)
        eng = _engine([_axis()], factor=1, segment=4, bias=5.0)
        with pytest.raises(InsufficientDataError, match="needs 5 s of the log; it has only 4 s"):
            _run(eng, np.arange(4.0), chunk)
    eng = _engine([_axis()], factor=2, bias=6.0)  # exactly the window: fine
    _run(eng, np.arange(12.0), 5)
    assert eng.first_active() == [None]  # never past the window: the model never acts


@pytest.mark.parametrize("bad", ["abc", 0, -1.0, None, float("nan"), "re-estimate", [1]])
def test_bad_bias_is_one_line(bad):
    with pytest.raises(ConfigError) as info:
        _engine([_axis()], bias=bad)
    assert str(info.value) == (f"bias must be 'keep' or a re-estimation window > 0 s; got {bad!r}; pass bias= keep "
                               "or re-estimate:SECONDS")


@pytest.mark.parametrize("bad", [0, -2, 2.0, True, "3", None])
def test_bad_factor_and_segment_are_one_line(bad):
    with pytest.raises(ConfigError) as info:
        _engine([_axis()], factor=bad)
    assert str(info.value) == f"factor must be an integer >= 1; got {bad!r}"
    eng = _engine([_axis()], factor=np.int32(2))
    assert eng.factor == 2 and type(eng.factor) is int and eng.seg_blocks == 131072 and eng.seg_native == 262144
    assert _engine([_axis()], factor=1).seg_blocks == 262144
    assert _engine([_axis()], factor=3, segment=5).seg_native == 15
    assert _engine([_axis()], factor=3, segment=1).seg_blocks == 1
    for seg in (0, -1):
        with pytest.raises(ConfigError, match=rf"^segment must be >= 1 modelling interval; got {seg}$"):
            _engine([_axis()], segment=seg)


def test_push_checks_the_shape_and_counts():
    eng = _engine([_axis("gx"), _axis("gz")], factor=2, segment=2)
    for bad in (np.zeros(4), np.zeros((4, 1)), np.zeros((4, 3)), np.zeros((2, 2, 2))):
        with pytest.raises(ConfigError, match=r"rate_dph.*shape \(n, 2\)"):
            eng.push(np.arange(4.0), bad)
    assert eng.push(np.arange(3.0), np.ones((3, 2))) == []  # less than a segment: held
    assert eng.n_in == 3 and eng.n_out == 0
    out = eng.push(np.arange(3.0, 9.0), np.ones((6, 2)))  # 9 samples: two segments of 4 out, 1 held
    assert [b.t_s.tolist() for b in out] == [[0, 1, 2, 3], [4, 5, 6, 7]]
    assert eng.n_in == 9 and eng.n_out == 8
    last = eng.finish()
    assert [b.t_s.tolist() for b in last] == [[8.0]] and eng.n_out == 9
    assert eng.finish() == []  # nothing left
    fresh = _engine([_axis()], factor=2)
    assert fresh.finish() == [] and fresh.model_rate_series().shape == (0, 1) and fresh.first_active() == [None]
    quiet = _engine([_axis()], factor=2, keep_model_rate=False)
    _run(quiet, np.arange(10.0), 3)
    assert quiet.block_means_dph == [] and quiet.model_rate_series().shape == (0, 1)


def test_finish_with_only_held_calibration_segments():
    """Segments held for the bias window, the log ending exactly at a segment boundary: finish emits them."""
    eng = _engine([_axis(bias=0.0)], factor=2, bias=4.0, segment=2)
    x = np.arange(8.0)
    blocks = eng.push(np.arange(8.0), x.reshape(-1, 1))  # two segments of 2 intervals: 4 intervals = the window
    blocks += eng.finish()
    comp = np.concatenate([b.compensated_dph for b in blocks])[:, 0]
    assert_allclose(comp, x - np.where(np.arange(8) < 8, 0.0, 0.0))  # all calibrating: the bundle's bias (0)
    assert eng.re_estimated_bias_dph == [pytest.approx(3.5)]
    eng = _engine([_axis(bias=0.0)], factor=2, bias=6.0, segment=2)
    eng.push(np.arange(8.0), x.reshape(-1, 1))
    with pytest.raises(InsufficientDataError):
        eng.finish()


class _RateModel:
    """A rate-input model (the Kalman filter's interface): predicts the previous sample, sigma 0.5 + j / 10."""

    input_kind = "rate"

    def filter(self, z, state=None):
        prev = 0.0 if state is None else state[0]
        j0 = 0 if state is None else state[1]
        pred = np.concatenate([[prev], z[:-1]]) if z.size else np.empty(0)
        sigma = 0.5 + (j0 + np.arange(z.size)) / 10.0
        return pred, sigma, (z[-1] if z.size else prev, j0 + z.size)

    def forecast_with_uncertainty(self, steps, state=None):
        return np.array([state[0]]), np.array([0.5 + state[1] / 10.0]), state


@pytest.mark.parametrize("chunk", (1, 7, None))
def test_rate_input_model_drift_and_sigma_are_held(chunk):
    ax = _axis(bias=1.0, earth=2.0)
    ax.models = {"kalman": _RateModel()}
    x = _log(17)
    eng = _engine([ax], factor=2, model="kalman", bias=2.0, segment=3)
    assert eng.has_sigma is True
    out = _run(eng, x, chunk)
    means = x[:16].reshape(8, 2).mean(axis=1)
    level = means[:2].mean()
    z = means - level
    p = np.r_[0.0, z]  # previous sample; the 9th is the prediction after the log
    sig = 0.5 + np.arange(9) / 10.0
    drift = np.repeat(p, 2)[:17]
    sigma = np.repeat(sig, 2)[:17]
    drift[:4], sigma[:4] = 0.0, np.nan  # calibrating (2 intervals)
    assert_allclose(out["drift_dph"][:, 0], drift, rtol=1e-12, atol=1e-12)
    assert_allclose(out["sigma"][:, 0], sigma, rtol=1e-12)
    assert_allclose(out["compensated_dph"][:, 0], x - np.where(np.arange(17) < 4, 1.0, level - 2.0) - drift,
                    rtol=1e-12, atol=1e-9)
    assert eng.first_active() == [4]


def test_sigma_is_nan_for_axes_without_a_rate_model():
    ax = _axis("gx")
    ax.models = {"kalman": _RateModel()}
    eng = StreamCompensator([AxisPlan("gx", ax, "kalman"), AxisPlan("gz", _axis("gz"), "persistence")], factor=1,
                            model_dt_s=1.0, wavelet="haar", mode="periodization")
    out = _run(eng, np.column_stack([_log(10), _log(10, 5)]), 3)
    assert np.isfinite(out["sigma"][:, 0]).all() and np.isnan(out["sigma"][:, 1]).all()


# ---------------------------------------------------------------------------------------------------------------
# the log source and its matching to a bundle


def _csv(path, header, x, t=None):
    x = np.asarray(x, dtype=float).reshape(len(x), -1)
    t = np.arange(x.shape[0], dtype=float) if t is None else t
    np.savetxt(path, np.column_stack([t, x]), delimiter=",", header=header, comments="", fmt="%.17g")
    return path


def _all(src, chunk):
    parts = list(src.chunks(chunk))
    assert all(p[0].shape[0] <= chunk for p in parts)
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def test_open_log_reads_the_declared_unit_and_chunks_any_size(tmp_path):
    from fogdrift.compensate.sources import DEFAULT_CHUNK, open_log

    v = 0.01 + 1e-3 * np.arange(23)
    src = open_log(_csv(tmp_path / "s.csv", "t_s,gz[deg/s]", v, t=5.0 + 0.5 * np.arange(23)))
    assert (src.unit, src.unit_given, src.declared_unit, src.scale_to_dph) == ("deg/s", False, "deg/s", 3600.0)
    assert src.axis_names == ("gz",) and src.dt_s == 0.5 and src.t0_s == 5.0 and src.n_samples == 23
    assert src.path == tmp_path / "s.csv" and len(src.sha256) == 64
    assert not any("read in chunks" in n for n in src.notes) and "unit 'deg/s' declared in the file" in src.notes
    for chunk in (1, 7, 64, DEFAULT_CHUNK):
        t, x = _all(src, chunk)
        assert_allclose(t, 5.0 + 0.5 * np.arange(23), rtol=1e-15)
        assert_allclose(x[:, 0], v * 3600.0, rtol=1e-12)
    assert DEFAULT_CHUNK == 1048576
    assert len(list(src.chunks())) == 1
    for bad in (0, -1, 1.5, True, "7", None):
        with pytest.raises(ConfigError) as info:
            list(src.chunks(bad))
        assert str(info.value) == f"chunk_samples= must be an integer >= 1 (rows read at a time); got {bad!r}"
    t, x = _all(src, np.int64(5))
    assert t.size == 23

    given = open_log(tmp_path / "s.csv", unit="deg/h")  # the option takes precedence over the file's unit
    assert (given.unit, given.unit_given, given.declared_unit, given.scale_to_dph) == ("deg/h", True, "deg/s", 1.0)
    assert_allclose(_all(given, 7)[1][:, 0], v, rtol=1e-12)


@pytest.mark.parametrize("kind", ("npy", "csv"))
def test_open_log_hands_the_time_unit_on_and_records_the_file(tmp_path, kind):
    """A time column in ms (10-ms steps from 5 ms): read as such on both paths; the streamed source names its file
    and its SHA-256 (both go into the outputs' JSON)."""
    import hashlib

    from fogdrift.compensate.sources import open_log

    t_ms = 5.0 + 10.0 * np.arange(12)
    gz = np.arange(12.0)
    if kind == "npy":
        path = tmp_path / "r.npy"
        np.save(path, np.column_stack([t_ms, gz]))
        src = open_log(path, unit="deg/h", time_column="col0", time_unit="ms")
        assert any("read in chunks" in n for n in src.notes)  # the streamed path
    else:
        path = _csv(tmp_path / "r.csv", "stamp,gz[deg/h]", gz, t=t_ms)  # a name that says no unit
        src = open_log(path, time_column="stamp", time_unit="ms")
        assert not any("read in chunks" in n for n in src.notes)
    assert src.dt_s == pytest.approx(0.01, rel=1e-12, abs=0) and src.t0_s == pytest.approx(0.005, rel=1e-12, abs=0)
    t, x = _all(src, 5)
    assert_allclose(t, 0.005 + 0.01 * np.arange(12), rtol=1e-12, atol=0)
    assert_array_equal(x[:, 0], gz)
    assert src.path == path and src.sha256 == hashlib.sha256(path.read_bytes()).hexdigest()


def test_npy_is_streamed_from_the_file_and_other_options_load_it(tmp_path, monkeypatch):
    import fogdrift.compensate.sources as sources

    np.save(tmp_path / "r.npy", np.column_stack([np.arange(10.0), -np.arange(10.0)]))
    calls = []
    real_load = sources.load
    real_segments = sources.load_segments
    monkeypatch.setattr(sources, "load", lambda *a, **k: calls.append(k) or real_load(*a, **k))
    monkeypatch.setattr(sources, "load_segments", lambda *a, **k: calls.append(k) or real_segments(*a, **k))
    src = sources.open_log(tmp_path / "r.npy", unit="deg/s", rate_hz=2.0)
    assert calls == [] and any("read in chunks" in n for n in src.notes)
    assert src.axis_names == ("col0", "col1") and src.dt_s == 0.5 and src.declared_unit is None and src.t0_s == 0.0
    assert (src.unit, src.unit_given, src.scale_to_dph) == ("deg/s", True, 3600.0)
    for chunk in (1, 3, 64):
        t, x = _all(src, chunk)
        assert_array_equal(t, 0.5 * np.arange(10))
        assert_allclose(x, 3600.0 * np.column_stack([np.arange(10.0), -np.arange(10.0)]), rtol=1e-15)
    src = sources.open_log(tmp_path / "r.npy", unit="deg/s", rate_hz=2.0, columns=["col1"], format="npy")
    assert calls == [] and src.axis_names == ("col1",)
    assert_allclose(_all(src, 4)[1][:, 0], -3600.0 * np.arange(10.0))
    for kw in (dict(gaps="split"), dict(format="table")):
        calls.clear()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                src = sources.open_log(tmp_path / "r.npy", unit="deg/s", rate_hz=2.0, **kw)
            except (ConfigError, DataFormatError):
                pass
        assert len(calls) == 1, kw
        assert calls[0]["unit"] == "deg/s" and "reader_options" not in calls[0] and "temperature" not in calls[0]
        assert calls[0].get("gaps") == (None if "gaps" in kw else "error")


def test_a_log_without_a_unit_is_refused_suggesting_the_bundles(tmp_path):
    from fogdrift.compensate.sources import open_log

    log = _csv(tmp_path / "n.csv", "t_s,gz", np.arange(5.0))
    with pytest.raises(ConfigError) as info:
        open_log(log, bundle_unit="deg/s")
    assert str(info.value) == (f"{log}: the log declares no rate unit and none was given; pass unit= deg/s (the bundle "
                               "was trained on deg/s) or the unit of its numbers (units are never guessed)")
    assert info.value.__cause__ is None and info.value.__suppress_context__
    with pytest.raises(ConfigError) as info:  # no bundle unit to suggest: the reader's own line
        open_log(log)
    assert str(info.value).startswith(f"{log}: no rate unit: the file declares none for gz; pass unit= (")
    assert open_log(log, unit="deg/h", bundle_unit="deg/s").unit == "deg/h"
    np.save(tmp_path / "r.npy", np.arange(10.0))  # no interval either: that is the line, not the unit's
    with pytest.raises(ConfigError) as info:
        open_log(tmp_path / "r.npy", unit="deg/h", bundle_unit="deg/h")
    assert "the log declares no rate unit" not in str(info.value)
    with pytest.raises(ConfigError, match="declares no rate unit and none was given; pass unit= deg/h"):
        open_log(tmp_path / "r.npy", rate_hz=1.0, bundle_unit="deg/h")


def test_accelerometer_channels_are_refused_naming_them(tmp_path):
    from fogdrift.compensate.sources import open_log

    one = _csv(tmp_path / "a1.csv", "t_s,ax[m/s^2]", np.ones((5, 1)))
    with pytest.raises(ConfigError) as info:
        open_log(one)
    assert str(info.value) == (f"{one}: compensate applies a gyro drift model; ax is an accelerometer channel (specific "
                               "force, from its unit): leave them out with columns=")
    two = _csv(tmp_path / "a2.csv", "t_s,ax[m/s^2],ay[m/s^2]", np.ones((5, 2)))
    with pytest.raises(ConfigError) as info:
        open_log(two)
    assert str(info.value) == (f"{two}: compensate applies a gyro drift model; ax, ay are accelerometer channels "
                               "(specific force, from its unit): leave them out with columns=")
    mixed = _csv(tmp_path / "m.csv", "t_s,gz[deg/s],ax[m/s^2]", np.ones((5, 2)))  # refused, naming the file
    with pytest.raises(DataFormatError) as info:
        open_log(mixed)
    assert str(info.value) == (f"{mixed}: rate columns declare different units ['deg/s', 'm/s^2']; expected one unit "
                               "(choose columns with columns=)")


def test_one_declared_unit_for_every_rate_column():
    from fogdrift.compensate.sources import _one_declared

    assert _one_declared([], "p") is None and _one_declared([None, None], "p") is None
    assert _one_declared(["deg/s", "deg/s"], "p") == "deg/s"
    with pytest.raises(DataFormatError, match=r"q: .*different units.*'deg/h', 'deg/s'"):
        _one_declared(["deg/s", "deg/h"], "q")
    with pytest.raises(DataFormatError) as info:
        _one_declared(["deg/s", "deg/h", None], "p.csv")
    assert str(info.value) == ("p.csv: rate columns declare different units ['None', 'deg/h', 'deg/s']; expected one "
                               "unit (choose columns with columns=)")


def test_gaps_split_compensates_the_longest_segment_and_says_so(tmp_path):
    from fogdrift.compensate.sources import open_log
    from fogdrift.errors import FogdriftWarning

    t = np.r_[np.arange(10.0), 30.0 + np.arange(25.0)]
    log = _csv(tmp_path / "g.csv", "t_s,gz[deg/h]", np.arange(35.0), t=t)
    with pytest.warns(FogdriftWarning) as rec:
        src = open_log(log, gaps="split")
    assert [str(w.message) for w in rec] == [
        f"{log}: 2 segments between gaps; compensating the longest (25 samples, segment 2 of 2: samples 10-34 "
        "(lines 12-36), after a gap of 21 s)"]
    import linecache

    line = linecache.getline(rec[0].filename, rec[0].lineno)  # stacklevel: not fogdrift's own warn call
    assert line.strip() and "warn(" not in line and "FogdriftWarning" not in line and "samples, " not in line
    assert src.n_samples == 25 and src.t0_s == 30.0
    assert src.notes[-1] == "segment 2 of 2: samples 10-34 (lines 12-36), after a gap of 21 s"
    t_, x_ = _all(src, 7)
    assert_array_equal(t_, 30.0 + np.arange(25.0))
    assert_array_equal(x_[:, 0], np.arange(10.0, 35.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        src = open_log(_csv(tmp_path / "ok.csv", "t_s,gz[deg/h]", np.arange(9.0)), gaps="split")  # one: no warning
    assert src.n_samples == 9
    with pytest.raises(DataFormatError):
        open_log(log)


def _bundle(**kw):
    d = dict(input_unit="deg/h", native_dt_s=0.1, block_average_factor=10, model_dt_s=1.0, axis_names=("gx", "gz"))
    d.update(kw)
    return SimpleNamespace(**d)


def _source(**kw):
    d = dict(unit="deg/h", unit_given=False, declared_unit="deg/h", scale_to_dph=1.0, dt_s=0.1, axis_names=("gz",),
             path="log.csv")
    d.update(kw)
    return SimpleNamespace(**d)


def test_match_log_units_by_hand():
    from fogdrift.compensate.sources import match_log

    m = match_log(_source(), _bundle())
    assert m.unit == "deg/h" and m.scale_to_dph == 1.0 and m.factor == 10 and type(m.factor) is int
    assert m.axes == (("gz", "gz"),) and m.notes == ("axes of the bundle not in the log (not compensated): gx",)
    with pytest.raises(ConfigError) as info:
        match_log(_source(unit="deg/s", declared_unit="deg/s", scale_to_dph=3600.0), _bundle())
    assert str(info.value) == ("log.csv: the log declares unit deg/s but the bundle was trained on deg/h; pass unit= "
                               "deg/s to convert it")
    m = match_log(_source(unit="deg/s", unit_given=True, declared_unit=None, scale_to_dph=3600.0), _bundle())
    assert m.unit == "deg/s" and m.scale_to_dph == 3600.0
    assert m.notes[:2] == ("unit: the log declares none; its numbers are read as deg/s ({opt:unit})",
                           "unit: the log is read as deg/s ({opt:unit}) and converted; the bundle was trained on deg/h")
    m = match_log(_source(unit="deg/h", unit_given=True, declared_unit=" deg/s "), _bundle())
    assert m.notes[0] == "unit: the log declares deg/s; its numbers are read as deg/h ({opt:unit} takes precedence)"
    assert len(m.notes) == 2  # the unit is the bundle's: nothing converted
    m = match_log(_source(unit="deg/h", unit_given=True, declared_unit="deg/h"), _bundle())
    assert m.notes == ("axes of the bundle not in the log (not compensated): gx",)


def test_match_log_rates_exactly_at_the_tolerance():
    from fogdrift.compensate.sources import match_log

    b = _bundle()
    for dt in (0.1, 0.1 * (1 + 0.9e-6), 0.1 * (1 - 0.9e-6)):
        assert match_log(_source(dt_s=dt), b).factor == 10
    with pytest.raises(ConfigError) as info:
        match_log(_source(dt_s=0.1 * (1 + 1.1e-6)), b)
    assert str(info.value) == ("log.csv: the log is sampled at 9.99999 Hz, the bundle's training log at 10 Hz (models "
                               "at 1 Hz); pass accept_rate= to block-average it to the bundle's modelling rate")
    m = match_log(_source(dt_s=0.02), b, accept_rate=True)
    assert m.factor == 50 and type(m.factor) is int
    assert m.notes[0] == "rate: the log (50 Hz) differs from the training log (10 Hz); block-averaged x50 to the modelling rate"
    assert match_log(_source(dt_s=0.1), b, accept_rate=True).notes[0].startswith("axes")  # same rate: no note
    assert match_log(_source(dt_s=0.02), _bundle(model_dt_s=0.5), accept_rate=True).factor == 25  # 50 Hz -> 2 Hz
    with pytest.raises(ConfigError) as info:
        match_log(_source(dt_s=0.3), b, accept_rate=True)
    assert str(info.value) == ("log.csv: the log's 3.33333 Hz cannot be block-averaged to the bundle's modelling rate "
                               "1 Hz by an integer factor")
    assert info.value.__cause__ is None


def test_match_log_edges_the_workqueue_rerun_found():
    """Survivors of the full mutmut re-run of sources.py (0 undecided with the workqueue layer)."""
    from fogdrift.compensate.sources import match_log, parse_axis_map

    # the tolerance is inclusive: 1 s in 1e6 s is a relative difference of exactly 1e-6 in floating point
    assert abs(1e6 + 1.0 - 1e6) / 1e6 == 1e-6
    big = _bundle(native_dt_s=1e6, model_dt_s=1e7)
    assert match_log(_source(dt_s=1e6 + 1.0), big).factor == 10
    with pytest.raises(ConfigError):
        match_log(_source(dt_s=1e6 + 2.0), big)
    # the modelling rate is 1 / model_dt_s in both refusals (2 Hz for 0.5 s, not 0.5)
    half = _bundle(model_dt_s=0.5, block_average_factor=5)
    with pytest.raises(ConfigError) as info:
        match_log(_source(dt_s=0.05), half)
    assert "(models at 2 Hz)" in str(info.value)
    with pytest.raises(ConfigError) as info:
        match_log(_source(dt_s=0.3), half, accept_rate=True)
    assert str(info.value).endswith("cannot be block-averaged to the bundle's modelling rate 2 Hz by an integer factor")
    # every missing bundle axis is listed, separated by ", "
    m = match_log(_source(axis_names=("gz",)), _bundle(axis_names=("gx", "gy", "gz")))
    assert m.notes == ("axes of the bundle not in the log (not compensated): gx, gy",)
    # an empty entry between two others is skipped, not the end of the map; an entry splits at its first "="
    assert parse_axis_map("col0=gz, ,col1=gx") == {"col0": "gz", "col1": "gx"}
    assert parse_axis_map("col0=g=z") == {"col0": "g=z"}


def test_match_log_axes_by_name_and_map():
    from fogdrift.compensate.sources import match_log, parse_axis_map

    assert parse_axis_map(None) == {} and parse_axis_map("") == {} and parse_axis_map(" , ") == {}
    assert parse_axis_map({0: "gz", "a": 1}) == {"0": "gz", "a": "1"}
    assert parse_axis_map(" col0 = gz ,col1=gx,") == {"col0": "gz", "col1": "gx"}
    for bad in ("col0", "=gz", "col0=", " = ", "col0=gz,col1"):
        with pytest.raises(ConfigError) as info:
            parse_axis_map(bad)
        item = bad.split(",")[-1].strip()
        assert str(info.value) == (f"axis map entries look like LOG_AXIS=BUNDLE_AXIS (e.g. col0=gz); got {item!r} in "
                                   "axis_map=")
    b = _bundle()
    m = match_log(_source(axis_names=("col0", "col1")), b, axis_map="col0=gz,col1=gx")
    assert m.axes == (("col0", "gz"), ("col1", "gx"))
    assert m.notes == ("axis: log col0 -> bundle gz", "axis: log col1 -> bundle gx")
    m = match_log(_source(axis_names=("gx", "gz")), b)
    assert m.axes == (("gx", "gx"), ("gz", "gz")) and m.notes == ()
    with pytest.raises(ConfigError) as info:
        match_log(_source(axis_names=("gz",)), b, axis_map="col9=gz,col8=gx")
    assert str(info.value) == "axis map names ['col9', 'col8'], not axes of the log ['gz']; check axis_map="
    with pytest.raises(ConfigError) as info:
        match_log(_source(axis_names=("gy",)), b)
    assert str(info.value) == ("log.csv: log axis 'gy' has no model in the bundle, whose axes are ['gx', 'gz'] (pass "
                               "axis_map= gy=AXIS, or choose columns with columns=)")
    with pytest.raises(ConfigError) as info:
        match_log(_source(axis_names=("col0",)), b, axis_map="col0=gy")
    assert str(info.value) == "log.csv: log axis 'col0' has no model in the bundle, whose axes are ['gx', 'gz']"
    with pytest.raises(ConfigError) as info:
        match_log(_source(axis_names=("col0", "gz")), b, axis_map={"col0": "gz"})
    assert str(info.value) == "log axes 'col0' and 'gz' both map to bundle axis 'gz'; check axis_map="


# ---------------------------------------------------------------------------------------------------------------
# the streamed writers


def test_csv_writer_header_and_rows_by_hand(tmp_path):
    from fogdrift.compensate.outputs import CsvWriter

    w = CsvWriter(tmp_path / "c.csv", ["gx", "gz"], "deg/s", with_sigma=False)
    w.write(np.array([0.0, 0.5]), np.array([[1.0, 2.0], [3.0, 1 / 3]]), np.array([[0.1, 0.2], [0.3, 0.4]]), None)
    w.write(np.array([1.0]), np.array([[5.0, 6.0]]), np.array([[7.0, 8.0]]), None)
    w.close()
    assert w._fh.closed
    assert (tmp_path / "c.csv").read_text().splitlines() == [
        "t_s,gx[deg/s],gz[deg/s],gx_drift[deg/s],gz_drift[deg/s]", "0,1,2,0.1,0.2", "0.5,3,0.333333333333,0.3,0.4",
        "1,5,6,7,8"]
    w = CsvWriter(tmp_path / "s.csv", ["gz"], "deg/h", with_sigma=True)
    w.write(np.array([2.0]), np.array([[1.0]]), np.array([[-2.0]]), np.array([[0.25]]))
    w.write(np.array([3.0]), np.array([[1e20]]), np.array([[-2.5e-05]]), np.array([[1e-300]]))  # C's %g exponent
    w.abort()
    assert w._fh.closed
    assert (tmp_path / "s.csv").read_text() == ("t_s,gz[deg/h],gz_drift[deg/h],gz_drift_sigma[deg/h]\n2,1,-2,0.25\n"
                                                "3,1e+20,-2.5e-05,1e-300\n")


@pytest.mark.parametrize("with_sigma", (False, True))
@pytest.mark.parametrize("name", ("c.npz", ".fogdrift-tmp-77-c.npz"))
def test_npz_writer_assembles_the_archive_from_member_files(tmp_path, with_sigma, name):
    import zipfile

    from fogdrift.compensate.outputs import NpzWriter
    from fogdrift.output import TMP_PREFIX

    t = np.arange(5.0)
    comp = np.column_stack([t * 2, t * 3])
    drift = np.column_stack([-t, t / 7])
    sigma = np.column_stack([t + 0.5, t + 1.5])
    w = NpzWriter(tmp_path / name, 5, ["gx", "gz"], "deg/s", 3600.0, with_sigma)
    stem = name if name.startswith(TMP_PREFIX) else f"{TMP_PREFIX}{os.getpid()}-{name}"
    members = ["t_s", "compensated", "drift_estimate"] + (["drift_sigma"] if with_sigma else [])
    assert sorted(os.listdir(tmp_path)) == sorted(f"{stem}.{m}.npy" for m in members)
    w.write(t[:2], comp[:2], drift[:2], sigma[:2] if with_sigma else None)
    w.write(t[2:], comp[2:], drift[2:], sigma[2:] if with_sigma else None)
    assert w.n == 5
    w.close()
    assert os.listdir(tmp_path) == [name]  # the member files are gone
    with zipfile.ZipFile(tmp_path / name) as zf:
        assert {i.compress_type for i in zf.infolist()} == {zipfile.ZIP_STORED}
        assert sorted(zf.namelist()) == sorted(m + ".npy" for m in members + ["axis_names", "unit", "scale_to_dph"])
        with zf.open("compensated.npy") as fh:
            assert np.lib.format.read_magic(fh) == (2, 0)
    with np.load(tmp_path / name, allow_pickle=False) as z:
        assert_array_equal(z["t_s"], t)
        assert_array_equal(z["compensated"], comp)
        assert_array_equal(z["drift_estimate"], drift)
        assert z["compensated"].dtype == np.float64 and z["compensated"].shape == (5, 2)
        assert z["axis_names"].tolist() == ["gx", "gz"] and str(z["unit"]) == "deg/s"
        assert float(z["scale_to_dph"]) == 3600.0 and z["scale_to_dph"].dtype == np.float64
        if with_sigma:
            assert_array_equal(z["drift_sigma"], sigma)


def test_npz_writer_abort_and_a_short_write_leave_nothing(tmp_path, monkeypatch):
    from fogdrift.compensate.outputs import NpzWriter

    w = NpzWriter(tmp_path / "a.npz", 3, ["gz"], "deg/h", 1.0, True)
    w.write(np.arange(2.0), np.ones((2, 1)), np.ones((2, 1)), np.ones((2, 1)))
    w.abort()
    assert os.listdir(tmp_path) == [] and all(fh.closed for fh in w._files.values())
    w = NpzWriter(tmp_path / "b.npz", 3, ["gz"], "deg/h", 1.0, False)
    w.write(np.arange(2.0), np.ones((2, 1)), np.ones((2, 1)), None)
    with pytest.raises(RuntimeError, match=r"NPZ writer.*2 rows.*3"):
        w.close()
    assert os.listdir(tmp_path) == []
    calls = []

    def header_fails_on_the_second(fh, d):
        calls.append(d)
        if len(calls) == 2:
            raise OSError("disk full")
        real(fh, d)

    real = np.lib.format.write_array_header_2_0
    monkeypatch.setattr(np.lib.format, "write_array_header_2_0", header_fails_on_the_second)
    with pytest.raises(OSError, match="disk full"):
        NpzWriter(tmp_path / "c.npz", 3, ["gx", "gz"], "deg/h", 1.0, False)
    assert os.listdir(tmp_path) == []
    assert calls[0] == {"descr": "<f8", "fortran_order": False, "shape": (3,)}
    assert calls[1] == {"descr": "<f8", "fortran_order": False, "shape": (3, 2)}


@pytest.mark.parametrize("chunk", (1, 3, 7, None))
def test_allan_accumulator_block_means_by_hand(chunk):
    from fogdrift.compensate.outputs import AllanAccumulator

    assert AllanAccumulator(1 << 22, 1).f == 1 and AllanAccumulator((1 << 22) + 1, 1).f == 2
    assert AllanAccumulator(0, 1).f == 1
    acc = AllanAccumulator(10, 2, max_points=3)  # f = ceil(10 / 3) = 4
    assert acc.f == 4
    x = np.column_stack([np.arange(10.0), 100.0 + np.arange(10.0)])
    step = 10 if chunk is None else chunk
    for lo in range(0, 10, step):
        acc.add(x[lo:lo + step], -x[lo:lo + step])
    before, after = acc.series()
    assert_allclose(before, [[1.5, 101.5], [5.5, 105.5]])
    assert_allclose(after, -before)
    assert_allclose(acc.series(1)[0], [[5.5, 105.5]])  # from native sample 1: the next whole block
    assert_allclose(acc.series(4)[0], [[5.5, 105.5]])
    assert acc.series(5)[0].shape == (0, 2)
    assert acc.series(8)[1].shape == (0, 2)


def test_plot_before_after_draws_what_it_says(monkeypatch, tmp_path):
    import fogdrift.compensate.outputs as outputs
    from fogdrift.report.figures import literal

    saved = {}

    def fake_save(fig, path, **kw):
        saved.update(fig=fig, path=path, kw=kw)
        return "returned"

    monkeypatch.setattr(outputs, "save_figure", fake_save)

    def res(adev):
        adev = np.asarray(adev, dtype=float)
        return SimpleNamespace(tau_s=np.array([1.0, 2.0, 4.0]), adev_dph=adev, adev_lo68_dph=adev * 0.5,
                               adev_hi68_dph=adev * 1.25)

    curves = [("gx", res([0.0, 2.0, 1.0]), res([3.0, 1.5, 0.5]), "AR$x$"), ("g$z", res([0, 0, 0]), res([0, 0, 0]), "b")]
    caveats = {"gx": "the lower ADEV is not evidence " + "word " * 30, "g$z": "fine"}
    assert outputs.plot_before_after(curves, tmp_path / "f.png", "T$1$", caveats) == "returned"
    fig = saved["fig"]
    assert saved["path"] == tmp_path / "f.png" and saved["kw"] == {"dpi": 110, "bbox_inches": "tight"}
    assert_allclose(fig.get_size_inches(), [10.4, 4.2])
    axs = fig.axes
    assert len(axs) == 2
    for ax, name in zip(axs, ("gx", "g$z")):
        assert ax.get_xscale() == "log" and ax.get_xlabel() == "τ [s]" and ax.get_ylabel() == "σ(τ) [deg/h]"
        assert ax.get_title() == literal(f"T$1$: {name}")
        assert ax.xaxis.get_gridlines()[0].get_visible() and ax.xaxis.get_gridlines()[0].get_alpha() == 0.3
        assert ax.xaxis.get_minor_ticks()[0].gridline.get_visible()  # which="both": the log decades' minor grid
        assert ax.get_legend().get_texts()[0].get_fontsize() == 7
    assert axs[0].get_yscale() == "log" and axs[1].get_yscale() == "linear"  # all-zero ADEVs: a linear axis
    assert [t.get_text() for t in axs[0].get_legend().get_texts()] == ["log (bias removed)",
                                                                        "compensated: " + literal("AR$x$")]
    before, after = axs[0].containers
    line = before.lines[0]
    assert_array_equal(line.get_xdata(), [2.0, 4.0])
    assert_array_equal(line.get_ydata(), [2.0, 1.0])
    assert line.get_color() == "k" and line.get_marker() == "o" and line.get_linestyle() == "-"
    assert line.get_markersize() == 3 and line.get_linewidth() == 0.8
    assert after.lines[0].get_color() == "C3"
    assert_array_equal(after.lines[0].get_xdata(), [1, 2, 4])
    segs = before.lines[2][0].get_segments()  # yerr: adev - lo68 below, hi68 - adev above
    assert_allclose([s[0][1] for s in segs], [1.0, 0.5])
    assert_allclose([s[1][1] for s in segs], [2.5, 1.25])
    assert axs[1].containers[0].lines[0].get_xdata().size == 0
    [text] = axs[0].texts
    assert text.get_position() == (0.0, -0.17) and text.get_transform() == axs[0].transAxes
    assert text.get_ha() == "left" and text.get_va() == "top" and text.get_fontsize() == 7 and text.get_color() == "C3"
    import textwrap

    assert text.get_text() == literal(textwrap.fill(caveats["gx"], width=80)) and "\n" in text.get_text()
    assert [t.get_text() for t in axs[1].texts] == ["fine"] and axs[1].texts[0].get_color() == "k"
    outputs.pyplot().close(fig)
    for cav in (None, {}, {"gx": ""}, {"gz": "not checked"}):
        outputs.plot_before_after(curves[:1], tmp_path / "g.png", "t", cav)
        assert len(saved["fig"].axes[0].texts) == 0
        assert_allclose(saved["fig"].get_size_inches(), [5.2, 4.2])
        outputs.pyplot().close(saved["fig"])
    outputs.plot_before_after(curves[:1], tmp_path / "g.png", "t", {"gx": "x not checked"})
    assert saved["fig"].axes[0].texts[0].get_color() == "C3"
    outputs.pyplot().close(saved["fig"])
    outputs.plot_before_after(curves[:1], tmp_path / "g.png", "t", {"gx": "a" * 40 + " " + "b" * 40})  # 81 chars
    assert saved["fig"].axes[0].texts[0].get_text() == "a" * 40 + "\n" + "b" * 40  # wrapped at 80
    outputs.pyplot().close(saved["fig"])


# ---------------------------------------------------------------------------------------------------------------
# the compensated test block of analyze


def _model_axis():
    rate = np.array([0.5, -1.0, 2.0, 0.25, 1.0, -0.5, 3.0])  # bias and Earth rate removed
    return SimpleNamespace(name="g z", split={"train": (0, 3), "test": (3, 7)}, bias_dph=4.0, earth_rate_dph=EARTH_30,
                           rate_dph=rate, dt_s=0.5,
                           causal_predictions={"AR(p)": np.array([0.1, np.nan, 0.3, 0.4]),
                                               "persistence": [1.0, 2.0, 3.0, 4.0], "custom": np.zeros(4)})


def test_compensated_test_block_by_definition_by_hand():
    from fogdrift.compensate.holdout import compensated_test_block

    cols = compensated_test_block(_model_axis(), t0_s=10.0)
    assert list(cols) == ["t_s", "measured", "bias", "ar", "persistence", "custom"]
    measured = np.array([0.25, 1.0, -0.5, 3.0]) + 4.0 + EARTH_30
    assert_allclose(cols["t_s"], [11.5, 12.0, 12.5, 13.0])
    assert_allclose(cols["measured"], measured, rtol=1e-15)
    assert_allclose(cols["bias"], measured - 4.0, rtol=1e-15)  # the Earth rate stays
    assert_allclose(cols["ar"], measured - 4.0 - [0.1, np.nan, 0.3, 0.4], rtol=1e-15)
    assert_allclose(cols["persistence"], measured - 4.0 - [1, 2, 3, 4], rtol=1e-15)
    assert cols["persistence"].dtype == np.float64
    assert_allclose(compensated_test_block(_model_axis())["t_s"], [1.5, 2.0, 2.5, 3.0])
    ma = _model_axis()
    ma.rate_dph = ma.rate_dph.astype(np.float32) + np.float32(0.1)  # float32 in: the columns are float64
    cols = compensated_test_block(ma)
    assert all(v.dtype == np.float64 for v in cols.values())
    assert_allclose(cols["measured"][0], float(np.float32(0.25) + np.float32(0.1)) + 4.0 + EARTH_30, rtol=1e-15)


def test_write_compensated_test_block_by_hand(tmp_path):
    from fogdrift.compensate.holdout import write_compensated_test_block
    from fogdrift.io import load

    ma = _model_axis()
    ma.causal_predictions = {"AR(p)": np.array([0.1, np.nan, 0.3, 0.4])}
    ma.rate_dph = np.array([0.5, -1.0, 2.0, 1.0, 2.0, 1 / 3, 5.0])
    ma.earth_rate_dph = 0.0
    other = _model_axis()
    other.name = "gx"
    paths = write_compensated_test_block([ma, other], tmp_path, t0_s=0.0)
    assert paths == [tmp_path / "compensated_test_g_z.csv", tmp_path / "compensated_test_gx.csv"]
    assert sorted(os.listdir(tmp_path)) == ["compensated_test_g_z.csv", "compensated_test_gx.csv"]  # no temporaries
    assert paths[0].read_text().splitlines() == [
        "t_s,measured[deg/h],bias[deg/h],ar[deg/h]", "1.5,5,1,0.9", "2,6,2,", "2.5,4.33333333333,0.333333333333,0.0333333333333",
        "3,9,5,4.6"]
    back = load(paths[1], columns=["measured", "persistence"])
    assert back.dt_s == 0.5 and back.n_samples == 4 and back.axis_names == ("measured", "persistence")
    assert write_compensated_test_block([], tmp_path) == []
    (tmp_path / "t0").mkdir()
    write_compensated_test_block([ma], tmp_path / "t0", t0_s=100.0)
    assert [ln.split(",")[0] for ln in (tmp_path / "t0" / "compensated_test_g_z.csv").read_text().splitlines()] == \
        ["t_s", "101.5", "102", "102.5", "103"]
    (tmp_path / "d").mkdir()
    write_compensated_test_block([ma], tmp_path / "d")  # default time origin 0
    assert (tmp_path / "d" / "compensated_test_g_z.csv").read_text().splitlines()[1].startswith("1.5,")


def test_a_failure_while_writing_the_test_block_leaves_no_file(tmp_path, monkeypatch):
    from fogdrift.compensate.holdout import write_compensated_test_block

    calls = []

    def fails_in_the_second_row(v):
        calls.append(v)
        if len(calls) > 10:
            raise KeyboardInterrupt
        return math.isfinite(v)

    monkeypatch.setattr(np, "isfinite", fails_in_the_second_row)
    with pytest.raises(KeyboardInterrupt):
        write_compensated_test_block([_model_axis()], tmp_path)
    assert os.listdir(tmp_path) == []


def test_bias_window_ending_in_the_last_short_segment_gets_the_prediction_after_the_log():
    """11 samples at factor 2 (5 intervals and 1 sample), bias window 4 s: the one (final, held) segment completes
    the window; the last native sample gets the prediction after the log, (z[3] + z[4]) / 2."""
    x = _log(11, 8)
    eng = _engine([_axis(bias=3.0)], factor=2, bias=4.0)
    out = _run(eng, x, None)
    means = x[:10].reshape(5, 2).mean(axis=1)
    z = means - means[:4].mean()
    assert_allclose(out["drift_dph"][10, 0], 0.5 * (z[3] + z[4]), rtol=1e-12)
    assert_array_equal(out["drift_dph"][:8, 0], 0.0)
    assert_allclose(out["drift_dph"][8:10, 0], 0.5 * (z[2] + z[3]), rtol=1e-12)


def test_a_full_segment_is_processed_as_soon_as_it_is_complete():
    eng = _engine([_axis()], factor=2, segment=2)  # 4 native samples per segment
    out = eng.push(np.arange(4.0), np.ones((4, 1)))
    assert [b.t_s.tolist() for b in out] == [[0.0, 1.0, 2.0, 3.0]] and eng.n_out == 4
    assert eng.finish() == []


def test_integer_input_is_read_as_float():
    x = np.arange(10)
    a = _engine([_axis(bias=1.5)], factor=2)
    blocks = a.push(np.arange(10.0), x.reshape(-1, 1)) + a.finish()
    comp = np.concatenate([b.compensated_dph for b in blocks])[:, 0]
    assert comp.dtype == np.float64
    assert_allclose(comp, _run(_engine([_axis(bias=1.5)], factor=2), x.astype(float), None)["compensated_dph"][:, 0])
    assert comp[0] == -1.5
    b = _engine([_axis(bias=1.5)], factor=2)  # integer times too (a log stamped in whole seconds)
    blocks = b.push(np.arange(10), x.reshape(-1, 1)) + b.finish()
    assert all(blk.t_s.dtype == np.float64 for blk in blocks)
    assert_array_equal(np.concatenate([blk.t_s for blk in blocks]), np.arange(10.0))


def test_npz_members_over_the_zip64_limit_are_written(tmp_path, monkeypatch):
    """A compensated log over 2 GiB needs ZIP64 members; the limit is lowered to 300 bytes here to check it."""
    import zipfile

    from fogdrift.compensate.outputs import NpzWriter

    monkeypatch.setattr(zipfile, "ZIP64_LIMIT", 300)  # the 40-row members (448 bytes) are over it
    w = NpzWriter(tmp_path / "big.npz", 40, ["gz"], "deg/h", 1.0, False)
    w.write(np.arange(40.0), np.ones((40, 1)), np.zeros((40, 1)), None)
    w.close()
    monkeypatch.undo()
    with np.load(tmp_path / "big.npz") as z:
        assert_array_equal(z["t_s"], np.arange(40.0))


def test_npz_writer_stores_float64_whatever_it_is_given(tmp_path):
    from fogdrift.compensate.outputs import NpzWriter

    w = NpzWriter(tmp_path / "i.npz", 3, ["gz"], "deg/h", 1.0, False)
    w.write(np.arange(3), np.arange(3, dtype=np.float32).reshape(3, 1) + 0.5, np.array([[1], [2], [3]]), None)
    w.close()
    with np.load(tmp_path / "i.npz") as z:
        assert_array_equal(z["t_s"], [0.0, 1.0, 2.0])
        assert_array_equal(z["compensated"][:, 0], [0.5, 1.5, 2.5])
        assert_array_equal(z["drift_estimate"][:, 0], [1.0, 2.0, 3.0])


def test_open_log_hands_every_reading_option_to_the_reader(tmp_path):
    from fogdrift.compensate.sources import open_log

    log = _csv(tmp_path / "t.csv", "t_s,gz[deg/h],temp[degC]", np.column_stack([np.arange(5.0), 20 + np.arange(5.0)]))
    assert open_log(log, temperature="temp").axis_names == ("gz",)  # the temperature column is not a rate
    with pytest.raises(DataFormatError, match="unknown unit 'degC'"):
        open_log(log)
    with pytest.raises((ConfigError, DataFormatError)):  # a forced format is used
        open_log(log, temperature="temp", format="npz")
    with pytest.raises((ConfigError, DataFormatError)):  # reader options are used (';' splits nothing here)
        open_log(log, temperature="temp", reader_options={"delimiter": ";"})
