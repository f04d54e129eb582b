"""Names that do not lie: a series an accelerometer's numbers can reach is not called ``rate_dph``.

An accelerometer channel is held in m/s^2 (:data:`fogdrift.units.INTERNAL_UNITS`); the statistics and both noise
estimators take its series as they take a gyro's.  Their series parameter is ``y`` (its unit is the channel's,
carried by :class:`fogdrift.signal.Channel`); ``rate_dph`` stays only where the numbers are a gyro's by construction
(the drift models, the compensation, the heading error, :attr:`fogdrift.io.GyroRecord.rate_dph`, which refuses a
record with accelerometer channels).
"""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src" / "fogdrift"


def _accel_reaching():
    """The callables the `allan`, `noise`, `consistency` and `batch` commands hand an accelerometer's series."""
    from fogdrift.allan import allan_variance
    from fogdrift.allan.segments import allan_variance_segments
    from fogdrift.allan.sums import AllanSums
    from fogdrift.evaluation.consistency import observed_angle_errors_deg
    from fogdrift.gmwm.analysis import analyse_gmwm
    from fogdrift.gmwm.wvar import haar_wvar
    from fogdrift.noise.spectral import analyse_spectrum
    from fogdrift.outliers import find_outliers, treat_outliers
    from fogdrift.pipeline import analyse_allan

    return [allan_variance, allan_variance_segments, AllanSums, AllanSums.holds, observed_angle_errors_deg,
            analyse_gmwm, haar_wvar, analyse_spectrum, find_outliers, treat_outliers, analyse_allan]


@pytest.mark.parametrize("func", _accel_reaching(), ids=lambda f: f.__qualname__)
def test_a_series_of_either_quantity_has_no_gyro_unit_in_its_name(func):
    names = list(inspect.signature(func).parameters)
    assert "y" in names, names
    assert not [n for n in names if n.endswith(("_dph", "_dph2"))], names


def test_a_function_told_the_quantity_does_not_call_its_series_rate_dph():
    """Every function with a ``quantity`` parameter takes either quantity: none of its parameters is ``rate_dph``."""
    found, bad = 0, []
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                args = [a.arg for a in node.args.args + node.args.posonlyargs + node.args.kwonlyargs]
                if "quantity" in args:
                    found += 1
                    if "rate_dph" in args:
                        bad.append(f"{path.relative_to(SRC)}:{node.lineno} {node.name}")
    assert found >= 5  # the scan sees the functions it is about
    assert not bad, bad


def test_the_messages_name_the_series_as_the_caller_passed_it():
    """A bad accelerometer series is refused naming ``y``, not a gyro unit."""
    import numpy as np

    from fogdrift.errors import DataFormatError
    from fogdrift.gmwm.wvar import haar_wvar

    with pytest.raises(DataFormatError) as info:
        haar_wvar(np.array([[0.1, 0.2], [0.3, 0.1], [0.2, np.nan], [0.1, 0.3]]), 0.01)
    assert str(info.value).startswith("y[:, 1][2] is nan"), str(info.value)
