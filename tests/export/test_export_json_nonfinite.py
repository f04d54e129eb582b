"""The json export target writes a non-finite value as null (found by mutation round 3, issue 24): a GMWM result
without ``tau_range_s`` gave the channel a NaN tau range, and ``json.dumps(allow_nan=False)`` stopped the export with
a ValueError (its ``default`` hook is never called for floats)."""

from __future__ import annotations

import json
import math

from fogdrift.export import build_context, render
from fogdrift.export.writers import _json_safe
from fogdrift.io import from_array


def _axis():
    return {"name": "gx", "method": "gmwm", "selection": {"ieee": {
        "model": "WN", "terms": {"N_dprh": {"value": 0.3, "lo95": 0.27, "hi95": 0.33, "unit": "deg/sqrt(h)"}},
        "gm": [], "b_headline": {"value_dph": 1.5, "lo95_dph": 1.0, "hi95_dph": 2.0, "tau_s": 300.0},
        "dt_s": 0.01}}}


def test_nan_tau_range_is_written_as_null(tmp_path):
    p = tmp_path / "noise.json"
    record = from_array([0.0, 0.0], dt_s=0.01).metadata()  # the record block as fogdrift writes it
    p.write_text(json.dumps({"record": record, "axes": [_axis()]}))
    ctx = build_context([p])
    assert all(math.isnan(x) for x in ctx.gyro[0].tau_range_s)
    d = json.loads(render("json", ctx))                       # strict JSON: no NaN token
    assert d["channels"][0]["tau_range_s"] == [None, None]
    assert abs(d["channels"][0]["export_values"]["N"]["si"] / (0.3 * math.pi / 180.0 / 60.0) - 1) < 1e-12


def test_json_safe_by_hand():
    assert _json_safe({"a": [1.0, math.nan, (math.inf, -math.inf)], "b": {"c": 2}, "d": "x", "e": None}) == \
        {"a": [1.0, None, [None, None]], "b": {"c": 2}, "d": "x", "e": None}
