"""The model bundle: everything needed to re-apply fitted drift models to a new log, in one directory.

``analyze`` and ``model`` write one bundle per run at ``OUT/bundle/``; ``fogdrift compensate`` reads it.
Layout (no pickle; every file is JSON or NPZ)::

    bundle/
      manifest.json          format, format_version, fogdrift version, the training input (source,
                             SHA-256, time range, split), the training log's signal description
                             (:mod:`fogdrift.signal`: its sampling and its channels, where each came
                             from, the one place the sample interval and the input unit are written),
                             the block-average factor to the modelling rate, wavelet / mode, the
                             analysis settings, and per axis: bias and
                             how it was estimated, Earth-rate setting, level, causal-drift window,
                             noise model, and the model files with their SHA-256
      <axis>/<model>.json    one fitted drift model (:func:`fogdrift.models.save_model`)
      <axis>/<model>.npz

Model keys are registry names (:data:`fogdrift.models.MODEL_NAMES`: ``"ar"``, ``"kalman"``, ...).
The noise model of an axis is the Allan fit of its training block at the modelling rate (coefficients
A_-2..A_2 in (deg/h)^2 with tau in s, their covariance and the IEEE-952 terms), the Kalman model's
state-space components if one was fitted, and a ``"gmwm"`` slot (None until a GMWM fit exists).

:func:`load_bundle` validates everything (keys, types, units, intervals, wavelet and level, the models'
classes and the files' SHA-256) and refuses a bundle of a newer format version with one clear line.  A
format-2 manifest (the intervals and the unit written beside the signal description as ``native_dt_s``,
``model_dt_s``, their rates, ``input_unit`` and ``rate_unit_internal``) is read through :func:`_manifest_v2_as_v3`,
the one converter.

Examples
--------
>>> import tempfile
>>> from fogdrift.io import from_array
>>> from fogdrift.pipeline import AnalysisConfig, run_models
>>> from fogdrift.simulate import simulate
>>> rec = from_array(simulate(6000, 1.0, arw_dprh=0.05, rrw_dphrh=0.5, bias_dph=3.0, seed=1), dt_s=1.0,
...                  axis_names=["gz"])
>>> cfg = AnalysisConfig(models=("ar", "persistence"), model_rate_hz=None)
>>> out = tempfile.mkdtemp()
>>> b = write_bundle(out, run_models(rec, cfg), cfg, rec)
>>> back = load_bundle(out)
>>> back.axis_names, sorted(back.axis("gz").models), back.axis("gz").causal_window
(('gz',), ['ar', 'persistence'], 128)
"""

from __future__ import annotations

import datetime
import hashlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import __version__, documents
from ._util import safe_name, strict_json
from .allan import allan_variance
from .errors import ConfigError, FogdriftError, ModelFileError
from .io.hashing import file_sha256
from .lifting import MODES, max_level, wavelist
from .models import MODELS, MODEL_NAMES, load_model, model_spec, save_model
from .models.model_files import model_file_paths
from .noise import fit_noise
from .output import atomic_path
from .signal import Channel, Sampling, SignalDescription, channel_unit
from .units import check_dt_s

__all__ = [
    "BUNDLE_FORMAT",
    "BUNDLE_FORMAT_VERSION",
    "BundleAxis",
    "Bundle",
    "bundle_from_model_axes",
    "save_bundle",
    "write_bundle",
    "load_bundle",
    "seal_manifest",
]

BUNDLE_FORMAT = "fogdrift-bundle"
#: Version of the bundle layout (manifest keys, file names). Readers refuse a newer one.  Version 2 added the
#: integrity seal; a version-1 bundle (no seal) is refused with the advice to re-create it.  Version 3 writes the
#: sampling once, in ``signal.sampling`` (the modelling interval is ``block_average_factor`` times its ``dt_s``);
#: a version-2 manifest is converted on reading.
BUNDLE_FORMAT_VERSION = 3
#: Manifest keys of format 2 that repeat the sampling of ``signal.sampling`` (dropped by the conversion).
_V2_SAMPLING_KEYS = ("native_dt_s", "native_rate_hz", "model_dt_s", "model_rate_hz")
#: Manifest keys that repeat the unit of ``signal.channels`` (``unit_as_read``; ``rate_unit_internal`` was the
#: constant "deg/h"): checked against the channels and dropped on reading, never written.
_UNIT_KEYS = ("input_unit", "rate_unit_internal")
MANIFEST = "manifest.json"
#: Manifest key of the seal: SHA-256 of the canonical manifest without this key.
SEAL_KEY = "seal_sha256"


