"""The declared settings a command may offer as options, by name (:mod:`fogdrift.constraints`): the Allan stage's
(:data:`fogdrift.allan.settings.ALLAN_SETTINGS`), the outlier treatment (:data:`fogdrift.outliers.OUTLIERS_SETTING`)
and the modelling stage's (:data:`fogdrift.models.settings.MODEL_SETTINGS`).  ``fogdrift.cli._app.FLAGS`` spells
``{opt:NAME}`` from them and ``fogdrift.cli._settings.with_settings`` makes their options."""

from __future__ import annotations

from ..allan.settings import ALLAN_SETTINGS
from ..models.settings import MODEL_SETTINGS
from ..outliers import OUTLIERS_SETTING

__all__ = ["ROWS"]

#: Every declared setting a command may offer, by name.
ROWS = {s.name: s for s in (*ALLAN_SETTINGS, OUTLIERS_SETTING, *MODEL_SETTINGS)}
