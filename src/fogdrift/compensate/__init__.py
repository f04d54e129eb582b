"""Apply a model bundle to a new log, causally and in bounded memory (``fogdrift compensate``).

Modules: :mod:`fogdrift.models.causal_predictor` (a fitted model as a causal one-step drift estimator; re-exported
by :mod:`.predictors` for old imports), :mod:`.engine` (the streaming
compensator and its native-rate design), :mod:`.sources` (chunked reading; matching unit, rate and axes to the
bundle), :mod:`.outputs` (streamed CSV/NPZ, the before/after Allan figure), :mod:`.run` (:func:`compensate_file`),
:mod:`.holdout` (the compensated held-out test block ``fogdrift analyze`` writes; named so that pytest does not
collect it).
"""

from .engine import AxisPlan, OutputBlock, StreamCompensator, segment_blocks
from ..models.causal_predictor import CausalPredictor, causal_weights, history_length
from .run import CompensationResult, compensate_file, default_model, parse_bias
from .sources import LogMatch, LogSource, match_log, open_log

__all__ = [
    "compensate_file",
    "CompensationResult",
    "parse_bias",
    "default_model",
    "StreamCompensator",
    "AxisPlan",
    "OutputBlock",
    "segment_blocks",
    "CausalPredictor",
    "causal_weights",
    "history_length",
    "open_log",
    "match_log",
    "LogSource",
    "LogMatch",
]