def _canonical_sha256(doc: dict) -> str:
    """SHA-256 of the manifest without its seal, serialised canonically (sorted keys, no spaces)."""
    body = {k: v for k, v in doc.items() if k != SEAL_KEY}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=False)
    return hashlib.sha256(text.encode("ascii")).hexdigest()


def seal_manifest(doc: dict) -> dict:
    """``doc`` with its integrity seal (:data:`SEAL_KEY`) set.

    The manifest holds the SHA-256 of every model file, so one hash over the manifest covers the whole bundle:
    a change to any field (a bias, the unit, a file entry) or to any file is refused at load.  It detects an
    edited or damaged bundle; it is not a signature (whoever can write the folder can re-seal it).

    Examples
    --------
    >>> d = seal_manifest({"format": "fogdrift-bundle", "axes": []})
    >>> len(d["seal_sha256"]), seal_manifest(d) == d
    (64, True)
    """
    return {**{k: v for k, v in doc.items() if k != SEAL_KEY}, SEAL_KEY: _canonical_sha256(doc)}


def _inside(root: Path, rel: str) -> bool:
    """Whether the relative path ``rel`` names a place inside ``root`` (no absolute path, no ``..``)."""
    if not rel or Path(rel).is_absolute() or "\\" in rel or ".." in Path(rel).parts:
        return False
    try:
        (root / rel).resolve().relative_to(root.resolve())
    except ValueError:
        return False
    return True


def _check_finite_parameters(npz_path: Path, where: str) -> None:
    """Refuse a model whose parameter arrays hold NaN or inf (training curves, diagnostics only, may)."""
    try:
        with np.load(npz_path, allow_pickle=False) as z:
            for key in z.files:
                a = z[key]
                if key.endswith("_curve_") or a.dtype.kind not in "fc":
                    continue
                if not np.all(np.isfinite(a)):
                    raise ModelFileError(f"{npz_path}: parameter {key!r} of {where} holds NaN or inf; a model with "
                                         "non-finite parameters cannot be applied (re-create the bundle)")
    except ModelFileError:
        raise
    except Exception as exc:  # a damaged archive: load_model reports it with its own words
        raise ModelFileError(f"{npz_path}: not a readable model archive of {where} ({type(exc).__name__})") from None


@dataclass(frozen=True)
class BundleAxis:
    """One axis of a bundle.

    Attributes
    ----------
    name : str
        Axis name as in the training log (``gx``); logs are matched to it by name.
    bias_dph : float
        Constant bias removed before modelling [deg/h] (Earth rate not included).
    bias_method : str
        How ``bias_dph`` was estimated, in words (samples and times of the training block).
    earth_rate_dph : float
        Earth-rate projection removed with the bias [deg/h] (0 without a latitude).
    earth_orientation : str, list or None
        Axis orientation used for the projection (``"up"``, an east-north-up vector), or None.
    level : int
        Wavelet decomposition level of the drift separation.
    causal_window : int
        Window [samples at the modelling rate] of the causal (real-time) drift fed to the drift models.
    noise_model : dict
        ``{"allan": {...} or None, "kalman_components": [...] or None, "gmwm": None}``.
    models : dict
        Registry name -> fitted :class:`~fogdrift.models.DriftModel`.
    """

    name: str
    bias_dph: float
    bias_method: str
    earth_rate_dph: float
    earth_orientation: object
    level: int
    causal_window: int
    noise_model: dict
    models: dict


