"""The drift-model registry: one table from a model name to its lazily imported class.

Every drift model fogdrift knows is one row of :data:`MODELS`: the name used on the command line
and in :class:`~fogdrift.pipeline.AnalysisConfig` ``models``, the module and class (strings, so
nothing is imported until a model is used), the display label, a one-line description for CLI
help, and which attributes of the analysis settings become which constructor keywords. The
same rows serve :func:`build_model` (name -> unfitted model), :func:`~fogdrift.models.load_model`
(class name in a model file -> class) and the CLI help (:func:`describe_models`). The row order
is the report order.

Adding a model is one new module (a :class:`~fogdrift.models.DriftModel` subclass) plus one row
here; the contract tests (``tests/models/test_model_contract.py``) then run over it. A hyper-parameter users may set
is one :class:`ModelParam` in the row's ``params``: it becomes ``--param MODEL.NAME=VALUE`` on ``analyze`` and
``model``, ``AnalysisConfig.model_params`` in the library and fleets, with the constructor's default and the
model's own ``_validate`` as its rule (nothing else to edit). This module imports nothing from the model
modules and nothing heavy (no NumPy, no JAX).
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from dataclasses import dataclass

from ..errors import ConfigError

__all__ = [
    "ModelSpec",
    "ModelParam",
    "declared_params",
    "parse_model_params",
    "check_model_params",
    "describe_params",
    "MODELS",
    "MODEL_NAMES",
    "model_spec",
    "model_class",
    "build_model",
    "describe_models",
    "class_for_file",
    "file_class_names",
    "RECURRENT_WEIGHT_COPIES",
    "recurrent_memory_need",
]


@dataclass(frozen=True)
class ModelParam:
    """A hyper-parameter of a model that users may set, declared once.

    Its default is the model constructor's, its rule the model's own ``_validate`` (called on the value before
    any data is read); the declaration adds only how a command-line value is read and one line of help.

    Attributes
    ----------
    name : str
        The constructor keyword.
    kind : type
        ``int``, ``float`` or ``str``: how ``--param MODEL.NAME=VALUE`` reads VALUE.
    help : str
        One line for CLI help, with its unit.
    """

    name: str
    kind: type
    help: str


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
    params : tuple of ModelParam
        Hyper-parameters users may set by name (:func:`parse_model_params`, ``AnalysisConfig.model_params``).
    inputs : tuple of str
        Constructor keywords the caller supplies at run time, not from the settings: ``"dt_s"`` (the sample
        interval at the modelling rate, for a model that works in seconds; :func:`build_model` takes it in
        ``inputs=``) and ``"progress"`` (the per-epoch callback of a model that trains; ``progress=``).  A model
        is given only what its row declares.
    """

    name: str
    module: str
    cls: str
    label: str
    description: str
    settings: tuple = ()
    fixed: tuple = ()
    params: tuple = ()
    inputs: tuple = ()

    def load(self) -> type:
        """Import ``module`` and return the class (later calls hit the import cache)."""
        return getattr(importlib.import_module(self.module), self.cls)


#: float32 copies of a recurrent network's weights while it trains: the weights, their gradient, Adam's two moments,
#: the best-so-far snapshot of early stopping and one update temporary.
RECURRENT_WEIGHT_COPIES = 6


def recurrent_memory_need(n_hidden: int, n_inputs: int) -> int:
    """Bytes the weights of an Elman network with ``n_hidden`` hidden units and ``n_inputs`` inputs take while
    training: ``(h^2 + h n_in + 2 h + 1)`` float32 weights x :data:`RECURRENT_WEIGHT_COPIES` (activations aside).

    >>> recurrent_memory_need(16, 8)  # 4 bytes x 6 copies x (256 + 128 + 32 + 1)
    10008
    """
    h, i = int(n_hidden), int(n_inputs)
    return 4 * RECURRENT_WEIGHT_COPIES * (h * h + h * i + 2 * h + 1)


_RECURRENT = (("lags", "lags"), ("hidden", "hidden"), ("activation", "activation"), ("training", "training"),
              ("epochs", "epochs"), ("seed", "seed"))
#: The recurrent rows report their training epochs to the caller's progress callback.
_RECURRENT_INPUTS = ("progress",)
_RECURRENT_PARAMS = (
    ModelParam("patience", int, "early stopping: epochs without a better validation loss before training stops"),
    ModelParam("learning_rate", float, "step size of the optimiser (default: the training scheme's own)"),
    ModelParam("weight_decay", float, "L2 penalty on the weights (AdamW), >= 0"),
    ModelParam("window", int, "truncated-BPTT window [samples]"),
)

