"""Moved to :mod:`fogdrift.models.causal_predictor` (a fitted model as a causal one-step drift estimator, below
both ``compensate`` and ``evaluation``); this name re-exports it until ``evaluation.heading``/``artefacts`` import
it from there (then the compensate <-> evaluation import cycle is gone and this module can go)."""

from ..models.causal_predictor import RECURRENT_HISTORY, CausalPredictor, causal_weights, history_length

__all__ = ["causal_weights", "history_length", "CausalPredictor", "RECURRENT_HISTORY"]
