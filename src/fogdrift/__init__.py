"""fogdrift: characterise, model and compensate optical-gyro drift.

Internal units: angular rate in deg/h, time and tau in seconds.
Heavy dependencies (JAX, matplotlib) are imported only by the modules that need them.
"""

__version__ = "0.1.0"

from .errors import (  # noqa: F401
    ConfigError,
    DataFormatError,
    FogdriftError,
    FogdriftWarning,
    InsufficientDataError,
    ModelFileError,
    NotFittedError,
)

__all__ = [
    "__version__",
    "FogdriftError",
    "DataFormatError",
    "InsufficientDataError",
    "ConfigError",
    "NotFittedError",
    "ModelFileError",
    "FogdriftWarning",
]
