"""The scheme table: registry helpers and validation."""

from __future__ import annotations

import json

import pytest

from fogdrift import lifting as L
from fogdrift.errors import ConfigError


def test_wavelist_is_the_registry():
    assert L.wavelist() == list(L.WAVELETS) == ["haar", "db2"]
    assert L.wavelist("db") == ["db2"]
    assert L.wavelist("haar") == ["haar"]
    assert L.wavelist("sym") == []
    for name in L.wavelist():
        assert L.get_wavelet(name).name == name
        assert L.get_wavelet(name.upper()) is L.WAVELETS[name]


def test_get_wavelet_errors():
    with pytest.raises(ConfigError) as err:
        L.get_wavelet("db99")
    assert "['haar', 'db2']" in str(err.value)
    assert "wavelet=" in str(err.value)  # {opt:wavelet}
    assert "--wavelet" in err.value.render({"wavelet": "--wavelet"})
    with pytest.raises(ConfigError, match="LiftingScheme"):
        L.get_wavelet(4)
    scheme = L.WAVELETS["db2"]
    assert L.get_wavelet(scheme) is scheme


def test_scheme_validation_and_json():
    for name, scheme in L.WAVELETS.items():
        d = json.loads(json.dumps(scheme.to_dict()))
        assert d["name"] == name
        assert len(d["steps"]) == len(scheme.steps)
    with pytest.raises(ConfigError):
        L.LiftingStep("split", ((0, 1.0),))
    with pytest.raises(ConfigError):
        L.LiftingStep("predict", ())
    step = L.LiftingStep("predict", ((0, 1.0),))
    with pytest.raises(ConfigError, match="non-zero"):
        L.LiftingScheme("x", (step,), 0.0, 1.0)
    with pytest.raises(ConfigError, match="detail_sign"):
        L.LiftingScheme("x", (step,), 1.0, 1.0, detail_sign=2.0)
    with pytest.raises(ConfigError, match="filter_length"):
        L.LiftingScheme("x", (step,), 1.0, 1.0, filter_length=1)

