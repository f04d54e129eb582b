"""Model files: a fitted drift model as ``<base>.json`` + ``<base>.npz``, written and read without pickle.

The estimators hold no file code: a model gives its fitted state as data (:meth:`DriftModel.get_state
<fogdrift.models.base.DriftModel.get_state>`: a JSON-ready dict and a dict of arrays) and takes it back
(:meth:`~fogdrift.models.base.DriftModel.set_state`); this module turns that into files and back.

Layout (:data:`FORMAT_VERSION`):

* ``<base>.json``: ``{"format": "fogdrift-model", "format_version": 1, "class": <class name>,
  "params": <hyper-parameters, callables as null>, "state": <the JSON part of the state>}``, indented;
* ``<base>.npz``: the arrays of the state, by name (``np.savez``, read with ``allow_pickle=False``).

Each file is written through a temporary name and renamed when complete (:func:`fogdrift.output.atomic_path`),
so a file under the final name is always whole, and inside a run's output folder it is listed in the manifest.
Both are complete before the first is renamed (the JSON file, then the archive), so a failed write leaves the
previous pair of files as it was.

A file names its class (``"class": "GM11"``); :func:`load_model` finds the module of that class in the registry
table (:mod:`fogdrift.models.registry`) and imports only that module, so loading a GM(1,1), AR or persistence
model never imports JAX.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .. import documents
from .._util import strict_json
from ..errors import ModelFileError
from ..output import atomic_path
from .base import DriftModel
from .registry import class_for_file, file_class_names

__all__ = ["FORMAT_VERSION", "save_model", "load_model", "model_file_paths"]

#: Version of the model-file layout (JSON keys and NPZ array names); unchanged since the first release.
FORMAT_VERSION = 1


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


def save_model(model: DriftModel, path) -> tuple[Path, Path]:
    """Write a fitted model to ``<path>.json`` + ``<path>.npz``.

    Parameters
    ----------
    model : DriftModel
        A fitted model of a class the registry knows (its class name is the file's ``"class"``).
    path : str or Path
        Base path; a ``.json`` or ``.npz`` suffix is dropped (:func:`model_file_paths`).

    Returns
    -------
    (Path, Path)
        The JSON and the NPZ file written.

    Raises
    ------
    NotFittedError
        ``model`` is not fitted (nothing is written).

    Examples
    --------
    >>> import tempfile
    >>> from fogdrift.models import Persistence
    >>> with tempfile.TemporaryDirectory() as d:
    ...     json_path, npz_path = save_model(Persistence().fit([0.1, 0.2]), Path(d) / "drift")
    ...     (json_path.name, npz_path.name, load_model(Path(d) / "drift").last_)
    ('drift.json', 'drift.npz', 0.2)
    """
    meta, arrays = model.get_state()  # refuses an unfitted model before any file exists
    json_path, npz_path = model_file_paths(path)
    doc = {
        "format": "fogdrift-model",
        "format_version": FORMAT_VERSION,
        "class": type(model).__name__,
        "params": model.get_params(serialisable=True),
        "state": meta,
    }
    # both files are written under temporary names before either is renamed: a write that fails (disk full,
    # interruption) leaves the previous pair as it was, never a new JSON beside an old archive
    with atomic_path(npz_path) as tmp_npz:
        np.savez(tmp_npz, **{k: np.asarray(v) for k, v in arrays.items()})
        with atomic_path(json_path) as tmp_json:
            tmp_json.write_text(strict_json(doc))
    return json_path, npz_path


def load_model(path, *, expected: type | None = None) -> DriftModel:
    """Load a drift model from ``<path>.json`` + ``<path>.npz`` (no pickle).

    Parameters
    ----------
    path : str or Path
        Base path as given to :func:`save_model` (a ``.json`` or ``.npz`` suffix is dropped).
    expected : type, optional
        A model class: the stored class must be it or a subclass of it.

    Returns
    -------
    DriftModel
        A fitted model of the class named in the file; only that class's module is imported.

    Raises
    ------
    ModelFileError
        Missing or corrupt file, another format version, a class the registry does not know (or not
        ``expected``), or parameters/state that do not describe a fitted model of that class.
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
    version = doc.get("format_version")
    if type(version) is not int or version != FORMAT_VERSION:  # neither true nor 1.0 nor "1" pass for 1
        raise ModelFileError(
            f"{json_path}: format version {version!r}; this fogdrift reads {FORMAT_VERSION}"
        )
    cls = class_for_file(doc.get("class"))
    if cls is None:
        raise ModelFileError(f"{json_path}: unknown model class {doc.get('class')!r}; "
                             f"expected one of {', '.join(file_class_names())}")
    if expected is not None and not issubclass(cls, expected):
        raise ModelFileError(f"{path}: holds a {cls.__name__}, not a {expected.__name__}")
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
        model.set_state(state, arrays)
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise ModelFileError(
            f"{json_path}: the stored state does not describe a fitted {cls.__name__} "
            f"(missing or malformed {exc!s}); save the model again"
        ) from exc
    return model
