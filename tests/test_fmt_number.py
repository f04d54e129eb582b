"""``fogdrift._util.fmt_number``, the one number formatter, through the cells its callers write: each caller's rule
(significant digits, where scientific notation starts, what a missing or non-finite value reads as) as the texts
a reader sees, written out by hand."""
from __future__ import annotations

import math

import numpy as np
import pytest

from fogdrift import plausibility, spec
from fogdrift._util import fmt_number
from fogdrift.cli import consistency
from fogdrift.evaluation import verdicts
from fogdrift.export import writers

NAN, INF = float("nan"), float("inf")

#: value -> (spec._g, plausibility._fmt, consistency._fmt, verdicts._f, writers.fmt)
#: spec and consistency: "%.3g"; plausibility and verdicts: 3 significant digits, "%.2e" outside [1e-3, 1e4),
#: non-finite "n/a" (verdicts also writes -0 as 0); writers: "%.6g" that always reads back as a float literal.
CELLS = [
    (0.0, ("0", "0", "0", "0", "0.0")),
    (-0.0, ("-0", "-0", "-0", "0", "-0.0")),
    (2.5, ("2.5", "2.5", "2.5", "2.5", "2.5")),
    (-1e-7, ("-1e-07", "-1.00e-07", "-1e-07", "-1.00e-07", "-1.0e-07")),
    (1e-3, ("0.001", "0.001", "0.001", "0.001", "0.001")),
    (0.00099999, ("0.001", "1.00e-03", "0.001", "1.00e-03", "0.00099999")),
    (1e4, ("1e+04", "1.00e+04", "1e+04", "1.00e+04", "10000.0")),
    (123456789.0, ("1.23e+08", "1.23e+08", "1.23e+08", "1.23e+08", "1.23457e+08")),
    (1 / 3, ("0.333", "0.333", "0.333", "0.333", "0.333333")),
    (math.pi, ("3.14", "3.14", "3.14", "3.14", "3.14159")),
    (NAN, ("nan", "n/a", "–", "n/a", "nan")),
    (INF, ("inf", "n/a", "–", "n/a", "inf")),
    (-INF, ("-inf", "n/a", "–", "n/a", "-inf")),
    (np.float32(3.7), ("3.7", "3.7", "3.7", "3.7", "3.7")),
    (np.int64(42), ("42", "42", "42", "42", "42.0")),
    (np.float64(NAN), ("nan", "n/a", "–", "n/a", "nan")),
]
CALLERS = (spec._g, plausibility._fmt, lambda x: consistency._fmt(x, 3), lambda x: verdicts._f(x, 3), writers.fmt)
NAMES = ("spec", "plausibility", "consistency", "verdicts", "writers")


@pytest.mark.parametrize("i", range(len(CALLERS)), ids=NAMES)
@pytest.mark.parametrize("x, cells", CELLS, ids=[repr(c[0]) for c in CELLS])
def test_each_caller_writes_its_cell(x, cells, i):
    assert CALLERS[i](x) == cells[i]


def test_digits_and_missing_values():
    assert consistency._fmt(2 / 3, 4) == "0.6667" and verdicts._f(2 / 3, 2) == "0.67" and verdicts._f(1e5, 2) == "1.0e+05"
    assert verdicts._f(None) == "n/a" and consistency._fmt(None) == "–"
    assert writers.fmt("1e-5") == "1.0e-05" and writers.fmt("7") == "7.0"  # text cells read as numbers


def test_fmt_number_options():
    assert fmt_number(-0.0, 4, sci_outside=(1e-3, 1e4)) == "0"
    assert fmt_number(2.0) == "2" and fmt_number(1e-5) == "1e-05"
    assert fmt_number(0.0, 3, sci_outside=(1e-3, 1e4), zero=None) == "0"
    assert fmt_number(NAN, 6, nonfinite=None, float_literal=True) == "nan"
    assert fmt_number(None) == "–" and fmt_number("< 7.06") == "< 7.06"
