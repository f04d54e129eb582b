"""``fogdrift._util.strict_json``: the one strict-JSON serialiser of the result files, checked against the plain
round trip ``json.loads(json.dumps(x, default=json_default))`` with NaN and infinity read as null."""

import json
import math
import random

import numpy as np
import pytest

from fogdrift._util import json_default, strict_json


class _HasDict:
    def __init__(self, d):
        self.d = d

    def to_dict(self):
        return self.d


def _reference(x):
    """The value strict_json must write: the standard library's own encoding, non-finite numbers as null."""
    return json.loads(json.dumps(x, default=json_default), parse_constant=lambda _: None)


def _document(rng: random.Random, depth: int = 0):
    """A nested document of what results hold: numpy scalars and arrays (with NaN and infinity), tuples, bools,
    objects with ``to_dict``, dicts with non-string keys."""
    kind = rng.randrange(15 if depth < 4 else 9)
    if kind == 0:
        return rng.choice([1.5, math.nan, math.inf, -0.0, 1e300, 3, -math.inf])
    if kind == 1:
        return np.float64(rng.choice([2.25, np.nan]))
    if kind == 2:
        return rng.choice([np.int32(7), np.uint8(3), np.float32(0.1), np.bool_(True)])
    if kind == 3:
        return rng.choice([True, False, None, "s", ""])
    if kind == 4:
        return np.array([1.0, np.nan, 2.0, -np.inf])[: rng.randrange(5)]
    if kind == 5:
        return rng.choice([np.arange(rng.randrange(4)), np.array([True, False]), np.zeros((2, 2)),
                           np.array([[np.nan, 1.0]])])
    if kind == 6:
        return [1, 2.0, None, math.nan]
    if kind == 7:
        return np.arange(3, dtype=np.float32) / 3
    if kind == 8:
        return "x" * rng.randrange(3)
    if kind == 9:
        return {rng.choice(["a", "b", 1, 2.5, True, None]): _document(rng, depth + 1) for _ in range(rng.randrange(4))}
    if kind in (10, 11):
        items = [_document(rng, depth + 1) for _ in range(rng.randrange(4))]
        return items if kind == 10 else tuple(items)
    if kind == 12:
        return _HasDict({"x": _document(rng, depth + 1)})
    return {"k": _document(rng, depth + 1), "l": [_document(rng, depth + 1)]}


@pytest.mark.parametrize("indent", [None, 1, 2])
def test_strict_json_writes_the_round_trip_value_on_random_documents(indent):
    rng = random.Random(20261129)
    for _ in range(600):
        doc = {"a": _document(rng), "b": _document(rng)}
        ref = _reference(doc)
        text = strict_json(doc, indent=indent)
        got = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-standard constant {c} written"))
        assert got == ref
        if indent is None:
            assert text == json.dumps(ref, allow_nan=False)
        else:
            # the same value laid out as the standard indenting encoder does, but lists of numbers on one line
            assert json.dumps(got, indent=indent) == json.dumps(ref, indent=indent)
            for numbers in _number_lists(ref):
                assert any(json.dumps(numbers) in line for line in text.splitlines()), numbers


def _number_lists(x):
    """Every non-empty list of numbers and nulls inside ``x`` (each written on one line)."""
    if isinstance(x, dict):
        return [v for item in x.values() for v in _number_lists(item)]
    if isinstance(x, list):
        if x and all(v is None or type(v) in (int, float) for v in x):
            return [x]
        return [v for item in x for v in _number_lists(item)]
    return []


def test_strict_json_layout_numbers_on_one_line_objects_and_flags_indented():
    doc = {"tau": np.array([0.5, np.nan]), "flags": np.array([True, False]), "axes": [{"m": (1, 2)}], "k": {2: 1}}
    assert strict_json(doc, indent=1).splitlines() == [
        "{", ' "tau": [0.5, null],', ' "flags": [', "  true,", "  false", " ],", ' "axes": [', "  {",
        '   "m": [1, 2]', "  }", " ],", ' "k": {', '  "2": 1', " }", "}"]


def test_strict_json_sorts_converted_keys_and_refuses_what_json_refuses():
    assert strict_json({2: "b", "1": "a", None: 0}, indent=None, sort_keys=True) == '{"1": "a", "2": "b", "null": 0}'
    with pytest.raises(TypeError):
        strict_json({(1, 2): 0})
    with pytest.raises(TypeError):
        strict_json({"z": 1j})


@pytest.mark.parametrize("indent", [None, 2])
def test_strict_json_long_number_lists_equal_the_round_trip(indent):
    """Long lists of plain numbers (a 25 000-tau curve) take a path of their own: non-finite values anywhere as
    null, int lists and huge ints as written, bools and numpy scalars through the general walk."""
    rng = np.random.default_rng(7)
    floats = rng.normal(size=3000).tolist()
    cases = [floats, [*floats[:-1], math.nan], [math.inf, *floats[1:]], [*floats[:5], None, *floats[5:]],
             list(range(3000)), [10 ** 400, 1, 2], [1, 2.5, 10 ** 30], [True, 1, 2], [1.0, np.float64(2.0), 3.0],
             [None, None], [-0.0, 1e-320, 1.7976931348623157e308], tuple(floats[:50]), [1.5, False]]
    for x in cases:
        doc = {"c": x, "rows": [{"v": x}]}
        got = json.loads(strict_json(doc, indent=indent))
        assert got == _reference(doc)
        assert strict_json(doc, indent=None) == json.dumps(_reference(doc), allow_nan=False)


def test_raw_json_is_written_as_its_text():
    from fogdrift._util import RawJson

    vals = [0.1, 2.5e-7, 3.0]
    raw = {"a": RawJson(json.dumps(vals)), "b": [{"c": RawJson("[1, null]")}]}
    plain = {"a": vals, "b": [{"c": [1, None]}]}
    for indent in (None, 2):
        assert strict_json(raw, indent=indent) == strict_json(plain, indent=indent)
