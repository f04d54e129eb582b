"""Compatibility alias: the grey models moved to :mod:`fogdrift.models.grey`; import from there."""

from .models.grey import *  # noqa: F401,F403
from .models.grey import __all__  # noqa: F401