@dataclass(frozen=True)
class Bundle:
    """A loaded (or freshly built) bundle; see the module docstring.

    Attributes
    ----------
    axes : tuple of BundleAxis
    input_unit : str
        Unit of the training log's numbers (``"deg/s"``); a log to compensate must match it or be
        mapped explicitly (``apply_unit``).  Not written to the manifest: read from its
        ``signal.channels`` (their ``unit_as_read``).
    native_dt_s, model_dt_s : float
        Sample interval of the training log and of the modelling series [s];
        ``model_dt_s = block_average_factor * native_dt_s``.  Not written to the manifest: read from its
        ``signal.sampling.dt_s`` and ``block_average_factor``.
    block_average_factor : int
        Samples of the training log (at ``native_dt_s``) per modelling sample.
    wavelet, mode : str
        Lifting wavelet and boundary mode of the drift separation.
    latitude_deg : float or None
    training : dict
        ``source, sha256, t0_s, t_end_s, duration_s, n_samples, split`` (modelling-rate sample ranges
        ``[start, stop)`` of train / val / test and their times in s).
    settings : dict
        The analysis settings (:meth:`fogdrift.pipeline.AnalysisConfig.to_dict`).
    fogdrift_version : str
    format_version : int
    created_utc : str
    path : Path or None
        Directory it was loaded from or saved to.
    signal : fogdrift.signal.SignalDescription or None
        The training log's signal description as loaded (native sampling, channels, where the rate and the
        unit came from).  A format-2 manifest without one gets one made from ``input_unit`` and
        ``native_dt_s`` with the sources ``"bundle"``; :func:`save_bundle` makes that one too for a bundle
        built without a description.
    """

    axes: tuple
    input_unit: str
    native_dt_s: float
    model_dt_s: float
    block_average_factor: int
    wavelet: str
    mode: str
    latitude_deg: float | None
    training: dict
    settings: dict
    fogdrift_version: str = __version__
    format_version: int = BUNDLE_FORMAT_VERSION
    created_utc: str = ""
    path: Path | None = field(default=None, compare=False)
    signal: SignalDescription | None = None

    @property
    def axis_names(self) -> tuple:
        return tuple(a.name for a in self.axes)

    def axis(self, name: str) -> BundleAxis:
        """The axis called ``name`` (exact match)."""
        for a in self.axes:
            if a.name == name:
                return a
        raise ConfigError(f"the bundle has no axis {name!r}; its axes are {list(self.axis_names)}")

    @property
    def model_names(self) -> tuple:
        """Registry names of the models every axis has, in registry order."""
        common = set.intersection(*(set(a.models) for a in self.axes)) if self.axes else set()
        return tuple(n for n in MODEL_NAMES if n in common)


# ------------------------------------------------------------------------------------------------------
# building
# ------------------------------------------------------------------------------------------------------
def _registry_name(label: str) -> str:
    for spec in MODELS:
        if spec.label == label:
            return spec.name
    raise ConfigError(f"fitted model {label!r} is not in the model registry")


def _allan_noise_model(x, dt_s) -> dict:
    try:
        fit = fit_noise(allan_variance(x, dt_s, taus="octave"))
    except FogdriftError as exc:
        return {"source": "training block at the modelling rate", "A": None, "reason": str(exc)}
    return {
        "source": "training block at the modelling rate",
        "A": [float(a) for a in fit.A],
        "selected": list(fit.selected),
        "fit_quality": {"chi2_red": float(fit.chi2_red), "p_value": float(fit.p_value), "quality": fit.quality},
        "A_unit": "(deg/h)^2 with tau in s: sigma^2(tau) = sum_n A_n tau^n, n = -2..2",
        "tau_range_s": [float(fit.tau_min_s), float(fit.tau_max_s)],
        "terms": {k: t.to_dict() for k, t in fit.terms.items()},
    }


