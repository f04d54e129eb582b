"""The settings of the Allan stage, declared once (:mod:`fogdrift.constraints`): the sampling of the operator sums
and the statistic of the family.

Each row of :data:`ALLAN_SETTINGS` is a field of :class:`fogdrift.pipeline.AnalysisConfig` with the row's default;
its rule is what :meth:`~fogdrift.pipeline.AnalysisConfig.validate` checks, and the ``allan``, ``analyze`` and
``batch`` commands make their option from it.  The values come from the tables they choose among
(:data:`~fogdrift.allan.statistics.ESTIMATORS`, :data:`~fogdrift.allan.statistics.STATISTICS`), so a statistic added
there is a value of ``--statistic`` with no other edit.

Examples
--------
>>> [(s.name, s.default, s.rule.describe()) for s in ALLAN_SETTINGS]  # doctest: +NORMALIZE_WHITESPACE
[('estimator', 'overlapping', "one of 'overlapping', 'non-overlapping', 'fast'"),
 ('statistic', 'adev', "one of 'adev', 'hdev', 'mdev'")]
"""

from __future__ import annotations

from ..constraints import Choice, Setting
from .statistics import ESTIMATORS, STATISTICS

__all__ = ["ALLAN_SETTINGS"]

#: The Allan stage's settings, in the order of the CLI's help.
ALLAN_SETTINGS: tuple[Setting, ...] = (
    Setting("estimator", "overlapping", Choice(ESTIMATORS), "--estimator", "overlapping, non-overlapping or fast."),
    Setting("statistic", "adev", Choice(tuple(STATISTICS)), "--statistic",
            "adev (Allan), hdev (Hadamard: blind to a rate ramp) or mdev (modified Allan)."),
)
