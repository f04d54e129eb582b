"""Issue 21 item 3: the local number formatters now go through ``fogdrift._util.fmt_number``.

Each old helper is copied here verbatim as the oracle; the routed helper must write byte-identical text on every
value (0, -0, negatives, 1e-7, 1e7, the 1e-3 / 1e4 edges, rounding carries, NaN, +-inf, integers, numpy scalars).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from fogdrift import plausibility, spec
from fogdrift._util import fmt_number
from fogdrift.cli import consistency
from fogdrift.evaluation import verdicts
from fogdrift.export import writers


# --- the old helpers, verbatim (oracles) ---------------------------------------------------------------------------
def old_spec_g(x) -> str:
    return f"{x:.3g}"


def old_plausibility_fmt(x: float) -> str:
    if not math.isfinite(x):
        return "n/a"
    return f"{x:.3g}" if x == 0 or 1e-3 <= abs(x) < 1e4 else f"{x:.2e}"


def old_consistency_fmt(x, d=3) -> str:
    return "–" if x is None or not math.isfinite(x) else f"{x:.{d}g}"


def old_verdicts_f(x, digits=3) -> str:
    if x is None or not math.isfinite(x):
        return "n/a"
    if x == 0:
        return "0"
    if abs(x) >= 1e4 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def old_writers_fmt(x: float) -> str:
    s = f"{float(x):.6g}"
    mant, _, exp = s.partition("e")
    if "." not in mant and mant not in ("inf", "-inf", "nan"):
        mant += ".0"
    return mant + ("e" + exp if exp else "")


NAN, INF = float("nan"), float("inf")
VALUES = [0.0, -0.0, 0, 1, -1, 2, 2.5, -2.5, 1e-7, -1e-7, 1e7, -1e7, 1e-5, 123456789.0, 12345.0, 9999.0,
          9999.5, 9995.0, 1e4, -1e4, 1e-3, 0.001, 0.00099999, 0.00099949, -0.00099999, 0.5, 1 / 3, -2 / 3,
          math.pi, 100.0, 1000.0, 999.95, 0.12345, 2.41234, 1e300, 5e-324, 1e16, 12, 360000, 0.1 + 0.2,
          NAN, INF, -INF, np.float64(0.0123), np.float32(3.7), np.int64(42), np.float64(NAN)]
assert len(VALUES) >= 20


@pytest.mark.parametrize("x", VALUES, ids=repr)
def test_spec_g_unchanged(x):
    assert spec._g(x) == old_spec_g(x)


@pytest.mark.parametrize("x", VALUES, ids=repr)
def test_plausibility_fmt_unchanged(x):
    assert plausibility._fmt(x) == old_plausibility_fmt(x)


@pytest.mark.parametrize("x", VALUES + [None], ids=repr)
@pytest.mark.parametrize("d", [3, 4])
def test_consistency_fmt_unchanged(x, d):
    assert consistency._fmt(x, d) == old_consistency_fmt(x, d)


@pytest.mark.parametrize("x", VALUES + [None], ids=repr)
@pytest.mark.parametrize("digits", [2, 3, 4])
def test_verdicts_f_unchanged(x, digits):
    assert verdicts._f(x, digits) == old_verdicts_f(x, digits)


@pytest.mark.parametrize("x", VALUES + ["1e-5", "7"], ids=repr)
def test_writers_fmt_unchanged(x):
    assert writers.fmt(x) == old_writers_fmt(x)


def test_hand_written_cells():
    """Independent of the oracles: the texts a reader sees, written out by hand."""
    assert plausibility._fmt(-0.0) == "-0" and verdicts._f(-0.0) == "0"
    assert plausibility._fmt(0.00099999) == "1.00e-03" and plausibility._fmt(12345.0) == "1.23e+04"
    assert verdicts._f(None) == "n/a" and consistency._fmt(None) == "–" and consistency._fmt(INF) == "–"
    assert spec._g(NAN) == "nan" and spec._g(-1e-7) == "-1e-07"
    assert writers.fmt(1e-5) == "1.0e-05" and writers.fmt(-2) == "-2.0" and writers.fmt(-INF) == "-inf"
    assert writers.fmt(1e7) == "1.0e+07" and writers.fmt(0.5) == "0.5"


def test_new_options_leave_existing_callers_alone():
    """``zero`` and ``float_literal`` default to the old rule: report tables' cells as before."""
    assert fmt_number(-0.0, 4, sci_outside=(1e-3, 1e4)) == "0"
    assert fmt_number(2.0) == "2" and fmt_number(1e-5) == "1e-05"
    assert fmt_number(0.0, 3, sci_outside=(1e-3, 1e4), zero=None) == "0"
    assert fmt_number(NAN, 6, nonfinite=None, float_literal=True) == "nan"
