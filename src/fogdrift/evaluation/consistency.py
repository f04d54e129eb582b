"""Will these noise numbers work in my filter?  Predicted against measured angle error on a held-out log.

Protocol (the heading protocol of :mod:`fogdrift.evaluation.heading`, without a drift model):
on a held-out static rate series ``y`` [deg/h] sampled every ``dt`` s,

* origins ``t0`` every ``step_s`` s (default ``T_cal + h`` for each horizon h: calibration and horizon windows
  of different origins never overlap, so the origins are independent samples for the counts);
* **calibration** on ``[t0 - T_cal, t0)``: the bias is the window mean;
* the **angle error** after horizon ``h`` is ``E(h) = dt/3600 * sum_{t0 <= t < t0 + h} (y(t) - b)`` [deg].

A noise model (a list of components in IEEE-952 units, :mod:`fogdrift.models.statespace`) predicts
``Var E(h)`` in closed form (continuous time; :func:`angle_error_variance_deg2`).  With the rate components in
deg/s and ``T = T_cal``:

===============  ==========================================================================================
white, N          N_s^2 (h + h^2/T)               N_s = N[deg/sqrt(h)]/60 (the h^2/T part: the error of the
                                                   calibration mean, N_s^2/T, carried over h)
random walk, K    K_s^2 (h^3/3 + h^2 T/3)         K_s = K[deg/h^1.5]/216000 deg/s^1.5
Gauss-Markov      V(h) + (h/T)^2 V(T) - 2 (h/T) C  V(L) = 2 s^2 Tc^2 (L/Tc - 1 + e^(-L/Tc)),
  (sigma, Tc)                                       C = s^2 Tc^2 (1 - e^(-h/Tc)) (1 - e^(-T/Tc)), s = sigma/3600
quantization, Q   Q_a^2 (1 + (1 + h/T)^2 + (h/T)^2)  angle white noise (IEEE-952 C.3, AVAR 3 Q^2/tau^2),
                                                   Q_a = Q[urad] in deg; bounded, does not grow with h
ramp, R           R_s^2 (h^2/2 + h T/2)^2          a random constant slope of 1-sigma R_s = R[deg/h^2]/3600^2
===============  ==========================================================================================

(derivations in ``docs/consistency.md``; every term is linear in its parameter's variance, and the sum is exact
for independent components).

**Coverage**: the fraction of origins with ``|E(h)| <= z sigma_pred(h)`` for the 68.27 % (z = 1) and 95 %
(z = 1.96) bands.  **Inflation factor** lambda: multiply every component's variance parameter (N^2, K^2,
sigma^2, Q^2, R^2, i.e. the continuous process-noise and measurement-noise densities, "Q and R of the filter")
by lambda; the predicted variance scales by lambda exactly.  The smallest lambda that gives nominal coverage
``p`` at a horizon is ``(q_p / z_p)^2`` with ``q_p`` the ``ceil(p n)``-th smallest ``|E| / sigma_pred`` of
``n`` origins; its 95 % interval comes from the binomial order-statistic ranks (distribution-free).  A lambda
below 1 means the model is conservative there: no inflation is needed.  Multiply *standard deviations* (N, K,
...) by ``sqrt(lambda)``.

**Accelerometers** (``quantity="accel"``): the same formulas give the *velocity* error [m/s] of a specific force
[m/s^2] whose components hold m/s^2 in place of deg/h (the convention of :mod:`fogdrift.export`: the statespace
formulas are linear in the rate unit), i.e. every deg/h -> deg/s factor 1/3600 of the gyro case is 1.

**White + random-walk targets** (Kalibr, VINS, ORB-SLAM3 keep only N and K): :func:`random_walk_covering`
finds the random walk K_eff that makes the white + K_eff model predict the *same* angle-error variance at the
user's horizon as the full model (flicker / Gauss-Markov / quantization / ramp parts folded into K), after the
same calibration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._util import fmt_number
from ..errors import ConfigError, InsufficientDataError
from ..models.components import components_from_gmwm, components_from_noise_fit  # re-exported
from ..models.statespace import check_components
from ..units import DEG_PER_RAD, RAD_PER_DEG, S_PER_H

__all__ = [
    "BANDS",
    "verdict_line",
    "summary_cell",
    "angle_error_variance_deg2",
    "observed_angle_errors_deg",
    "inflation_factor",
    "coverage_rows",
    "random_walk_covering",
    "reduced_model",
    "components_from_noise_fit",
    "components_from_gmwm",
    "CoverageRow",
    "ConsistencyResult",
    "check_consistency",
]

#: (name, nominal coverage, z): the 1-sigma band (68.27 %) and the 95 % band.
BANDS = (("68 %", 0.6826894921370859, 1.0), ("95 %", 0.95, 1.959963984540054))

_DEG_PER_URAD = 1e-6 * DEG_PER_RAD
#: Integration factor of the internal rate unit per second: deg/h * s -> deg (gyro), m/s^2 * s -> m/s (accel).
_INTEGRATE = {"gyro": 1.0 / S_PER_H, "accel": 1.0}


def _quantity(quantity) -> str:
    if quantity not in _INTEGRATE:
        raise ConfigError(f"quantity must be 'gyro' or 'accel'; got {quantity!r}")
    return quantity


def _horizons(horizons_s) -> np.ndarray:
    h = np.atleast_1d(np.asarray(horizons_s, dtype=np.float64))
    if h.ndim != 1 or h.size == 0 or not np.all(np.isfinite(h)) or np.any(h <= 0):
        raise ConfigError(f"{{opt:horizons}} must be one or more finite numbers > 0 [s]; got {horizons_s!r}")
    return h


def _t_cal(t_cal_s) -> float:
    try:
        t = float(t_cal_s)
    except (TypeError, ValueError):
        t = math.nan
    if not (math.isfinite(t) and t > 0):
        raise ConfigError(f"{{opt:calibration}} (the calibration window) must be a finite number > 0 [s]; "
                          f"got {t_cal_s!r}")
    return t


def _component_variance_deg2(c: dict, h: np.ndarray, T: float) -> np.ndarray:
    kind = c["kind"]
    if kind == "white":
        n = c["arw_dprh"] / 60.0  # deg/sqrt(s)
        return n * n * (h + h * h / T)
    if kind == "random_walk":
        k = c["rrw_dphrh"] / S_PER_H**1.5  # deg/s^1.5
        return k * k * (h**3 / 3.0 + h * h * T / 3.0)
    if kind == "gauss_markov":
        s2 = (c["sigma_dph"] / S_PER_H) ** 2
        tc = c["tc_s"]

        def v(L):
            x = np.asarray(L, dtype=np.float64) / tc
            # x - 1 + e^-x = x + expm1(-x), with a series for small x (cancellation)
            core = np.where(x < 1e-4, x * x / 2.0 - x**3 / 6.0, x + np.expm1(-x))
            return 2.0 * s2 * tc * tc * core

        cross = s2 * tc * tc * (-np.expm1(-h / tc)) * (-math.expm1(-T / tc))
        return v(h) + (h / T) ** 2 * v(T) - 2.0 * (h / T) * cross
    if kind == "quantization":
        q = c["q_urad"] * _DEG_PER_URAD
        return q * q * (1.0 + (1.0 + h / T) ** 2 + (h / T) ** 2)
    if kind == "ramp":
        r = c["ramp_dph2"] / S_PER_H**2  # deg/s^2
        return (r * (h * h / 2.0 + h * T / 2.0)) ** 2
    raise ConfigError(f"unknown noise component kind {kind!r}")  # pragma: no cover - check_components refuses it


def angle_error_variance_deg2(components, horizons_s, t_cal_s, *, by_component: bool = False, quantity="gyro"):
    """Predicted variance [deg^2] of the angle error after a static calibration (module docstring table).

    With ``quantity="accel"``: the velocity error [(m/s)^2] of components in m/s^2 in place of deg/h.

    Parameters
    ----------
    components : list of dict
        Noise components in IEEE-952 units (:func:`fogdrift.models.statespace.check_components`).
    horizons_s : float or array_like
        Horizons h [s] after the end of the calibration window.
    t_cal_s : float
        Calibration window T [s]; the bias is its mean.
    by_component : bool
        Also return the variance of each component (list of arrays, same order).
    quantity : {"gyro", "accel"}

    Returns
    -------
    ndarray, shape (n_horizons,)
        Var E(h) [deg^2]; with ``by_component``, ``(total, [per component])``.

    Examples
    --------
    White noise of N = 0.6 deg/sqrt(h) (0.01 deg/sqrt(s)), 100 s calibration, 100 s horizon:
    1e-4 (100 + 100) = 0.02 deg^2.

    >>> float(angle_error_variance_deg2([{"kind": "white", "arw_dprh": 0.6}], 100.0, 100.0)[0])
    0.02
    """
    comps = check_components(components)
    h = _horizons(horizons_s)
    T = _t_cal(t_cal_s)
    parts = [_component_variance_deg2(c, h, T) for c in comps]
    if _quantity(quantity) == "accel":  # the formulas carry 1/S_PER_H^2 for deg/h -> deg/s; m/s^2 needs none
        parts = [p * S_PER_H**2 for p in parts]
    total = np.sum(parts, axis=0) if parts else np.zeros_like(h)
    return (total, parts) if by_component else total


def observed_angle_errors_deg(y, dt_s, t_cal_s, horizons_s, *, step_s=None, quantity="gyro"):
    """Angle errors [deg] at rolling origins of a static rate series, after a window-mean calibration.

    With ``quantity="accel"``: velocity errors [m/s] of a specific force [m/s^2].

    Parameters
    ----------
    y : array_like, shape (n,)
        Static series (finite) in its internal unit: a rate in deg/h (``quantity="gyro"``), a specific force in
        m/s^2 (``"accel"``, whose "angle" is a velocity in m/s).
    dt_s : float
        Sample interval [s].
    t_cal_s : float
        Calibration window [s] (rounded to whole samples).
    horizons_s : array_like
        Horizons [s] (rounded to whole samples, at least one).
    step_s : float or None
        Origin spacing [s]; default ``t_cal_s + max(horizons_s)`` (no two origins share a sample).

    Returns
    -------
    origins_s : ndarray, shape (m,)
        Origin times [s] from the first sample.
    errors : ndarray, shape (m, n_horizons)
        E(h) = dt/3600 sum (y - b) over ``[t0, t0 + h)`` [deg].

    Raises
    ------
    InsufficientDataError
        Fewer samples than one calibration window plus the longest horizon.

    Examples
    --------
    A rate 3.6 deg/h above its calibrated mean from the origin on: 1e-3 deg per second of horizon.

    >>> y = np.r_[np.zeros(10), np.full(10, 3.6)]
    >>> _, e = observed_angle_errors_deg(y, 1.0, 10.0, [5.0, 10.0])
    >>> np.round(e, 6).tolist()
    [[0.005, 0.01]]
    """
    y = np.asarray(y, dtype=np.float64).ravel()
    dt = float(dt_s)
    T = _t_cal(t_cal_s)
    h = _horizons(horizons_s)
    m = max(1, int(round(T / dt)))
    k = np.maximum(1, np.round(h / dt).astype(np.int64))
    step = T + float(h.max()) if step_s is None else float(step_s)
    if not (math.isfinite(step) and step > 0):
        raise ConfigError(f"{{opt:origin_step}} must be a finite number > 0 [s]; got {step_s!r}")
    s = max(1, int(round(step / dt)))
    need = m + int(k.max())
    if y.size < need:
        raise InsufficientDataError(f"the held-out log has {y.size} samples ({y.size * dt:g} s); one calibration "
                                    f"window plus the longest horizon needs {need} ({need * dt:g} s)",
                                    needed=need, got=int(y.size))
    if not np.all(np.isfinite(y)):
        raise ConfigError("the held-out rate has non-finite samples")
    c = _centred_angle(y)
    origins = np.arange(m, y.size - int(k.max()) + 1, s)
    bias = (c[origins] - c[origins - m]) / m
    errors = np.empty((origins.size, k.size))
    for j, kk in enumerate(k):
        errors[:, j] = (c[origins + kk] - c[origins] - kk * bias) * (dt * _INTEGRATE[_quantity(quantity)])
    return origins * dt, errors


def _centred_angle(y: np.ndarray, block: int = 1 << 20) -> np.ndarray:
    """``[0, cumsum(y - median(y))]`` (centred: the cumulative sum stays small), accumulated a block at a time into
    one output array: the same sequential sums bit for bit, without two more 8-bytes-per-sample temporaries.

    >>> y = np.random.default_rng(0).standard_normal(1000)
    >>> np.array_equal(_centred_angle(y, 64), np.concatenate([[0.0], np.cumsum(y - np.median(y))]))
    True
    """
    med = np.median(y)
    c = np.empty(y.size + 1)
    c[0] = 0.0
    for a in range(0, y.size, block):
        seg = c[a + 1:a + 1 + block]
        np.subtract(y[a:a + block], med, out=seg)
        if a:
            seg[0] = c[a] + seg[0]  # the running sum carried into the block, as cumsum adds it
        np.cumsum(seg, out=seg)
    return c


def inflation_factor(ratio_abs, coverage: float, z: float) -> tuple[float, float, float]:
    """Smallest variance factor lambda with empirical coverage >= ``coverage``, with a 95 % interval.

    Parameters
    ----------
    ratio_abs : array_like
        ``|E| / sigma_pred`` over independent origins.
    coverage : float
        Nominal coverage p of the band (0 < p < 1).
    z : float
        Band half-width in predicted sigmas (1 for 68.27 %, 1.96 for 95 %).

    Returns
    -------
    (lam, lo95, hi95) : floats
        ``lam = (q_(r) / z)^2`` with ``q_(r)`` the r = ceil(p n)-th smallest ratio; the interval uses the order
        statistics at the binomial 2.5 % / 97.5 % ranks (NaN where they fall outside the sample: too few
        origins).

    Examples
    --------
    >>> inflation_factor([0.5, 1.0, 1.5, 2.0], 0.5, 1.0)[0]  # 2 of 4 within 1.0: lambda = 1
    1.0
    """
    from scipy.stats import binom

    r = np.sort(np.abs(np.asarray(ratio_abs, dtype=np.float64)))
    n = r.size
    if n == 0:
        return math.nan, math.nan, math.nan
    rank = min(n, max(1, math.ceil(coverage * n - 1e-9)))
    lam = (r[rank - 1] / z) ** 2
    lo_rank = int(binom.ppf(0.025, n, coverage))
    hi_rank = int(binom.ppf(0.975, n, coverage)) + 1
    lo = (r[lo_rank - 1] / z) ** 2 if 1 <= lo_rank <= n else math.nan
    hi = (r[hi_rank - 1] / z) ** 2 if 1 <= hi_rank <= n else math.nan
    return float(lam), float(lo), float(hi)


@dataclass(frozen=True)
class CoverageRow:
    """One target model at one horizon.

    Attributes
    ----------
    horizon_s : float
    n_origins : int
        Independent (non-overlapping) origins counted.
    sigma_pred : float
        Predicted 1-sigma of the error, in ``unit``.
    rms : float
        Measured RMS of the error, in ``unit``.
    coverage : dict
        Band name -> measured fraction of origins inside the band.
    inflation : dict
        Band name -> (lambda, lo95, hi95): the smallest variance factor giving nominal coverage.
    unit : str
        ``"deg"`` (angle error of a gyro) or ``"m/s"`` (velocity error of an accelerometer).
    """

    horizon_s: float
    n_origins: int
    sigma_pred: float
    rms: float
    coverage: dict
    inflation: dict
    unit: str = "deg"

    def to_dict(self) -> dict:
        def f(x):
            return None if x is None or not math.isfinite(x) else float(x)

        return {"horizon_s": float(self.horizon_s), "n_origins": int(self.n_origins),
                "sigma_pred": f(self.sigma_pred), "rms": f(self.rms), "unit": self.unit,
                "coverage": {k: f(v) for k, v in self.coverage.items()},
                "inflation": {k: {"lambda": f(v[0]), "lo95": f(v[1]), "hi95": f(v[2])}
                              for k, v in self.inflation.items()}}


def coverage_rows(errors_deg, sigma_pred_deg, horizons_s, *, unit: str = "deg") -> list[CoverageRow]:
    """Coverage of the 68 % / 95 % bands and the inflation factors, one row per horizon.

    Parameters
    ----------
    errors_deg : sequence of array_like, one per horizon
        Measured angle errors [deg] at that horizon's independent origins (may be pooled over logs of one
        axis), or one array of shape (n_origins, n_horizons).
    sigma_pred_deg : array_like, shape (n_horizons,)
        Predicted 1-sigma [deg].
    horizons_s : array_like, shape (n_horizons,)
    unit : str
        Unit of the errors (``"deg"``; ``"m/s"`` for velocity errors), carried into the rows.
    """
    h = _horizons(horizons_s)
    if isinstance(errors_deg, np.ndarray) and errors_deg.ndim == 2:
        errors_deg = [errors_deg[:, j] for j in range(errors_deg.shape[1])]
    sig = np.broadcast_to(np.asarray(sigma_pred_deg, dtype=np.float64), h.shape)
    if len(errors_deg) != h.size:
        raise ConfigError(f"{len(errors_deg)} error arrays for {h.size} horizons")
    rows = []
    for j, hj in enumerate(h):
        e = np.asarray(errors_deg[j], dtype=np.float64).ravel()
        ratio = np.abs(e) / sig[j]
        cov = {name: float(np.mean(ratio <= z)) if e.size else math.nan for name, _, z in BANDS}
        infl = {name: inflation_factor(ratio, p, z) for name, p, z in BANDS}
        rows.append(CoverageRow(horizon_s=float(hj), n_origins=int(e.size), sigma_pred=float(sig[j]),
                                rms=float(np.sqrt(np.mean(e**2))) if e.size else math.nan, coverage=cov,
                                inflation=infl, unit=unit))
    return rows


def reduced_model(components, keep=("white", "random_walk")) -> list[dict]:
    """The components a white + random-walk estimator (Kalibr, VINS, ORB-SLAM3) keeps: N and K only.

    Examples
    --------
    >>> reduced_model([{"kind": "white", "arw_dprh": 1.0}, {"kind": "gauss_markov", "tc_s": 10, "sigma_dph": 3}])
    [{'kind': 'white', 'arw_dprh': 1.0}]
    """
    return [c for c in check_components(components) if c["kind"] in keep]


def random_walk_covering(components, horizon_s: float, t_cal_s: float, *, k_bound_dphrh=None,
                         quantity="gyro") -> dict:
    """The random walk K_eff [deg/h^1.5] that, with the model's white noise, covers the whole drift at ``horizon_s``.

    K_eff solves ``K_s^2 (h^3/3 + h^2 T/3) = Var_full(h) - Var_white(h)``: the white + K_eff model predicts the
    same angle-error variance after the calibration as the full model (its flicker / Gauss-Markov /
    quantization / ramp / random-walk parts folded into one random walk).

    ``k_bound_dphrh``: the fit's 95 % upper bound on K when the model has no random walk (the sentence then
    compares K_eff with that bound).

    Returns
    -------
    dict
        ``k_eff_dphrh``, ``k_alone_dphrh`` (the model's own random walk, 0 when it has none), ``ratio`` (K_eff /
        K alone; None without a random walk), ``ratio_to_bound`` (K_eff / ``k_bound_dphrh`` or None),
        ``horizon_s``, ``t_cal_s``, and ``sentence``: "to cover the bias wander over 60 s, use
        gyroscope_random_walk = X rad/s^2/sqrt(Hz) (Y deg/h^1.5): Z x the random walk alone".

    Examples
    --------
    A model that is only a random walk is covered by itself:

    >>> d = random_walk_covering([{"kind": "white", "arw_dprh": 0.1}, {"kind": "random_walk", "rrw_dphrh": 2.0}],
    ...                          60.0, 60.0)
    >>> round(d["k_eff_dphrh"], 9), d["ratio"]
    (2.0, 1.0)
    """
    comps = check_components(components)
    h = float(_horizons(horizon_s)[0])
    T = _t_cal(t_cal_s)
    _, parts = angle_error_variance_deg2(comps, h, T, by_component=True)
    drift = sum(float(p[0]) for c, p in zip(comps, parts) if c["kind"] != "white")
    unit = h**3 / 3.0 + h * h * T / 3.0
    k_eff = math.sqrt(max(drift, 0.0) / unit) * S_PER_H**1.5
    k_alone = math.sqrt(sum(c["rrw_dphrh"] ** 2 for c in comps if c["kind"] == "random_walk"))
    ratio = k_eff / k_alone if k_alone > 0 else None
    accel = _quantity(quantity) == "accel"
    # SI: gyro K [deg/h^1.5] -> rad/s^1.5 = rad/s^2/sqrt(Hz); accel K [(m/s^2)/sqrt(h)] -> m/s^2.5 = m/s^3/sqrt(Hz)
    si = k_eff / 60.0 if accel else k_eff / S_PER_H**1.5 * RAD_PER_DEG
    ku = "(m/s^2)/sqrt(h)" if accel else "deg/h^1.5"
    kb = None if k_bound_dphrh is None or not k_bound_dphrh > 0 else float(k_bound_dphrh)
    to_bound = None if kb is None or ratio is not None else k_eff / kb
    if k_eff == 0.0:
        tail = "the model has no drift beyond its white noise, so nothing to cover (a filter may still want a small K)"
    elif ratio is not None:
        tail = f"{ratio:.3g}× the random walk alone ({k_alone:.3g} {ku})"
    elif to_bound is not None:
        tail = (f"{to_bound:.3g}× the random walk's 95 % upper bound ({kb:.3g} {ku}; the fit has no random "
                "walk of its own)")
    else:
        tail = "the model has no random walk of its own (K alone = 0)"
    name, si_unit = ("accelerometer_random_walk", "m/s^3/sqrt(Hz)") if accel else ("gyroscope_random_walk",
                                                                                  "rad/s^2/sqrt(Hz)")
    sentence = (f"to cover the bias wander over {h:g} s (after a {T:g} s calibration), use {name} = "
                f"{si:.3g} {si_unit} ({k_eff:.3g} {ku}): {tail}")
    return {"k_eff_dphrh": k_eff, "k_alone_dphrh": k_alone, "ratio": ratio, "ratio_to_bound": to_bound,
            "k_bound_dphrh": kb, "horizon_s": h, "t_cal_s": T,
            "k_eff_si": si, "sentence": sentence}


@dataclass
class ConsistencyResult:
    """Coverage of one target model on held-out logs, per axis.

    Attributes
    ----------
    target : str
        Name of the target model (``"full"``, ``"white+RW"``, ``"white+RW covering 60 s"``, ...).
    axes : dict
        Axis -> ``{"components": [...], "rows": [CoverageRow, ...], "n_logs": int}``.
    t_cal_s : float
    horizons_s : tuple of float
    """

    target: str
    axes: dict
    t_cal_s: float
    horizons_s: tuple
    notes: list = field(default_factory=list)

    def worst_inflation(self, axis: str) -> tuple[float, float, str]:
        """(lambda, horizon, band) of the largest inflation factor of one axis over horizons and bands."""
        best = (-math.inf, math.nan, "")
        for row in self.axes[axis]["rows"]:
            for band, (lam, _, _) in row.inflation.items():
                if math.isfinite(lam) and lam > best[0]:
                    best = (lam, row.horizon_s, band)
        return best

    def to_dict(self) -> dict:
        return {"target": self.target, "t_cal_s": self.t_cal_s, "horizons_s": list(self.horizons_s),
                "notes": list(self.notes),
                "axes": {a: {"components": v["components"], "n_logs": v["n_logs"], "quantity": v.get("quantity"),
                             "rows": [r.to_dict() for r in v["rows"]]} for a, v in self.axes.items()}}


def check_consistency(target: str, components_by_axis: dict, held_out: list, *, t_cal_s: float, horizons_s,
                      step_s=None, quantity="gyro") -> ConsistencyResult:
    """Run one target model per axis over held-out static logs and count its coverage.

    Parameters
    ----------
    target : str
        Name of the target model (a label).
    components_by_axis : dict
        Axis name -> components (IEEE-952 units).
    held_out : list of (rate_by_axis, dt_s)
        Each held-out log: ``{axis: rate [deg/h]}`` and its sample interval [s]; origins of all logs are pooled
        per axis.
    t_cal_s, horizons_s
        See :func:`observed_angle_errors_deg`.  A log shorter than ``t_cal_s + h`` gives no origin at horizon h;
        a horizon no log reaches is an :class:`~fogdrift.errors.InsufficientDataError`.
    step_s : float or None
        Origin spacing [s]; default ``t_cal_s + h`` for each horizon (non-overlapping windows, so more origins
        count at short horizons).
    quantity : "gyro", "accel" or dict
        Per axis (a dict) or for all: gyro rates [deg/h] give angle errors [deg], accelerometer specific forces
        [m/s^2] velocity errors [m/s].
    """
    h = _horizons(horizons_s)
    T = _t_cal(t_cal_s)
    axes = {}
    for axis, comps in components_by_axis.items():
        comps = check_components(comps)
        q = quantity.get(axis, "gyro") if isinstance(quantity, dict) else quantity
        sigma = np.sqrt(angle_error_variance_deg2(comps, h, T, quantity=q))
        if not np.all(sigma > 0):
            raise ConfigError(f"axis {axis}: the {target} model predicts no angle error (no components)")
        errs = [[] for _ in h]
        for rates, dt in held_out:
            if axis not in rates:
                raise ConfigError(f"the held-out log has no axis {axis!r} (has {', '.join(rates)})")
            for j, hj in enumerate(h):  # per horizon: origins T_cal + h apart (independent windows)
                try:
                    errs[j].append(observed_angle_errors_deg(rates[axis], dt, T, [hj], step_s=step_s,
                                                             quantity=q)[1][:, 0])
                except InsufficientDataError:  # this log is shorter than T_cal + h: no origin at this horizon
                    errs[j].append(np.empty(0))
        e = [np.concatenate(x) for x in errs]
        empty = [f"{hj:g}" for hj, x in zip(h, e) if x.size == 0]
        if empty:
            longest = max(len(rates[axis]) * dt for rates, dt in held_out)
            raise InsufficientDataError(
                f"no held-out log is long enough for the horizon(s) {', '.join(empty)} s after a {T:g} s calibration "
                f"(the longest is {longest:g} s); shorten {{opt:horizons}} or {{opt:calibration}}")
        axes[axis] = {"components": comps, "rows": coverage_rows(e, sigma, h, unit="m/s" if q == "accel" else "deg"),
                      "n_logs": len(held_out), "quantity": q}
    return ConsistencyResult(target=target, axes=axes, t_cal_s=T, horizons_s=tuple(float(x) for x in h))


# ------------------------------------------------------------------------------------------------------------------
# verdicts in words
# ------------------------------------------------------------------------------------------------------------------
def _fmt(x, d=3) -> str:
    """``d`` significant digits, ``–`` when missing or not finite: :func:`fogdrift._util.fmt_number`."""
    return fmt_number(x, d)


def verdict_line(res, axis: str) -> str:
    """One sentence per target and axis: the inflation the user needs, or that none is needed.

    Inflation is needed when some horizon and band under-covers beyond counting error (the 95 % interval of its
    λ lies above 1); the factor to use is then the largest λ over horizons and bands (nominal coverage at every
    one).  Otherwise: "no inflation needed" (every λ <= 1) or "... within counting error"."""
    rows = res.axes[axis]["rows"]
    cells = [(*row.inflation[b], row.horizon_s, b, row.n_origins) for row in rows for b in row.inflation
             if math.isfinite(row.inflation[b][0])]
    if not cells:
        return f"{axis}: too few origins to count"
    lam, lo, hi, h, band, n = max(cells)
    if lam <= 1.0:
        return (f"{axis}: no inflation needed: the model covers at least nominally at every horizon (largest "
                f"λ {_fmt(lam)} at {h:g} s, {band} band)")
    significant = [c for c in cells if c[1] > 1.0]
    if not significant:
        return (f"{axis}: no inflation needed within counting error: every λ's 95 % interval reaches 1 (largest "
                f"λ {_fmt(lam)} at {h:g} s, {band} band, {n} origins, interval from {_fmt(lo)})")
    sig = max(significant, key=lambda c: c[1])
    where = "" if sig[3:5] == (h, band) else (f"; beyond counting error at {sig[3]:g} s, {sig[4]} band: λ "
                                              f"{_fmt(sig[0])} [{_fmt(sig[1])}, {_fmt(sig[2])}]")
    return (f"{axis}: inflate the variances by λ = {_fmt(lam)} ({h:g} s, {band} band, 95 % [{_fmt(lo)}, "
            f"{_fmt(hi)}], {n} origins{where}): multiply N, K, σ by {_fmt(math.sqrt(lam))}")


def summary_cell(res, axis: str) -> str:
    """``1.67 [1.14, 2.46]`` when inflation is needed (the rule of :func:`verdict_line`), else ``none (largest
    1.19)``."""
    cells = [(*row.inflation[b],) for row in res.axes[axis]["rows"] for b in row.inflation
             if math.isfinite(row.inflation[b][0])]
    if not cells:
        return "–"
    lam, lo, hi = max(cells)
    if lam <= 1.0 or not any(c[1] > 1.0 for c in cells):
        return f"none (largest {_fmt(lam)})"
    return f"{_fmt(lam)} [{_fmt(lo)}, {_fmt(hi)}]"