def bundle_from_model_axes(model_axes, cfg, record) -> Bundle:
    """A :class:`Bundle` (not yet saved) from the pipeline's fitted axes.

    Parameters
    ----------
    model_axes : list of fogdrift.pipeline.ModelAxis
        From :func:`~fogdrift.pipeline.run_models` or ``[ax.models for ax in run_analysis(...).axes]``.
    cfg : fogdrift.pipeline.AnalysisConfig
        The settings of that run.
    record : fogdrift.io.GyroRecord
        The training log as loaded (native rate): unit, interval, SHA-256 and time range.
    """
    if not model_axes:
        raise ConfigError("no fitted axes to bundle")
    dt_m = float(model_axes[0].dt_s)
    factor = int(model_axes[0].block_average_factor)  # decided once by the pipeline, read back
    axes = []
    for ma in model_axes:
        level = int(ma.level)
        a, b = ma.split["train"]
        orient = cfg.earth_axes.get(ma.name) if cfg.latitude_deg is not None else None
        t0 = record.t0_s
        method = (f"mean of the training block at the modelling rate (samples {a}..{b - 1} of {dt_m:g} s, "
                  f"t = {t0 + a * dt_m:.6g}..{t0 + b * dt_m:.6g} s)"
                  + (f" minus the Earth-rate projection {ma.earth_rate_dph:.6g} deg/h" if ma.earth_rate_dph else ""))
        kalman = next((m for m in ma.fitted.values() if type(m).__name__ == "Kalman"), None)
        noise = {"allan": _allan_noise_model(ma.rate_dph[a:b], dt_m),
                 "kalman_components": None if kalman is None else kalman.components_,
                 "gmwm": None}
        axes.append(BundleAxis(
            name=ma.name, bias_dph=float(ma.bias_dph), bias_method=method, earth_rate_dph=float(ma.earth_rate_dph),
            earth_orientation=orient, level=level, causal_window=int(ma.causal_window), noise_model=noise,
            models={_registry_name(label): model for label, model in ma.fitted.items()},
        ))
    split = {k: {"samples": list(v), "t_s": [record.t0_s + v[0] * dt_m, record.t0_s + v[1] * dt_m]}
             for k, v in model_axes[0].split.items()}
    training = {
        "source": record.source, "sha256": record.sha256, "t0_s": record.t0_s,
        "t_end_s": record.t0_s + record.duration_s, "duration_s": record.duration_s,
        "n_samples": record.n_samples, "axis_names": list(record.axis_names), "split": split,
    }
    return Bundle(
        axes=tuple(axes), input_unit=record.input_unit, native_dt_s=float(record.dt_s), model_dt_s=dt_m,
        block_average_factor=factor, wavelet=cfg.wavelet, mode=cfg.mode,
        latitude_deg=None if cfg.latitude_deg is None else float(cfg.latitude_deg), training=training,
        settings=cfg.to_dict(), created_utc=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        signal=record.signal,
    )


