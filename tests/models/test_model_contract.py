"""Contract checks run over every drift model in the registry (the scikit-learn ``estimator_checks`` idea).

The cases come from ``fogdrift.models.MODELS`` (one row per model; a class missing from
``TEST_PARAMS`` runs with ``FAST_OVERRIDES`` filtered to its signature), so a model added to the
registry is contract-checked without editing this file. The Elman rows are skipped when JAX
does not import.
"""

from __future__ import annotations

import copy
import importlib.util
import inspect
import json

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from fogdrift.errors import DataFormatError, NotFittedError
from fogdrift.models import MODELS, load_model, save_model

_ELMAN_FAST = {"lags": 2, "hidden": 3, "epochs": 15, "patience": 5, "window": 32, "seed": 0}

#: class name -> list of constructor kwargs to test (small and fast).
TEST_PARAMS = {
    "Persistence": [{}],
    "AR": [{"order": 3}, {"order": "aic", "max_order": 4}],
    "GM11": [{"mode": "rolling", "window": 6}, {"mode": "whole", "shift": 0.5}],
    "Elman": [_ELMAN_FAST],
    "GreyElman": [_ELMAN_FAST],
    "Kalman": [{}, {"components": [{"kind": "white", "arw_dprh": 1e-4},
                                   {"kind": "gauss_markov", "tc_s": 30.0, "sigma_dph": 0.05}]}],
}
FAST_OVERRIDES = {"lags": 2, "hidden": 3, "epochs": 15, "patience": 5, "seed": 0}


def _params_for(cls) -> list[dict]:
    if cls.__name__ in TEST_PARAMS:
        return TEST_PARAMS[cls.__name__]
    names = set(inspect.signature(cls.__init__).parameters)
    return [{k: v for k, v in FAST_OVERRIDES.items() if k in names}]


def _classes() -> list[type]:
    out = []
    for spec in MODELS:
        if spec.module.endswith(".elman") and importlib.util.find_spec("jax") is None:  # pragma: no cover
            continue
        out.append(spec.load())
    return out


CASES = [
    pytest.param(cls, params, id=f"{cls.__name__}-{i}")
    for cls in _classes()
    for i, params in enumerate(_params_for(cls))
]


def _series(seed: int, n: int = 200) -> np.ndarray:
    """Seeded drift-like series [deg/h]: slow oscillation + trend + small noise."""
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    return 0.05 * np.sin(2 * np.pi * k / 60) + 1e-4 * k + rng.normal(0, 0.005, n)


Y = _series(0)
TRAIN, VAL, TEST = Y[:120], Y[120:160], Y[160:]
HIST = Y[:160]


def _fitted_state(model) -> dict:
    return {k: v for k, v in vars(model).items() if k.endswith("_") and not k.startswith("__")}


def _assert_state_equal(a: dict, b: dict):
    assert a.keys() == b.keys()
    for key in a:
        va, vb = a[key], b[key]
        if isinstance(va, (np.ndarray, list, tuple, float, int)) and not isinstance(va, bool):
            assert_array_equal(np.asarray(va), np.asarray(vb), err_msg=key)
        elif hasattr(va, "__dict__") or isinstance(va, dict):
            # pytrees / parameter dicts: compare their leaves
            import jax

            la, lb = jax.tree_util.tree_leaves(va), jax.tree_util.tree_leaves(vb)
            assert len(la) == len(lb), key
            for x, y in zip(la, lb):
                assert_array_equal(np.asarray(x), np.asarray(y), err_msg=key)
        else:
            assert va == vb, key


@pytest.fixture(scope="module")
def fitted_cache():
    return {}


def _fit(cls, params, cache, key="base"):
    ck = (cls.__name__, repr(sorted(params.items())), key)
    if ck not in cache:
        cache[ck] = cls(**params).fit(TRAIN, VAL)
    return cache[ck]


def test_every_registry_row_is_contract_checked():
    """Every row of the registry yields at least one case (with JAX: all five models)."""
    expected = {spec.cls for spec in MODELS}
    if importlib.util.find_spec("jax") is None:  # pragma: no cover
        expected -= {"Elman", "GreyElman"}
    assert {c.values[0].__name__ for c in CASES} == expected >= {"Persistence", "AR", "GM11"}


@pytest.mark.parametrize("cls, params", CASES)
def test_constructor_stores_params_unchanged(cls, params):
    model = cls(**params)
    got = model.get_params()
    for k, v in params.items():
        assert got[k] is v, k
    defaults = {p.name: p.default for p in inspect.signature(cls.__init__).parameters.values()
                if p.name != "self" and p.kind != p.VAR_KEYWORD}
    assert got == {**defaults, **params}
    clone = cls(**got)
    assert clone.get_params() == got
    assert not _fitted_state(model)  # nothing learned in __init__


@pytest.mark.parametrize("cls, params", CASES)
def test_unfitted_model_raises(cls, params, tmp_path):
    model = cls(**params)
    with pytest.raises(NotFittedError):
        model.predict(TEST, history=HIST)
    with pytest.raises(NotFittedError):
        model.forecast(3)
    with pytest.raises(NotFittedError):
        save_model(model, tmp_path / "m")


@pytest.mark.parametrize("cls, params", CASES)
def test_fit_returns_self_and_output_lengths(cls, params, fitted_cache):
    model = cls(**params)
    assert model.fit(TRAIN, VAL) is model
    for y, hist in ((TEST, HIST), (TEST, None), (TEST[:1], HIST)):
        out = model.predict(y, history=hist)
        assert out.shape == y.shape
    for h in (1, 7):
        assert model.forecast(h).shape == (h,)
        assert model.forecast(h, history=HIST).shape == (h,)
    assert np.isfinite(model.predict(TEST, history=HIST)).all()


