"""Compatibility alias: AR(p) moved to :mod:`fogdrift.models.ar` (persistence to
:mod:`fogdrift.models.persistence`); import from there."""

from .models.ar import *  # noqa: F401,F403
from .models.ar import __all__  # noqa: F401
