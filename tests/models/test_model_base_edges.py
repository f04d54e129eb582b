"""``models/base.py`` and ``models/model_files.py`` at their edges: the parameter interface, the model-file layout
and every refusal of :func:`load_model`, each with the message a user sees.

Expected values are written out by hand: the JSON keys of a model file, the repr of a model, and the
one-line ``ModelFileError`` for each way a file can be wrong (path first, then what is wrong).
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from fogdrift.errors import ConfigError, ModelFileError, NotFittedError
from fogdrift.models import AR, FORMAT_VERSION, DriftModel, Persistence, load_model, save_model


def _saved(tmp_path, name="m"):
    save_model(Persistence().fit([0.1, 0.25]), tmp_path / name)
    return tmp_path / f"{name}.json", tmp_path / f"{name}.npz"


def _rewrite(json_path, **changes):
    doc = json.loads(json_path.read_text())
    for key, value in changes.items():
        if value is _DROP:
            del doc[key]
        else:
            doc[key] = value
    json_path.write_text(json.dumps(doc))


_DROP = object()


# -- parameters ------------------------------------------------------------------------------
def test_set_params_sets_known_names_and_returns_self():
    m = AR(order=2)
    assert m.set_params(order=5, max_order=8) is m
    assert m.get_params() == {"order": 5, "max_order": 8}


def test_set_params_refuses_unknown_names_with_the_valid_list():
    m = AR(order=2)
    with pytest.raises(ConfigError) as err:
        m.set_params(order=3, bogus=1)
    assert str(err.value) == f"AR has no parameter 'bogus'; valid: {sorted(AR().get_params())}"


def test_repr_lists_the_parameters_in_constructor_order():
    params = AR(order=3).get_params()
    expected = "AR(" + ", ".join(f"{k}={v!r}" for k, v in params.items()) + ")"
    assert repr(AR(order=3)) == expected
    assert repr(Persistence()) == "Persistence()"


def test_unfitted_model_refuses_to_save(tmp_path):
    with pytest.raises(NotFittedError, match=r"Persistence.*not fitted.*fit\("):
        save_model(Persistence(), tmp_path / "m")
    assert list(tmp_path.iterdir()) == []


def test_fitted_means_an_attribute_ending_in_underscore():
    m = Persistence()
    m.__dunder__ = 1  # a dunder name is not a fitted attribute
    assert not m._is_fitted()
    m.last_ = 0.0
    assert m._is_fitted()


# -- the file layout -------------------------------------------------------------------------
def test_model_file_holds_exactly_the_documented_keys(tmp_path):
    m = AR(order=2).fit(np.random.default_rng(5).standard_normal(300))
    json_path, npz_path = save_model(m, tmp_path / "ar")
    doc = json.loads(json_path.read_text())
    assert list(doc) == ["format", "format_version", "class", "params", "state"]
    assert doc["format"] == "fogdrift-model" and doc["format_version"] == FORMAT_VERSION == 1
    assert doc["class"] == "AR" and doc["params"] == m.get_params()
    with np.load(npz_path, allow_pickle=False) as npz:
        assert set(npz.files) == set(m._get_state()[1])
    back = load_model(tmp_path / "ar")
    y = np.random.default_rng(6).standard_normal(50)
    np.testing.assert_array_equal(back.predict(y), m.predict(y))


def test_numpy_scalars_in_the_state_are_written_as_json_numbers(tmp_path):
    m = Persistence().fit([1.0])
    m.last_ = np.float32(0.5)  # not a Python float subclass (np.float64 is): needs the json default hook
    json_path, _ = save_model(m, tmp_path / "p")
    assert json.loads(json_path.read_text())["state"] == {"last_": 0.5}


@pytest.mark.parametrize(
    ("given", "stem"),
    [("drift.v2", "drift.v2"), ("drift.v2.json", "drift.v2"), ("drift.npz", "drift"), ("drift", "drift")],
)
def test_other_suffixes_are_part_of_the_name(tmp_path, given, stem):
    json_path, npz_path = save_model(Persistence().fit([0.4]), tmp_path / given)
    assert (json_path.name, npz_path.name) == (f"{stem}.json", f"{stem}.npz")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([f"{stem}.json", f"{stem}.npz"])
    assert load_model(tmp_path / given).last_ == 0.4


def test_load_with_an_expected_class_checks_the_stored_class(tmp_path):
    _saved(tmp_path)
    assert load_model(tmp_path / "m", expected=Persistence).last_ == 0.25
    assert isinstance(load_model(tmp_path / "m", expected=DriftModel), Persistence)  # a subclass is accepted
    with pytest.raises(ModelFileError) as err:
        load_model(tmp_path / "m", expected=AR)
    assert str(err.value) == f"{tmp_path / 'm'}: holds a Persistence, not a AR"


# -- every refusal of load_model, one line each -----------------------------------------------
def test_missing_json_file(tmp_path):
    with pytest.raises(ModelFileError) as err:
        load_model(tmp_path / "nothing")
    assert str(err.value) == f"{tmp_path / 'nothing.json'}: model file not found"


def test_invalid_json_names_line_and_column(tmp_path):
    json_path, _ = _saved(tmp_path)
    json_path.write_text('{\n  "format": "fogdrift-model",\n  oops\n}')
    with pytest.raises(ModelFileError) as err:
        load_model(tmp_path / "m")
    assert re.fullmatch(re.escape(str(json_path)) + r":3:3: not valid JSON \(.+\)", str(err.value))


def test_other_format_version(tmp_path):
    json_path, _ = _saved(tmp_path)
    _rewrite(json_path, format_version=2)
    with pytest.raises(ModelFileError) as err:
        load_model(json_path)
    assert str(err.value) == f"{json_path}: format version 2; this fogdrift reads 1"


def test_unknown_class_lists_the_known_ones(tmp_path):
    json_path, _ = _saved(tmp_path)
    _rewrite(json_path, **{"class": "Transformer"})
    with pytest.raises(ModelFileError) as err:
        load_model(json_path)
    msg = str(err.value)
    assert msg.startswith(f"{json_path}: unknown model class 'Transformer'; expected one of ")
    for name in ("AR", "Persistence", "GM11"):
        assert name in msg.split("expected one of ")[1].split(", ")


def test_missing_array_file(tmp_path):
    json_path, npz_path = _saved(tmp_path)
    npz_path.unlink()
    with pytest.raises(ModelFileError) as err:
        load_model(json_path)
    assert str(err.value) == f"{npz_path}: model array file not found"


def test_corrupt_array_file(tmp_path):
    json_path, npz_path = _saved(tmp_path)
    npz_path.write_bytes(b"not a zip archive")
    with pytest.raises(ModelFileError) as err:
        load_model(json_path)
    assert str(err.value).startswith(f"{npz_path}: cannot read arrays (")


def test_pickled_arrays_are_refused_not_loaded(tmp_path):
    json_path, npz_path = _saved(tmp_path)
    np.savez(npz_path, evil=np.array([{"a": 1}], dtype=object))
    with pytest.raises(ModelFileError, match=r"cannot read arrays \(.*allow_pickle"):
        load_model(json_path)


@pytest.mark.parametrize("state", [_DROP, None, [1, 2]])
def test_missing_state_is_a_model_file_error(tmp_path, state):
    json_path, _ = _saved(tmp_path)
    _rewrite(json_path, state=state)
    with pytest.raises(ModelFileError) as err:
        load_model(json_path)
    assert str(err.value) == (f"{json_path}: no fitted state (the 'state' object is missing or not an object)")


def test_state_without_a_fitted_attribute(tmp_path):
    json_path, _ = _saved(tmp_path)
    _rewrite(json_path, state={"other": 1})
    with pytest.raises(ModelFileError, match=r"does not describe a fitted Persistence \(missing or malformed 'last_'\)"):
        load_model(json_path)


def test_state_missing_an_array(tmp_path):
    save_model(AR(order=2).fit(np.random.default_rng(1).standard_normal(200)), tmp_path / "ar")
    np.savez(tmp_path / "ar.npz")
    with pytest.raises(ModelFileError, match=r"ar\.json.*not describe a fitted AR"):
        load_model(tmp_path / "ar")


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ([1], "'params' must be an object, not list"),
        ({"bogus": 1}, "parameters do not fit a AR ("),
    ],
)
def test_parameters_that_do_not_fit_the_class(tmp_path, params, message):
    save_model(AR(order=2).fit(np.random.default_rng(2).standard_normal(200)), tmp_path / "ar")
    _rewrite(tmp_path / "ar.json", params=params)
    with pytest.raises(ModelFileError) as err:
        load_model(tmp_path / "ar")
    assert str(err.value).startswith(f"{tmp_path / 'ar.json'}: {message}")