@pytest.mark.parametrize("cls, params", CASES)
def test_refit_same_data_same_predictions(cls, params, fitted_cache):
    a = _fit(cls, params, fitted_cache)
    b = cls(**params).fit(TRAIN, VAL)
    assert_array_equal(a.predict(TEST, history=HIST), b.predict(TEST, history=HIST))
    assert_array_equal(a.forecast(5), b.forecast(5))


@pytest.mark.parametrize("cls, params", CASES)
def test_save_load_round_trip(cls, params, fitted_cache, tmp_path):
    model = _fit(cls, params, fitted_cache)
    save_model(model, tmp_path / "model")
    back = load_model(tmp_path / "model")
    assert type(back) is cls
    assert back.get_params() == model.get_params()
    assert_array_equal(back.predict(TEST, history=HIST), model.predict(TEST, history=HIST))
    assert_array_equal(back.predict(TEST), model.predict(TEST))
    assert_array_equal(back.forecast(6), model.forecast(6))
    assert_array_equal(back.forecast(6, history=HIST), model.forecast(6, history=HIST))


@pytest.mark.parametrize("cls, params", CASES)
def test_the_state_as_data_holds_everything_learned(cls, params, fitted_cache, tmp_path):
    """A model rebuilt from its file has every learned attribute of the original, equal: a field that
    ``get_state`` drops (or ``set_state`` forgets) shows here even when the predictions do not use it; and a
    learned scalar is stored as the JSON kind it is (int, float, bool)."""
    model = _fit(cls, params, fitted_cache)
    save_model(model, tmp_path / "model")
    back = load_model(tmp_path / "model")
    _assert_state_equal(_fitted_state(back), _fitted_state(model))
    meta, arrays = model.get_state()
    back_meta, back_arrays = back.get_state()
    assert back_meta == meta and back_arrays.keys() == arrays.keys()
    for key in arrays:
        assert_array_equal(back_arrays[key], arrays[key], err_msg=key)
    rebuilt = cls(**model.get_params()).set_state(meta, arrays)  # the same through the state API, no file
    _assert_state_equal(_fitted_state(rebuilt), _fitted_state(model))
    # a scalar keeps its JSON kind in the file (a count written as 300.0 would change every file's bytes)
    stored = json.loads((tmp_path / "model.json").read_text())["state"]
    for key, value in stored.items():
        learned = getattr(model, key, None)
        if isinstance(learned, (bool, np.bool_)):
            assert type(value) is bool, key
        elif isinstance(learned, (int, np.integer)):
            assert type(value) is int, key
        elif isinstance(learned, (float, np.floating)):
            assert type(value) is float or (value is None and not np.isfinite(learned)), key


@pytest.mark.parametrize("cls, params", CASES)
def test_nan_input_raises_data_format_error(cls, params, fitted_cache):
    bad = TRAIN.copy()
    bad[17] = np.nan
    with pytest.raises(DataFormatError):
        cls(**params).fit(bad, VAL)
    model = _fit(cls, params, fitted_cache)
    bad_test = TEST.copy()
    bad_test[3] = np.inf
    with pytest.raises(DataFormatError):
        model.predict(bad_test, history=HIST)
    with pytest.raises(DataFormatError):
        model.predict(TEST, history=np.r_[HIST[:-1], np.nan])


@pytest.mark.parametrize("cls, params", CASES)
def test_predictions_never_use_the_future(cls, params, fitted_cache):
    """out[k] depends on history and y[:k] only: replacing y[j:] by other data leaves out[:j + 1] bit-identical.

    Checked at several cut points j, with the replacement far outside the training range (a
    model that normalises with statistics of the data it predicts, or that looks one sample
    ahead, changes its earlier outputs).
    """
    model = _fit(cls, params, fitted_cache)
    base = model.predict(TEST, history=HIST)
    other = _series(99)[: TEST.size] * 10.0 + 3.0
    for j in (0, 1, 7, TEST.size - 1):
        changed = np.r_[TEST[:j], other[j:]]
        assert not np.array_equal(changed, TEST)
        assert_array_equal(model.predict(changed, history=HIST)[: j + 1], base[: j + 1], err_msg=f"cut {j}")


@pytest.mark.parametrize("cls, params", CASES)
def test_validation_block_is_used_exactly_when_declared(cls, params, fitted_cache):
    """``uses_validation`` tells the truth. False: ``y_val`` is ignored, so a very different validation
    block gives a bit-identical fitted state and predictions. True (early stopping): the fitted
    state changes with it (test_elman.py checks that the normalisation still comes from
    ``y_train`` only)."""
    model = _fit(cls, params, fitted_cache)
    other_val = _series(98)[120:160] * 10.0 + 3.0
    twin = cls(**params).fit(TRAIN, other_val)
    if not cls.uses_validation:
        _assert_state_equal(_fitted_state(twin), _fitted_state(model))
        assert_array_equal(twin.predict(TEST, history=HIST), model.predict(TEST, history=HIST))
    else:
        with pytest.raises(AssertionError):
            _assert_state_equal(_fitted_state(twin), _fitted_state(model))


@pytest.mark.parametrize("cls, params", CASES)
def test_predict_and_forecast_leave_the_fit_untouched(cls, params, fitted_cache):
    """Predicting or forecasting on data that differ from the training record changes no fitted attribute."""
    model = _fit(cls, params, fitted_cache)
    state = copy.deepcopy(_fitted_state(model))
    other = _series(99) * 10.0 + 3.0
    model.predict(other[160:], history=other[:160])
    model.predict(other[160:])
    model.forecast(4, history=other)
    model.forecast(4)
    _assert_state_equal(_fitted_state(model), state)
