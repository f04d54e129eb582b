"""Compatibility alias: the Elman models moved to :mod:`fogdrift.models.elman`; import from there."""

from .models.elman import *  # noqa: F401,F403
from .models.elman import __all__  # noqa: F401
