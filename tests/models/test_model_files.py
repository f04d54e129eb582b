"""Model files and the persistence baseline at their edges (found unasserted by the mutation run).

A one-sample training block and a one-sample history are enough for persistence; ``save_model``/``load_model``
drop a ``.json``/``.npz`` suffix, refuse a JSON document that is not a fogdrift model (also a list), refuse
pickled arrays, take the class defaults when a file has no ``params``, and write callables as null.  The state
API (``get_state``/``set_state``) and the files made from it: the exact bytes, a load-save round trip that
changes nothing, the one format version read, and writes that never leave a partial file.
"""

from __future__ import annotations

import errno
import json
from pathlib import Path

import numpy as np
import pytest

from fogdrift.errors import ModelFileError, NotFittedError, ResourceError
from fogdrift.models import AR, Persistence, load_model, save_model


def test_persistence_needs_only_one_sample():
    m = Persistence().fit([0.3])
    assert m.last_ == 0.3 and m.forecast(2).tolist() == [0.3, 0.3]
    assert m.forecast(3, history=[0.7]).tolist() == [0.7, 0.7, 0.7]
    assert m.predict([1.0, 2.0], history=[0.7]).tolist() == [0.7, 1.0]
    assert np.isnan(m.predict([1.0, 2.0])[0])


@pytest.mark.parametrize("suffix", ["", ".json", ".npz"])
def test_save_and_load_drop_the_suffix(tmp_path, suffix):
    m = Persistence().fit([0.1, 0.25])
    json_path, npz_path = save_model(m, tmp_path / f"pers{suffix}")
    assert (json_path.name, npz_path.name) == ("pers.json", "pers.npz")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pers.json", "pers.npz"]
    doc = json.loads(json_path.read_text())
    assert doc["class"] == "Persistence" and doc["state"] == {"last_": 0.25}
    assert json_path.read_text().startswith('{\n  "format"')  # indented for people who open it
    for name in ("pers", "pers.json", "pers.npz"):
        assert load_model(tmp_path / name).last_ == 0.25


@pytest.mark.parametrize("doc", [[1, 2], {"format": "other"}, "fogdrift-model"])
def test_load_refuses_documents_that_are_not_model_files(tmp_path, doc):
    (tmp_path / "m.json").write_text(json.dumps(doc))
    np.savez(tmp_path / "m.npz")
    with pytest.raises(ModelFileError, match="not a fogdrift model file"):
        load_model(tmp_path / "m")


def test_load_refuses_pickled_arrays(tmp_path):
    save_model(Persistence().fit([1.0]), tmp_path / "m")
    np.savez(tmp_path / "m.npz", evil=np.array([{"a": 1}], dtype=object))
    with pytest.raises(ModelFileError):
        load_model(tmp_path / "m")


def test_load_without_params_uses_the_class_defaults(tmp_path):
    rng = np.random.default_rng(3)
    save_model(AR(order=2).fit(rng.standard_normal(200)), tmp_path / "ar")
    doc = json.loads((tmp_path / "ar.json").read_text())
    del doc["params"]
    (tmp_path / "ar.json").write_text(json.dumps(doc))
    model = load_model(tmp_path / "ar")
    assert model.get_params() == AR().get_params()


def test_callable_parameters_are_written_as_null():
    class WithCallback(Persistence):
        def __init__(self, progress=None, scale=1.0):
            self.progress, self.scale = progress, scale

    m = WithCallback(progress=lambda *a: None, scale=2.0)
    assert m.get_params(serialisable=True) == {"progress": None, "scale": 2.0}


# -- the state as data and the files made from it ----------------------------------------------------------------
def test_get_state_refuses_an_unfitted_model_and_set_state_returns_the_model():
    with pytest.raises(NotFittedError):
        Persistence().get_state()
    m = Persistence()
    assert m.set_state({"last_": 0.5}, {}) is m
    assert m.get_state() == ({"last_": 0.5}, {}) and m.forecast(2).tolist() == [0.5, 0.5]


def test_a_persistence_file_byte_for_byte(tmp_path):
    """The layout written out by hand: indented JSON, keys in this order, no trailing newline; an empty archive."""
    json_path, npz_path = save_model(Persistence().fit([0.1, 0.25]), tmp_path / "p")
    assert json_path.read_text() == ('{\n  "format": "fogdrift-model",\n  "format_version": 1,\n'
                                     '  "class": "Persistence",\n  "params": {},\n  "state": {\n'
                                     '    "last_": 0.25\n  }\n}')
    with np.load(npz_path, allow_pickle=False) as npz:
        assert npz.files == []


def test_saving_a_loaded_model_writes_the_same_files(tmp_path):
    """Load then save gives the JSON bytes and the arrays (names, dtypes, values) of the first save: nothing
    is lost or retyped on the way through a file (an int read back as a float would show)."""
    rng = np.random.default_rng(4)
    first = save_model(AR(order=3).fit(rng.standard_normal(300)), tmp_path / "a")
    second = save_model(load_model(tmp_path / "a"), tmp_path / "b")
    assert second[0].read_bytes() == first[0].read_bytes()
    with np.load(first[1], allow_pickle=False) as x, np.load(second[1], allow_pickle=False) as y:
        assert x.files == y.files and x.files
        for key in x.files:
            assert x[key].dtype == y[key].dtype
            np.testing.assert_array_equal(x[key], y[key])


@pytest.mark.parametrize("version", [0, 2, "1", True, 1.0, None])
def test_only_format_version_1_is_read(tmp_path, version):
    json_path, _ = save_model(Persistence().fit([0.1]), tmp_path / "m")
    doc = json.loads(json_path.read_text())
    doc["format_version"] = version
    json_path.write_text(json.dumps(doc))
    with pytest.raises(ModelFileError) as err:
        load_model(tmp_path / "m")
    assert str(err.value) == f"{json_path}: format version {version!r}; this fogdrift reads 1"


@pytest.mark.parametrize("failing", ["json", "npz"])
def test_a_failed_write_leaves_no_partial_file_and_keeps_the_previous_one(tmp_path, monkeypatch, failing):
    """Files appear under their final names only when both are complete: a write of either that fails half-way
    (disk full) leaves the previous model's pair as it was, puts nothing under a new name, and leaves no
    temporary file behind."""
    json_path, npz_path = save_model(Persistence().fit([0.1]), tmp_path / "m")
    before = {p.name: p.read_bytes() for p in (json_path, npz_path)}

    def half_then_fail(path, *args, **kwargs):
        Path(path).write_bytes(b'{"format": "fogdr')
        raise OSError(errno.ENOSPC, "No space left on device")

    if failing == "json":
        monkeypatch.setattr(Path, "write_text", half_then_fail)
    else:
        monkeypatch.setattr(np, "savez", half_then_fail)
    for base in ("m", "new"):
        with pytest.raises(ResourceError, match=rf"cannot write {base}\.{failing}: No space left"):
            save_model(Persistence().fit([0.9]), tmp_path / base)
    monkeypatch.undo()
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before  # never a new JSON beside an old archive
    assert load_model(tmp_path / "m").last_ == 0.1
