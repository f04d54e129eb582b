"""Estimator-style interface shared by every drift model, and the persistence baseline.

Contract (scikit-learn shape, see ``docs`` and the style examples):

* the constructor only stores hyper-parameters, under the names given, keyword-only;
* ``fit(y_train, y_val=None)`` learns from the training block (and may use the chronologically
  following validation block for early stopping) and returns ``self``; everything learned ends
  in ``_``; normalisation statistics, shifts etc. come from ``y_train`` only;
* ``predict(y, history=None)`` gives **one-step-ahead** predictions from measured data:
  ``out[k]`` predicts ``y[k]`` from ``history`` (the measured samples immediately before
  ``y``) and ``y[:k]``; entries with too little history are NaN;
* ``forecast(h, history=None)`` runs free for ``h`` steps after the end of ``history``
  (default: after the end of the training block), feeding predictions back;
* ``save(path)`` writes ``path.json`` (class, format version, hyper-parameters, small state)
  and ``path.npz`` (arrays); :func:`load_model` reads them back without pickle.

Series are 1-D float arrays of drift samples in deg/h at a fixed sample interval.

Model files name their class (``"class": "GM11"``); :func:`load_model` finds the module of that
class in the registry table (:mod:`fogdrift.models.registry`) and imports only that module, so
loading a GM(1,1), AR or persistence model never imports JAX.
"""

from __future__ import annotations

import inspect
import json
from pathlib import Path

import numpy as np

from .. import documents
from .._util import check_series, strict_json
from ..errors import ConfigError, ModelFileError, NotFittedError
from ..output import atomic_path
from .registry import class_for_file, file_class_names

__all__ = ["DriftModel", "load_model", "model_file_paths", "check_series", "FORMAT_VERSION"]

#: Version of the model-file layout (JSON keys and NPZ array names); unchanged since the first release.
FORMAT_VERSION = 1


class DriftModel:
    """Base class of drift models: parameter handling, fitted check, JSON + NPZ persistence.

    Subclasses implement ``fit``, ``predict``, ``forecast`` and the two state hooks
    ``_get_state() -> (meta: dict, arrays: dict[str, ndarray])`` and
    ``_set_state(meta, arrays)``; ``meta`` must be JSON-serialisable.
    """

    #: Name shown in tables and reports (the registry row repeats it for CLI help).
    label = "model"
    #: True when ``fit`` uses ``y_val`` (early stopping); False: ``y_val`` is accepted and ignored.
    uses_validation = False
    #: What the model is fed when it compensates a gyro: ``"drift"`` (a separated drift series, the
    #: paper's framing; the causal drift in real time) or ``"rate"`` (the bias-removed rate itself, e.g.
    #: a Kalman filter whose noise model includes the white noise).
    input_kind = "drift"

    @classmethod
    def _param_names(cls) -> list[str]:
        sig = inspect.signature(cls.__init__)
        return [p.name for p in sig.parameters.values() if p.name != "self" and p.kind != p.VAR_KEYWORD]

    def get_params(self) -> dict:
        """Hyper-parameters exactly as given to the constructor."""
        return {name: getattr(self, name) for name in self._param_names()}

    def _serialisable_params(self) -> dict:
        """Hyper-parameters for a model file: callables (progress callbacks) are not saved."""
        return {k: (None if callable(v) else v) for k, v in self.get_params().items()}

    def set_params(self, **params):
        valid = set(self._param_names())
        for key, value in params.items():
            if key not in valid:
                raise ConfigError(f"{type(self).__name__} has no parameter {key!r}; valid: {sorted(valid)}")
            setattr(self, key, value)
        return self

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"

    # -- fitted state -------------------------------------------------------------------
    def _is_fitted(self) -> bool:
        return any(k.endswith("_") and not k.startswith("__") for k in vars(self))

    def _check_fitted(self) -> None:
        if not self._is_fitted():
            raise NotFittedError(f"{type(self).__name__} is not fitted yet; call fit(y_train) first")

    def _validate(self):
        """The one validation hook of a model: check the hyper-parameters, raise ConfigError naming the bad one.

        Called by ``fit`` (and wherever a model needs its checked settings); it may return what it derived
        (the Elman models their training configuration, the Kalman filter its ``dt_s``).  The default checks
        nothing.
        """
        return None

    def _get_state(self):  # pragma: no cover - abstract
        raise NotImplementedError

    def _set_state(self, meta: dict, arrays: dict) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    # -- persistence ----------------------------------------------------------------------
    def save(self, path) -> tuple[Path, Path]:
        """Write ``<path>.json`` and ``<path>.npz``; returns both paths."""
        self._check_fitted()
        json_path, npz_path = model_file_paths(path)
        meta, arrays = self._get_state()
        doc = {
            "format": "fogdrift-model",
            "format_version": FORMAT_VERSION,
            "class": type(self).__name__,
            "params": self._serialisable_params(),
            "state": meta,
        }
        # each file complete or absent (temporary name, renamed when written): fogdrift.output.atomic_path
        with atomic_path(json_path) as tmp:
            tmp.write_text(strict_json(doc))
        with atomic_path(npz_path) as tmp:
            np.savez(tmp, **{k: np.asarray(v) for k, v in arrays.items()})
        return json_path, npz_path

    @classmethod
    def load(cls, path):
        """Load a model saved by :meth:`save`; the stored class must be ``cls`` or a subclass."""
        model = load_model(path)
        if not isinstance(model, cls):
            raise ModelFileError(f"{path}: holds a {type(model).__name__}, not a {cls.__name__}")
        return model


