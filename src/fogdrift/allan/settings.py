"""The settings of the Allan stage, declared once (:mod:`fogdrift.constraints`): the sampling of the operator sums,
the statistic of the family, the tau grid and the tau range of the noise fit.

Each row of :data:`ALLAN_SETTINGS` is a field of :class:`fogdrift.pipeline.AnalysisConfig` with the row's default;
its rule is what :meth:`~fogdrift.pipeline.AnalysisConfig.validate` checks, and the ``allan``, ``analyze``,
``batch`` (and, for the grid, ``separate``) commands make their option from it.  The choices come from the tables
they choose among (:data:`~fogdrift.allan.statistics.ESTIMATORS`, :data:`~fogdrift.allan.statistics.STATISTICS`),
so a statistic added there is a value of ``--statistic`` with no other edit.

Examples
--------
>>> [(s.name, s.default) for s in ALLAN_SETTINGS]
[('estimator', 'overlapping'), ('statistic', 'adev'), ('taus', 'octave'), ('fit_tau_s', (None, None))]
>>> parse_taus("64"), parse_fit_taus("1:"), parse_fit_taus("0.1:300")
(64, (1.0, None), (0.1, 300.0))
>>> TauRange().holds((1.0, None)), TauRange().holds((3.0, 2.0)), TauGrid().holds(0)
(True, False, False)
"""

from __future__ import annotations

import math
import numbers

from ..constraints import Choice, Rule, Setting
from ..errors import ConfigError
from .grid import MAX_TAUS
from .statistics import ESTIMATORS, STATISTICS

__all__ = ["ALLAN_SETTINGS", "TauGrid", "TauRange", "parse_fit_taus", "parse_taus"]

#: The named tau grids (:func:`fogdrift.allan.grid.tau_grid`).
GRIDS = ("octave", "decade", "all")


class TauGrid(Rule):
    """A named grid (:data:`GRIDS`) or a number of log-spaced taus in ``[1, MAX_TAUS]``."""

    type = str

    def describe(self) -> str:
        return f"'octave', 'decade', 'all' or a number of taus in [1, {MAX_TAUS}]"

    def holds(self, value) -> bool:
        if isinstance(value, str):
            return value.lower() in GRIDS
        return isinstance(value, numbers.Integral) and not isinstance(value, bool) and 1 <= int(value) <= MAX_TAUS


class TauRange(Rule):
    """``(MIN, MAX)`` in s, each a finite number > 0 or None (no limit), ``MIN < MAX`` when both are given."""

    type = str

    def describe(self) -> str:
        return "(MIN, MAX) in s, each > 0 or None, MIN < MAX"

    def holds(self, value) -> bool:
        try:
            lo, hi = value
        except (TypeError, ValueError):
            return False
        for v in (lo, hi):
            if v is not None and (isinstance(v, bool) or not isinstance(v, numbers.Real)
                                  or not math.isfinite(float(v)) or not float(v) > 0):
                return False
        return lo is None or hi is None or float(lo) < float(hi)


def parse_taus(text: str):
    """``--taus`` text: ``'64'`` -> 64 (a number of taus), a grid's name as it is."""
    return int(text) if text.isdigit() else text


def parse_fit_taus(text: str) -> tuple:
    """``--fit-taus`` text ``MIN:MAX`` in s, either side may be empty: ``'1:'`` -> ``(1.0, None)``."""
    lo, sep, hi = text.partition(":")
    try:
        if not sep:
            raise ValueError
        return (float(lo) if lo.strip() else None, float(hi) if hi.strip() else None)
    except ValueError:
        raise ConfigError(f"{{opt:fit_tau_s}} must look like MIN:MAX in seconds (e.g. '1:' or '0.1:300'), got "
                          f"{text!r}") from None


#: The Allan stage's settings, in the order of the CLI's help.
ALLAN_SETTINGS: tuple[Setting, ...] = (
    Setting("estimator", "overlapping", Choice(ESTIMATORS), "--estimator", "overlapping, non-overlapping or fast."),
    Setting("statistic", "adev", Choice(tuple(STATISTICS)), "--statistic",
            "adev (Allan), hdev (Hadamard: blind to a rate ramp) or mdev (modified Allan)."),
    Setting("taus", "octave", TauGrid(), "--taus", "Tau grid: octave, decade, all, or a number of log-spaced taus.",
            parse=parse_taus, text="octave"),
    Setting("fit_tau_s", (None, None), TauRange(), "--fit-taus",
            "Tau range of the noise fit MIN:MAX [s], either side may be empty, e.g. '1:'.", parse=parse_fit_taus,
            text=":"),
)
