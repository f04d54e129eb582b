"""Edges of fogdrift.metrics that the mutation run (docs/testing-rounds.md) found unasserted.

Hand values and exact boundaries: the p0 of AGO values, the training-block checks of ``mase`` and
``evaluate`` (exactly 2 samples accepted, 2-D or NaN refused), inf refused in either prediction, the
"was the series demeaned?" threshold 0.01 std on both sides, the error counts, the warnings' category and
the line they point at (the caller's), and ``MetricsResult.to_dict``.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from fogdrift.errors import DataFormatError, FogdriftWarning, InsufficientDataError
from fogdrift.metrics import evaluate, mase, p0, p0_ago, skill

# mutmut's trampolines add stack frames, so "the warning points at the caller" cannot hold under mutation
# testing; the normal suite checks it (stacklevel mutants are listed as tool-equivalent in docs/testing-rounds.md)
import fogdrift.metrics  # noqa: E402

CALLER_LINE_CHECKED = "mutants" not in Path(fogdrift.metrics.__file__).parts

Y = np.array([2.0, 4.0, 8.0])
YH = np.array([1.0, 5.0, 6.0])
YP = np.array([1.5, 3.0, 9.0])


def _evaluate(y_train, **kw):
    kw.setdefault("offset_convention", "as_measured")
    return evaluate(kw.pop("y", Y), kw.pop("yhat", YH), y_train=y_train, yhat_persistence=kw.pop("yp", YP), **kw)


def test_p0_ago_hand_value_and_flag():
    # 100 (1 - (1/2 + 1/4 + 2/8)/3) = 66.667 % (same numbers as the original-domain hand value)
    with pytest.warns(FogdriftWarning, match="AGO"):
        assert p0_ago(Y, YH) == pytest.approx(200.0 / 3.0, rel=1e-12)


@pytest.mark.parametrize("func", [lambda tr: mase(Y, YH, tr), lambda tr: _evaluate(tr)])
def test_training_block_checks(func):
    # exactly 2 samples are enough (one difference)
    out = func(np.array([0.0, 3.0]))
    value = out if isinstance(out, float) else out.mase
    assert value == pytest.approx((4.0 / 3.0) / 3.0, rel=1e-12)
    for bad in (np.ones((3, 2)), np.array([0.0, np.nan, 1.0]), np.array([1.0])):
        with pytest.raises(DataFormatError, match="y_train must be a finite 1-D series of at least 2 samples"):
            func(bad)


def test_evaluate_refuses_2d_test_block_and_inf_in_either_prediction():
    with pytest.raises(DataFormatError, match="y_test must be a finite 1-D series"):
        evaluate(np.ones((3, 2)), np.ones((3, 2)), y_train=[0.0, 1.0], yhat_persistence=np.ones((3, 2)),
                 offset_convention="as_measured")
    for yh, yp in ((np.array([1.0, np.inf, 6.0]), YP), (YH, np.array([1.5, -np.inf, 9.0]))):
        with pytest.raises(DataFormatError, match="may hold NaN"):
            _evaluate([0.0, 1.0], yhat=yh, yp=yp)


def test_no_common_sample_gives_the_counts():
    with pytest.raises(InsufficientDataError) as err:
        _evaluate([0.0, 1.0], yhat=np.array([np.nan, 1.0, np.nan]), yp=np.array([1.0, np.nan, np.nan]))
    assert (err.value.needed, err.value.got) == (1, 0)


@pytest.mark.parametrize("mean, std_scale, convention, warns", [
    (0.05, 10.0, "demeaned_by_train_mean", False),  # |mean| 0.05 < 0.01 * 10
    (1.0, 10.0, "demeaned_by_train_mean", True),    # |mean| 1 > 0.1 (but < 1.01 * std)
    (1.0, 10.0, "as_measured", False),              # only the demeaned convention is checked
    (0.0, 0.0, "demeaned_by_train_mean", False),    # 0 is not > 0
])
def test_demeaned_warning_threshold(mean, std_scale, convention, warns):
    tr = mean + std_scale * np.array([-1.0, 1.0, -1.0, 1.0])  # std = std_scale exactly, mean exactly `mean`
    with warnings.catch_warnings(record=True) as log:
        warnings.simplefilter("always")
        _evaluate(tr, offset_convention=convention)
    demeaned = [w for w in log if "was the series demeaned" in str(w.message)]
    assert len(demeaned) == int(warns)
    assert all(w.category is FogdriftWarning for w in log)
    assert not CALLER_LINE_CHECKED or all(w.filename == __file__ for w in demeaned)  # the caller's line


def test_warnings_are_fogdrift_warnings_at_the_callers_line():
    with warnings.catch_warnings(record=True) as log:
        warnings.simplefilter("always")
        # p0 guard (a zero in y), persistence exact -> skill undefined, and a zero-diff training block -> mase
        r = evaluate(np.array([0.0, 1.0, 2.0]), np.array([0.5, 1.0, 2.0]), y_train=np.array([1.0, 1.0, 1.0]),
                     yhat_persistence=np.array([0.0, 1.0, 2.0]), offset_convention="as_measured")
        mase([1.0, 2.0], [1.0, 2.5], [3.0, 3.0])
        p0([0.0, 1.0], [0.0, 1.0], offset_convention="as_measured")
        skill([1.0, 2.0], [1.0, 2.0], [1.0, 2.0])
    assert math.isnan(r.p0_pct) and math.isnan(r.mase) and math.isnan(r.skill)
    assert len(log) >= 6
    assert all(w.category is FogdriftWarning for w in log), [w.category for w in log]
    assert not CALLER_LINE_CHECKED or all(w.filename == __file__ for w in log), [(w.filename, str(w.message))
                                                                                for w in log]


def test_to_dict_keeps_values_and_maps_nan_to_none():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FogdriftWarning)
        r = _evaluate([0.0, 3.0])
    d = r.to_dict()
    assert d["n"] == 3 and d["offset_convention"] == "as_measured" and d["domain"] == "original"
    assert d["rmse_dph"] == pytest.approx(math.sqrt(2.0), rel=1e-12) and d["mase"] == pytest.approx(4.0 / 9.0)