#: The registry, in report order.
MODELS: tuple[ModelSpec, ...] = (
    ModelSpec("grey-elman", "fogdrift.models.elman", "GreyElman", "grey-Elman",
              "Elman network on the AGO of the drift, restored by IAGO (Tang et al. 2012)", _RECURRENT,
              params=_RECURRENT_PARAMS, inputs=_RECURRENT_INPUTS),
    ModelSpec("elman", "fogdrift.models.elman", "Elman", "Elman",
              "Elman recurrent network on the last `lags` drift samples", _RECURRENT, params=_RECURRENT_PARAMS,
              inputs=_RECURRENT_INPUTS),
    ModelSpec("gm11", "fogdrift.models.grey", "GM11", "GM(1,1)",
              "rolling GM(1,1) grey model over the last `gm_window` samples", (("window", "gm_window"),),
              (("mode", "rolling"),),
              params=(ModelParam("shift_margin", float, "margin [x the series' spread] of the automatic shift "
                                 "that keeps the accumulated series positive"),)),
    ModelSpec("ar", "fogdrift.models.ar", "AR", "AR(p)",
              "least-squares AR(p) with intercept, p = `lags`", (("order", "lags"),)),
    ModelSpec("kalman", "fogdrift.models.kalman", "Kalman", "Kalman",
              "Kalman filter on the rate from the training block's noise model (bias, random walk, Gauss-Markov)",
              settings=(("noise_method", "noise_method"),), inputs=("dt_s",)),
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


def declared_params() -> list[tuple[str, ModelParam]]:
    """``[(model name, ModelParam), ...]`` of every row, in registry order."""
    return [(spec.name, p) for spec in MODELS for p in spec.params]


def describe_params() -> str:
    """The settable hyper-parameters in one line for CLI help, models sharing a declaration named together.

    Examples
    --------
    >>> print(describe_params().split("; ")[-1])  # doctest: +ELLIPSIS
    gm11.shift_margin (float): margin [x the series' spread] of the automatic shift ...
    """
    groups: dict = {}
    for model, p in declared_params():
        groups.setdefault(p, []).append(model)
    return "; ".join(f"{'|'.join(models)}.{p.name} ({p.kind.__name__}): {p.help}" for p, models in groups.items())


def _param(model: str, name: str) -> tuple[ModelSpec, ModelParam]:
    spec = model_spec(model)
    for p in spec.params:
        if p.name == name:
            return spec, p
    known = ", ".join(f"{m}.{q.name}" for m, q in declared_params()) or "none"
    raise ConfigError(f"{{opt:model_params}} {model}.{name}: {spec.name} declares no such parameter; "
                      f"settable: {known}")


def parse_model_params(assignments) -> dict:
    """``["gm11.shift_margin=2", ...]`` (``--param``) as ``{"gm11": {"shift_margin": 2.0}}``, each VALUE read by
    its declaration's kind; unchecked otherwise (:func:`check_model_params` applies the models' rules).

    Examples
    --------
    >>> parse_model_params(["gm11.shift_margin=2", "elman.patience=50"])
    {'gm11': {'shift_margin': 2.0}, 'elman': {'patience': 50}}
    >>> parse_model_params(["elman.patience=5.5"])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fogdrift.errors.ConfigError: model_params= elman.patience=5.5: expected an integer; got '5.5'
    """
    out: dict = {}
    for text in assignments or ():
        key, eq, value = str(text).partition("=")
        model, dot, name = key.strip().partition(".")
        if not (eq and dot and model and name):
            raise ConfigError(f"{{opt:model_params}} {text!r}: expected MODEL.NAME=VALUE, e.g. gm11.shift_margin=2")
        spec, p = _param(model, name.strip())
        raw = value.strip()
        try:
            val = p.kind(raw)
        except ValueError:
            what = {int: "an integer", float: "a number"}.get(p.kind, p.kind.__name__)
            raise ConfigError(f"{{opt:model_params}} {spec.name}.{p.name}={raw}: expected {what}; got {raw!r}") \
                from None
        out.setdefault(spec.name, {})[p.name] = val
    return out


def check_model_params(model_params, models=None) -> dict:
    """``{model: {name: value}}`` with canonical model names, every parameter declared, of its kind and accepted
    by the model's own ``_validate`` (the model is built with it, nothing fitted); ``models``: the models run,
    when given a parameter of another model is refused (it would silently do nothing).

    Raises
    ------
    ConfigError
        An unknown model or parameter, a value of the wrong kind, a value the model's rule refuses.
    """
    if model_params is None:
        return {}
    if not isinstance(model_params, Mapping):
        raise ConfigError(f"{{opt:model_params}} must map model names to {{parameter: value}}; got {model_params!r}")
    run = None if models is None else {model_spec(m).name for m in models}
    out: dict = {}
    for model, values in model_params.items():
        if not isinstance(values, Mapping):
            raise ConfigError(f"{{opt:model_params}} {model!r} must map parameter names to values; got {values!r}")
        for name, value in values.items():
            spec, p = _param(model, str(name))
            if run is not None and spec.name not in run:
                raise ConfigError(f"{{opt:model_params}} {spec.name}.{p.name} is set but {spec.name} is not among "
                                  f"the models run ({{opt:models}}: {', '.join(sorted(run))})")
            ok = (isinstance(value, p.kind) or (p.kind is float and isinstance(value, int))) \
                and not isinstance(value, bool)
            if not ok:
                raise ConfigError(f"{{opt:model_params}} {spec.name}.{p.name} must be {p.kind.__name__}; got {value!r}")
            value = p.kind(value)
            try:
                spec.load()(**{p.name: value})._validate()
            except ConfigError as exc:
                raise ConfigError(f"{{opt:model_params}} {spec.name}.{p.name}={value!r}: {exc}") from None
            out.setdefault(spec.name, {})[p.name] = value
    return out


def build_model(name: str, settings=None, progress=None, *, inputs=None):
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
        ``progress(epoch, n_epochs, train_loss, val_loss)``, passed to the models whose row declares it
        (``ModelSpec.inputs``: the recurrent ones); ignored by the others.
    inputs : mapping, optional
        Values from the data (``{"dt_s": 1.0}``); a model receives those its row declares (``ModelSpec.inputs``),
        the others are not passed.

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
    >>> build_model("kalman", {"noise_method": "gmwm"}, inputs={"dt_s": 0.5}).get_params()["dt_s"]
    0.5
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
    if settings is not None:
        mp = settings.get("model_params") if isinstance(settings, Mapping) else getattr(settings, "model_params", None)
        kwargs.update((mp or {}).get(spec.name, {}))
    given = {**(inputs or {}), **({} if progress is None else {"progress": progress})}
    kwargs.update({k: v for k, v in given.items() if k in spec.inputs})
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
