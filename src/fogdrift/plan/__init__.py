"""``fogdrift plan``: how long must a record be for the Allan fit and the GMWM to resolve each noise term and to
reach a stated interval width.

:mod:`.model` (the model, targets and lengths, parsed), :mod:`.analytic` (expected widths from the Allan fit's own
covariance laws), :mod:`.montecarlo` (simulated records through the real fit), :mod:`.gmwm` (the same for the
GMWM of the model's latent processes), :mod:`.core` (the plan).
:mod:`.fleet` (how many units of a type to record for its spread and mean, a batch fleet table as the pilot).
"""

from .core import MAX_LENGTH_S, Plan, make_plan
from .model import (DEFAULT_TARGETS, PlanModel, fmt_length, model_from_fit, parse_length, parse_model,
                    parse_targets, read_model_file)

__all__ = ["make_plan", "Plan", "PlanModel", "parse_model", "parse_targets", "parse_length", "model_from_fit",
           "read_model_file", "fmt_length", "DEFAULT_TARGETS", "MAX_LENGTH_S"]