def save_bundle(bundle: Bundle, out_dir) -> Path:
    """Write ``bundle`` to the directory ``out_dir`` (created; an existing manifest is replaced); returns it."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    axes_doc = []
    for ax in bundle.axes:
        files = {}
        for name, model in ax.models.items():
            rel = f"{safe_name(ax.name)}/{safe_name(name)}"
            json_path, npz_path = save_model(model, out / rel)
            files[name] = {"file": rel, "class": type(model).__name__, "label": model.label,
                           "input": model.input_kind,
                           "sha256": {"json": file_sha256(json_path), "npz": file_sha256(npz_path)}}
        axes_doc.append({
            "name": ax.name, "bias_dph": ax.bias_dph, "bias_method": ax.bias_method,
            "earth_rate_dph": ax.earth_rate_dph, "earth_orientation": ax.earth_orientation, "level": ax.level,
            "causal_window": ax.causal_window, "causal_window_s": ax.causal_window * bundle.model_dt_s,
            "noise_model": ax.noise_model, "models": files,
        })
    signal = bundle.signal
    if signal is None:
        names = bundle.training.get("axis_names") or list(bundle.axis_names)
        signal = _bundle_signal(names, channel_unit(bundle.input_unit, None), bundle.native_dt_s)
    elif abs(signal.sampling.dt_s - bundle.native_dt_s) > 1e-9 * bundle.native_dt_s:
        raise ConfigError(f"the bundle's native_dt_s {bundle.native_dt_s!r} differs from its signal description's "
                          f"sample interval {signal.sampling.dt_s!r}")
    else:
        odd = [c.name for c in signal.channels if c.unit_as_read != bundle.input_unit]
        if odd:
            raise ConfigError(f"the bundle's input_unit {bundle.input_unit!r} is not the unit of its signal "
                              f"description's channels {odd}")
    # the sampling and the unit are written once, in signal; the intervals are read back from its sampling and the
    # factor, the input unit from its channels
    doc = {
        "format": BUNDLE_FORMAT, "format_version": BUNDLE_FORMAT_VERSION, "fogdrift_version": bundle.fogdrift_version,
        "created_utc": bundle.created_utc,
        "block_average_factor": bundle.block_average_factor, "wavelet": bundle.wavelet, "mode": bundle.mode,
        "latitude_deg": bundle.latitude_deg, "training": bundle.training, "settings": bundle.settings,
        "signal": signal.to_dict(), "axes": axes_doc,
    }
    # sealed over the strict (NaN -> null) tree that is written: one serialiser, _util.strict_json
    text = strict_json(seal_manifest(json.loads(strict_json(doc, indent=None))))
    # the manifest last and whole (temporary name, renamed): a bundle without one is incomplete, never half-read
    with atomic_path(out / MANIFEST) as tmp:
        tmp.write_text(text)
    return out


def write_bundle(out_dir, model_axes, cfg, record) -> Bundle:
    """Build (:func:`bundle_from_model_axes`) and save (:func:`save_bundle`) a bundle; returns it with ``path`` set.

    This is the one call ``analyze`` / ``model`` make: ``write_bundle(out / "bundle", model_axes, cfg, record)``.
    """
    bundle = bundle_from_model_axes(model_axes, cfg, record)
    path = save_bundle(bundle, out_dir)
    return _with_path(bundle, path)


def _with_path(bundle: Bundle, path: Path) -> Bundle:
    import dataclasses

    return dataclasses.replace(bundle, path=Path(path))


# ------------------------------------------------------------------------------------------------------
# loading
# ------------------------------------------------------------------------------------------------------
class _Doc:
    """Typed access to the manifest with located errors (``manifest.json: axes[1].level: ...``)."""

    def __init__(self, path: Path):
        self.path = path

    def fail(self, where: str, what: str):
        raise ModelFileError(f"{self.path}: {where}: {what}")

    def get(self, obj, key, kind, where, *, optional=False):
        if not isinstance(obj, dict) or key not in obj:
            if optional:
                return None
            self.fail(f"{where}{key}", "missing")
        value = obj[key]
        if value is None and optional:
            return None
        if kind == "number":
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                self.fail(f"{where}{key}", f"expected a finite number, got {value!r}")
            return float(value)
        if kind == "positive":
            v = self.get(obj, key, "number", where)
            if not v > 0:
                self.fail(f"{where}{key}", f"expected a number > 0, got {value!r}")
            return v
        if kind == "int":
            if isinstance(value, bool) or not isinstance(value, int):
                self.fail(f"{where}{key}", f"expected an integer, got {value!r}")
            return value
        if not isinstance(value, kind):
            self.fail(f"{where}{key}", f"expected {kind.__name__}, got {type(value).__name__}")
        return value


def load_bundle(path) -> Bundle:
    """Load and validate a bundle directory (or its ``manifest.json``).

    Raises
    ------
    ModelFileError
        Missing or corrupt manifest, a newer format version, a missing or wrong key, an invalid unit,
        interval, wavelet, mode, level or window, a model file that is missing, modified (SHA-256) or of
        another class.  The message names the file and the key.
    """
    p = Path(path)
    if p.name != MANIFEST and p.is_file():
        raise ModelFileError(f"{p}: is a file; expected a bundle directory (OUT/bundle, written by 'fogdrift analyze' "
                             f"or 'fogdrift model') or its {MANIFEST}")
    root = p.parent if p.name == MANIFEST else p
    mpath = root / MANIFEST
    try:
        raw = documents.read(mpath, yaml=False)
    except documents.DocumentError as exc:
        raise ModelFileError(str(exc)) from None
    except (FileNotFoundError, NotADirectoryError):
        raise ModelFileError(f"{mpath}: bundle manifest not found; expected the directory written by "
                             "'fogdrift analyze' or 'fogdrift model' (OUT/bundle)") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ModelFileError(f"{mpath}: not valid JSON ({exc})") from None
    except (OSError, RecursionError, MemoryError) as exc:
        raise ModelFileError(f"{mpath}: cannot read the bundle manifest ({type(exc).__name__}: "
                             f"{getattr(exc, 'strerror', None) or exc})") from None
    d = _Doc(mpath)
    if not isinstance(raw, dict) or raw.get("format") != BUNDLE_FORMAT:
        raise ModelFileError(f"{mpath}: not a fogdrift bundle (format {raw.get('format') if isinstance(raw, dict) else None!r})")
    version = d.get(raw, "format_version", "int", "")
    if version > BUNDLE_FORMAT_VERSION:
        raise ModelFileError(
            f"{mpath}: bundle format version {version} was written by fogdrift {raw.get('fogdrift_version')}; "
            f"this fogdrift {__version__} reads format version {BUNDLE_FORMAT_VERSION} and older: upgrade fogdrift")
    if version < 1:
        d.fail("format_version", f"expected an integer >= 1, got {version}")
    if version < 2:
        raise ModelFileError(f"{mpath}: bundle format version {version} has no integrity seal; re-create the bundle "
                             f"with this fogdrift {__version__} ('fogdrift model' or 'fogdrift analyze')")
    seal = raw.get(SEAL_KEY)
    try:
        expected = _canonical_sha256(raw)
    except (TypeError, ValueError):
        expected = None
    if not isinstance(seal, str) or seal != expected:
        raise ModelFileError(f"{mpath}: the manifest does not match its integrity seal ({SEAL_KEY}): it was edited "
                             "or damaged after the bundle was written; re-create the bundle")
    # a format-3 manifest may still repeat the unit beside its description: checked and dropped the same way
    raw = _manifest_v2_as_v3(raw, d) if version == 2 else _unit_keys_dropped(raw, d)
    signal = _signal_of(raw, d)
    unit = signal.channels[0].unit_as_read
    native = signal.sampling.dt_s
    factor = d.get(raw, "block_average_factor", "int", "")
    if factor < 1:
        d.fail("block_average_factor", f"expected an integer >= 1, got {factor}")
    model_dt = factor * native
    try:
        check_dt_s(model_dt, "the modelling interval (block_average_factor x signal.sampling.dt_s)")
    except ConfigError as exc:
        d.fail("block_average_factor", str(exc))
    wavelet = d.get(raw, "wavelet", str, "")
    if wavelet not in wavelist():
        d.fail("wavelet", f"unknown wavelet {wavelet!r}; expected one of {wavelist()}")
    mode = d.get(raw, "mode", str, "")
    if mode not in MODES:
        d.fail("mode", f"unknown mode {mode!r}; expected one of {list(MODES)}")
    latitude = d.get(raw, "latitude_deg", "number", "", optional=True)
    if latitude is not None and not -90.0 <= latitude <= 90.0:
        d.fail("latitude_deg", f"expected a latitude in [-90, 90] deg, got {latitude!r}")
    training = d.get(raw, "training", dict, "")
    train_stop = _train_stop(training)
    settings = d.get(raw, "settings", dict, "")
    axes_raw = d.get(raw, "axes", list, "")
    if not axes_raw:
        d.fail("axes", "no axis")
    axes, seen = [], set()
    for i, ax in enumerate(axes_raw):
        w = f"axes[{i}]."
        name = d.get(ax, "name", str, w)
        if name in seen:
            d.fail(f"{w}name", f"axis {name!r} appears twice")
        seen.add(name)
        window = d.get(ax, "causal_window", "int", w)
        level = d.get(ax, "level", "int", w)
        if window < 2:
            d.fail(f"{w}causal_window", f"expected an integer >= 2, got {window}")
        if window > (train_stop or MAX_CAUSAL_WINDOW):
            limit = (f"the {train_stop}-sample training block it must warm up in" if train_stop
                     else f"{MAX_CAUSAL_WINDOW} samples")
            d.fail(f"{w}causal_window", f"expected at most {limit}, got {window}")
        if not 1 <= level <= max_level(window, wavelet, mode):
            d.fail(f"{w}level", f"level {level} is not valid for a {window}-sample window with {wavelet}")
        models_raw = d.get(ax, "models", dict, w)
        if not models_raw:
            d.fail(f"{w}models", "no model")
        models = {}
        for key, entry in models_raw.items():
            wm = f"{w}models.{key}."
            try:
                spec = model_spec(key)
            except ConfigError:
                d.fail(f"{w}models", f"unknown model {key!r}")
            rel = d.get(entry, "file", str, wm)
            if not _inside(root, rel):
                d.fail(f"{wm}file", f"{rel!r} is not a relative path inside the bundle")
            cls = d.get(entry, "class", str, wm)
            if cls != spec.cls:
                d.fail(f"{wm}class", f"{key!r} is a {spec.cls}, got {cls!r}")
            sums = d.get(entry, "sha256", dict, wm)
            base = root / rel
            for ext, f in zip(("json", "npz"), model_file_paths(base)):
                if not f.is_file():
                    raise ModelFileError(f"{f}: model file of {name}/{key} is missing")
                if sums.get(ext) != file_sha256(f):
                    raise ModelFileError(f"{f}: SHA-256 differs from the manifest; the model file was modified "
                                         "after the bundle was written")
            _check_finite_parameters(model_file_paths(base)[1], f"{name}/{key}")
            model = load_model(base)
            if type(model).__name__ != spec.cls:
                raise ModelFileError(f"{base}.json: holds a {type(model).__name__}, the manifest says {spec.cls}")
            models[spec.name] = model
        bias = d.get(ax, "bias_dph", "number", w)
        earth = d.get(ax, "earth_rate_dph", "number", w)
        for key, value in (("bias_dph", bias), ("earth_rate_dph", earth)):
            if abs(value) > MAX_ABS_RATE_DPH:
                d.fail(f"{w}{key}", f"expected |{key}| <= {MAX_ABS_RATE_DPH:g} deg/h, got {value!r}")
        axes.append(BundleAxis(
            name=name, bias_dph=bias, bias_method=d.get(ax, "bias_method", str, w),
            earth_rate_dph=earth,
            earth_orientation=ax.get("earth_orientation"), level=level, causal_window=window,
            noise_model=d.get(ax, "noise_model", dict, w), models=models,
        ))
    return Bundle(
        axes=tuple(axes), input_unit=unit, native_dt_s=native, model_dt_s=model_dt, block_average_factor=factor,
        wavelet=wavelet, mode=mode, latitude_deg=latitude, training=training, settings=settings,
        fogdrift_version=str(raw.get("fogdrift_version", "")), format_version=version,
        created_utc=str(raw.get("created_utc", "")), path=root, signal=signal,
    )


#: The largest causal window [samples] a bundle without a readable training split may hold (2^31).
MAX_CAUSAL_WINDOW = 2**31
#: The largest |bias| or |Earth rate| a bundle may hold [deg/h]: 1e9 deg/h is about 770 revolutions per
#: second, beyond any gyro's range; a larger value is damage, not a measurement.
MAX_ABS_RATE_DPH = 1e9


def _train_stop(training) -> int | None:
    """End of the training block [samples at the modelling rate] from ``training.split``, or None."""
    try:
        stop = training["split"]["train"]["samples"][1]
    except (KeyError, IndexError, TypeError):
        return None
    return stop if isinstance(stop, int) and not isinstance(stop, bool) and stop > 0 else None


def _bundle_signal(names, unit_spec, native_dt_s: float) -> SignalDescription:
    """A description made from the input unit and the native interval alone, with the sources ``"bundle"``: for a
    bundle whose training log's description is not known."""
    scale = unit_spec.scale_to_internal(native_dt_s)
    return SignalDescription(Sampling(dt_s=native_dt_s, dt_source="bundle"), tuple(
        Channel(name=n, unit=unit_spec, unit_source="bundle", declared_unit=None, scale_to_internal=scale)
        for n in dict.fromkeys(names)))


