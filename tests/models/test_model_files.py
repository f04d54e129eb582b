"""Model files and the persistence baseline at their edges (found unasserted by the mutation run).

A one-sample training block and a one-sample history are enough for persistence; ``save``/``load_model``
drop a ``.json``/``.npz`` suffix, refuse a JSON document that is not a fogdrift model (also a list), refuse
pickled arrays, take the class defaults when a file has no ``params``, and write callables as null.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from fogdrift.errors import ModelFileError
from fogdrift.models import AR, Persistence, load_model


def test_persistence_needs_only_one_sample():
    m = Persistence().fit([0.3])
    assert m.last_ == 0.3 and m.forecast(2).tolist() == [0.3, 0.3]
    assert m.forecast(3, history=[0.7]).tolist() == [0.7, 0.7, 0.7]
    assert m.predict([1.0, 2.0], history=[0.7]).tolist() == [0.7, 1.0]
    assert np.isnan(m.predict([1.0, 2.0])[0])


@pytest.mark.parametrize("suffix", ["", ".json", ".npz"])
def test_save_and_load_drop_the_suffix(tmp_path, suffix):
    m = Persistence().fit([0.1, 0.25])
    json_path, npz_path = m.save(tmp_path / f"pers{suffix}")
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
    Persistence().fit([1.0]).save(tmp_path / "m")
    np.savez(tmp_path / "m.npz", evil=np.array([{"a": 1}], dtype=object))
    with pytest.raises(ModelFileError):
        load_model(tmp_path / "m")


def test_load_without_params_uses_the_class_defaults(tmp_path):
    rng = np.random.default_rng(3)
    AR(order=2).fit(rng.standard_normal(200)).save(tmp_path / "ar")
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
    assert m._serialisable_params() == {"progress": None, "scale": 2.0}
