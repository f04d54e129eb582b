"""The settings of the modelling stage, declared once: field, default, rule, CLI flag and help
(:mod:`fogdrift.constraints`).

Each :class:`~fogdrift.constraints.Setting` row of :data:`MODEL_SETTINGS` is a field of
:class:`fogdrift.pipeline.AnalysisConfig` with the row's default.  The row's rule is what
:meth:`~fogdrift.pipeline.AnalysisConfig.validate` checks (one message form for every setting, the option named as
``{opt:NAME}``); the CLI builds its options from the rows (``fogdrift.cli._settings.with_settings``: the flag, the
type, the help text and the default), and its error messages spell ``{opt:NAME}`` with the row's flag.  A new
setting of the stage is one field and one row.  A hyper-parameter of one drift model is not a setting of the
stage: it is a :class:`~fogdrift.models.registry.ModelParam` of the model's row (``--param MODEL.NAME=VALUE``).

:data:`STAGE_SETTINGS` is every declared setting of an analysis, in one place: the Allan stage's
(:data:`fogdrift.allan.settings.ALLAN_SETTINGS`), the outlier treatment (:data:`fogdrift.outliers.OUTLIERS_SETTING`)
and this stage's; :data:`SETTINGS` holds them by name.  ``AnalysisConfig`` and the CLI read them from here.

This module imports nothing heavy (the CLI reads it to build ``--help``).

Examples
--------
>>> SETTINGS["gm_window"].rule.describe()
'an integer >= 4'
>>> SETTINGS["val_fraction"].rule.describe(), SETTINGS["val_fraction"].rule.holds(1.0)
('a number in [0, 1)', False)
>>> [s.name for s in STAGE_SETTINGS][:5]
['estimator', 'statistic', 'taus', 'fit_tau_s', 'outliers']
"""

from __future__ import annotations

from ..allan.settings import ALLAN_SETTINGS
from ..constraints import Choice, Integer, Number, Setting
from ..outliers import OUTLIERS_SETTING

__all__ = ["GM11_MIN_LENGTH", "MODEL_SETTINGS", "SETTINGS", "STAGE_SETTINGS"]


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
    Setting("gm_window", 8, Integer(GM11_MIN_LENGTH), "--gm-window",
            "Rolling window [samples] of the one-step GM(1,1)."),
)

#: Every declared setting of an analysis (:mod:`fogdrift.constraints`): the Allan stage's, the outlier treatment,
#: the modelling stage's.  Each is a field of :class:`~fogdrift.pipeline.AnalysisConfig` with the row's default and
#: rule; a command offers those it names (``fogdrift.cli._settings.with_settings``).
STAGE_SETTINGS: tuple[Setting, ...] = (*ALLAN_SETTINGS, OUTLIERS_SETTING, *MODEL_SETTINGS)

#: :data:`STAGE_SETTINGS` by name.
SETTINGS: dict[str, Setting] = {s.name: s for s in STAGE_SETTINGS}
