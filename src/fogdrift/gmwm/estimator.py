"""The GMWM estimator: fit a latent-process model to a Haar wavelet variance.

``theta_hat = argmin_theta (nu_hat - nu(theta))^T Omega (nu_hat - nu(theta))`` ([GMWM2013]_;
[GMWM]_ §3), computed as a Cholesky-whitened nonlinear least-squares problem
(trust-region reflective, tolerances 1e-12: the algorithm of ``scipy.optimize.least_squares``, run compiled by
:mod:`fogdrift.gmwm.solver`, SciPy itself where that hands a run back) in the free
parameters ``z = log(theta)`` (``log beta`` for a GM, so ``1 - phi`` is never formed).

Weighting steps: step 1 with ``Omega_1 = diag(eta3_j / (2 nu_hat_j^2))`` (the eta3
variance; or the nonparametric ACVS variance if the WV carries it and
``weights="nonparametric"``), step 2 with ``Omega_2 = V(theta_1)^-1``, the model-based
covariance of :mod:`fogdrift.gmwm.covariance` (divided by the efficiency for a robust WV),
restarted from ``theta_1``; by default up to two more updates ``V(theta_2)``,
``V(theta_3)`` (iterated GMWM).  Weights built from ``nu_hat`` itself favour scales that
came out low (badly so at the last, eta ~ 1, scale); the model-based steps remove that.

Starting values are deterministic ([GMWM]_ §3): WN from ``tau_1 nu_1`` (the minimum of
``tau_j nu_j`` over the lower half of the scales when QN is present), RW from
``12 nu_J / tau_J``, QN from the excess at ``tau_1``, DR from ``4 sqrt(nu_J) / tau_J``,
FLICKER from the minimum of the curve, and every placement of the GM peaks
(``beta = 3.785 / tau_j*``, height from the residual curve) over the scales; all candidates
are ranked by the step-1 objective and the best ``n_starts`` (plus the best with RW and QN
shrunk 0.3x) are optimised.

Standard errors: delta (sandwich) method in ``z``,
``Cov(z) = (A^T Omega A)^-1 A^T Omega V Omega A (A^T Omega A)^-1`` with ``A = d nu / d z^T``
(analytic but for the GM ``beta`` column: a central difference, step 1e-3 in ``log beta``); with
``Omega = V^-1`` it is ``(A^T V^-1 A)^-1``.
95 % intervals ``exp(z +- 1.96 se)``.  Weakly identified components get optimistic SEs;
``n_boot > 0`` adds parametric-bootstrap percentile intervals.

J-test: under ``Omega = V^-1``, ``Q(theta_hat) ~ chi2(J - p)``.  It over-rejects (V is
evaluated at ``theta_1``, the asymptotics are large-scale approximations): about 15 % of
correct models fall below p = 0.05 in the notes' simulation ([GMWM]_ §3).  Read a small
p-value as "look at the residuals", not as a verdict.

WIC ([GMWM]_ §5): ``Q(theta_hat) + 2 tr(Omega A (A^T Omega A)^-1 A^T Omega V)``, which is
``Q + 2p`` when ``Omega = V^-1``.

References
----------
.. [GMWM2013] S. Guerrier, J. Skaloud, Y. Stebler, M.-P. Victoria-Feser, "Wavelet-variance-based
   estimation for composite stochastic processes", JASA 108(503), 2013, 1021-1030.
.. [GMWM] fogdrift GMWM method notes, ``shared/docs/gmwm-notes.md`` §3, §5, R6 of §7.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy import linalg
from scipy.linalg import lapack

from ..errors import ConfigError, FogdriftError, FogdriftWarning, InsufficientDataError, NotFittedError
from ..noise.discrepancy import discrepancy_relcov
from ..noise.distributions import chi2_sf
from .covariance import model_wvar_covariance
from .ieee import to_ieee
from .processes import LatentModel, parse_model
from .simulate import simulate_latent
from .solver import FALLBACK, trf_solve
from .starts import bounds as _bounds
from .starts import starts as _starts
from .wvar import WvarResult, haar_wvar

__all__ = ["GMWMFit", "GMWM", "gmwm_fit", "Whitener", "fit_covariance", "sandwich"]

_Z95 = 1.959963984540054


# ----------------------------------------------------------------------------------------
# Weighting
# ----------------------------------------------------------------------------------------
class Whitener:
    """``r = W d`` with ``W^T W = Omega``: diagonal weights or the inverse Cholesky factor of V.

    Parameters
    ----------
    V : ndarray (J, J), optional
        Covariance; ``Omega = V^-1`` (Cholesky ``V = C C^T``, ``W = C^-1``).
    weights : ndarray (J,), optional
        Diagonal ``Omega`` (``W = sqrt(weights)``).
    source : str
        How Omega was obtained (recorded in the fit).
    """

    def __init__(self, *, V=None, weights=None, source=""):
        self.source = source
        if (V is None) == (weights is None):
            raise ConfigError("give exactly one of V and weights")
        if weights is not None:
            self.w = np.sqrt(np.asarray(weights, dtype=np.float64))
            self.C = None
            self.V = np.diag(1.0 / self.w**2)
        else:
            V = np.asarray(V, dtype=np.float64)
            V = 0.5 * (V + V.T)
            self.V = V
            self.w = None
            d = np.sqrt(np.diag(V))
            corr = V / np.outer(d, d)
            try:
                cc = linalg.cholesky(corr, lower=True)
            except linalg.LinAlgError:
                ev, evec = np.linalg.eigh(corr)
                ev = np.maximum(ev, 1e-10 * ev.max())
                corr = (evec * ev) @ evec.T
                cc = linalg.cholesky(corr, lower=True)
                warnings.warn("the WV covariance was not positive definite; its eigenvalues were clipped "
                              "at 1e-10 of the largest", FogdriftWarning, stacklevel=3)
            self.C = cc * d[:, None]
            # explicit inverse: J is small, and plain einsum avoids BLAS thread start-up per call
            cinv, info = lapack.dtrtri(self.C, lower=1)  # (solve_triangular on I starts BLAS threads)
            self.Cinv = np.tril(cinv) if info == 0 else linalg.solve_triangular(self.C, np.eye(d.size), lower=True)

    def __call__(self, d):
        d = np.asarray(d, dtype=np.float64)
        if self.C is None:
            return self.w[:, None] * d if d.ndim == 2 else self.w * d
        if d.ndim == 2:
            return np.einsum("ij,jk->ik", self.Cinv, d)
        return np.einsum("ij,j->i", self.Cinv, d)

    def restrict(self, idx) -> "Whitener":
        """The whitener of the sub-vector ``idx`` (sub-matrix of V)."""
        if self.C is None:
            return Whitener(weights=self.w[idx] ** 2, source=self.source)
        return Whitener(V=self.V[np.ix_(idx, idx)], source=self.source)


def eta3_weights(wv: WvarResult) -> np.ndarray:
    """Step-1 weights ``eta3_j / (2 nu_hat_j^2)`` (inverse eta3 variance, times the efficiency)."""
    return wv.eta3 * wv.efficiency / (2.0 * wv.nu2_dph2**2)


# ----------------------------------------------------------------------------------------
# Result
# ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class GMWMFit:
    """Result of :func:`gmwm_fit` (units: deg/h per sample; tau in samples, scale in s).

    Attributes
    ----------
    model : str
        Canonical model string.
    param_names : tuple of str
    theta : ndarray (p,)
        Natural parameters (variances in (deg/h)^2, ``beta`` per sample, ``omega`` deg/h per sample).
    theta_lo95, theta_hi95 : ndarray (p,)
        Delta-method 95 % intervals ``exp(z +- 1.96 se_z)``.
    z, se_z : ndarray (p,)
        Free parameters ``log theta`` and their standard errors.
    cov_z : ndarray (p, p)
    q : float
        Objective at the optimum (with the final Omega).
    df : int
        ``J - p``.
    j_pvalue : float
        ``P(chi2_df > q)`` (NaN for df <= 0); over-rejects, see module notes.
    penalty : float
        WIC optimism ``2 tr(Omega A (A^T Omega A)^-1 A^T Omega V)``.
    wic : float
        ``q + penalty``.
    level, tau_samples : ndarray of int (J,)
        Scales used.
    scale_s, nu2_hat, nu2_fit, sd_nu2 : ndarray (J,)
        Scales in s, observed and fitted WV ((deg/h)^2), and the SD of the observed WV (from V).
    z_resid : ndarray (J,)
        Standardised residuals ``(nu_hat - nu_fit) / sd_nu2``.
    V : ndarray (J, J)
        Covariance of the WV estimates used for the SEs.
    omega_source : str
    theta_step1 : ndarray (p,)
    q_step1 : float
    steps : int
    dt_s : float
    n_samples : int
    converged : bool
    at_bound : tuple of str
        Parameters whose free value ended within 1e-3 of a bound.
    boot_lo95, boot_hi95 : ndarray or None
        Parametric-bootstrap percentile intervals (natural parameters), if requested.
    n_boot : int
    """

    model: str
    param_names: tuple
    theta: np.ndarray
    theta_lo95: np.ndarray
    theta_hi95: np.ndarray
    z: np.ndarray
    se_z: np.ndarray
    cov_z: np.ndarray
    q: float
    df: int
    j_pvalue: float
    penalty: float
    wic: float
    level: np.ndarray
    tau_samples: np.ndarray
    scale_s: np.ndarray
    nu2_hat: np.ndarray
    nu2_fit: np.ndarray
    sd_nu2: np.ndarray
    z_resid: np.ndarray
    V: np.ndarray = field(repr=False)
    omega_source: str = ""
    theta_step1: np.ndarray = field(default=None, repr=False)
    q_step1: float = float("nan")
    steps: int = 2
    dt_s: float = 1.0
    n_samples: int = 0
    converged: bool = True
    at_bound: tuple = ()
    boot_lo95: np.ndarray | None = None
    boot_hi95: np.ndarray | None = None
    n_boot: int = 0
    #: Hansen's J against the sampling error alone (``j_pvalue`` is its chi-squared p-value); ``q`` is the
    #: objective under the covariance with the model-discrepancy allowance, which the WIC uses.
    j_stat: float = float("nan")

    @property
    def latent_model(self) -> LatentModel:
        """The fitted :class:`LatentModel`."""
        return parse_model(self.model)

    def params(self) -> dict:
        """``{name: value}`` of the natural parameters."""
        return {n: float(v) for n, v in zip(self.param_names, self.theta)}

    def component_wv(self, tau_samples=None) -> np.ndarray:
        """WV of each component at ``tau_samples`` (default: the fitted scales), (n_comp, n_tau)."""
        tau = self.tau_samples if tau_samples is None else np.asarray(tau_samples)
        return self.latent_model.wv_components(self.theta, tau)

    def to_dict(self) -> dict:
        """JSON-serialisable dict."""
        def arr(a):
            return None if a is None else np.asarray(a, dtype=float).tolist()

        return {
            "model": self.model, "param_names": list(self.param_names),
            "theta": arr(self.theta), "theta_lo95": arr(self.theta_lo95), "theta_hi95": arr(self.theta_hi95),
            "z": arr(self.z), "se_z": arr(self.se_z), "cov_z": arr(self.cov_z),
            "q": float(self.q), "df": int(self.df), "j_stat": float(self.j_stat), "j_pvalue": float(self.j_pvalue),
            "penalty": float(self.penalty), "wic": float(self.wic),
            "level": [int(v) for v in self.level], "tau_samples": [int(v) for v in self.tau_samples],
            "scale_s": arr(self.scale_s), "nu2_hat_dph2": arr(self.nu2_hat), "nu2_fit_dph2": arr(self.nu2_fit),
            "sd_nu2_dph2": arr(self.sd_nu2), "z_resid": arr(self.z_resid),
            "omega_source": self.omega_source, "theta_step1": arr(self.theta_step1),
            "q_step1": float(self.q_step1), "steps": int(self.steps), "dt_s": float(self.dt_s),
            "n_samples": int(self.n_samples), "converged": bool(self.converged),
            "at_bound": list(self.at_bound), "boot_lo95": arr(self.boot_lo95), "boot_hi95": arr(self.boot_hi95),
            "n_boot": int(self.n_boot),
        }


# ----------------------------------------------------------------------------------------
# Problem: residuals, Jacobian, bounds, starts
# ----------------------------------------------------------------------------------------
class _Problem:
    def __init__(self, model: LatentModel, nu_hat, tau, whitener: Whitener):
        self.model = model
        self.nu_hat = np.asarray(nu_hat, dtype=np.float64)
        self.tau = np.asarray(tau, dtype=np.float64)
        self.W = whitener
        self.lo, self.hi = _bounds(model, self.nu_hat, self.tau)
        self._ev = model.evaluator(self.tau)  # the WV and Jacobian at tau for the optimiser (_fun, _jac)
        # the compiled solver's whitening: diagonal weights, or C^-1 (an empty array marks the other)
        self._compiled = model._compiled_ok
        self._w = whitener.w if whitener.C is None else np.empty(0)
        self._cinv = np.empty((0, 0)) if whitener.C is None else np.ascontiguousarray(whitener.Cinv)

    # The optimiser's residuals and Jacobian (:meth:`solve`): the same values as :meth:`resid` and :meth:`jac`
    # (same operations: tested bit for bit), without their per-call overhead (argument conversion, validation of
    # theta, two np.errstate contexts per call: :meth:`solve` enters one for the whole run).
    def _fun(self, z):
        nu = self._ev.wv(np.exp(z))
        if not np.isfinite(nu).all():
            return np.full(self.nu_hat.size, 1e10)
        d = self.nu_hat - nu
        W = self.W
        return W.w * d if W.C is None else np.einsum("ij,j->i", W.Cinv, d)

    def _jac(self, z):
        a = self._ev.jac(np.exp(z))
        if not np.isfinite(a).all():
            a = np.nan_to_num(a, nan=0.0, posinf=0.0, neginf=0.0)
        W = self.W
        return -(W.w[:, None] * a if W.C is None else np.einsum("ij,jk->ik", W.Cinv, a))

    def nu(self, z):
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            return self.model.wv(np.exp(z), self.tau)

    def resid(self, z):
        nu = self.nu(z)
        if not np.all(np.isfinite(nu)):
            return np.full(self.nu_hat.size, 1e10)
        return self.W(self.nu_hat - nu)

    def jac_nu(self, z):
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            return self.model.wv_jacobian(np.exp(np.asarray(z, dtype=np.float64)), self.tau)

    def jac(self, z):
        a = self.jac_nu(z)
        if not np.all(np.isfinite(a)):
            a = np.nan_to_num(a, nan=0.0, posinf=0.0, neginf=0.0)
        return -self.W(a)

    def q(self, z) -> float:
        r = self.resid(z)
        return float(r @ r)

    def solve(self, z0, max_nfev=2000):
        """Minimise Q from ``z0`` (clipped into the bounds): ``(z, q, converged)``.

        The compiled trust-region-reflective solver (:func:`fogdrift.gmwm.solver.trf_solve`, the algorithm of
        ``least_squares(method="trf", x_scale="jac")``); :meth:`solve_scipy` where it hands the run back undecided
        (a start or step where SciPy raises) or the model has a registered process without a compiled kernel.
        """
        if self._compiled:
            try:
                x, cost, status, _ = trf_solve(self._ev, self._w, self._cinv, self.nu_hat, self.lo, self.hi,
                                               self.clipped(z0), max_nfev)
            except ValueError:  # an SVD that did not converge (numpy.linalg.LinAlgError): SciPy decides
                status = FALLBACK
            if status != FALLBACK:
                return x, float(2.0 * cost), bool(status > 0)
        return self.solve_scipy(z0, max_nfev)

    def solve_scipy(self, z0, max_nfev=2000):
        """:meth:`solve` by ``scipy.optimize.least_squares`` (trf, bounds, ``x_scale="jac"``, tolerances 1e-12)."""
        from scipy import optimize  # only for the fallback: importing scipy.optimize costs a command ~0.5 s

        z0 = self.clipped(z0)
        with warnings.catch_warnings(), np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            try:
                res = optimize.least_squares(self._fun, z0, jac=self._jac, bounds=(self.lo, self.hi), method="trf",
                                             xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=max_nfev, x_scale="jac")
            except ValueError:  # the model gave no finite Jacobian on the way (a column scaled by "jac" became 0):
                q0 = self.q(z0)  # a failed start, not a failed fit: the other starts decide
                return z0, (q0 if np.isfinite(q0) else np.inf), False
        return res.x, float(2.0 * res.cost), bool(res.success)

    def clipped(self, z0) -> np.ndarray:
        """The start :meth:`solve` really uses: ``z0`` moved 1e-6 inside the bounds."""
        return np.clip(np.asarray(z0, dtype=np.float64), self.lo + 1e-6, self.hi - 1e-6)


def sandwich(A, whitener: Whitener, V):
    """Cov(z) of the GMWM's free parameters ``z = log theta`` and the WIC penalty.

    ``A``: the Jacobian ``d nu / d z`` (J x p) [(deg/h)^2]; ``whitener``: the weighting ``Omega``; ``V``: the
    covariance of the WV estimates [(deg/h)^4].  ``Cov(z) = (A' Omega A)^-1 A' Omega V Omega A (A' Omega A)^-1``
    (``(A' V^-1 A)^-1`` when ``Omega = V^-1``); a direction the scales do not identify gets infinite variance.
    """
    WA = whitener(A)
    u, s, vt = np.linalg.svd(WA, full_matrices=False)
    good = s > s[0] * 1e-12 if s.size and s[0] > 0 else np.zeros_like(s, dtype=bool)
    sinv = np.where(good, 1.0 / np.where(good, s, 1.0), 0.0)
    bread = (vt.T * sinv**2) @ vt  # (A^T Omega A)^-1
    # meat: A^T Omega V Omega A = WA^T (W V W^T) WA
    WV = whitener(whitener(V).T).T  # W V W^T
    meat = WA.T @ WV @ WA
    cov = bread @ meat @ bread
    proj = u[:, good] @ u[:, good].T  # WA (WA^T WA)^-1 WA^T
    penalty = 2.0 * float(np.trace(proj @ WV))
    if not np.all(good):
        cov = cov.copy()
        bad_dirs = vt[~good]
        for i in range(cov.shape[0]):
            if np.any(np.abs(bad_dirs[:, i]) > 1e-6):
                cov[i, i] = np.inf
    return cov, penalty


# ----------------------------------------------------------------------------------------
# The fit
# ----------------------------------------------------------------------------------------
def _check_wv(wvar) -> WvarResult:
    if not isinstance(wvar, WvarResult):
        raise ConfigError(f"expected a WvarResult (from haar_wvar or from_curve), got {type(wvar).__name__}")
    if wvar.nu2_dph2.ndim != 1:
        raise ConfigError(
            f"the wavelet variance has {wvar.n_axes} axes {list(wvar.axis_names)}; fit one at a time: "
            "wvar.axis(k)"
        )
    if np.any(~np.isfinite(wvar.nu2_dph2)) or np.any(wvar.nu2_dph2 <= 0):
        raise InsufficientDataError("every wavelet variance must be finite and > 0 (a constant or quantised "
                                    "series can give 0); exclude those scales with {opt:scales}")
    return wvar


def _scale_index(wvar: WvarResult, scales) -> np.ndarray:
    J = len(wvar)
    if scales is None:
        return np.arange(J)
    s = np.asarray(scales)
    if s.dtype == bool:
        if s.shape != (J,):
            raise ConfigError(f"a boolean scales mask needs {J} entries, got {s.shape}")
        idx = np.flatnonzero(s)
    else:
        lv = [int(v) for v in np.ravel(s)]
        pos = {int(l): i for i, l in enumerate(wvar.level)}
        bad = [l for l in lv if l not in pos]
        if bad:
            raise ConfigError(f"scales must be levels in {wvar.level.tolist()}, got {bad}")
        idx = np.array(sorted(pos[l] for l in lv), dtype=np.int64)
    return idx


def fit_covariance(model, theta, tau_samples, n_coef, *, efficiency=1.0, allowance=True) -> np.ndarray:
    """The covariance the GMWM weights and forms its standard errors with [(deg/h)^4], (J, J).

    The model's sampling covariance of the Haar WV estimates at ``tau_samples`` [samples] with ``n_coef``
    coefficients each (:func:`~fogdrift.gmwm.covariance.model_wvar_covariance`), divided by the estimator's
    ``efficiency`` (1 for the classical WV), plus (``allowance``) the model-discrepancy allowance
    (:mod:`fogdrift.noise.discrepancy`, the same one the Allan fit uses).  ``model``: string or
    :class:`~fogdrift.gmwm.processes.LatentModel`; ``theta``: its natural parameters.
    """
    mdl = parse_model(model)
    tau = np.asarray(tau_samples)
    V = model_wvar_covariance(mdl, theta, tau, np.asarray(n_coef)) / efficiency
    if not allowance:
        return V
    nu = mdl.wv(np.asarray(theta, dtype=np.float64), tau.astype(np.float64))
    return V + discrepancy_relcov(tau) * np.outer(nu, nu)


def _model_V(model: LatentModel, theta, wv: WvarResult, idx, allowance=True) -> np.ndarray:
    """Covariance of the WV estimates at ``idx`` under the model (:func:`fit_covariance` of ``wv``'s scales)."""
    return fit_covariance(model, theta, wv.tau_samples[idx], wv.n_coef[idx], efficiency=wv.efficiency,
                          allowance=allowance)


def _j_statistic(mdl: LatentModel, theta, wv: WvarResult, idx, resid) -> float:
    """Hansen's J of the final fit against the sampling error alone (no allowance): a specification test of the
    model as a textbook sum; the fit and its checks are judged with the allowance."""
    Vs = _model_V(mdl, theta, wv, idx, allowance=False)
    try:
        w = Whitener(V=Vs)(resid)
        return float(w @ w)
    except (FogdriftError, np.linalg.LinAlgError, ValueError):
        return float("nan")


def _best_solution(prob: _Problem, starts, n_keep, screen_nfev=150):
    """Optimise from each start with a small budget (most good starts converge in < 50
    evaluations; degenerate ones creep towards a bound for thousands), then polish the best
    with the full budget.  Returns the best (q, z, converged) and all (q, z, ok) sorted."""
    sols, done = [], {}
    for z0 in starts[:n_keep]:
        # a start equal (once clipped into the bounds) to one already run gives the same run: not run again
        key = prob.clipped(z0).tobytes()
        if key not in done:
            done[key] = prob.solve(z0, max_nfev=screen_nfev)
        z, q, ok = done[key]
        sols.append((q, z, ok))
    sols.sort(key=lambda s: s[0])
    q, z, ok = sols[0]
    if not ok:
        z, q, ok = prob.solve(z, max_nfev=2000)
        sols[0] = (q, z, ok)
    return (q, z, ok), sols


def _prepare(wvar, model, scales, weights):
    wv = _check_wv(wvar)
    mdl = parse_model(model)
    if weights not in ("eta3", "nonparametric"):
        raise ConfigError(f"weights must be 'eta3' or 'nonparametric', got {weights!r}")
    idx = _scale_index(wv, scales)
    J = idx.size
    if J < mdl.n_params + 1:
        raise InsufficientDataError(
            f"{mdl.name} has {mdl.n_params} parameters but only {J} scales are used; need at least "
            f"{mdl.n_params + 1} (use a longer record, fewer components or more {{opt:scales}})",
            needed=mdl.n_params + 1, got=J,
        )
    return wv, mdl, idx


def _step1(wv: WvarResult, mdl: LatentModel, idx, *, weights="eta3", n_starts=5, start=None):
    """Step 1 (diagonal weights): returns (theta1, q1, [(q, z, ok), ...] sorted, Whitener)."""
    nu_hat = wv.nu2_dph2[idx]
    tau = wv.tau_samples[idx].astype(np.float64)
    if weights == "nonparametric":
        if wv.var_nonparam_dph4 is None:
            raise ConfigError("weights='nonparametric' needs haar_wvar(..., nonparametric_var=True)")
        w1 = 1.0 / wv.var_nonparam_dph4[idx]
        src1 = "nonparametric ACVS variance"
    else:
        w1 = eta3_weights(wv)[idx]
        src1 = "eta3"
    W1 = Whitener(weights=w1, source=src1)
    prob1 = _Problem(mdl, nu_hat, tau, W1)
    starts = _starts(mdl, nu_hat, tau, w1)
    if start is not None:
        s0 = np.asarray(start, dtype=np.float64)
        if s0.shape != (mdl.n_params,) or np.any(s0 <= 0):
            raise ConfigError(f"start must be {mdl.n_params} values > 0 {mdl.param_names}")
        starts = [s0] + starts
    n_starts = max(0 if start is not None else 1, int(n_starts))
    zstarts = [np.log(s) for s in starts]
    keep = zstarts[:n_starts + 1] if n_starts else zstarts[:1]
    (q1, z1, ok1), sols1 = _best_solution(prob1, keep, len(keep))
    theta1 = mdl.sort_gm(np.exp(z1))
    return theta1, q1, sols1, W1, ok1


def _finish(wv: WvarResult, mdl: LatentModel, idx, theta1, q1, sols1, W1, ok1, *, V=None, steps=4,
            omega_source=None, n_boot=0, seed=None, n_starts=5) -> GMWMFit:
    """Final step(s): Omega = V^-1 for a given V, else ``steps - 1`` model-V updates; SEs, J-test, WIC."""
    nu_hat = wv.nu2_dph2[idx]
    tau = wv.tau_samples[idx].astype(np.float64)
    J = idx.size
    z1 = np.log(theta1)
    if V is not None:
        Vf = np.asarray(V, dtype=np.float64)
        if Vf.shape != (J, J):
            raise ConfigError(f"V must be ({J}, {J}) for the {J} scales used, got {Vf.shape}")
        Wf = Whitener(V=Vf, source=omega_source or "given V")
        prob = _Problem(mdl, nu_hat, tau, Wf)
        (q, z, ok), _ = _best_solution(prob, [z1] + [s[1] for s in sols1[1:2]], 2)
        n_steps = 2
    elif steps >= 2:
        z, n_steps = z1, 1
        extra = [s[1] for s in sols1[1:2]]
        for k in range(1, steps):
            Vf = _model_V(mdl, mdl.from_free(z), wv, idx)
            Wf = Whitener(V=Vf, source=f"model V(theta_{k})")
            prob = _Problem(mdl, nu_hat, tau, Wf)
            (q, z_new, ok), _ = _best_solution(prob, [z] + extra, 1 + len(extra))
            extra = []
            z_new = np.log(mdl.sort_gm(np.exp(z_new)))
            n_steps = k + 1
            done = np.max(np.abs(z_new - z)) < 1e-5
            z = z_new
            if done:
                break
    else:
        Vf = _model_V(mdl, theta1, wv, idx)
        Wf = W1
        prob = _Problem(mdl, nu_hat, tau, W1)
        q, z, ok = q1, z1, ok1
        n_steps = 1
    theta = mdl.sort_gm(np.exp(z))
    z = np.log(theta)
    A = prob.jac_nu(z)
    cov, penalty = sandwich(A, Wf, Vf)
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    nu_fit = mdl.wv(theta, tau)
    sd = np.sqrt(np.diag(Vf))
    df = J - mdl.n_params
    j_q = _j_statistic(mdl, theta, wv, idx, nu_hat - nu_fit)
    jp = float(chi2_sf(j_q, df)) if df > 0 and math.isfinite(j_q) else float("nan")
    at_bound = tuple(n for n, zi, lo, hi in zip(mdl.param_names, z, prob.lo, prob.hi)
                     if zi - lo < 1e-3 or hi - zi < 1e-3)
    boot_lo = boot_hi = None
    if n_boot:
        boot_lo, boot_hi = _bootstrap(mdl, theta, wv, idx, int(n_boot), seed, n_starts)
    with np.errstate(over="ignore"):
        lo95, hi95 = np.exp(z - _Z95 * se), np.exp(z + _Z95 * se)
    return GMWMFit(
        model=mdl.name, param_names=mdl.param_names, theta=theta,
        theta_lo95=lo95, theta_hi95=hi95,
        z=z, se_z=se, cov_z=cov, q=q, df=df, j_pvalue=jp, penalty=penalty, wic=q + penalty,
        level=wv.level[idx], tau_samples=wv.tau_samples[idx], scale_s=wv.scale_s[idx],
        nu2_hat=nu_hat, nu2_fit=nu_fit, sd_nu2=sd, z_resid=(nu_hat - nu_fit) / sd, V=Vf,
        omega_source=Wf.source, theta_step1=theta1, q_step1=q1, steps=n_steps, dt_s=wv.dt_s,
        n_samples=wv.n_samples, converged=ok, at_bound=at_bound, boot_lo95=boot_lo, boot_hi95=boot_hi,
        n_boot=int(n_boot), j_stat=j_q,
    )


def gmwm_fit(wvar, model="WN+RW+GM", *, steps=4, scales=None, weights="eta3", V=None, n_starts=5,
             start=None, n_boot=0, seed=None) -> GMWMFit:
    """Fit a latent-process model to a Haar wavelet variance by the GMWM.

    Parameters
    ----------
    wvar : WvarResult
        One axis (``haar_wvar(...).axis(k)`` or :func:`from_curve`).
    model : str or LatentModel
        E.g. ``"WN+RW"``, ``"QN+WN+RW+2GM"``, ``"WN+AR1"``, ``"WN+RW+DR"``.
    steps : int, keyword-only
        Weighting steps: 1 = eta3 (or nonparametric) weights only; 2 = the classic two-step
        estimator, ``Omega = V(theta_1)^-1``; ``k > 2`` = up to ``k - 1`` successive updates
        ``Omega = V(theta_{i})^-1`` (iterated GMWM), stopping when ``max |dz| < 1e-5``.  The
        default 4 protects against a poor step 1: eta3 weights ``eta / (2 nu_hat^2)`` are
        huge where ``nu_hat`` came out low by chance, e.g. at the last scale (eta ~ 1), and a
        single V at that estimate inherits the bias (seen for RW in simulations; 2-3 updates
        converge).
    scales : array_like, optional
        Levels to use (e.g. ``range(6, 19)``) or a boolean mask over ``wvar.level``.
    weights : {"eta3", "nonparametric"}
        Step-1 weights (nonparametric needs ``haar_wvar(..., nonparametric_var=True)``).
    V : ndarray (J, J), optional
        A fixed covariance of the used WV estimates: ``Omega = V^-1`` for the final step and V
        for the SEs (a common Omega for model selection).  Overrides step 2.
    n_starts : int
        Number of ranked heuristic starting points optimised in step 1 (one more, the next
        ranked, is always added).
    start : array_like, optional
        Natural parameters to start from (added in front of the heuristic ones).
    n_boot : int
        Parametric-bootstrap replicates for percentile intervals (each replicate simulates a
        record of ``n_samples`` and refits with step 1; costly for long records).
    seed : int, optional
        Seed of the bootstrap.

    Returns
    -------
    GMWMFit

    Raises
    ------
    ConfigError
        Bad model string, options or a multi-axis WV.
    InsufficientDataError
        Fewer scales than parameters + 1, or a non-positive WV.

    Examples
    --------
    >>> from fogdrift.gmwm import haar_wvar, simulate_latent
    >>> x = simulate_latent("WN+RW", [1.0, 1e-6], 2**16, seed=3)
    >>> fit = gmwm_fit(haar_wvar(x, 0.01), "WN+RW")
    >>> round(float(fit.theta[0]), 1), bool(0.3e-6 < fit.theta[1] < 3e-6)
    (1.0, True)
    """
    if not (isinstance(steps, (int, np.integer)) and steps >= 1):
        raise ConfigError(f"steps must be an integer >= 1, got {steps!r}")
    wv, mdl, idx = _prepare(wvar, model, scales, weights)
    theta1, q1, sols1, W1, ok1 = _step1(wv, mdl, idx, weights=weights, n_starts=n_starts, start=start)
    return _finish(wv, mdl, idx, theta1, q1, sols1, W1, ok1, V=V, steps=steps, n_boot=n_boot, seed=seed,
                   n_starts=n_starts)


def _bootstrap(mdl, theta, wv, idx, n_boot, seed, n_starts):
    if wv.n_samples < 2:
        raise ConfigError("a parametric bootstrap needs n_samples")
    ss = np.random.SeedSequence(seed)
    levels = int(wv.level.max())
    draws = []
    for child in ss.spawn(n_boot):
        x = simulate_latent(mdl, theta, wv.n_samples, seed=child)
        wb = haar_wvar(x, wv.dt_s, levels=levels, robust=wv.robust,
                       efficiency=wv.efficiency if wv.robust else 0.6)
        try:
            fb = gmwm_fit(wb, mdl, steps=1, scales=wv.level[idx], n_starts=min(n_starts, 3), start=theta)
        except (FogdriftError, np.linalg.LinAlgError, linalg.LinAlgError):  # pragma: no cover - skipped replicate
            continue
        draws.append(fb.theta)
    d = np.array(draws)
    return np.percentile(d, 2.5, axis=0), np.percentile(d, 97.5, axis=0)


# ----------------------------------------------------------------------------------------
# Estimator
# ----------------------------------------------------------------------------------------
class GMWM:
    """Scikit-learn style GMWM estimator (the constructor only stores its arguments).

    Parameters
    ----------
    model : str
        Latent model, e.g. ``"WN+RW+GM"`` (see :func:`fogdrift.gmwm.processes.parse_model`).
    steps, scales, weights, n_starts, n_boot, random_state
        As in :func:`gmwm_fit` (``random_state`` is its ``seed``; ``steps`` default 4).

    Attributes
    ----------
    model_ : LatentModel
    theta_ : ndarray (p,)
        Natural parameters (deg/h per sample units).
    se_z_ : ndarray (p,)
        Standard errors of ``log theta``.
    ci95_ : ndarray (2, p)
        95 % intervals of ``theta``.
    q_, j_pvalue_, wic_ : float
    fit_ : GMWMFit
        Everything else.
    ieee_ : IEEEResult
        IEEE-952 quantities with intervals (:func:`fogdrift.gmwm.ieee.to_ieee`).

    Examples
    --------
    >>> from fogdrift.gmwm import haar_wvar, simulate_latent
    >>> wv = haar_wvar(simulate_latent("WN+GM", [1.0, 0.01, 1e-4], 2**15, seed=0), 0.01)
    >>> est = GMWM("WN+GM").fit(wv)
    >>> est.model_.name, round(float(est.theta_[0]), 1)
    ('WN+GM', 1.0)
    """

    def __init__(self, model="WN+RW+GM", *, steps=4, scales=None, weights="eta3", n_starts=5, n_boot=0,
                 random_state=None):
        self.model = model
        self.steps = steps
        self.scales = scales
        self.weights = weights
        self.n_starts = n_starts
        self.n_boot = n_boot
        self.random_state = random_state

    def get_params(self, deep=True) -> dict:
        """Constructor arguments (scikit-learn contract)."""
        return {k: getattr(self, k) for k in ("model", "steps", "scales", "weights", "n_starts", "n_boot",
                                               "random_state")}

    def set_params(self, **params) -> "GMWM":
        """Set constructor arguments; returns self."""
        for k, v in params.items():
            if k not in self.get_params():
                raise ConfigError(f"unknown parameter {k!r} for GMWM")
            setattr(self, k, v)
        return self

    def fit(self, wvar, y=None) -> "GMWM":
        """Fit to a :class:`WvarResult`; returns self."""
        fit = gmwm_fit(wvar, self.model, steps=self.steps, scales=self.scales, weights=self.weights,
                       n_starts=self.n_starts, n_boot=self.n_boot, seed=self.random_state)
        self.fit_ = fit
        self.model_ = fit.latent_model
        self.theta_ = fit.theta
        self.se_z_ = fit.se_z
        self.ci95_ = np.vstack([fit.theta_lo95, fit.theta_hi95])
        self.q_ = fit.q
        self.j_pvalue_ = fit.j_pvalue
        self.wic_ = fit.wic
        self.ieee_ = to_ieee(fit)
        return self

    def _check(self):
        if not hasattr(self, "fit_"):
            raise NotFittedError("this GMWM instance is not fitted yet; call fit(wvar) first")

    def predict_wv(self, tau_samples) -> np.ndarray:
        """Fitted WV ((deg/h)^2) at Haar scales ``tau_samples`` (samples)."""
        self._check()
        return self.model_.wv(self.theta_, tau_samples)
