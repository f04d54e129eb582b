"""fogdrift: characterise, model and compensate optical-gyro drift.

Internal units: angular rate in deg/h, time and tau in seconds.
Heavy dependencies (JAX, matplotlib) are imported only by the modules that need them.

The front door (each name imported on first use, scipy's lazy-root pattern, so ``import fogdrift`` stays free and
the CLI's entry point owns SIGINT before anything is imported):

* ``fogdrift.read(path, unit=..., rate_hz=...)`` -> ``GyroRecord`` (:func:`fogdrift.io.load`), and
  ``fogdrift.from_array(rates, dt_s=..., unit=...)``;
* ``fogdrift.run_allan(record)``, ``run_noise``, ``run_separate``, ``run_model``, ``run_analyze``, ``run_export``:
  the commands' workflows (:mod:`fogdrift.workflows`), returning their run objects, with ``write_allan``,
  ``write_noise``, ``write_separate``, ``write_model``, ``write_analyze``, ``write_export`` for their files;
* ``fogdrift.fit_noise(allan_result)`` (the Allan fit) and ``fogdrift.simulate_rate(n, dt_s, ...)``
  (:func:`fogdrift.simulate.simulate`).

>>> import fogdrift
>>> rec = fogdrift.from_array(fogdrift.simulate_rate(2**13, 0.01, arw_dprh=0.1, seed=2), dt_s=0.01, axis_names=["gz"])
>>> run = fogdrift.run_allan(rec)
>>> run.results[0].noise.terms["N"].status
'resolved'
"""

__version__ = "0.1.0"

#: name -> (module, attribute) of the front door, imported on first use.
_FRONT_DOOR = {
    "read": ("fogdrift.io", "load"),
    "from_array": ("fogdrift.io", "from_array"),
    "run_allan": ("fogdrift.workflows.allan", "run_allan"),
    "write_allan": ("fogdrift.workflows.allan", "write_allan"),
    "run_noise": ("fogdrift.workflows.noise", "run_noise"),
    "write_noise": ("fogdrift.workflows.noise", "write_noise"),
    "run_separate": ("fogdrift.workflows.separate", "run_separate"),
    "write_separate": ("fogdrift.workflows.separate", "write_separate"),
    "run_model": ("fogdrift.workflows.model", "run_model"),
    "write_model": ("fogdrift.workflows.model", "write_model"),
    "run_export": ("fogdrift.workflows.export", "run_export"),
    "write_export": ("fogdrift.workflows.export", "write_export"),
    "run_analyze": ("fogdrift.workflows.analyze", "run_analyze"),
    "write_analyze": ("fogdrift.workflows.analyze", "write_analyze"),
    "fit_noise": ("fogdrift.noise", "fit_noise"),
    "simulate_rate": ("fogdrift.simulate", "simulate"),
}

_ERRORS = (
    "FogdriftError",
    "DataFormatError",
    "InsufficientDataError",
    "ConfigError",
    "NotFittedError",
    "ModelFileError",
    "FogdriftWarning",
)

__all__ = ["__version__", *_ERRORS, *_FRONT_DOOR]


def __getattr__(name):
    """The error classes of :mod:`fogdrift.errors` and the front door, imported on first use."""
    if name in _ERRORS:
        from . import errors

        return getattr(errors, name)
    if name in _FRONT_DOOR:
        import importlib

        module, attr = _FRONT_DOOR[name]
        return getattr(importlib.import_module(module), attr)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
