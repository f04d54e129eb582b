"""Gyro noise components as a linear state-space model, and the Kalman filter that runs it.

A gyro rate sample (deg/h, interval ``dt_s``) is modelled as

    y_k = b + r_k + sum_i g_i,k + c_k + v_k

* ``b``: the residual constant bias, a random constant (prior 1-sigma ``bias_prior_dph``);
* ``r``: rate random walk, r_{k+1} = r_k + w_k, Var w = K^2 dt (K in (deg/h)/sqrt(s));
* ``g_i``: first-order Gauss-Markov states, g_{k+1} = phi g_k + w_k, phi = exp(-dt/T_c),
  Var w = sigma^2 (1 - phi^2), stationary variance sigma^2;
* ``c``: rate ramp, c_{k+1} = c_k + s dt with a random constant slope s of prior 1-sigma R
  ((deg/h)/s);
* ``v``: white measurement noise, Var v = N^2/dt (angle random walk N in (deg/h) sqrt(s)) plus
  the quantization noise treated as white, 2 Q^2/dt^2 (Q in (deg/h) s = arcsec).

The *drift* is everything but ``v``.  A noise model is a list of **components**, plain dicts in
IEEE-952 units (JSON-ready; :data:`COMPONENT_KINDS` is the table of kinds and keys)::

    {"kind": "white", "arw_dprh": N}            # deg/sqrt(h)
    {"kind": "quantization", "q_urad": Q}       # microradian
    {"kind": "random_walk", "rrw_dphrh": K}      # deg/h^1.5
    {"kind": "gauss_markov", "tc_s": T, "sigma_dph": s}
    {"kind": "ramp", "ramp_dph2": R}            # deg/h^2

so a model identified from Allan coefficients (:func:`components_from_allan`) and one from a GMWM
fit (a list of white / random-walk / Gauss-Markov terms, method notes §9.7) feed the same filter.
Flicker (bias instability B) is not Markov; :func:`flicker_as_gauss_markov` replaces it by
Gauss-Markov terms whose summed Allan variance matches the flat 0.4413 B^2 over a tau range
(method notes §9.7, "B from Gauss-Markov terms").

Conversions (IEEE Std 952-1997 Annex C, method notes §2.3): N[(deg/h) sqrt(s)] = 60 N[deg/sqrt(h)],
K[(deg/h)/sqrt(s)] = K[deg/h^1.5]/60, R[(deg/h)/s] = R[deg/h^2]/3600, Q[arcsec] = Q[urad]/4.848137.
From Allan coefficients (sigma^2 = sum A_n tau^n, (deg/h)^2 and s): N^2 = A_-1, K^2 = 3 A_1,
R^2 = 2 A_2, Q^2 = A_-2/3, B^2 = A_0 pi/(2 ln 2).

:func:`kalman_filter` is the textbook filter (Joseph-form update) compiled with numba; it carries
``(x, P)`` *predicted for the next sample*, so a long log can be filtered in pieces with results
identical to one pass.  :func:`forecast_uncertainty` propagates the error covariance of a
free-running forecast together with the integrated angle error.

References
----------
R. E. Kalman, "A new approach to linear filtering and prediction problems", J. Basic Eng.
82(1):35-45, 1960.  IEEE Std 952-1997, Annex C.  Method notes §2.2-2.3 and §9.4, §9.7.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ConfigError
from ..noise.processes import TableView, component_specs, power_law_names, processes
from ..noise.processes.flicker import flicker_as_gauss_markov
from ..noise.processes.gauss_markov import gm_avar_dph2
from ..noise.terms import TERMS
from ..units import S_PER_H

__all__ = [
    "COMPONENT_KINDS",
    "check_components",
    "component_densities",
    "components_from_allan",
    "flicker_as_gauss_markov",
    "gm_avar_dph2",
    "StateSpace",
    "state_space",
    "kalman_filter",
    "forecast_uncertainty",
]

#: Component kinds -> (parameter keys in order, one-line description with units): the rows' components.
COMPONENT_KINDS = TableView(lambda: {k: (c.keys, c.description) for k, c in component_specs().items()},
                            "COMPONENT_KINDS")


def check_components(components) -> list[dict]:
    """Validate a list of noise components; returns plain float dicts in the order given.

    Raises
    ------
    ConfigError
        Not a list of dicts, unknown kind, missing/extra key, negative or non-finite value,
        ``tc_s <= 0``.

    Examples
    --------
    >>> check_components([{"kind": "white", "arw_dprh": 0.1}])
    [{'kind': 'white', 'arw_dprh': 0.1}]
    >>> check_components([{"kind": "flicker", "b_dph": 1.0}])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    fogdrift.errors.ConfigError: noise component 0 has kind 'flicker'; expected one of white, quantization, ...
    """
    if isinstance(components, (str, bytes, dict)) or not hasattr(components, "__iter__"):
        raise ConfigError(f"components must be a list of dicts; got {type(components).__name__}")
    out = []
    for i, comp in enumerate(components):
        if not isinstance(comp, dict) or "kind" not in comp:
            raise ConfigError(f"noise component {i} must be a dict with a 'kind'; got {comp!r}")
        kind = comp["kind"]
        if kind not in COMPONENT_KINDS:
            raise ConfigError(f"noise component {i} has kind {kind!r}; expected one of {', '.join(COMPONENT_KINDS)}")
        keys = COMPONENT_KINDS[kind][0]
        extra = sorted(set(comp) - set(keys) - {"kind"})
        missing = [k for k in keys if k not in comp]
        if extra or missing:
            raise ConfigError(f"noise component {i} ({kind}) needs exactly the keys {list(keys)}; "
                              f"missing {missing}, unexpected {extra}")
        clean = {"kind": kind}
        for k in keys:
            try:
                v = float(comp[k])
            except (TypeError, ValueError):
                v = math.nan
            if not (math.isfinite(v) and v >= 0) or (k == "tc_s" and v <= 0):
                raise ConfigError(f"noise component {i} ({kind}): {k} must be a finite number "
                                  f"{'> 0' if k == 'tc_s' else '>= 0'}; got {comp[k]!r}")
            clean[k] = v
        out.append(clean)
    return out


# ---------------------------------------------------------------------------------------------------
# Allan coefficients -> components
# ---------------------------------------------------------------------------------------------------
def components_from_allan(A, *, tau_range_s, terms=TERMS, ramp="random_walk",
                          max_flicker_terms: int = 4) -> list[dict]:
    """Noise components from Allan-law coefficients A_-2..A_2 ((deg/h)^2, tau in s).

    Parameters
    ----------
    A : array_like, shape (5,)
        Non-negative coefficients of sigma^2(tau) = sum_n A_n tau^n, n = -2..2 (e.g. ``NoiseFit.A``).
    tau_range_s : (float, float)
        Tau range of the fit [s]; the flicker term is replaced by Gauss-Markov terms over it
        (:func:`flicker_as_gauss_markov`), from the white/flicker crossover A_-1/A_0 on where that is
        inside the range (below it white noise dominates and short correlation times would only
        duplicate it).
    terms : sequence of str
        Which of Q, N, B, K, R to turn into components (zero coefficients are skipped).
    ramp : {"random_walk", "state"}
        How a rate ramp R becomes a component.  ``"random_walk"`` (default): a random walk with the
        same Allan variance at the longest fitted tau (A_1 += A_2 tau_max), i.e. a slow change the
        filter keeps tracking; a ramp seen in a finite training record rarely continues unchanged,
        and a ramp state (no process noise) makes the filter ever more confident of its slope.
        ``"state"``: a ramp state with a random constant slope of 1-sigma R.
    max_flicker_terms : int
        Most Gauss-Markov terms standing in for B.

    Returns
    -------
    list of dict
        See the module docstring.

    Examples
    --------
    >>> comps = components_from_allan([0, 36.0, 0, 1/3 * 1e-4, 0], tau_range_s=(1, 100))
    >>> [(c["kind"], round(list(c.values())[1], 6)) for c in comps]
    [('white', 0.1), ('random_walk', 0.6)]
    """
    a = np.asarray(A, dtype=np.float64)
    n_power = len(power_law_names())
    if a.shape not in ((5,), (n_power,)) or not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ConfigError(f"A must be {n_power} finite non-negative numbers (A_-2..A_2 of Q, N, B, K, R, then any "
                          f"registered power-law process's); got {A!r}")
    terms = tuple(terms)
    if ramp not in ("random_walk", "state"):
        raise ConfigError(f"ramp must be 'random_walk' or 'state'; got {ramp!r}")
    if ramp == "random_walk" and "R" in terms:
        a = a.copy()
        a[3] += a[4] * float(tau_range_s[1])
        terms = tuple(t for t in terms if t != "R") + (("K",) if "K" not in terms and a[3] > 0 else ())
    ctx = {"tau_range_s": tau_range_s, "A_white": a[1], "max_flicker_terms": max_flicker_terms}
    rows = sorted((p for p in processes() if p.name in terms and p.power_law and p.to_components is not None),
                  key=lambda p: p.component_rank)
    index = {name: i for i, name in enumerate(power_law_names()) if i < a.size}
    out = []
    for p in rows:
        if p.name in index:
            out.extend(p.to_components(float(a[index[p.name]]), ctx))
    return out


# ---------------------------------------------------------------------------------------------------
# state space
# ---------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class StateSpace:
    """Discrete model x_{k+1} = F x_k + w_k (Cov Q), y_k = H x_k + v_k (Var r), per sample of ``dt_s``.

    Attributes
    ----------
    F, Q : ndarray, shape (n, n)
    H : ndarray, shape (n,)
    r : float
        Measurement-noise variance [(deg/h)^2].
    x0, P0 : ndarray, shapes (n,), (n, n)
        Prior mean and covariance of the state at the first sample.
    names : tuple of str
        State names (``"bias"``, ``"random_walk"``, ``"gm_<T_c>s"``, ``"ramp"``, ``"ramp_slope"``).
    dt_s : float
    """

    F: np.ndarray
    Q: np.ndarray
    H: np.ndarray
    r: float
    x0: np.ndarray
    P0: np.ndarray
    names: tuple
    dt_s: float

    @property
    def n_states(self) -> int:
        return int(self.H.size)


def component_densities(components) -> dict:
    """The noise densities of a (checked) component list in the Allan-law units, summed per kind.

    The one place the component parameters are turned into densities, for the discrete filter
    (:func:`state_space`) and the continuous model of :mod:`fogdrift.export.discretize`.

    Returns
    -------
    dict
        ``white2`` white-rate PSD [(deg/h)^2 s] (N in deg/sqrt(h) x 60), ``quant2`` Q^2 [((deg/h) s)^2 = arcsec^2],
        ``rw2`` rate-random-walk intensity [(deg/h)^2 / s] (K in deg/h^1.5 / 60), ``random_walk`` (bool: any such
        component), ``gms`` [(tc_s, sigma_dph), ...] in order, ``ramps`` slopes [deg/h/s] (R in deg/h^2 / 3600).

    Examples
    --------
    >>> d = component_densities([{"kind": "white", "arw_dprh": 0.1}, {"kind": "quantization", "q_urad": 4.8481368},
    ...                          {"kind": "random_walk", "rrw_dphrh": 0.6}, {"kind": "ramp", "ramp_dph2": 36.0}])
    >>> round(d["white2"], 9), round(d["quant2"], 6), round(d["rw2"], 9), d["random_walk"], d["ramps"]
    (36.0, 1.0, 0.0001, True, [0.01])
    """
    out = {"white2": 0.0, "quant2": 0.0, "rw2": 0.0, "random_walk": False, "gms": [], "ramps": []}
    specs = component_specs()
    for c in components:
        specs[c["kind"]].densities(c, out)  # each row's component adds its densities
    return out


def state_space(components, *, dt_s: float, bias_prior_dph: float) -> StateSpace:
    """Build the :class:`StateSpace` of a component list (see the module docstring).

    Parameters
    ----------
    components : list of dict
        Noise components (:func:`check_components`).
    dt_s : float
        Sample interval [s] of the series the filter will run on.
    bias_prior_dph : float
        Prior 1-sigma of the random-constant bias state [deg/h] (> 0).

    Raises
    ------
    ConfigError
        Invalid components, ``dt_s`` or prior, or no white/quantization component (the filter
        needs measurement noise).

    Examples
    --------
    >>> ss = state_space([{"kind": "white", "arw_dprh": 0.1}, {"kind": "random_walk", "rrw_dphrh": 0.6}],
    ...                  dt_s=1.0, bias_prior_dph=10.0)
    >>> ss.names, round(ss.r, 6), round(float(ss.Q[1, 1]), 8)
    (('bias', 'random_walk'), 36.0, 0.0001)
    """
    comps = check_components(components)
    try:
        dt = float(dt_s)
        prior = float(bias_prior_dph)
    except (TypeError, ValueError):
        raise ConfigError(f"dt_s and bias_prior_dph must be numbers; got {dt_s!r}, {bias_prior_dph!r}") from None
    if not (math.isfinite(dt) and dt > 0):
        raise ConfigError(f"dt_s must be a finite number > 0; got {dt_s!r}")
    if not (math.isfinite(prior) and prior > 0):
        raise ConfigError(f"bias_prior_dph must be a finite number > 0; got {bias_prior_dph!r}")
    d = component_densities(comps)
    r = d["white2"] / dt + 2.0 * d["quant2"] / (dt * dt)
    has_rw, q_rw, gms, ramps = d["random_walk"], d["rw2"] * dt, d["gms"], d["ramps"]
    if not r > 0:
        raise ConfigError("the noise model has no white measurement noise; a Kalman filter needs a 'white' or "
                          "'quantization' component with a value > 0")
    names = ["bias"]
    diag_q, diag_p = [0.0], [prior * prior]
    if has_rw:
        names.append("random_walk")
        diag_q.append(q_rw)
        diag_p.append(0.0)
    phis = []
    for tc, sigma in gms:
        names.append(f"gm_{tc:.4g}s")
        phis.append(math.exp(-dt / tc))
        diag_q.append(-sigma * sigma * math.expm1(-2.0 * dt / tc))
        diag_p.append(sigma * sigma)
    n = len(names) + (2 if ramps else 0)
    F = np.eye(n)
    Q = np.zeros((n, n))
    P0 = np.zeros((n, n))
    H = np.ones(n)
    for i, (q, p) in enumerate(zip(diag_q, diag_p)):
        Q[i, i] = q
        P0[i, i] = p
    for j, phi in enumerate(phis):
        i = 1 + int(has_rw) + j
        F[i, i] = phi
    if ramps:
        i = n - 2
        names += ["ramp", "ramp_slope"]
        F[i, i + 1] = dt
        H[i + 1] = 0.0
        P0[i + 1, i + 1] = float(np.sum(np.square(ramps)))
    return StateSpace(F=F, Q=Q, H=H, r=float(r), x0=np.zeros(n), P0=P0, names=tuple(names), dt_s=dt)


# ---------------------------------------------------------------------------------------------------
# the filter (numba)
# ---------------------------------------------------------------------------------------------------
_KERNELS: dict = {}


def _filter_py(F, Q, H, r, x, P, y, pred, pred_var):  # pragma: no cover - runs compiled
    """Run the filter over y; x, P (predicted for y[0]) are updated in place to the prediction after y[-1]."""
    n = H.shape[0]
    ph = np.empty(n)
    gain = np.empty(n)
    xu = np.empty(n)
    a = np.empty((n, n))
    tmp = np.empty((n, n))
    for k in range(y.shape[0]):
        hx = 0.0
        for i in range(n):
            hx += H[i] * x[i]
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += P[i, j] * H[j]
            ph[i] = s
        hph = 0.0
        for i in range(n):
            hph += H[i] * ph[i]
        pred[k] = hx
        pred_var[k] = hph
        innov_var = hph + r
        innov = y[k] - hx
        for i in range(n):
            gain[i] = ph[i] / innov_var
            xu[i] = x[i] + gain[i] * innov
        # Joseph form: P = (I - K H) P (I - K H)^T + K r K^T
        for i in range(n):
            for j in range(n):
                a[i, j] = (1.0 if i == j else 0.0) - gain[i] * H[j]
        for i in range(n):
            for j in range(n):
                s = 0.0
                for m in range(n):
                    s += a[i, m] * P[m, j]
                tmp[i, j] = s
        for i in range(n):
            for j in range(n):
                s = 0.0
                for m in range(n):
                    s += tmp[i, m] * a[j, m]
                P[i, j] = s + gain[i] * r * gain[j]
        # predict: x = F xu, P = F P F^T + Q
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += F[i, j] * xu[j]
            x[i] = s
        for i in range(n):
            for j in range(n):
                s = 0.0
                for m in range(n):
                    s += F[i, m] * P[m, j]
                tmp[i, j] = s
        for i in range(n):
            for j in range(i, n):
                s = 0.0
                for m in range(n):
                    s += tmp[i, m] * F[j, m]
                s += Q[i, j]
                P[i, j] = s
                P[j, i] = s


def _forecast_py(F, Q, H, r, dt, x, P, mean, rate_var, angle_var):  # pragma: no cover - runs compiled
    """Free-run mean, drift-error variance and integrated angle-error variance for len(mean) samples."""
    n = H.shape[0]
    c = np.zeros(n)
    c_new = np.empty(n)
    ph = np.empty(n)
    xn = np.empty(n)
    tmp = np.empty((n, n))
    s_angle = 0.0
    for k in range(mean.shape[0]):
        hx = 0.0
        for i in range(n):
            hx += H[i] * x[i]
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += P[i, j] * H[j]
            ph[i] = s
        hph = 0.0
        hc = 0.0
        for i in range(n):
            hph += H[i] * ph[i]
            hc += H[i] * c[i]
        mean[k] = hx
        rate_var[k] = hph
        s_angle = s_angle + dt * dt * (hph + r) + 2.0 * dt * hc
        angle_var[k] = s_angle
        for i in range(n):
            s = 0.0
            t = 0.0
            for j in range(n):
                s += F[i, j] * (c[j] + dt * ph[j])
                t += F[i, j] * x[j]
            c_new[i] = s
            xn[i] = t
        for i in range(n):
            c[i] = c_new[i]
            x[i] = xn[i]
        for i in range(n):
            for j in range(n):
                s = 0.0
                for m in range(n):
                    s += F[i, m] * P[m, j]
                tmp[i, j] = s
        for i in range(n):
            for j in range(i, n):
                s = 0.0
                for m in range(n):
                    s += tmp[i, m] * F[j, m]
                s += Q[i, j]
                P[i, j] = s
                P[j, i] = s


def _kernels():
    """Compile (or load from numba's disk cache) the two loops on first use."""
    if not _KERNELS:
        import numba

        _KERNELS["filter"] = numba.njit(cache=True)(_filter_py)
        _KERNELS["forecast"] = numba.njit(cache=True)(_forecast_py)
    return _KERNELS


def _state_arrays(ss: StateSpace, state):
    if state is None:
        return ss.x0.copy(), ss.P0.copy()
    x, P = state
    x = np.array(x, dtype=np.float64)
    P = np.array(P, dtype=np.float64)
    if x.shape != (ss.n_states,) or P.shape != (ss.n_states, ss.n_states):
        raise ConfigError(f"state must be (x, P) with shapes ({ss.n_states},) and ({ss.n_states}, {ss.n_states}); "
                          f"got {x.shape} and {P.shape}")
    return x, P


def kalman_filter(ss: StateSpace, y, state=None):
    """Run the Kalman filter over ``y`` [deg/h].

    Parameters
    ----------
    ss : StateSpace
    y : ndarray, shape (n,)
        Finite measurements (the caller validates them).
    state : (x, P) or None
        State predicted for ``y[0]`` (as returned by a previous call); None: the prior.

    Returns
    -------
    pred : ndarray, shape (n,)
        One-step predicted drift H x_{k|k-1} [deg/h] (uses ``y[:k]`` only).
    pred_sigma : ndarray, shape (n,)
        Its 1-sigma, sqrt(H P_{k|k-1} H^T) [deg/h] (drift uncertainty, measurement noise excluded).
    state : (ndarray, ndarray)
        (x, P) predicted for the sample after ``y[-1]``: pass it on to continue.

    Notes
    -----
    Filtering ``y`` in pieces, each call continuing from the previous ``state``, gives results
    bit-identical to one call (the loop is strictly sequential).

    Examples
    --------
    >>> ss = state_space([{"kind": "white", "arw_dprh": 1 / 60}], dt_s=1.0, bias_prior_dph=100.0)
    >>> pred, sigma, _ = kalman_filter(ss, np.full(4, 2.0))
    >>> np.round(pred, 4).tolist(), np.round(sigma, 3).tolist()  # the running mean, shrunk by the prior
    ([0.0, 1.9998, 1.9999, 1.9999], [100.0, 1.0, 0.707, 0.577])
    """
    x, P = _state_arrays(ss, state)
    yy = np.ascontiguousarray(y, dtype=np.float64)
    pred = np.empty(yy.size)
    var = np.empty(yy.size)
    _kernels()["filter"](ss.F, ss.Q, ss.H, float(ss.r), x, P, yy, pred, var)
    return pred, np.sqrt(np.maximum(var, 0.0)), (x, P)


def forecast_uncertainty(ss: StateSpace, h: int, state=None):
    """Free-run forecast of ``h`` samples from a predicted state, with its uncertainty.

    Parameters
    ----------
    ss : StateSpace
    h : int
        Horizon in samples (>= 0).
    state : (x, P) or None
        State predicted for the first forecast sample (from :func:`kalman_filter`); None: the prior.

    Returns
    -------
    mean : ndarray, shape (h,)
        Forecast drift H F^j x [deg/h].
    rate_sigma : ndarray, shape (h,)
        1-sigma of the drift error at each sample [deg/h].
    angle_sigma : ndarray, shape (h,)
        1-sigma of the integrated error dt * sum_{i<=j} (y_i - mean_i) after j + 1 samples, measurement
        noise included, in **deg** ((deg/h) s / 3600).

    Notes
    -----
    Error e_j = x_j - x_hat_j with covariance P_j, angle a_j, cross-covariance c_j = Cov(e_j, a_j):
    Var a_{j+1} = Var a_j + dt^2 (H P_j H^T + r) + 2 dt H c_j, c_{j+1} = F (c_j + dt P_j H^T),
    P_{j+1} = F P_j F^T + Q (a_0 = 0, c_0 = 0).

    Examples
    --------
    >>> ss = state_space([{"kind": "white", "arw_dprh": 1 / 60}], dt_s=1.0, bias_prior_dph=1e-9)
    >>> _, _, ang = forecast_uncertainty(ss, 3600)
    >>> round(float(ang[-1] * 3600), 6)  # pure white noise of 1 (deg/h) sqrt(s): sqrt(3600 s) = 60 arcsec
    60.0
    """
    if isinstance(h, bool) or not isinstance(h, (int, np.integer)) or h < 0:
        raise ConfigError(f"h must be an integer >= 0; got {h!r}")
    x, P = _state_arrays(ss, state)
    mean = np.empty(int(h))
    rate_var = np.empty(int(h))
    angle_var = np.empty(int(h))
    _kernels()["forecast"](ss.F, ss.Q, ss.H, float(ss.r), float(ss.dt_s), x, P, mean, rate_var, angle_var)
    return mean, np.sqrt(np.maximum(rate_var, 0.0)), np.sqrt(np.maximum(angle_var, 0.0)) / S_PER_H
