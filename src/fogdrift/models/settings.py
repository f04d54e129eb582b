"""The settings of the modelling stage, declared once: field, rule, CLI flag and help (scikit-learn's
``_parameter_constraints`` made a table).

Each :class:`Setting` row of :data:`MODEL_SETTINGS` is a field of :class:`fogdrift.pipeline.AnalysisConfig` with
the same default.  The row's :class:`Rule` is what :meth:`~fogdrift.pipeline.AnalysisConfig.validate` checks (one
message form for every setting, the option named as ``{opt:NAME}``); the CLI builds its options from the rows
(``fogdrift.cli._app.with_settings``: the flag, the type, the help text and the default), and its error messages
spell ``{opt:NAME}`` with the row's flag.  A new setting of the stage is one field and one row.  A
hyper-parameter of one drift model is not a setting of the stage: it is a
:class:`~fogdrift.models.registry.ModelParam` of the model's row (``--param MODEL.NAME=VALUE``).

This module imports nothing heavy (the CLI reads it to build ``--help``).

Examples
--------
>>> setting("gm_window").rule.describe()
'an integer >= 4'
>>> setting("val_fraction").rule.describe(), setting("val_fraction").rule.holds(1.0)
('a number in [0, 1)', False)
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

from ..errors import ConfigError

__all__ = ["Choice", "Integer", "Number", "Rule", "Setting", "MODEL_SETTINGS", "setting"]


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
        return " or ".join(repr(v) for v in self.values)

    def holds(self, value) -> bool:
        return isinstance(value, str) and value in self.values


@dataclass(frozen=True)
class Setting:
    """One setting: the :class:`~fogdrift.pipeline.AnalysisConfig` field ``name``, its ``default`` (the field's
    and the CLI option's), its ``rule``, the CLI ``flag`` and the ``help`` text (units in brackets)."""

    name: str
    default: object
    rule: Rule
    flag: str
    help: str


#: Smallest series GM(1,1) is fitted to: n = 4 gives 3 equations for the 2 unknowns (a, b).
GM11_MIN_LENGTH = 4

#: The modelling stage's settings, in the order of the CLI's help.
MODEL_SETTINGS: tuple[Setting, ...] = (
    Setting("hidden", 16, Integer(1), "--hidden", "Elman hidden units."),
    Setting("lags", 4, Integer(1), "--lags", "Input lags p of Elman/grey-Elman, order of AR."),
    Setting("epochs", 2000, Integer(1), "--epochs", "Maximum training epochs (early stopping on validation)."),
    Setting("seed", 0, Integer(0), "--seed", "Random seed."),
    Setting("training", "bptt", Choice(("bptt", "bp")), "--training", "bptt (Adam) or bp (classic traingdx)."),
    Setting("train_fraction", 0.6, Number(0.0, 1.0), "--train-fraction", "Chronological training share."),
    Setting("val_fraction", 0.2, Number(0.0, 1.0, "left"), "--val-fraction", "Validation share (early stopping)."),
    Setting("causal_window_s", 128.0, Number(0.0), "--causal-window",
            "Window [s] of the causal (real-time) drift of the practical compensation."),
    Setting("gm_window", 8, Integer(GM11_MIN_LENGTH), "--gm-window", "Rolling window [samples] of the one-step GM(1,1)."),
)

_BY_NAME = {s.name: s for s in MODEL_SETTINGS}


def setting(name: str) -> Setting:
    """The row of ``name`` (KeyError for a name the table does not hold)."""
    return _BY_NAME[name]
