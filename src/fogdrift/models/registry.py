"""The drift-model registry: one table from a model name to its lazily imported class.

Every drift model fogdrift knows is one row of :data:`MODELS`: the name used on the command line
and in :class:`~fogdrift.pipeline.AnalysisConfig` ``models``, the module and class (strings, so
nothing is imported until a model is used), the display label, a one-line description for CLI
help, and which attributes of the analysis settings become which constructor keywords. The
same rows serve :func:`build_model` (name -> unfitted model), :func:`~fogdrift.models.load_model`
(class name in a model file -> class) and the CLI help (:func:`describe_models`). The row order
is the report order.

Adding a model is one new module (a :class:`~fogdrift.models.DriftModel` subclass) plus one row
here; the contract tests (``tests/test_model_contract.py``) then run over it. This module
imports nothing from the model modules and nothing heavy (no NumPy, no JAX).
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from dataclasses import dataclass

from ..errors import ConfigError

__all__ = [
    "ModelSpec",
    "MODELS",
    "MODEL_NAMES",
    "model_spec",
    "model_class",
    "build_model",
    "describe_models",
    "class_for_file",
    "file_class_names",
]


@dataclass(frozen=True)
class ModelSpec:
    """One row of the registry.

    Attributes
    ----------
    name : str
        Model name on the command line and in the analysis settings (lower case).
    module : str
        Dotted path of the module that defines the class; imported on first use.
    cls : str
        Class name in ``module``; also the ``"class"`` written into model files.
    label : str
        Display label in tables and reports (equal to the class's ``label``).
    description : str
        One line for CLI help.
    settings : tuple of (str, str)
        ``(constructor keyword, settings attribute)`` pairs: :func:`build_model` passes
        ``settings.<attribute>`` as ``<keyword>``.
    fixed : tuple of (str, object)
        Constructor keywords with a fixed value.
    """

    name: str
    module: str
    cls: str
    label: str
    description: str
    settings: tuple = ()
    fixed: tuple = ()

    def load(self) -> type:
        """Import ``module`` and return the class (later calls hit the import cache)."""
        return getattr(importlib.import_module(self.module), self.cls)


_RECURRENT = (("lags", "lags"), ("hidden", "hidden"), ("activation", "activation"), ("training", "training"),
              ("epochs", "epochs"), ("seed", "seed"))

#: The registry, in report order.
MODELS: tuple[ModelSpec, ...] = (
    ModelSpec("grey-elman", "fogdrift.models.elman", "GreyElman", "grey-Elman",
              "Elman network on the AGO of the drift, restored by IAGO (Tang et al. 2012)", _RECURRENT),
    ModelSpec("elman", "fogdrift.models.elman", "Elman", "Elman",
              "Elman recurrent network on the last `lags` drift samples", _RECURRENT),
    ModelSpec("gm11", "fogdrift.models.grey", "GM11", "GM(1,1)",
              "rolling GM(1,1) grey model over the last `gm_window` samples", (("window", "gm_window"),),
              (("mode", "rolling"),)),
    ModelSpec("ar", "fogdrift.models.ar", "AR", "AR(p)",
              "least-squares AR(p) with intercept, p = `lags`", (("order", "lags"),)),
    ModelSpec("kalman", "fogdrift.models.kalman", "Kalman", "Kalman",
              "Kalman filter on the rate from the training block's noise model (bias, random walk, Gauss-Markov)"),
    ModelSpec("persistence", "fogdrift.models.persistence", "Persistence", "persistence",
              "repeat the last value (the baseline every table shows)"),
)

#: Model names accepted by :func:`build_model` and ``AnalysisConfig.models``, in report order.
MODEL_NAMES: tuple[str, ...] = tuple(spec.name for spec in MODELS)


def model_spec(name: str) -> ModelSpec:
    """The registry row of a model name (case-insensitive).

    Raises
    ------
    ConfigError
        Unknown name; the message lists the valid names.

    Examples
    --------
    >>> model_spec("GM11").cls
    'GM11'
    >>> model_spec("lstm")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fogdrift.errors.ConfigError: unknown drift model 'lstm'; pass models= as a subset of grey-elman, elman, gm11, ...
    """
    key = name.strip().lower() if isinstance(name, str) else None
    for spec in MODELS:
        if spec.name == key:
            return spec
    valid = ", ".join(spec.name for spec in MODELS)
    raise ConfigError(f"unknown drift model {name!r}; pass {{opt:models}} as a subset of {valid}")


def model_class(name: str) -> type:
    """The model class of a name, imported now (e.g. ``model_class("ar")`` imports only :mod:`fogdrift.models.ar`)."""
    return model_spec(name).load()


def build_model(name: str, settings=None, progress=None):
    """An unfitted drift model from its name and the analysis settings.

    Parameters
    ----------
    name : str
        One of :data:`MODEL_NAMES` (case-insensitive).
    settings : object or mapping, optional
        Anything with the attributes (or keys) the row needs, e.g. an
        :class:`~fogdrift.pipeline.AnalysisConfig` (``lags``, ``hidden``, ``activation``,
        ``training``, ``epochs``, ``seed``, ``gm_window``). None: the class defaults.
    progress : callable, optional
        ``progress(epoch, n_epochs, train_loss, val_loss)``, passed to models that take one
        (the recurrent ones); ignored by the others.

    Returns
    -------
    DriftModel

    Raises
    ------
    ConfigError
        Unknown name, or ``settings`` lacks an attribute the model needs.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> build_model("gm11", SimpleNamespace(gm_window=12))
    GM11(mode='rolling', window=12, shift='auto', shift_margin=1.0)
    >>> build_model("AR", {"lags": 3})
    AR(order=3, max_order=12)
    """
    spec = model_spec(name)
    cls = spec.load()
    kwargs = dict(spec.fixed)
    if settings is not None:
        for keyword, attribute in spec.settings:
            try:
                kwargs[keyword] = settings[attribute] if isinstance(settings, Mapping) else getattr(settings, attribute)
            except (KeyError, AttributeError):
                raise ConfigError(f"model {spec.name!r} needs the setting {attribute!r}; "
                                  f"{type(settings).__name__} has none") from None
    if progress is not None and "progress" in cls._param_names():
        kwargs["progress"] = progress
    return cls(**kwargs)


def describe_models() -> str:
    """One line per model, ``name: description``, in report order (for CLI help).

    Examples
    --------
    >>> print(describe_models().splitlines()[0])
    grey-elman: Elman network on the AGO of the drift, restored by IAGO (Tang et al. 2012)
    """
    return "\n".join(f"{spec.name}: {spec.description}" for spec in MODELS)


def class_for_file(class_name) -> type | None:
    """The class a model file names (``"class"`` key), imported now; None when no row has it."""
    for spec in MODELS:
        if spec.cls == class_name:
            return spec.load()
    return None


def file_class_names() -> tuple[str, ...]:
    """Class names :func:`class_for_file` knows, in registry order."""
    return tuple(spec.cls for spec in MODELS)
