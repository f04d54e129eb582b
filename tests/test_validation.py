"""One series validator (issue 8): models, metrics and the lifting transform give the same messages.

``fogdrift._util.check_series`` is the only place that checks a series; ``metrics._pair`` and
``lifting.transform._as_signal`` call it. The expected messages are written out here, so a copy that
drifts away (a different wording, a different error class, an off-by-one index) fails.
"""

from __future__ import annotations

import numpy as np
import pytest

from fogdrift import metrics
from fogdrift._util import check_series
from fogdrift.errors import DataFormatError, InsufficientDataError
from fogdrift.lifting import lift, separate
from fogdrift.models import AR, Persistence

NAN_AT_2 = [0.0, 1.0, np.nan, 3.0, 4.0, 5.0]
INF_AT_4 = [0.0, 1.0, 2.0, 3.0, -np.inf, 5.0]

ENTRY_POINTS = {
    # name used in the message -> callable taking one bad series
    "y": lambda x: check_series(x),
    "x": lambda x: lift(x),
    "y_train": lambda x: AR(order=1).fit(x),
    "yhat": lambda x: metrics.rmse(np.zeros(len(x)), x),
}


@pytest.mark.parametrize("name", ENTRY_POINTS)
@pytest.mark.parametrize("series, where, text", [(NAN_AT_2, 2, "nan"), (INF_AT_4, 4, "-inf")])
def test_non_finite_message_is_the_same_everywhere(name, series, where, text):
    with pytest.raises(DataFormatError) as err:
        ENTRY_POINTS[name](series)
    assert str(err.value).startswith(f"{name}[{where}] is {text}; expected finite values")


def test_metrics_adds_its_hint_to_the_shared_message():
    with pytest.raises(DataFormatError) as err:
        metrics.mae(NAN_AT_2, np.zeros(6))
    assert str(err.value) == "y[2] is nan; expected finite values (drop warm-up NaN first, or use evaluate())"


@pytest.mark.parametrize("name", ENTRY_POINTS)
def test_two_dimensional_input_message_is_the_same_everywhere(name):
    with pytest.raises(DataFormatError) as err:
        ENTRY_POINTS[name](np.ones((4, 2)))
    assert str(err.value) == f"{name} must be a 1-D series of shape (n_samples,); got shape (4, 2)"


def test_two_dimensional_allowed_where_axes_are_columns():
    drift, _ = separate(np.ones((8, 2)), "haar", 1)
    assert drift.shape == (8, 2)
    with pytest.raises(DataFormatError) as err:
        separate(np.ones((2, 2, 2)), "haar", 1)
    assert str(err.value) == "x must be 1-D (n_samples,) or 2-D (n_samples, n_axes); got shape (2, 2, 2)"
    with pytest.raises(DataFormatError, match=r"x\[3, 1\].* nan"):
        separate(np.where(np.arange(16).reshape(8, 2) == 7, np.nan, 1.0), "haar", 1)


@pytest.mark.parametrize("name", ENTRY_POINTS)
def test_non_numeric_message_is_the_same_everywhere(name):
    with pytest.raises(DataFormatError) as err:
        ENTRY_POINTS[name](["a", "b"])
    assert str(err.value) == f"{name} must be a numeric series; got list"


@pytest.mark.parametrize("call, message", [
    (lambda: lift([1.0]), "x has 1 samples; a wavelet level needs at least 2"),
    (lambda: metrics.rmse([], []), "y has 0 samples; expected at least 1"),
    (lambda: Persistence().fit([]), "y_train has 0 samples; expected at least 1"),
    (lambda: check_series([1.0, 2.0], "h", min_length=3, needed_by="this model"),
     "h has 2 samples; this model needs at least 3"),
])
def test_too_short_is_insufficient_data_with_counts(call, message):
    with pytest.raises(InsufficientDataError) as err:
        call()
    assert str(err.value) == message


def test_length_mismatch_and_contiguous_float64():
    with pytest.raises(DataFormatError, match=r"y and yhat.*same length.*\b3\b.*\b2\b"):
        metrics.rmse([1.0, 2.0, 3.0], [1.0, 2.0])
    out = check_series(np.arange(10)[::2])
    assert out.dtype == np.float64 and out.flags.c_contiguous and out.tolist() == [0.0, 2.0, 4.0, 6.0, 8.0]
