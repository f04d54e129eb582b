"""Drift models: one estimator contract, one registry.

Layout
------
* :mod:`~fogdrift.models.base` — :class:`DriftModel` (the contract: ``fit``/``predict``/``forecast``,
  the fitted state as data: ``get_state``/``set_state``);
* :mod:`~fogdrift.models.model_files` — model files (JSON + NPZ, no pickle): :func:`save_model`,
  :func:`load_model`, :data:`FORMAT_VERSION`;
* :mod:`~fogdrift.models.registry` — the table from model name to lazily imported class, its
  settings and help text: :data:`MODEL_NAMES`, :func:`build_model`, :func:`describe_models`;
* :mod:`~fogdrift.models.persistence` — :class:`Persistence`, the baseline;
* :mod:`~fogdrift.models.ar` — least-squares AR(p) (``ar_fit``, ``ar_aic``, ``AR``);
* :mod:`~fogdrift.models.grey` — AGO/IAGO, GM(1,1) and its precision tests, ``GM11``;
* :mod:`~fogdrift.models.elman` — the Elman cell, ``Elman``, ``GreyElman``, ``fit_many`` (JAX);
* :mod:`~fogdrift.models.training` — the cell-agnostic recurrent training loop (JAX).

Importing this package imports neither JAX nor any model module but persistence. The model
classes are attributes of the package all the same (``from fogdrift.models import GM11``): each
is imported on first access, through the registry.
"""

from __future__ import annotations

from . import registry as _registry
from .base import DriftModel, check_series
from .model_files import FORMAT_VERSION, load_model, save_model
from .persistence import Persistence
from .registry import (MODEL_NAMES, MODELS, ModelParam, ModelSpec, build_model, check_model_params, declared_params,
                       describe_models, model_class, model_spec, parse_model_params)

__all__ = [
    "DriftModel",
    "FORMAT_VERSION",
    "save_model",
    "load_model",
    "check_series",
    "Persistence",
    "MODELS",
    "MODEL_NAMES",
    "ModelSpec",
    "ModelParam",
    "declared_params",
    "parse_model_params",
    "check_model_params",
    "model_spec",
    "model_class",
    "build_model",
    "describe_models",
]


def __getattr__(name: str):
    """Model classes by class name (``GM11``, ``AR``, ``Elman``, ``GreyElman``), imported on first use."""
    cls = _registry.class_for_file(name)
    if cls is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return cls
