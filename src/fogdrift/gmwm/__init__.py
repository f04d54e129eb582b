"""GMWM: Haar wavelet variance, latent gyro error processes and the Generalized Method of Wavelet Moments.

Modules (one concept each):

* :mod:`~fogdrift.gmwm.wvar` - Haar MODWT wavelet variance (classical and robust), eta3 CIs,
  published curves (:func:`from_curve`).
* :mod:`~fogdrift.gmwm.processes` - the latent processes (WN, QN, RW, DR, FLICKER, GM) as a
  registry: theoretical WV, SDF, IEEE mapping; composite models (:func:`parse_model`).
* :mod:`~fogdrift.gmwm.covariance` - model-based covariance of WV estimates (that of Allan-family
  estimates is :mod:`fogdrift.noise.covariance`).
* :mod:`~fogdrift.gmwm.estimator` - the GMWM fit (:func:`gmwm_fit`, :class:`GMWM`).
* :mod:`~fogdrift.gmwm.selection` - WIC model selection with sanity checks and automatic
  exclusion of short scales no candidate explains.
* :mod:`~fogdrift.gmwm.ieee` - IEEE-952 quantities (N, K, R, Q, B, GM T_c / sigma) with CIs.
* :mod:`~fogdrift.gmwm.simulate` - simulator of the latent processes.
* :mod:`~fogdrift.gmwm.analysis` - one axis end to end (log or published curve), as the CLI and
  the pipeline use it.

Units: rates in deg/h (so WVs in (deg/h)^2), time and scales in s.

Examples
--------
>>> from fogdrift.gmwm import haar_wvar, simulate_latent, select_model
>>> x = simulate_latent("WN+RW", [1.0, 1e-5], 2**15, seed=2)        # deg/h, per sample
>>> sel = select_model(haar_wvar(x, 0.01), ["WN", "WN+RW", "WN+GM"])
>>> sel.selected, round(sel.ieee.terms["N_dprh"].value * 60 / 0.1, 1)   # N = sqrt(sigma2 dt) / 60
('WN+RW', 1.0)
"""

from .covariance import filter_gram, model_wvar_covariance, wvar_covariance
from .estimator import GMWM, GMWMFit, gmwm_fit
from .ieee import BiasInstability, IEEEResult, IEEEValue, to_ieee
from .processes import PROCESSES, LatentModel, Process, ar1_wv, flicker_wv_factor, parse_model
from .selection import DEFAULT_CANDIDATES, CandidateScore, ExcludedScale, SelectionResult, select_model
from .simulate import simulate_latent
from .wvar import WvarResult, from_curve, haar_wvar

__all__ = [
    "WvarResult", "haar_wvar", "from_curve",
    "Process", "PROCESSES", "LatentModel", "parse_model", "ar1_wv", "flicker_wv_factor",
    "filter_gram", "wvar_covariance", "model_wvar_covariance",
    "GMWM", "GMWMFit", "gmwm_fit",
    "DEFAULT_CANDIDATES", "CandidateScore", "ExcludedScale", "SelectionResult", "select_model",
    "IEEEValue", "BiasInstability", "IEEEResult", "to_ieee",
    "simulate_latent",
]
