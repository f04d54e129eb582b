"""IEEE-952 noise identification from an Allan-family curve (Allan, Hadamard, modified Allan).

The model (IEEE Std 952-1997 Annex C; method notes 2.2-2.5), sigma in deg/h and tau in s: the
five terms are independent, so their variances add,

    sigma^2(tau) = sum_n A_n g_n(tau),   e.g. for the Allan variance
    A_Q tau^-2 + A_N tau^-1 + A_B + A_K tau + A_R tau^2,
    A_Q = 3 Q^2,  A_N = N^2,  A_B = (2 ln2 / pi) B^2,  A_K = K^2 / 3,  A_R = R^2 / 2

(Q, N, B, K, R in the Allan-law units: (deg/h) s, (deg/h) sqrt(s), deg/h, (deg/h)/sqrt(s),
(deg/h)/s).  :data:`TERM_TABLE` holds the statistic-independent facts of each term (name,
units, header, the conversion to the reported unit, its Allan law); :data:`VARIANCE_LAWS`
holds each statistic's law ``g_n`` and constant (the Hadamard and modified Allan variances
weight the terms differently, and the Hadamard variance cannot see a rate ramp at all).  Both
live in :mod:`fogdrift.noise_terms` and are re-exported here.  :func:`fit_noise` reads the law
table of the result's ``statistic``.

The curve is fitted with non-negative coefficients by relative-error weighted least squares
(weights ``edf/2``, i.e. each residual divided by its standard deviation
``sigma_model^2 sqrt(2/edf)``), iterated with the model in the denominator (IRLS).
Coefficients are then converted to the usual units (:meth:`TermSpec.from_A`).

Uncertainty.  Variances at neighbouring taus come from the same data and are
positively correlated, which a plain WLS covariance ignores.  fogdrift therefore computes the
covariance from the *full* weighted design (all fitted terms, not only the active set) with
each point's weight divided by the number of grid points per octave around it (so a dense
grid carries about the information of an octave grid), inflates it by the reduced
chi-squared when that exceeds 1, and never lets the standard deviation of ``A_n`` fall below
``min_i A_n sqrt(2/edf_i) / share_in`` (``share_in`` = the term's fraction of the model at
tau_i): strongly correlated points, e.g. white PM at all small taus, carry no more
information than the single most informative one.  95 % intervals are ``A +- 1.96 sd`` (clipped at 0) mapped
through the monotone conversion.  With ``n_boot > 0`` a seeded parametric bootstrap
(``sigma*^2 = model chi2(edf')/edf'`` with the same density correction of the EDF) is used
instead.

A term whose lower 95 % bound is above zero is *resolved* (``reason`` empty).  A term whose
interval reaches zero is still reported with ``lo95 = 0`` and a ``reason`` saying it is not
resolved from zero.  A term is *not estimable* (``estimable=False``, ``value`` None,
``hi95`` = its 95 % upper bound, ``reason`` says why) when it is a long-tau term (B, K, R) that the
record does not resolve from zero (only a longer record can), or a short-tau term (Q, N) whose
dominance region lies below the shortest measured tau (sample interval too coarse).  The classic IEEE slope read-outs are returned alongside as a
cross-check.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import ConfigError, InsufficientDataError
from .noise_terms import (  # noqa: F401  (re-exported: the term table's public home is noise_terms)
    TERM_HEADERS,
    TERM_TABLE,
    TERM_UNITS,
    TERMS,
    UNESTIMABLE,
    VARIANCE_LAWS,
    TermLaw,
    TermSpec,
    default_terms,
    laws_of,
    term_spec,
)
from .units import B_FACTOR, URAD_PER_ARCSEC

__all__ = [
    "TERMS",
    "TERM_UNITS",
    "TERM_HEADERS",
    "TERM_TABLE",
    "TermSpec",
    "term_spec",
    "TermLaw",
    "VARIANCE_LAWS",
    "UNESTIMABLE",
    "default_terms",
    "NoiseTerm",
    "NoiseFit",
    "fit_noise",
    "coefficients_from_A",
    "paper_table1_from_A",
    "B_FACTOR",
]

_Z95 = 1.959963984540054


@dataclass(frozen=True)
class NoiseTerm:
    """One identified noise coefficient.

    Attributes
    ----------
    name : str
        ``"Q"``, ``"N"``, ``"B"``, ``"K"``, ``"R"`` (or ``"Q_arcsec"``).
    value : float or None
        Estimate in ``unit``; None when not estimable.
    unit : str
    std : float or None
        Standard uncertainty (delta method on the fit covariance, or bootstrap s.d.).
    lo95, hi95 : float or None
        95 % interval.  For a non-estimable term ``hi95`` is the 95 % upper bound (or None if
        the term was not fitted) and ``lo95`` is None.
    estimable : bool
    reason : str
        Empty when estimable; otherwise why not.
    """

    name: str
    value: float | None
    unit: str
    std: float | None
    lo95: float | None
    hi95: float | None
    estimable: bool
    reason: str

    def to_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass(frozen=True)
class NoiseFit:
    """Result of :func:`fit_noise`.

    Attributes
    ----------
    terms : dict[str, NoiseTerm]
        Q (urad), N (deg/sqrt(h)), B (deg/h), K (deg/h^1.5), R (deg/h^2), keyed by name.
    q_arcsec : NoiseTerm
        Q in arcsec.
    A : ndarray, shape (5,)
        Fitted coefficient of each term Q, N, B, K, R: the constant of its leading power of tau
        in the statistic's law (:data:`VARIANCE_LAWS`), in units of sigma^2 [(deg/h)^2] with tau
        in s (0 for unfitted terms).  For the Allan variance these are A_-2 .. A_2 of
        ``sigma^2 = sum_n A_n tau^n``.
    A_cov : ndarray, shape (5, 5)
        Covariance of ``A`` (zero rows/columns for unfitted terms).
    fitted_terms : tuple of str
    tau_min_s, tau_max_s : float
        Tau range of the points used.
    method : str
        ``"wls-nnls"`` or ``"log"`` (plus ``"+bootstrap"``).
    readouts : dict[str, float or None]
        Classic IEEE-952 slope read-outs (units in the keys), None where the curve shows no
        such slope: ``"Q_urad@tau=sqrt3s"``, ``"N_dprh@tau=1h"``, ``"B_dph@min"``,
        ``"K_dphrh@tau=3h"``, ``"R_dph2@tau=sqrt2h"``.  The keys name the Allan read-off
        points; for another statistic the value is the coefficient read off that statistic's
        own slope line through its own law (e.g. the -3/2 line of white PM in MDEV).
    chi2_red : float
        Reduced chi-squared of the (density-corrected) weighted fit.
    n_points : int
        Number of taus used.
    statistic : str
        The statistic the curve was (``"adev"``, ``"hdev"``, ``"mdev"``).
    dt_s : float or None
        Sample interval of the curve in s (the modified Allan laws depend on it).
    """

    terms: dict
    q_arcsec: NoiseTerm
    A: np.ndarray
    A_cov: np.ndarray
    fitted_terms: tuple
    tau_min_s: float
    tau_max_s: float
    method: str
    readouts: dict
    chi2_red: float
    n_points: int
    statistic: str = "adev"
    dt_s: float | None = None

    def to_dict(self) -> dict:
        """JSON-serialisable dict."""
        return {
            "terms": {k: v.to_dict() for k, v in self.terms.items()},
            "q_arcsec": self.q_arcsec.to_dict(),
            "A": [float(a) for a in self.A],
            "A_cov": [[float(c) for c in row] for row in self.A_cov],
            "fitted_terms": list(self.fitted_terms),
            "tau_min_s": float(self.tau_min_s),
            "tau_max_s": float(self.tau_max_s),
            "method": self.method,
            "readouts": {k: (None if v is None else float(v)) for k, v in self.readouts.items()},
            "chi2_red": float(self.chi2_red),
            "n_points": int(self.n_points),
            "statistic": self.statistic,
            "dt_s": None if self.dt_s is None else float(self.dt_s),
        }

    def _term_var(self, name, tau_s, statistic) -> np.ndarray:
        term_spec(name)
        own = laws_of(self.statistic)
        i = TERMS.index(name)
        target = laws_of(self.statistic if statistic is None else statistic)
        t = np.asarray(tau_s, dtype=np.float64)
        if name not in own or name not in target or self.A[i] == 0:
            return np.zeros_like(t)  # a term a statistic cannot see contributes nothing to it
        x2 = self.A[i] / own[name].scale(self.dt_s)  # the coefficient X^2 in the Allan-law units
        return x2 * target[name].scale(self.dt_s) * target[name].shape(t, self.dt_s)

    def model_dev_dph(self, tau_s, statistic=None) -> np.ndarray:
        """Deviation of the fitted model in deg/h at ``tau_s`` (s).

        ``statistic`` (default: the fitted one) evaluates the fitted coefficients under another
        statistic's laws, e.g. ``"adev"`` for the Allan deviation a Hadamard fit implies (a term
        the target statistic cannot see contributes nothing).
        """
        return np.sqrt(sum(self._term_var(k, tau_s, statistic) for k in TERMS))

    def term_dev_dph(self, name, tau_s, statistic=None) -> np.ndarray:
        """Deviation of one fitted term in deg/h at ``tau_s`` (s); ``statistic`` as in :meth:`model_dev_dph`."""
        return np.sqrt(self._term_var(name, tau_s, statistic))

    def model_adev_dph(self, tau_s) -> np.ndarray:
        """Allan deviation of the fitted model in deg/h (``sqrt(sum_n A_n tau^n)`` for an Allan fit)."""
        return self.model_dev_dph(tau_s, "adev")

    def term_adev_dph(self, name, tau_s) -> np.ndarray:
        """Allan deviation of one fitted term in deg/h (``sqrt(A_n tau^n)`` for an Allan fit)."""
        return self.term_dev_dph(name, tau_s, "adev")


# ----------------------------------------------------------------------------------------
# Conversions
# ----------------------------------------------------------------------------------------
def _check_A(A) -> np.ndarray:
    a = np.asarray(A, dtype=np.float64)
    if a.shape != (5,) or not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ConfigError(f"A must be 5 finite non-negative numbers A_-2..A_2, got {A!r}")
    return a


def coefficients_from_A(A, *, statistic="adev", dt_s=None) -> dict[str, float]:
    """IEEE-952 coefficients from the fitted A of each term (sigma^2 in (deg/h)^2, tau in s).

    Parameters
    ----------
    A : array_like, shape (5,)
        Non-negative coefficients of Q, N, B, K, R in the statistic's law (for the Allan
        variance: A_-2, A_-1, A_0, A_1, A_2).
    statistic : str, keyword-only
        Whose laws (:data:`VARIANCE_LAWS`); default ``"adev"``.
    dt_s : float or None, keyword-only
        Sample interval in s (needed for ``"mdev"``, whose white-PM constant is 3 dt).

    Returns
    -------
    dict
        ``Q`` [urad], ``Q_arcsec`` [arcsec], ``N`` [deg/sqrt(h)], ``B`` [deg/h],
        ``K`` [deg/h^1.5], ``R`` [deg/h^2] (R is absent for ``"hdev"``).

    Notes
    -----
    Method notes 2.3 (Allan): Q[arcsec] = sqrt(A_-2/3) (1 (deg/h) s = 1 arcsec),
    Q[urad] = 4.848137 sqrt(A_-2/3), N = sqrt(A_-1)/60, B = sqrt(A_0)/0.664282,
    K = 60 sqrt(3 A_1), R = 3600 sqrt(2 A_2); in general ``to_unit sqrt(A / c)`` with the
    statistic's constant c (:meth:`TermSpec.from_A`).

    Examples
    --------
    >>> c = coefficients_from_A([1.27635511e-1, 9.0e-2, 4.412712e-5, 3.7037037e-8, 9.6450617e-11])
    >>> {k: round(v, 6) for k, v in c.items()}
    {'Q': 1.0, 'Q_arcsec': 0.206265, 'N': 0.005, 'B': 0.01, 'K': 0.02, 'R': 0.05}
    """
    a = _check_A(A)
    laws = laws_of(statistic)
    out = {}
    for i, name in enumerate(TERMS):
        if name in laws:
            out[name] = TERM_TABLE[name].from_A(a[i], laws[name].scale(dt_s))
            if name == "Q":
                out["Q_arcsec"] = out["Q"] / URAD_PER_ARCSEC
    return out


def paper_table1_from_A(A) -> dict[str, float]:
    """The conversions of Tang et al. (2012) Table 1, for replication only.

    **Q is wrong** in the paper: ``1e6 * 3600 * pi * sqrt(3 A_-2) / 180`` is ``3 * 3600^2``
    times the correct value (factor 3 inverted, 3600 multiplied instead of divided; method
    notes 2.4).  N, K, R are correct; B uses the rounded constant 0.6643.

    Returns
    -------
    dict
        ``Q`` [urad, erroneous], ``N``, ``B``, ``K``, ``R`` as in :func:`coefficients_from_A`,
        and ``Q_is_wrong`` = 1.0 as a flag.

    Examples
    --------
    >>> A = [1.27635511e-1, 9.0e-2, 4.412712e-5, 3.7037037e-8, 9.6450617e-11]
    >>> round(paper_table1_from_A(A)["Q"] / coefficients_from_A(A)["Q"])
    38880000
    """
    a = _check_A(A)
    return {
        "Q": 1e6 * 3600.0 * math.pi * math.sqrt(3.0 * a[0]) / 180.0,
        "N": math.sqrt(a[1]) / 60.0,
        "B": math.sqrt(a[2]) / 0.6643,
        "K": 60.0 * math.sqrt(3.0 * a[3]),
        "R": 3600.0 * math.sqrt(2.0 * a[4]),
        "Q_is_wrong": 1.0,
    }


def _conv(name, law, dt_s) -> float:
    """coefficient[unit] = _conv * sqrt(A) for a term under a law."""
    return TERM_TABLE[name].to_unit / math.sqrt(law.scale(dt_s))


# ----------------------------------------------------------------------------------------
# Fitting
# ----------------------------------------------------------------------------------------
def _points_per_octave(tau_s: np.ndarray) -> np.ndarray:
    l2 = np.log2(tau_s)
    return np.array([np.sum(np.abs(l2 - v) < 0.5 + 1e-9) for v in l2], dtype=np.float64)


def _wnnls(X, y, edf, n_iter):
    """Relative-error weighted NNLS with IRLS; returns coefficients and final denominators."""
    from scipy.optimize import nnls

    den = y.copy()
    coef = np.zeros(X.shape[1])
    for _ in range(n_iter):
        w = np.sqrt(edf / 2.0) / den
        Xw = X * w[:, None]
        scale = np.linalg.norm(Xw, axis=0)
        scale[scale == 0] = 1.0
        c, _ = nnls(Xw / scale, y * w, maxiter=50 * X.shape[1])
        coef = c / scale
        model = X @ coef
        if not np.all(model > 0):
            break
        den = model
    return coef, den


def _log_fit(X, y, edf, start):
    from scipy.optimize import least_squares

    w = np.sqrt(edf / 2.0)
    floor = 1e-6 * np.max(start * np.max(np.abs(X), axis=0)) / np.max(np.abs(X), axis=0)
    theta0 = np.log(np.maximum(start, np.maximum(floor, 1e-300)))

    def resid(th):
        return w * (np.log(X @ np.exp(th)) - np.log(y))

    res = least_squares(resid, theta0, method="trf", x_scale=1.0)
    coef = np.exp(res.x)
    coef[coef < 1e-12 * np.max(coef * np.max(X, axis=0)) / np.max(X, axis=0)] = 0.0
    return coef


#: Read-out keys (legacy names: the Allan read-off points) of the slope terms.
_READOUT_KEYS = {"Q": "Q_urad@tau=sqrt3s", "N": "N_dprh@tau=1h", "K": "K_dphrh@tau=3h", "R": "R_dph2@tau=sqrt2h"}


def _readouts(tau_s, dev, laws, dt_s):
    """Classic IEEE-952 slope read-outs (tau in s, deviation in deg/h) under a statistic's laws.

    For each slope term the point whose local log-log slope is nearest the term's slope
    ``power/2`` (within 0.2) is taken as on the term's line, and the coefficient read from it
    through the law: ``to_unit * dev / sqrt(scale * shape(tau))``.  For the Allan deviation this
    is the IEEE-952 rule (sigma(sqrt3 s) = Q, sigma(1 h) = N, sigma(3 h) = K, sigma(sqrt2 h) = R on
    the -1, -1/2, +1/2, +1 lines).  B is read at the minimum: ``dev_min / sqrt(c_B)``.
    """
    out = {"Q_urad@tau=sqrt3s": None, "N_dprh@tau=1h": None, "B_dph@min": None,
           "K_dphrh@tau=3h": None, "R_dph2@tau=sqrt2h": None}
    ok = dev > 0
    t, s = tau_s[ok], dev[ok]
    if t.size < 3:
        return out
    slope = np.gradient(np.log(s), np.log(t))
    i_min = int(np.argmin(s))
    # Falling terms (Q, N) are read left of the minimum, rising ones (K, R) right of it: a rising
    # piece inside a short-tau bump (e.g. vibration) is not rate random walk.
    for name, key in _READOUT_KEYS.items():
        if name not in laws:
            continue
        law = laws[name]
        mu = law.power / 2.0
        side = np.arange(t.size) <= i_min if mu < 0 else np.arange(t.size) >= i_min
        dist = np.where(side, np.abs(slope - mu), np.inf)
        i = int(np.argmin(dist))
        if dist[i] <= 0.2:
            shape = float(law.shape(t[i], dt_s))
            out[key] = float(TERM_TABLE[name].to_unit * s[i] / math.sqrt(law.scale(dt_s) * shape))
    if "B" in laws and 0 < i_min < s.size - 1:
        out["B_dph@min"] = float(s[i_min] / math.sqrt(laws["B"].scale(dt_s)))
    return out


def fit_noise(
    allan,
    *,
    terms=None,
    method="wls-nnls",
    n_boot=0,
    seed=0,
    tau_range_s=None,
    n_iter=4,
) -> NoiseFit:
    """Fit IEEE-952 noise terms to an Allan-family curve.

    Parameters
    ----------
    allan : AllanResult
        From :func:`fogdrift.allan.allan_variance`: any statistic (``adev``, ``hdev``, ``mdev``);
        its ``statistic`` field selects the laws (:data:`VARIANCE_LAWS`), its ``edf`` the
        weights.  Any object with ``statistic``, ``tau_s``, ``var_dph2``, ``edf`` and ``dt_s``
        will do.
    terms : sequence of str or None, keyword-only
        Terms to fit, a subset of ``("Q", "N", "B", "K", "R")``; None (default): every term the
        statistic can estimate (:func:`default_terms`: all five, or Q, N, B, K for ``hdev``).
    method : {"wls-nnls", "log"}, keyword-only
        ``"wls-nnls"``: relative-error weighted non-negative least squares with IRLS
        (method notes 2.5, items 1-2).  ``"log"``: minimise
        ``sum (edf/2) (log model - log sigma^2)^2`` over ``A_n = exp(theta_n)`` (item 3),
        started from the NNLS solution.
    n_boot : int, keyword-only
        0 (default): covariance from the weighted design; > 0: parametric bootstrap with
        this many seeded replicates.
    seed : int, keyword-only
        Seed of the bootstrap.
    tau_range_s : (float, float) or None, keyword-only
        Use only taus in this closed range (s).
    n_iter : int, keyword-only
        IRLS iterations.

    Returns
    -------
    NoiseFit

    Raises
    ------
    ConfigError
        Unknown term/method/statistic, a term the statistic cannot estimate (R with ``hdev``),
        bad ``n_boot`` or ``tau_range_s``.
    InsufficientDataError
        Fewer usable taus (sigma^2 > 0) than fitted terms + 1.

    Notes
    -----
    Minimises ``sum_i (edf_i/2) ((sum_n A_n g_n(tau_i) - s_i^2) / d_i)^2`` with ``A_n >= 0``,
    where ``g_n`` is the term's law under the statistic (``tau^n`` for the Allan variance),
    ``d_i`` is ``s_i^2`` in the first pass and the fitted model afterwards (Lv et al.,
    Optik 126 (2015) 2529; method notes 2.5).  See the module docstring for uncertainties
    and the estimability rule.

    Examples
    --------
    >>> from fogdrift.simulate import simulate
    >>> from fogdrift.allan import allan_variance
    >>> y = simulate(2**18, 0.1, arw_dprh=0.01, seed=3)
    >>> fit = fit_noise(allan_variance(y, 0.1), terms=("N", "K"))
    >>> round(fit.terms["N"].value, 3), fit.terms["K"].estimable
    (0.01, False)
    >>> fit_h = fit_noise(allan_variance(y, 0.1, statistic="hdev"), terms=("N", "K"))
    >>> fit_h.statistic, round(fit_h.terms["N"].value, 3)
    ('hdev', 0.01)
    """
    statistic = getattr(allan, "statistic", None)
    if not isinstance(statistic, str) or not all(hasattr(allan, a) for a in ("tau_s", "var_dph2", "edf", "dt_s")):
        raise ConfigError(f"allan must be an AllanResult (with statistic, tau_s, var_dph2, edf, dt_s), "
                          f"got {type(allan).__name__}")
    laws = laws_of(statistic)
    if terms is None:
        terms = default_terms(statistic)
    if isinstance(terms, str):
        terms = tuple(terms)
    terms = tuple(terms)
    bad = [t for t in terms if t not in TERMS]
    if bad or not terms or len(set(terms)) != len(terms):
        raise ConfigError(f"terms must be distinct names from {TERMS}, got {terms!r}")
    for t in terms:
        if t not in laws:
            raise ConfigError(
                f"statistic={statistic!r} cannot estimate {t} ({TERM_TABLE[t].long_name}): "
                f"{UNESTIMABLE.get((statistic, t), 'no law for it')}; drop {t} from {{opt:terms}} "
                f"or use {{opt:statistic}} adev"
            )
    terms = tuple(t for t in TERMS if t in terms)
    if method not in ("wls-nnls", "log"):
        raise ConfigError(f"method must be 'wls-nnls' or 'log', got {method!r}")
    if int(n_boot) != n_boot or n_boot < 0:
        raise ConfigError(f"n_boot must be an integer >= 0, got {n_boot!r}")
    dt_s = None if allan.dt_s is None else float(allan.dt_s)
    tau = np.asarray(allan.tau_s, dtype=np.float64)
    avar = np.asarray(allan.var_dph2, dtype=np.float64)
    edf = np.asarray(allan.edf, dtype=np.float64)
    use = (avar > 0) & np.isfinite(avar) & (edf > 0)
    if tau_range_s is not None:
        try:
            lo, hi = (float(v) for v in tau_range_s)
        except (TypeError, ValueError):
            raise ConfigError(f"tau_range_s must be (min_s, max_s), got {tau_range_s!r}") from None
        if not lo <= hi:
            raise ConfigError(f"tau_range_s must have min <= max, got {tau_range_s!r}")
        use &= (tau >= lo) & (tau <= hi)
    if use.sum() < len(terms) + 1:
        raise InsufficientDataError(
            f"fitting {len(terms)} noise terms needs at least {len(terms) + 1} taus with "
            f"sigma^2 > 0, got {int(use.sum())}",
            needed=len(terms) + 1,
            got=int(use.sum()),
        )
    tau, avar, edf = tau[use], avar[use], edf[use]
    term_laws = [laws[t] for t in terms]
    X = np.column_stack([law.shape(tau, dt_s) for law in term_laws])

    coef, den = _wnnls(X, avar, edf, n_iter)
    if method == "log":
        coef = _log_fit(X, avar, edf, coef)
        model = X @ coef
        den = model if np.all(model > 0) else den

    # covariance: full weighted design, density-corrected weights, chi2 inflation
    dens = _points_per_octave(tau)
    w = np.sqrt(edf / 2.0 / dens) / den
    Xw = X * w[:, None]
    resid = (X @ coef - avar) * w
    dof = max(1, tau.size - len(terms))
    chi2_red = float(resid @ resid / dof)
    scale = np.linalg.norm(Xw, axis=0)
    scale[scale == 0] = 1.0
    cov_s = np.linalg.pinv((Xw / scale).T @ (Xw / scale))
    cov = cov_s / np.outer(scale, scale) * max(1.0, chi2_red)
    # correlated taus carry no more information about a term than its single most
    # informative point: sd(A_n) >= min_i A_n sqrt(2/edf_i) / share_in
    model = X @ coef
    with np.errstate(divide="ignore", invalid="ignore"):
        share = X * coef[None, :] / model[:, None]
        floor = coef * np.min(np.sqrt(2.0 / edf)[:, None] / share, axis=0)
    floor = np.where(np.isfinite(floor), floor, 0.0)
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0))
    fac = np.where(sd > 0, np.maximum(1.0, floor / np.where(sd > 0, sd, 1.0)), 1.0)
    cov = cov * np.outer(fac, fac)
    method_name = method

    boot = None
    if n_boot > 0:
        rng = np.random.default_rng(seed)
        model = X @ coef
        edf_eff = np.maximum(edf / dens, 0.5)
        boot = np.empty((int(n_boot), len(terms)))
        for b in range(int(n_boot)):
            ystar = np.maximum(model * rng.chisquare(edf_eff) / edf_eff, 1e-300)
            boot[b], _ = _wnnls(X, ystar, edf, n_iter)
        cov = np.atleast_2d(np.cov(boot, rowvar=False))
        method_name += "+bootstrap"

    A = np.zeros(5)
    A_cov = np.zeros((5, 5))
    idx = np.array([TERMS.index(t) for t in terms])
    A[idx] = coef
    A_cov[np.ix_(idx, idx)] = cov

    results = {}
    for j, name in enumerate(terms):
        sd_a = float(math.sqrt(max(cov[j, j], 0.0)))
        if boot is not None:
            lo_a, hi_a = (float(v) for v in np.percentile(boot[:, j], [2.5, 97.5]))
            lo_a = lo_a if lo_a > 0 else 0.0
        else:
            lo_a, hi_a = max(0.0, coef[j] - _Z95 * sd_a), coef[j] + _Z95 * sd_a
        results[name] = _make_term(name, coef[j], sd_a, lo_a, hi_a, tau, term_laws, coef, j, dt_s)
    for name in TERMS:
        if name not in results:
            why = (f"not fitted (terms={terms})" if name in laws
                   else f"not estimable with statistic={statistic!r}: {UNESTIMABLE.get((statistic, name), '')}")
            results[name] = NoiseTerm(name, None, TERM_UNITS[name], None, None, None, False, why)
    qt = results["Q"]
    f = 1.0 / URAD_PER_ARCSEC

    def _sc(v):
        return None if v is None else v * f

    q_arcsec = NoiseTerm("Q_arcsec", _sc(qt.value), "arcsec", _sc(qt.std), _sc(qt.lo95), _sc(qt.hi95),
                         qt.estimable, qt.reason)
    return NoiseFit(
        terms={k: results[k] for k in TERMS},
        q_arcsec=q_arcsec,
        A=A,
        A_cov=A_cov,
        fitted_terms=terms,
        tau_min_s=float(tau.min()),
        tau_max_s=float(tau.max()),
        method=method_name,
        readouts=_readouts(np.asarray(allan.tau_s, float), np.sqrt(np.asarray(allan.var_dph2, float)), laws, dt_s),
        chi2_red=chi2_red,
        n_points=int(tau.size),
        statistic=statistic,
        dt_s=dt_s,
    )


def _make_term(name, a, sd_a, lo_a, hi_a, tau, term_laws, coef, j, dt_s) -> NoiseTerm:
    """NoiseTerm from the fitted A (and its interval); applies the estimability rule."""
    law = term_laws[j]
    conv, unit = _conv(name, law, dt_s), TERM_UNITS[name]
    if a > 0 and lo_a > 0:
        value = conv * math.sqrt(a)
        std = conv * sd_a / (2.0 * math.sqrt(a))
        return NoiseTerm(name, value, unit, std, conv * math.sqrt(lo_a), conv * math.sqrt(hi_a), True, "")
    upper = conv * math.sqrt(max(hi_a, 0.0))
    # where would a term at its upper bound start to dominate the rest of the model?  (leading
    # powers only: the small-m corrections of the modified Allan laws do not extrapolate)
    p = law.power
    rest_coef = coef.copy()
    rest_coef[j] = 0.0
    t_lo, t_hi = float(tau.min()), float(tau.max())
    grid = np.logspace(math.log10(t_lo) - 6, math.log10(t_hi) + 6, 1201)
    Xg = np.column_stack([lw.shape(grid, dt_s, leading_only=True) for lw in term_laws])
    rest = Xg @ rest_coef
    term = max(hi_a, 0.0) * grid**p
    dominates = term >= rest
    head = (f"{name} ({TERM_TABLE[name].long_name}) not resolved: A={a:.3g} +- {sd_a:.3g} (tau in s), "
            f"consistent with 0; 95 % upper bound {upper:.3g} {unit}")
    where = grid[dominates]
    if p >= 0:
        # B, K, R grow relative to the other terms with tau: when the record does not resolve them
        # from zero, only a longer record can; report the upper bound, not a number.
        extra = ""
        if where.size and t_hi < 3.0 * where.min():
            extra = f" < 3x the tau {where.min():.3g} s where {name} at its upper bound would dominate"
        return NoiseTerm(name, None, unit, None, None, upper, False,
                         f"record too short: tau_max {t_hi:.3g} s{extra}; " + head)
    if p < 0 and where.size and t_lo > where.max() / 3.0:
        return NoiseTerm(name, None, unit, None, None, upper, False,
                         f"sample interval too coarse: tau_min {t_lo:.3g} s > 1/3 of the tau "
                         f"{where.max():.3g} s below which {name} at its upper bound would dominate; " + head)
    # The measured tau range covers where the term would show, but the data do not separate it from
    # zero: report the estimate with its interval [0, upper] rather than hiding it.
    value = conv * math.sqrt(max(a, 0.0))
    std = conv * sd_a / (2.0 * math.sqrt(a)) if a > 0 else None
    return NoiseTerm(name, value, unit, std, 0.0, upper, True, head)
