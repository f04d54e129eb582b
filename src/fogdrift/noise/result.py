"""Result types of the noise identification: one coefficient (:class:`NoiseTerm`) and the whole fit
(:class:`NoiseFit`), JSON-serialisable, with the fitted curve available at any tau."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..units import name_keys
from .terms import laws_of, markov_shape, periodic_shape, power_terms, term_table

__all__ = ["NoiseTerm", "NoiseFit", "TERM_STATUSES"]

#: What a coefficient's ``status`` can be (see :class:`NoiseTerm`).
TERM_STATUSES = ("resolved", "unresolved", "absent", "not_estimable", "no_fit")


def _f(x):
    return None if x is None else float(x)


@dataclass(frozen=True)
class NoiseTerm:
    """One IEEE-952 coefficient.

    Attributes
    ----------
    name : str
        ``"Q"``, ``"N"``, ``"B"``, ``"K"`` or ``"R"``.
    value : float or None
        Estimate in ``unit`` from the selected model; None when the term is not in it.
    unit : str
    lo95, hi95 : float or None
        95 % interval over every plausible model (``lo95 = 0``: the data allow the term to vanish).  For an
        absent term ``hi95`` is a one-sided 95 % upper bound.
    status : str
        ``"resolved"`` (in the selected model, every plausible model needs it, lower bound > 0);
        ``"unresolved"`` (in the selected model, but its interval reaches 0); ``"absent"`` (not in the selected
        model); ``"not_estimable"`` (the data or the statistic cannot support a number; ``hi95`` may bound it);
        ``"no_fit"`` (no model fits the curve: ``value`` is the best candidate's, no result; ``hi95`` is the bound
        the measured curve sets on the term alone).
    reason : str
        Empty for a resolved term; otherwise the real cause, in words.
    """

    name: str
    value: float | None
    unit: str
    lo95: float | None
    hi95: float | None
    status: str
    reason: str

    @property
    def estimable(self) -> bool:
        """True when a value is reported (resolved or unresolved)."""
        return self.status in ("resolved", "unresolved")

    @property
    def resolved(self) -> bool:
        return self.status == "resolved"

    def to_dict(self) -> dict:
        out = {"name": self.name, "value": _f(self.value), "unit": self.unit, "lo95": _f(self.lo95),
               "hi95": _f(self.hi95), "status": self.status, "estimable": self.estimable, "reason": self.reason}
        if self.unit == "ug":  # an accelerometer's bias instability: also in m/s^2 (1 ug = 9.80665e-6 m/s^2)
            g = 9.80665e-6
            out["si"] = {"unit": "m/s^2", "value": None if self.value is None else self.value * g,
                         "lo95": None if self.lo95 is None else self.lo95 * g,
                         "hi95": None if self.hi95 is None else self.hi95 * g}
        return out


@dataclass
class NoiseFit:
    """Result of :func:`fogdrift.noise.fit_noise`.

    Attributes
    ----------
    statistic : str
        ``"adev"``, ``"hdev"`` or ``"mdev"``: whose laws were fitted.
    dt_s : float
        Sample interval [s].
    terms : dict[str, NoiseTerm]
        Q [urad], N [deg/sqrt(h)], B [deg/h], K [deg/h^1.5], R [deg/h^2].
    selected : tuple of str
        Terms of the selected model.
    A : ndarray, shape (5,)
        Fitted law coefficients of Q, N, B, K, R (0 for terms not in the model), variance in (deg/h)^2.
    candidates : list of dict
        Every candidate model: terms, chi2, IC, delta IC, plausible.
    plausible : list of str
        Models within the IC window of the best ("N+K", ...).
    fit_tau_s, fit_var, model_var, z : ndarray
        The fitted working points, their measured and fitted variance and standardized (normal-score) residuals.
    chi2, dof, chi2_red, p_value : float
        Goodness of fit (the whitened score objective is chi-squared with ``dof`` degrees of freedom when the
        model holds).
    quality : str
        ``"good"`` (p >= 0.01), ``"acceptable"`` (chi2_red <= 4) or ``"poor"``.
    inflation : float
        Factor ``max(1, chi2_red)`` applied to the profile thresholds (intervals widened by its square root).
    excluded : list of dict
        Tau ranges left out of the fit and why.
    notes : list of str
        Fit-quality and other statements, in words.
    b_min : dict
        Bias instability read at the minimum of the fitted ADEV (IEEE-952 practice), with its tau.
    readouts : dict
        Term -> :class:`fogdrift.noise.readouts.Readout`: slope read-outs, a labelled cross-check.
    n_samples : int
        Record length the curve came from.
    outliers : dict or None
        The outlier report of the rate that was analysed, when the caller attached it.
    shaped : dict
        The Annex C terms that are not power laws, when they were candidates: ``"S"`` (``A`` = Omega0^2
        [(deg/h)^2], ``lines`` [(Hz, relative power)], ``freq_hz`` of the reference line, ``description``) and
        ``"M"`` (``A`` = (q_c T_c)^2 [(deg/h)^2 s], ``tc_s`` with its 95 % interval ``tc_lo95_s``/``tc_hi95_s``
        [s], ``sigma_dph`` = q_c sqrt(T_c/2) [deg/h]).  Their coefficients are ``terms["S"]`` (Omega0 [deg/h]) and
        ``terms["M"]`` (q_c [deg/h/sqrt(s)]).
    no_fit : dict or None
        Set when no candidate fits (chi2_red above :data:`~fogdrift.noise.POOR_CHI2_RED` and the model misses
        points outside their own 95 % intervals): ``tau_min_s``, ``tau_max_s``, ``miss_tau_s``,
        ``best_candidate``.  The coefficients are then no result: tables show their upper bounds only.
    """

    statistic: str
    dt_s: float
    terms: dict
    selected: tuple
    A: np.ndarray
    candidates: list
    plausible: list
    fit_tau_s: np.ndarray
    fit_var: np.ndarray
    model_var: np.ndarray
    z: np.ndarray
    chi2: float
    dof: int
    chi2_red: float
    p_value: float
    quality: str
    inflation: float
    excluded: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    b_min: dict = field(default_factory=dict)
    readouts: dict = field(default_factory=dict)
    n_samples: int = 0
    outliers: dict | None = None
    shaped: dict = field(default_factory=dict)
    no_fit: dict | None = None
    quantity: str = "angular_rate"

    # -- the fitted curve ------------------------------------------------------------------------------------
    @property
    def fitted_terms(self) -> tuple:
        return tuple(self.selected)

    @property
    def tau_min_s(self) -> float:
        return float(self.fit_tau_s[0]) if len(self.fit_tau_s) else math.nan

    @property
    def tau_max_s(self) -> float:
        return float(self.fit_tau_s[-1]) if len(self.fit_tau_s) else math.nan

    def _x2(self, name) -> float:
        """Squared coefficient of a term in its Allan-law unit."""
        law = laws_of(self.statistic).get(name)
        if law is None:
            return 0.0
        names = power_terms()
        if name not in names or names.index(name) >= len(self.A):
            return 0.0
        return float(self.A[names.index(name)]) / law.scale(self.dt_s)

    def _term_var(self, name, tau_s, statistic) -> np.ndarray:
        law = laws_of(statistic).get(name)
        t = np.asarray(tau_s, dtype=np.float64)
        if law is None:
            return np.zeros_like(t)
        return self._x2(name) * law.scale(self.dt_s) * law.shape(t, self.dt_s)

    def _shaped_var(self, name, tau_s, statistic) -> np.ndarray:
        """Variance [(deg/h)^2] of the shaped term S or M at ``tau_s`` (0 when it is not in the model)."""
        t = np.asarray(tau_s, dtype=np.float64)
        info = self.shaped.get(name) or {}
        if name not in self.selected or not info.get("A"):
            return np.zeros_like(t)
        if name == "S":
            return info["A"] * periodic_shape(t, info["lines"], self.dt_s, statistic)
        return info["A"] * markov_shape(t, info["tc_s"], statistic, self.dt_s)

    def model_dev_dph(self, tau_s, statistic=None) -> np.ndarray:
        """Fitted deviation [deg/h] of ``statistic`` (default: the fitted one) at ``tau_s`` [s]: every selected term,
        the shaped S and M included (the curve of the printed model)."""
        st = statistic or self.statistic
        return np.sqrt(sum(self._term_var(n, tau_s, st) for n in power_terms())
                       + self._shaped_var("S", tau_s, st) + self._shaped_var("M", tau_s, st))

    def term_dev_dph(self, name, tau_s, statistic=None) -> np.ndarray:
        """Deviation [deg/h] of one term alone (its asymptote on the log-log plot)."""
        if name in ("S", "M"):
            return np.sqrt(self._shaped_var(name, tau_s, statistic or self.statistic))
        return np.sqrt(self._term_var(name, tau_s, statistic or self.statistic))

    def model_adev_dph(self, tau_s) -> np.ndarray:
        return self.model_dev_dph(tau_s, "adev")

    def term_adev_dph(self, name, tau_s) -> np.ndarray:
        return self.term_dev_dph(name, tau_s, "adev")

    def coefficient(self, name) -> float:
        """The term's coefficient in its reported unit from ``A`` (0 when absent)."""
        return term_table(self.quantity)[name].to_unit * math.sqrt(self._x2(name))

    # -- serialisation ------------------------------------------------------------------------------------------
    def to_dict(self) -> dict:
        return {
            "statistic": self.statistic,
            "dt_s": float(self.dt_s),
            "n_samples": int(self.n_samples),
            "selected": list(self.selected),
            "terms": {k: v.to_dict() for k, v in self.terms.items()},
            "A": [float(a) for a in self.A],
            "candidates": self.candidates,
            "plausible": list(self.plausible),
            "fit": {
                "tau_min_s": self.tau_min_s,
                "tau_max_s": self.tau_max_s,
                "points": [name_keys({"tau_s": float(t), "var_dph2": float(v), "model_var_dph2": float(m),
                                      "z": float(z)}, self.quantity)
                           for t, v, m, z in zip(self.fit_tau_s, self.fit_var, self.model_var, self.z)],
                "chi2": float(self.chi2), "dof": int(self.dof), "chi2_red": float(self.chi2_red),
                "p_value": float(self.p_value), "quality": self.quality,
                "interval_inflation": float(self.inflation),
            },
            "excluded": self.excluded,
            "notes": list(self.notes),
            "b_min": self.b_min,
            "readouts": {k: v.to_dict() for k, v in self.readouts.items()},
            "outliers": None if self.outliers is None else name_keys(self.outliers, self.quantity),
            "shaped": {k: name_keys({kk: vv for kk, vv in v.items() if not isinstance(vv, np.ndarray)}, self.quantity)
                       for k, v in self.shaped.items()},
            "no_fit": self.no_fit,
            **({"quantity": self.quantity} if self.quantity != "angular_rate" else {}),
        }
