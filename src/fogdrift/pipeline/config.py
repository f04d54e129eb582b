"""The settings of an analysis (:class:`AnalysisConfig`), each checked before any data is touched, with the
option named in the message (the CLI renders ``{opt:name}`` as its flag)."""

from __future__ import annotations

import dataclasses
from dataclasses import asdict, dataclass, field

import numpy as np

from ..errors import ConfigError
from ..io.readers.limits import ENV_MEMORY, format_bytes, memory_budget
from ..lifting import MODES, get_wavelet
from ..models import MODEL_NAMES, check_model_params, model_spec
from ..models.registry import RECURRENT_WEIGHT_COPIES, recurrent_memory_need
from ..models.settings import SETTINGS as _ROW, STAGE_SETTINGS
from ..noise.terms import TERM_TABLE
from ..units import check_rate_hz, earth_rate_projection_dph

__all__ = ["AnalysisConfig", "STAGE_SETTINGS", "check_options"]


@dataclass
class AnalysisConfig:
    """Every setting of an analysis; stored in the result JSON.

    Attributes
    ----------
    model_rate_hz : float or None
        Modelling rate [Hz]: the rate is block-averaged to this before separation and drift modelling.
        ``None`` keeps the native rate. Default 1 Hz (drift lives below ~0.1 Hz).
    wavelet, level, mode
        Lifting separation: wavelet name, decomposition level (int or ``"auto"``) and boundary mode
        (``"symmetric"`` avoids joining the end of a block to its start; ``"periodization"`` is
        PyWavelets-compatible).
    train_fraction, val_fraction : float
        Chronological split; the test block is the rest.
    latitude_deg : float or None
        If given, the Earth-rate projection for each axis in ``earth_axes`` is removed before the bias.
    earth_axes : dict
        Axis name -> orientation (``"up"``, ``"north"``, … or an east-north-up vector).
    models : tuple of str
        Names from :data:`MODEL_NAMES`.
    lags, hidden, epochs, seed, activation, training
        Elman / grey-Elman hyper-parameters (``lags`` is also the AR order).
    gm_window : int
        Rolling window [samples] of the one-step GM(1,1).
    causal_window_s : float
        Length [s] of the sliding window of the causal drift used by the practical compensation.
    taus : str
        Tau grid of the Allan analyses (``"octave"``, ``"decade"``, ``"all"`` or a number of log-spaced taus).
    estimator : str
        Allan estimator (``"overlapping"``, ``"non-overlapping"`` or ``"fast"``).
    statistic : str
        Allan-family statistic of the noise analyses (``"adev"``, ``"hdev"`` or ``"mdev"``).
    terms : tuple of str or None
        ``None`` (default): the noise model is selected from the data; a tuple fixes the terms fitted.
    outliers : str
        ``"warn"`` (report samples beyond 6 robust sigma), ``"clip"`` or ``"replace"`` them before the analyses.
    fit_tau_s : tuple of (float or None, float or None)
        Tau range [s] of the noise fit (None = no limit), e.g. to leave out a vibration bump that the
        IEEE-952 model does not describe.
    noise_method : str
        ``"allan"`` (default): the noise table is the Allan fit (:mod:`fogdrift.noise`); ``"gmwm"``: also the GMWM
        model selection on the Haar wavelet variance of the native-rate record (:mod:`fogdrift.gmwm.analysis`),
        which the report shows as the noise table; the Kalman drift model then identifies its noise components
        by a GMWM fit of its training block too (:class:`fogdrift.models.kalman.Kalman` ``noise_method``).
    model_params : dict
        ``{model: {parameter: value}}``: the hyper-parameters a model row declares settable
        (:func:`fogdrift.models.declared_params`; CLI ``--param MODEL.NAME=VALUE``), each checked by the model's
        own rule; empty (default): the constructors' defaults.

    Notes
    -----
    The declared settings (:data:`fogdrift.models.settings.STAGE_SETTINGS`) take their default and rule from one declaration each, which
    also makes their CLI options: the Allan stage's ``estimator``, ``statistic``, ``taus``, ``fit_tau_s``
    (:data:`fogdrift.allan.settings.ALLAN_SETTINGS`); ``outliers`` (:data:`fogdrift.outliers.OUTLIERS_SETTING`); the
    modelling stage's ``hidden``, ``lags``, ``epochs``, ``seed``, ``training``, ``train_fraction``,
    ``val_fraction``, ``causal_window_s``, ``gm_window`` (:data:`fogdrift.models.settings.MODEL_SETTINGS`).
    """

    model_rate_hz: float | None = 1.0
    wavelet: str = "db2"
    level: int | str = 4
    mode: str = "symmetric"
    train_fraction: float = _ROW["train_fraction"].default
    val_fraction: float = _ROW["val_fraction"].default
    latitude_deg: float | None = None
    earth_axes: dict = field(default_factory=dict)
    models: tuple = MODEL_NAMES
    lags: int = _ROW["lags"].default
    hidden: int = _ROW["hidden"].default
    epochs: int = _ROW["epochs"].default
    seed: int = _ROW["seed"].default
    activation: str = "tanh"
    training: str = _ROW["training"].default
    gm_window: int = _ROW["gm_window"].default
    causal_window_s: float = _ROW["causal_window_s"].default
    taus: str = _ROW["taus"].default
    estimator: str = _ROW["estimator"].default
    statistic: str = _ROW["statistic"].default
    terms: tuple | None = None
    fit_tau_s: tuple = _ROW["fit_tau_s"].default
    outliers: str = _ROW["outliers"].default
    noise_method: str = "allan"
    model_params: dict = field(default_factory=dict)

    def validate(self) -> "AnalysisConfig":
        """Check every setting; return the config with canonical model names (``self`` is never modified).

        The one validation point of the settings: the CLI builds a config and calls this before reading
        the file; nothing re-checks these settings elsewhere.

        Returns
        -------
        AnalysisConfig
            ``self`` when the model names are already the registry's, else a copy with them canonical
            (``"AR"`` -> ``"ar"``), duplicates dropped.

        Raises
        ------
        ConfigError
            The first invalid setting, named as ``{opt:NAME}``, with the rule and the value.
        """
        for s in STAGE_SETTINGS:  # each setting's own rule, from its one declaration
            s.rule.check(s.name, getattr(self, s.name))
        if self.train_fraction + self.val_fraction >= 1:
            raise ConfigError(
                f"the training and validation shares ({{opt:train_fraction}} + {{opt:val_fraction}}) must leave a "
                f"test block; got {self.train_fraction + self.val_fraction:.3g} >= 1"
            )

        if not self.models:
            raise ConfigError(f"no drift model given; pass {{opt:models}} with one or more of {list(MODEL_NAMES)}")
        # canonical registry names (any case accepted); an unknown name is an error, never a fallback
        models = tuple(dict.fromkeys(model_spec(m).name for m in self.models))

        if self.noise_method not in ("allan", "gmwm"):
            raise ConfigError(f"noise_method must be 'allan' or 'gmwm', got {self.noise_method!r} ({{opt:noise_method}})")
        if self.model_rate_hz is not None and (isinstance(self.model_rate_hz, bool) or not _finite_number(
                self.model_rate_hz) or not self.model_rate_hz > 0):
            raise ConfigError(f"the modelling rate ({{opt:model_rate_hz}}) must be > 0 Hz; got {self.model_rate_hz!r}")
        if self.model_rate_hz is not None:
            check_rate_hz(self.model_rate_hz, "the modelling rate ({opt:model_rate_hz})")
        if any(("hidden", "hidden") in model_spec(m).settings for m in self.models):
            need, budget = recurrent_memory_need(self.hidden, self.lags), memory_budget()
            if budget is not None and need > budget:
                raise ConfigError(f"{{opt:hidden}} {self.hidden}: the recurrent network's weights need about "
                                  f"{format_bytes(need)} while training ({self.hidden}^2 recurrent weights, float32, "
                                  f"x {RECURRENT_WEIGHT_COPIES} copies); expected at most the memory budget "
                                  f"{format_bytes(budget)} ({ENV_MEMORY}); choose a smaller {{opt:hidden}}")

        if self.latitude_deg is not None and not (_finite_number(self.latitude_deg)
                                                  and -90.0 <= float(self.latitude_deg) <= 90.0):
            raise ConfigError(f"latitude must be in [-90, 90] deg; got {self.latitude_deg!r} (option {{opt:latitude_deg}})")
        if self.latitude_deg is not None and not self.earth_axes:
            raise ConfigError("a latitude was given without the axis it applies to; pass {opt:earth_axes} AXIS=up|down|"
                              "north|south|east|west (the Earth-rate component depends on the axis orientation)")
        if not isinstance(self.earth_axes, dict):
            raise ConfigError(f"{{opt:earth_axes}} must map axis names to orientations; got {self.earth_axes!r}")
        if self.earth_axes and self.latitude_deg is None:
            raise ConfigError("an Earth-rate axis orientation ({opt:earth_axes}) was given without a latitude; pass "
                              "{opt:latitude_deg} DEG")
        if self.latitude_deg is not None:
            for orient in self.earth_axes.values():
                earth_rate_projection_dph(self.latitude_deg, orient)  # refuses an unknown orientation
        # activation: checked by the Elman models when built (reading their table here would import JAX)
        check_options(wavelet=self.wavelet, mode=self.mode, training=self.training, estimator=self.estimator,
                      terms=self.terms)
        if not (self.level == "auto" or (isinstance(self.level, (int, np.integer)) and not isinstance(self.level, bool)
                                         and self.level >= 1)):
            raise ConfigError(f"{{opt:level}} must be an integer >= 1 or 'auto', got {self.level!r}")
        model_params = check_model_params(self.model_params, models)
        if models == tuple(self.models) and model_params == self.model_params:
            return self
        return dataclasses.replace(self, models=models, model_params=model_params)

    def to_dict(self) -> dict:
        d = asdict(self)
        if not d["model_params"]:  # the default: results written before the field existed read the same
            del d["model_params"]
        d["models"] = list(self.models)
        d["terms"] = None if self.terms is None else list(self.terms)
        d["fit_tau_s"] = list(self.fit_tau_s)
        return d


def _finite_number(x) -> bool:
    try:
        return not isinstance(x, bool) and np.isfinite(float(x))
    except (TypeError, ValueError, OverflowError):
        return False


def check_options(*, wavelet=None, mode=None, training=None, estimator=None, terms=None) -> None:
    """Refuse a bad value of any of these settings (None: not checked), with the messages the CLI shows.

    Used by :meth:`AnalysisConfig.validate` and by commands that take some of these options without a full
    analysis configuration.
    """
    if wavelet is not None:
        get_wavelet(wavelet)
    if mode is not None:
        if mode not in MODES:
            raise ConfigError(f"{{opt:mode}} must be one of {list(MODES)}; got {mode!r}")
    for name, value in (("training", training), ("estimator", estimator)):
        if value is not None:
            _ROW[name].rule.check(name, value)
    if terms is not None:
        bad = [t for t in terms if t not in TERM_TABLE]
        if bad or not terms:
            raise ConfigError(f"{{opt:terms}} must list noise terms among Q, N, B, K, R; got {','.join(terms)!r}")
