"""Kalman-filter drift compensator built from an identified noise model (:class:`Kalman`).

Unlike the other drift models, which forecast a separated *drift* series, this one runs on the
gyro **rate** itself (``input_kind = "rate"``): the state-space model of
:mod:`fogdrift.models.statespace` (random-constant bias, rate random walk, Gauss-Markov terms,
ramp, white measurement noise) is filtered causally, and the drift estimate is the one-step
prediction H x_{k|k-1}.  This is the field's standard way to use a noise model; the paper's
models are judged beside it.

The noise model is either given (``components``, e.g. from a GMWM fit: white noise, random walk,
Gauss-Markov (T_c, sigma)) or identified in :meth:`Kalman.fit` from the **training block only**, so it
never sees validation or test data (method notes §5.1), by one of two methods (``noise_method``):

* ``"allan"`` (default): the Allan variance of the training block (:func:`fogdrift.allan.allan_variance` +
  :func:`fogdrift.noise.fit_noise`, then :func:`~fogdrift.models.statespace.components_from_allan`);
  :func:`identify_components`;
* ``"gmwm"``: the GMWM model selection on the Haar wavelet variance of the training block
  (:func:`fogdrift.gmwm.analysis.analyse_gmwm`, default candidates), its processes mapped to components by
  :func:`fogdrift.models.components.components_from_gmwm` (WN, QN, RW, each GM, flicker as GM terms; a
  drift DR as the random walk with its Allan variance at the longest scale, as the Allan route does);
  :func:`identify_components_gmwm`.  A block of fewer than :data:`GMWM_MIN_SAMPLES` samples is refused
  with one line.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from .._util import check_series
from ..allan import allan_variance
from ..errors import ConfigError, FogdriftError, FogdriftWarning, InsufficientDataError
from ..gmwm.analysis import analyse_gmwm
from ..noise import fit_noise
from ..noise.terms import TERMS
from .base import DriftModel
from .components import components_from_gmwm
from .statespace import (
    check_components,
    components_from_allan,
    forecast_uncertainty,
    kalman_filter,
    state_space,
)

__all__ = ["Kalman", "identify_components", "identify_components_gmwm", "NOISE_METHODS", "GMWM_MIN_SAMPLES"]

#: How :class:`Kalman` identifies its noise model from the training block when no ``components`` are given.
NOISE_METHODS = ("allan", "gmwm")

#: Fewest training samples a GMWM identification takes: 2^7, i.e. J = 6 Haar scales (a white + Gauss-Markov
#: model, 3 parameters, keeps 3 degrees of freedom for the WIC and the sanity checks).
GMWM_MIN_SAMPLES = 128


def identify_components(y, dt_s: float, *, terms=TERMS) -> tuple[list[dict], dict]:
    """Noise components of a rate series [deg/h] from its Allan variance (training block only).

    Returns ``(components, info)``; ``info`` holds the Allan coefficients ``A`` ((deg/h)^2, s),
    the fitted tau range and ``method``.  When the series is too short for an Allan fit (or the
    fit finds no white noise), white noise of variance var(diff(y))/2 per sample is used
    (``method = "difference-variance"``) and a :class:`~fogdrift.errors.FogdriftWarning` says so.

    Examples
    --------
    White noise of 6 deg/h per 1-s sample: the measurement variance of the resulting model is 36
    (deg/h)^2, whether the fit calls it N or splits it between N and Q (at tau >= dt they look alike):

    >>> y = np.random.default_rng(0).normal(0.0, 6.0, 20000)
    >>> comps, info = identify_components(y, 1.0)
    >>> r = state_space(comps, dt_s=1.0, bias_prior_dph=60.0).r
    >>> abs(r / 36.0 - 1) < 0.05, info["method"]
    (True, 'allan')
    """

    info = {"method": "allan", "A": None, "tau_range_s": None, "reason": ""}
    comps: list[dict] = []
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FogdriftWarning)
            fit = fit_noise(allan_variance(y, dt_s, taus="octave"))
        A = np.clip(np.asarray(fit.A, dtype=np.float64), 0.0, None)
        info["A"] = [float(a) for a in A]
        info["tau_range_s"] = [float(fit.tau_min_s), float(fit.tau_max_s)]
        comps = components_from_allan(A, tau_range_s=(fit.tau_min_s, fit.tau_max_s), terms=terms)
    except FogdriftError as exc:  # too short for a fit: fall back below
        info["reason"] = str(exc)
    if not any(c["kind"] in ("white", "quantization") for c in comps):
        var = float(np.var(np.diff(y))) / 2.0 if y.size > 2 else 0.0
        if not var > 0:
            var = max(float(np.var(y)), 1e-12)
        comps.insert(0, {"kind": "white", "arw_dprh": math.sqrt(var * dt_s) / 60.0})
        info["method"] = "difference-variance" if info["A"] is None else "allan+difference-variance"
        info["reason"] = info["reason"] or "the Allan fit found no white noise"
        warnings.warn(f"Kalman noise model: white noise from the variance of first differences ({info['reason']})",
                      FogdriftWarning, stacklevel=3)
    return comps, info


def identify_components_gmwm(y, dt_s: float) -> tuple[list[dict], dict]:
    """Noise components of a rate series [deg/h] from a GMWM fit of it (training block only).

    The GMWM model selection (:func:`fogdrift.gmwm.analysis.analyse_gmwm`: Haar wavelet variance, default
    candidates, WIC, sanity checks, short-scale exclusion) on ``y`` as given, then
    :func:`fogdrift.models.components.components_from_gmwm` with a drift DR folded into the random walk.

    Parameters
    ----------
    y : ndarray, shape (n,)
        Rate [deg/h] (the caller validates it: finite, 1-D).
    dt_s : float
        Sample interval [s].

    Returns
    -------
    components : list of dict
    info : dict
        ``method`` ("gmwm"), ``selected`` (the GMWM model, e.g. ``"WN+RW+GM"``), ``passed_checks``,
        ``n_samples``, ``tau_range_s`` (Allan times the fit covers [s]), ``notes`` and ``reason`` (why the
        selection is a fallback, empty otherwise).  JSON-ready (it is saved in the model file).

    Raises
    ------
    InsufficientDataError
        ``y`` has fewer than :data:`GMWM_MIN_SAMPLES` samples (one line, naming the alternative).

    Warns
    -----
    FogdriftWarning
        No GMWM candidate passed every sanity check: the components are those of the best candidate
        without a hard failure, and ``reason`` says why it was still taken.

    Examples
    --------
    White noise of 6 deg/h per 1-s sample is identified as WN alone, N = 6/60 deg/sqrt(h):

    >>> y = np.random.default_rng(0).normal(0.0, 6.0, 4096)
    >>> comps, info = identify_components_gmwm(y, 1.0)
    >>> info["selected"], [c["kind"] for c in comps], abs(comps[0]["arw_dprh"] / 0.1 - 1) < 0.05
    ('WN', ['white'], True)
    """
    n = int(np.asarray(y).size)
    if n < GMWM_MIN_SAMPLES:
        raise InsufficientDataError(
            f"Kalman noise_method 'gmwm': the training block has {n} samples at {1.0 / dt_s:.4g} Hz; a GMWM fit "
            f"needs at least {GMWM_MIN_SAMPLES} (use noise_method 'allan', a longer record or a higher model rate)",
            needed=GMWM_MIN_SAMPLES, got=n)
    with warnings.catch_warnings(record=True) as log:
        warnings.simplefilter("always", FogdriftWarning)
        axis = analyse_gmwm("train", y, dt_s)
    sel = axis.selection
    comps, notes = components_from_gmwm(axis, ramp="random_walk")
    reason = ""
    if not sel.passed_checks:
        failed = next((c for c in sel.candidates if c.model == sel.selected), None)
        why = "; ".join(failed.reasons) if failed is not None and failed.reasons else "see the GMWM candidates"
        reason = f"no GMWM candidate passed every sanity check; {sel.selected} has the smallest WIC ({why})"
        warnings.warn(f"Kalman noise model (GMWM): {reason}", FogdriftWarning, stacklevel=3)
    for w in log:  # anything else the GMWM said, passed on once
        if not (issubclass(w.category, FogdriftWarning) and "no candidate passed" in str(w.message)):
            warnings.warn(w.message, w.category, stacklevel=3)
    lo, hi = (float(v) for v in sel.ieee.tau_range_s)
    info = {"method": "gmwm", "selected": sel.selected, "passed_checks": bool(sel.passed_checks), "n_samples": n,
            "tau_range_s": [lo, hi], "notes": list(notes), "reason": reason}
    return comps, info


class Kalman(DriftModel):
    """Kalman-filter drift estimate from a noise model; runs on the (bias-removed) rate.

    Parameters
    ----------
    components : list of dict or None
        Noise components (see :mod:`fogdrift.models.statespace`), or None to identify them from
        the Allan variance of ``y_train`` in :meth:`fit`.
    dt_s : float
        Sample interval [s] of the series the model sees (the modelling interval).
    bias_prior_dph : float or None
        Prior 1-sigma of the random-constant bias state [deg/h]; None: 10 x std(y_train) (at least
        the white-noise 1-sigma), i.e. nearly diffuse.
    terms : sequence of str or None
        Allan terms turned into components when identifying (subset of Q, N, B, K, R); None: all.
        Used by ``noise_method="allan"`` only.
    noise_method : {"allan", "gmwm"}
        How the noise model is identified from ``y_train`` when ``components`` is None: the Allan fit
        (:func:`identify_components`, default) or the GMWM model selection
        (:func:`identify_components_gmwm`; at least :data:`GMWM_MIN_SAMPLES` training samples).  Ignored
        when ``components`` are given.

    Attributes
    ----------
    components_ : list of dict
        The noise model used.
    identification_ : dict
        How it was obtained: ``method`` (``"allan"``, ``"difference-variance"``, ``"allan+difference-variance"``,
        ``"gmwm"`` or ``"given"``) and its details (Allan ``A`` and tau range; the GMWM ``selected`` model,
        ``passed_checks``, ``n_samples``, tau range).  Saved in the model file.
    bias_prior_dph_ : float
    state_names_ : tuple of str
    x_end_, P_end_ : ndarray
        State predicted for the sample after the training block: start of :meth:`forecast`.

    Notes
    -----
    ``predict(y, history)`` filters ``history`` then ``y`` from the prior and returns the one-step
    predicted drift H x_{k|k-1}; :meth:`filter` also returns its 1-sigma and the final state, and
    :meth:`forecast_with_uncertainty` the free-run forecast with the 1-sigma of the drift and of the
    integrated angle error.  Feeding the wavelet drift instead of the rate (as the paper's models
    get) runs the same filter on a smoothed series; the pipeline passes the rate (``input_kind``).

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> y = 0.5 + rng.normal(0.0, 6.0, 3000)  # a 0.5 deg/h offset in white noise
    >>> model = Kalman(components=[{"kind": "white", "arw_dprh": 0.1}]).fit(y[:2000])
    >>> pred, sigma, _ = model.filter(y[2000:], history=y[:2000])
    >>> round(float(pred[-1]), 1), round(float(sigma[-1]), 2)  # the mean of 3000 samples, 6/sqrt(3000)
    (0.5, 0.11)
    """

    label = "Kalman"
    input_kind = "rate"

    def __init__(self, *, components=None, dt_s=1.0, bias_prior_dph=None, terms=None, noise_method="allan"):
        self.components = components
        self.dt_s = dt_s
        self.bias_prior_dph = bias_prior_dph
        self.terms = terms
        self.noise_method = noise_method

    # -- fit ------------------------------------------------------------------------------------
    def _validate(self) -> float:
        try:
            dt = float(self.dt_s)
        except (TypeError, ValueError):
            dt = math.nan
        if isinstance(self.dt_s, bool) or not (math.isfinite(dt) and dt > 0):
            raise ConfigError(f"Kalman dt_s must be a finite number > 0 s; got {self.dt_s!r}")
        if self.terms is not None and (isinstance(self.terms, str) or set(self.terms) - set("QNBKR")):
            raise ConfigError(f"Kalman terms must be None or a subset of Q, N, B, K, R; got {self.terms!r}")
        if not isinstance(self.noise_method, str) or self.noise_method not in NOISE_METHODS:
            raise ConfigError(f"Kalman noise_method must be one of {', '.join(NOISE_METHODS)}; "
                              f"got {self.noise_method!r}")
        return dt

    def fit(self, y_train, y_val=None):
        """Identify (or take) the noise model and filter ``y_train``; ``y_val`` is ignored (never seen).

        Raises
        ------
        ConfigError
            Bad parameter or component list.
        DataFormatError
            ``y_train`` not 1-D or not finite.
        InsufficientDataError
            ``noise_method="gmwm"`` and fewer than :data:`GMWM_MIN_SAMPLES` training samples.
        """
        dt = self._validate()
        y = check_series(y_train, "y_train", min_length=2)
        if self.components is None and self.noise_method == "gmwm":
            comps, info = identify_components_gmwm(y, dt)  # the training block only, never y_val
        elif self.components is None:
            comps, info = identify_components(y, dt, terms=tuple(self.terms or "QNBKR"))
        else:
            comps, info = check_components(self.components), {"method": "given"}
        white = max((c.get("arw_dprh", 0.0) * 60.0 / math.sqrt(dt) for c in comps), default=0.0)
        prior = self.bias_prior_dph
        prior = max(10.0 * float(np.std(y)), white, 1e-9) if prior is None else float(prior)
        ss = state_space(comps, dt_s=dt, bias_prior_dph=prior)
        self.components_ = comps
        self.identification_ = info
        self.bias_prior_dph_ = prior
        self.state_names_ = ss.names
        self._ss = ss
        _, _, (x, P) = kalman_filter(ss, y)
        self.x_end_, self.P_end_ = x, P
        return self

    @property
    def state_space_(self):
        """The :class:`~fogdrift.models.statespace.StateSpace` the filter runs (after :meth:`fit`)."""
        self._check_fitted()
        return self._ss

    # -- filtering ------------------------------------------------------------------------------
    def filter(self, y, *, history=None, state=None):
        """One-step drift estimates over ``y`` with their 1-sigma, and the final state.

        Parameters
        ----------
        y : array_like, shape (n,)
            Rate [deg/h] (bias-removed as the training block was).
        history : array_like, optional
            Samples just before ``y``, filtered first (from the prior, or from ``state``).
        state : (x, P), optional
            State predicted for the first sample (of ``history``, else of ``y``), e.g. the third
            return value of an earlier call: continues a filter run (bit-identical to one call).

        Returns
        -------
        pred : ndarray, shape (n,)
            H x_{k|k-1}: the drift estimate for ``y[k]`` from earlier samples [deg/h].
        sigma : ndarray, shape (n,)
            Its 1-sigma [deg/h].
        state : (ndarray, ndarray)
            State predicted for the sample after ``y``.
        """
        self._check_fitted()
        y = check_series(y, "y", min_length=0)
        if history is not None:
            h = check_series(history, "history", min_length=0)
            if h.size:
                _, _, state = kalman_filter(self._ss, h, state)
        return kalman_filter(self._ss, y, state)

    def predict(self, y, *, history=None):
        """One-step predicted drift [deg/h]: ``out[k]`` uses ``history`` and ``y[:k]`` only (never NaN)."""
        return self.filter(y, history=history)[0]

    def _start_state(self, history, state):
        if state is not None:
            return state
        if history is None:
            return self.x_end_.copy(), self.P_end_.copy()
        return self.filter(np.empty(0), history=history)[2]

    def forecast(self, h: int, *, history=None):
        """Free-run drift forecast [deg/h] of ``h`` samples after ``history`` (default: after the training block)."""
        return self.forecast_with_uncertainty(h, history=history)[0]

    def forecast_with_uncertainty(self, h: int, *, history=None, state=None):
        """Free-run forecast with its predicted uncertainty.

        Returns
        -------
        mean : ndarray, shape (h,)
            Forecast drift [deg/h].
        rate_sigma : ndarray, shape (h,)
            1-sigma of the drift error [deg/h].
        angle_sigma : ndarray, shape (h,)
            1-sigma [deg] of the angle error after j + 1 samples when ``mean`` is subtracted from
            the measured rate (white noise included): the predicted heading-error envelope.
        """
        self._check_fitted()
        if isinstance(h, bool) or not isinstance(h, (int, np.integer)) or h < 0:
            raise ConfigError(f"h must be an integer >= 0; got {h!r}")
        return forecast_uncertainty(self._ss, int(h), self._start_state(history, state))

    # -- fitted state as data ------------------------------------------------------------------
    def _get_state(self):
        meta = {"components_": self.components_, "identification_": self.identification_,
                "bias_prior_dph_": self.bias_prior_dph_, "state_names_": list(self.state_names_)}
        return meta, {"x_end_": self.x_end_, "P_end_": self.P_end_}

    def _set_state(self, meta, arrays):
        self.components_ = check_components(meta["components_"])
        self.identification_ = dict(meta["identification_"])
        self.bias_prior_dph_ = float(meta["bias_prior_dph_"])
        self._ss = state_space(self.components_, dt_s=self._validate(), bias_prior_dph=self.bias_prior_dph_)
        self.state_names_ = self._ss.names
        if tuple(meta["state_names_"]) != self.state_names_:
            raise ValueError(f"states {meta['state_names_']} do not match the components "
                             f"({list(self.state_names_)})")
        self.x_end_ = np.asarray(arrays["x_end_"], dtype=np.float64)
        self.P_end_ = np.asarray(arrays["P_end_"], dtype=np.float64)
