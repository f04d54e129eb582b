"""fogdrift: characterise, model and compensate optical-gyro drift.

Internal units: angular rate in deg/h, time and tau in seconds.
Heavy dependencies (JAX, matplotlib) are imported only by the modules that need them.
"""

__version__ = "0.1.0"

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


def __getattr__(name):
    """The error classes of :mod:`fogdrift.errors`, imported on first use: ``import fogdrift`` stays free, so the
    CLI's entry point (:func:`fogdrift.cli.main`) owns SIGINT before anything is imported."""
    if name in __all__[1:]:
        from . import errors

        return getattr(errors, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