def _manifest_v2_as_v3(raw: dict, d: _Doc) -> dict:
    """A format-2 manifest (its seal already checked) in the format-3 layout: ``native_dt_s``, ``model_dt_s`` and
    their rates checked (``model_dt_s = block_average_factor x native_dt_s``, the description's interval the
    native one) and dropped, a manifest without a ``signal`` given one made from ``input_unit`` and
    ``native_dt_s``, and ``input_unit`` / ``rate_unit_internal`` checked against the channels and dropped
    (:func:`_unit_keys_dropped`).  The one place format 2 is read; everything after it reads format 3."""
    unit_spec = _input_unit_spec(raw, d)
    native = d.get(raw, "native_dt_s", "positive", "")
    model_dt = d.get(raw, "model_dt_s", "positive", "")
    for key, value in (("native_dt_s", native), ("model_dt_s", model_dt)):
        try:
            check_dt_s(value, key)
        except ConfigError as exc:
            d.fail(key, str(exc))
    factor = d.get(raw, "block_average_factor", "int", "")
    if factor < 1 or abs(factor * native - model_dt) > 1e-9 * model_dt:
        d.fail("block_average_factor", f"model_dt_s {model_dt!r} is not {factor} x native_dt_s {native!r}")
    out = {k: v for k, v in raw.items() if k not in _V2_SAMPLING_KEYS}
    if raw.get("signal") is None:
        names = raw.get("training", {}).get("axis_names") if isinstance(raw.get("training"), dict) else None
        if not (isinstance(names, list) and names and all(isinstance(n, str) for n in names)):
            names = [a.get("name") for a in raw.get("axes", []) if isinstance(a, dict) and isinstance(a.get("name"), str)]
        try:
            out["signal"] = _bundle_signal(names, unit_spec, native).to_dict()
        except ConfigError as exc:
            d.fail("axes", str(exc))
        return _unit_keys_dropped(out, d)
    smp = raw["signal"].get("sampling") if isinstance(raw["signal"], dict) else None
    dt = smp.get("dt_s") if isinstance(smp, dict) else None
    if isinstance(dt, (int, float)) and not isinstance(dt, bool) and abs(dt - native) > 1e-9 * native:
        d.fail("signal.sampling.dt_s", f"{dt!r} differs from native_dt_s {native!r}")
    return _unit_keys_dropped(out, d)