def model_file_paths(path) -> tuple[Path, Path]:
    """The two files of a model saved under ``path``: ``(<base>.json, <base>.npz)``.

    A ``.json`` or ``.npz`` suffix of ``path`` is dropped; any other suffix is part of the name
    (``drift.v2`` -> ``drift.v2.json``, not ``drift.json``).

    Examples
    --------
    >>> [p.name for p in model_file_paths("models/drift.v2")]
    ['drift.v2.json', 'drift.v2.npz']
    >>> [p.name for p in model_file_paths("models/drift.npz")]
    ['drift.json', 'drift.npz']
    """
    base = Path(path)
    if base.suffix in (".json", ".npz"):
        base = base.with_suffix("")
    return base.with_name(base.name + ".json"), base.with_name(base.name + ".npz")


def load_model(path) -> DriftModel:
    """Load a drift model from ``<path>.json`` + ``<path>.npz`` (no pickle).

    Parameters
    ----------
    path : str or Path
        Base path as given to :meth:`DriftModel.save` (a ``.json`` or ``.npz`` suffix is dropped).

    Returns
    -------
    DriftModel
        A fitted model of the class named in the file; only that class's module is imported.

    Raises
    ------
    ModelFileError
        Missing or corrupt file, another format version, a class the registry does not know, or
        parameters/state that do not describe a fitted model of that class.
    """
    json_path, npz_path = model_file_paths(path)
    try:
        doc = documents.read(json_path, yaml=False)
    except FileNotFoundError:
        raise ModelFileError(f"{json_path}: model file not found") from None
    except documents.DocumentError as exc:
        raise ModelFileError(str(exc)) from None
    except json.JSONDecodeError as exc:
        raise ModelFileError(f"{json_path}:{exc.lineno}:{exc.colno}: not valid JSON ({exc.msg})") from exc
    if not isinstance(doc, dict) or doc.get("format") != "fogdrift-model":
        raise ModelFileError(f"{json_path}: not a fogdrift model file")
    if doc.get("format_version") != FORMAT_VERSION:
        raise ModelFileError(
            f"{json_path}: format version {doc.get('format_version')!r}; this fogdrift reads {FORMAT_VERSION}"
        )
    cls = class_for_file(doc.get("class"))
    if cls is None:
        raise ModelFileError(f"{json_path}: unknown model class {doc.get('class')!r}; "
                             f"expected one of {', '.join(file_class_names())}")
    try:
        with np.load(npz_path, allow_pickle=False) as npz:
            arrays = {k: npz[k] for k in npz.files}
    except FileNotFoundError:
        raise ModelFileError(f"{npz_path}: model array file not found") from None
    except (ValueError, OSError) as exc:
        raise ModelFileError(f"{npz_path}: cannot read arrays ({exc})") from exc
    params, state = doc.get("params", {}), doc.get("state")
    if not isinstance(params, dict):
        raise ModelFileError(f"{json_path}: 'params' must be an object, not {type(params).__name__}")
    if not isinstance(state, dict):
        raise ModelFileError(f"{json_path}: no fitted state (the 'state' object is missing or not an object)")
    try:
        model = cls(**params)
    except TypeError as exc:
        raise ModelFileError(f"{json_path}: parameters do not fit a {cls.__name__} ({exc})") from exc
    try:
        model._set_state(state, arrays)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise ModelFileError(
            f"{json_path}: the stored state does not describe a fitted {cls.__name__} "
            f"(missing or malformed {exc!s}); save the model again"
        ) from exc
    return model
