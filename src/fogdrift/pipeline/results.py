"""The result dataclasses of :mod:`fogdrift.pipeline`: what each stage returns, complete when built.

``run_allan`` returns :class:`AllanAxis` objects, ``run_separation`` :class:`SeparationAxis`, ``run_models``
:class:`ModelAxis`, ``run_analysis`` an :class:`AnalysisResult` of :class:`AnalysisAxis`.  Every field is
set when the object is constructed (nothing is patched afterwards) and typed with the class it holds.  The
facts a later stage needs are stored where the pipeline decides them: :attr:`ModelAxis.level`,
:attr:`ModelAxis.causal_window` and :attr:`ModelAxis.block_average_factor` are read back by the bundle, the
evaluation and the reports.  Import them from :mod:`fogdrift.pipeline` (re-exported there).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ..units import name_keys

if TYPE_CHECKING:  # result types of other stages, for the annotations only (no import at run time)
    from ..allan import AllanResult
    from ..evaluation import AxisEvaluation
    from ..gmwm.analysis import GmwmAxis
    from ..noise import NoiseFit
    from ..outliers import OutlierReport
    from .config import AnalysisConfig

__all__ = ["AllanAxis", "SeparationAxis", "ModelAxis", "CompensatedSignal", "AxisSpectrum", "AnalysisAxis",
           "AnalysisResult"]



@dataclass
class AllanAxis:
    """Allan analysis of one axis. ``allan`` is an AllanResult, ``noise`` a NoiseFit, ``outliers`` an
    OutlierReport of the rate that was analysed (None when not checked)."""

    name: str
    allan: AllanResult
    noise: NoiseFit
    outliers: OutlierReport | None = None
    #: The record screen of this axis (:meth:`fogdrift.screen.ScreenResult.to_dict` with the segments fitted), when
    #: one was made.
    screen: dict | None = None
    #: The noise fit of the whole record when ``noise`` is the fit of the quiet segments (``--segments auto`` on a
    #: disturbed axis, or explicit ranges): what ``--segments whole`` would have given.  None otherwise.
    whole_noise: NoiseFit | None = None

    def to_dict(self) -> dict:
        out = {"name": self.name, "allan": self.allan.to_dict(self.noise.quantity), "noise": self.noise.to_dict(),
               "outliers": None if self.outliers is None else name_keys(self.outliers.to_dict(), self.noise.quantity)}
        if self.screen is not None:
            out["screen"] = self.screen
        if self.whole_noise is not None:
            out["whole_record_noise"] = self.whole_noise.to_dict()
        return out


@dataclass
class SeparationAxis:
    """Lifting separation of one axis at the modelling rate.

    ``rate_dph`` is the (bias-removed) rate, ``drift_dph + noise_dph == rate_dph``; each of ``rows`` is
    ``(label, AllanAxis)`` for original / drift / noise.  ``mean_removed_dph`` is the mean that
    :func:`run_separation` subtracted before separating (None when the caller removed a bias itself).
    """

    name: str
    dt_s: float
    level: int
    rate_dph: np.ndarray
    drift_dph: np.ndarray
    noise_dph: np.ndarray
    rows: list
    level_scan: list | None = None
    mean_removed_dph: float | None = None

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "dt_s": self.dt_s,
            "level": self.level,
            "mean_removed_dph": self.mean_removed_dph,
            "n_samples": int(self.rate_dph.size),
            "max_abs_reconstruction_error_dph": float(np.max(np.abs(self.drift_dph + self.noise_dph - self.rate_dph))),
            "rows": [{"label": label, **row.to_dict()} for label, row in self.rows],
            "level_scan": None if self.level_scan is None else [_plain(d) for d in self.level_scan],
        }


@dataclass
class CompensatedSignal:
    """A compensated signal on the test block and its Allan analysis.

    ``kind`` is ``"reference"`` (uncompensated), ``"paper"`` (drift residual: wavelet drift minus the one-step
    predicted drift, as in the paper's Table 2) or ``"practical"`` (output minus a causal one-step drift
    prediction).
    """

    label: str
    kind: str
    model: str | None
    signal_dph: np.ndarray
    analysis: AllanAxis

    def to_dict(self) -> dict:
        return {"label": self.label, "kind": self.kind, "model": self.model, **self.analysis.to_dict()}


@dataclass
class ModelAxis:
    """Drift models of one axis: split, drift per block, predictions and metrics on the test block.

    ``level`` (the lifting level), ``causal_window`` (samples at the modelling rate of the causal drift) and
    ``block_average_factor`` (native samples per modelling sample) are decided once, by the pipeline, and
    stored here: the bundle, the evaluation and the reports read them back and never recompute them.
    """

    name: str
    dt_s: float
    split: dict
    bias_dph: float
    earth_rate_dph: float
    rate_dph: np.ndarray  # bias-removed rate at the modelling rate (whole record)
    drift_blocks: dict  # "train"/"val"/"test" -> drift separated inside that block
    causal_drift_dph: np.ndarray  # causal (real-time) drift of the whole record, NaN during warm-up
    predictions: dict  # model label -> one-step predictions of the test-block drift (paper target)
    causal_predictions: dict  # model label -> one-step predictions from the causal drift (test block)
    metrics: dict  # model label -> MetricsResult (paper target), scored from test index `score_from`
    causal_metrics: dict  # model label -> MetricsResult (causal target)
    p0_as_measured: dict  # model label -> (p0 model, p0 persistence) with bias + Earth rate added back [%]
    fitted: dict  # model label -> fitted DriftModel
    fit_seconds: dict
    level: int  # lifting level of the drift separation (resolved when the config says "auto")
    causal_window: int  # window [samples at the modelling rate] of the causal drift, warm-up inside training
    notes: list = field(default_factory=list)  # distinct warnings raised while evaluating
    score_from: int = 0  # first test-block index that the metrics and Table 2 score
    block_average_factor: int = 1  # native samples per modelling sample (decided once, see model_factor)

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "dt_s": self.dt_s,
            "level": self.level,
            "causal_window": self.causal_window,
            "causal_window_s": self.causal_window * self.dt_s,
            "block_average_factor": self.block_average_factor,
            "split": self.split,
            "bias_dph": self.bias_dph,
            "earth_rate_dph": self.earth_rate_dph,
            "metrics_paper_target": {k: v.to_dict() for k, v in self.metrics.items()},
            "metrics_causal_target": {k: v.to_dict() for k, v in self.causal_metrics.items()},
            "p0_as_measured_pct": {k: {"model": _f(a), "persistence": _f(b)} for k, (a, b) in self.p0_as_measured.items()},
            "fit_seconds": self.fit_seconds,
            "notes": self.notes,
            "score_from_test_index": self.score_from,
            "model_params": {k: _plain(m.get_params(serialisable=True)) for k, m in self.fitted.items()},
        }


@dataclass(frozen=True)
class AxisSpectrum:
    """The Welch PSD of one axis's rate as analysed (native rate, whole record;
    :func:`fogdrift.noise.spectral.welch_psd`): what the report draws as Fig. 2.  Not part of the JSON."""

    f_hz: np.ndarray
    psd: np.ndarray  # one-sided [(unit)^2/Hz]
    unit: str  # the channel's internal unit (fogdrift.units.INTERNAL_UNITS): "deg/h" or "m/s^2"


@dataclass
class AnalysisAxis:
    """Everything :func:`run_analysis` finds for one axis."""

    name: str
    original: AllanAxis  # native rate, whole record
    separation: SeparationAxis  # whole record at the modelling rate (figures 5, 6)
    models: ModelAxis
    table2: list  # CompensatedSignal rows, test block at the modelling rate
    evaluation: AxisEvaluation | None = None  # compensation evidence (fogdrift.evaluation.evaluated_analysis)
    gmwm: GmwmAxis | None = None  # GMWM noise model of the native-rate record (noise_method "gmwm")
    spectrum: AxisSpectrum | None = field(default=None, repr=False, compare=False)  # not in to_dict

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "original": self.original.to_dict(),
            "gmwm": None if self.gmwm is None else self.gmwm.to_dict(),
            "separation": self.separation.to_dict(),
            "models": self.models.to_dict(),
            "table2": [row.to_dict() for row in self.table2],
            "evaluation": None if self.evaluation is None else self.evaluation.to_dict(),
        }


@dataclass
class AnalysisResult:
    """Result of :func:`run_analysis` (JSON via :meth:`to_dict`)."""

    config: AnalysisConfig
    source: str
    sha256: str
    record: dict
    axes: list
    versions: dict
    wall_s: float
    model_record: dict = field(default_factory=dict)  # the record at the modelling rate (effective rate, factor)
    apply_to: "AnalysisResult | None" = None
    applied: bool = False  # True when these axes were modelled by another recording's fitted models

    def to_dict(self) -> dict:
        return {
            "fogdrift_result": "analysis",
            "source": self.source,
            "sha256": self.sha256,
            "applied_models_from_other_recording": self.applied,
            "config": self.config.to_dict(),
            "record": self.record,
            "model_record": self.model_record,
            "versions": self.versions,
            "wall_s": self.wall_s,
            "axes": [a.to_dict() for a in self.axes],
            "apply_to": None if self.apply_to is None else self.apply_to.to_dict(),
        }




def _f(x):
    x = float(x)
    return x if np.isfinite(x) else None


def _plain(obj):
    """JSON-able copy of a dataclass/dict/array tree."""
    if hasattr(obj, "to_dict"):
        return obj.to_dict()
    if hasattr(obj, "__dataclass_fields__"):
        return _plain(asdict(obj))
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if isinstance(obj, (np.floating, float)):
        return _f(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    return obj
