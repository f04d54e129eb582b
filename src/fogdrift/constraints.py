"""Declared settings: a :class:`Setting` row names a setting, its default, its :class:`Rule`, its CLI flag and help
(scikit-learn's ``_parameter_constraints`` made a table).

Each stage declares its rows where the stage lives (:data:`fogdrift.models.settings.MODEL_SETTINGS`,
:data:`fogdrift.allan.settings.ALLAN_SETTINGS`, :data:`fogdrift.outliers.OUTLIERS_SETTING`);
:meth:`fogdrift.pipeline.AnalysisConfig.validate` applies the rules and the CLI makes its options from the rows
(``fogdrift.cli._settings.with_settings``).  This module imports nothing heavy (the CLI reads it to build
``--help``).

Examples
--------
>>> Integer(4).describe(), Number(0.0, 1.0, "left").describe(), Choice(("a", "b", "c")).describe()
('an integer >= 4', 'a number in [0, 1)', "one of 'a', 'b', 'c'")
>>> Number(0.0, 1.0, "left").holds(1.0), Choice(("bptt", "bp")).describe()
(False, "'bptt' or 'bp'")
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable
from dataclasses import dataclass

from .errors import ConfigError

__all__ = ["Choice", "Integer", "Number", "Rule", "Setting"]


class Rule:
    """What values a setting takes: :attr:`type` (the CLI's parser), :meth:`describe` and :meth:`check`."""

    type: type = object

    def describe(self) -> str:  # pragma: no cover - every rule overrides it
        raise NotImplementedError

    def holds(self, value) -> bool:  # pragma: no cover - every rule overrides it
        raise NotImplementedError

    def check(self, name: str, value) -> None:
        """Raise :class:`~fogdrift.errors.ConfigError` ``{opt:name} must be <describe>; got <value>`` unless held."""
        if not self.holds(value):
            raise ConfigError(f"{{opt:{name}}} must be {self.describe()}; got {value!r}")


@dataclass(frozen=True)
class Integer(Rule):
    """An integer (not a bool) >= ``low``."""

    low: int
    type = int

    def describe(self) -> str:
        return f"an integer >= {self.low}"

    def holds(self, value) -> bool:
        return isinstance(value, numbers.Integral) and not isinstance(value, bool) and int(value) >= self.low


@dataclass(frozen=True)
class Number(Rule):
    """A finite number in the interval from ``low`` to ``high``; ``closed``: which ends belong to it."""

    low: float
    high: float = math.inf
    closed: str = "neither"  # "left", "right", "both" or "neither"
    type = float

    def describe(self) -> str:
        if math.isinf(self.high):
            return f"a number {'>=' if self.closed in ('left', 'both') else '>'} {self.low:g}"
        left = "[" if self.closed in ("left", "both") else "("
        right = "]" if self.closed in ("right", "both") else ")"
        return f"a number in {left}{self.low:g}, {self.high:g}{right}"

    def holds(self, value) -> bool:
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            return False
        v = float(value)
        if not math.isfinite(v):
            return False
        above = v >= self.low if self.closed in ("left", "both") else v > self.low
        below = v <= self.high if self.closed in ("right", "both") else v < self.high
        return above and below


@dataclass(frozen=True)
class Choice(Rule):
    """One of ``values`` (strings)."""

    values: tuple
    type = str

    def describe(self) -> str:
        if len(self.values) <= 2:
            return " or ".join(repr(v) for v in self.values)
        return "one of " + ", ".join(repr(v) for v in self.values)

    def holds(self, value) -> bool:
        return isinstance(value, str) and value in self.values


@dataclass(frozen=True)
class Setting:
    """One setting: the :class:`~fogdrift.pipeline.AnalysisConfig` field ``name``, its ``default`` (the field's
    and the CLI option's), its ``rule``, the CLI ``flag`` and the ``help`` text (units in brackets).

    A setting whose option is text that is not the value itself (``--fit-taus 1:300`` for ``(1.0, 300.0)``) gives
    ``parse`` (text -> value, a :class:`~fogdrift.errors.ConfigError` naming ``{opt:NAME}`` for bad text) and
    ``text``, the option's default (``parse(text) == default``)."""

    name: str
    default: object
    rule: Rule
    flag: str
    help: str
    parse: Callable[[str], object] | None = None
    text: str | None = None