def _input_unit_spec(raw: dict, d: _Doc):
    """The manifest's ``input_unit`` parsed (a unit of any quantity: gyro deg/s, accelerometer g ...)."""
    unit = d.get(raw, "input_unit", str, "")
    try:
        return channel_unit(unit, None)
    except ConfigError:
        d.fail("input_unit", f"unknown unit {unit!r}")


def _unit_keys_dropped(raw: dict, d: _Doc) -> dict:
    """``raw`` without :data:`_UNIT_KEYS`: an ``input_unit`` beside the description is checked to be the unit as
    read of every channel of ``signal.channels`` (a disagreement refused, naming the key) and never read."""
    if "input_unit" in raw:
        spec = _input_unit_spec(raw, d)
        sig = raw.get("signal")
        chans = sig.get("channels") if isinstance(sig, dict) else None
        odd = [c.get("name") for c in (chans if isinstance(chans, list) else [])
               if isinstance(c, dict) and c.get("unit_as_read") != spec.text]
        if odd:
            d.fail("input_unit", f"{spec.text!r} is not the unit of signal.channels {odd}; the manifest contradicts "
                                 "itself: re-create the bundle")
    return {k: v for k, v in raw.items() if k not in _UNIT_KEYS}


def _signal_of(raw: dict, d: _Doc) -> SignalDescription:
    """The manifest's signal description, the one home of the training log's sampling and input unit (its channels
    in one unit)."""
    if raw.get("signal") is None:
        d.fail("signal", "missing (the training log's signal description holds the bundle's sampling and unit)")
    try:
        signal = SignalDescription.from_dict(raw["signal"])
    except ConfigError as exc:
        d.fail("signal", str(exc))
    texts = list(dict.fromkeys(c.unit_as_read for c in signal.channels))
    if len(texts) > 1:
        d.fail("signal.channels", f"the channels are in {len(texts)} units {texts}; a bundle's training log is read in "
                                  "one unit")
    return signal
