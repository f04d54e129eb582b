"""Model selection for the GMWM: WIC over a candidate set, sanity checks, short-scale exclusion.

Procedure (:func:`select_model`; [GMWM]_ §5):

0. **Spectral lines** (``periodic``: the :class:`~fogdrift.noise.periodic.PeriodicContent` of the same rate,
   from its spectrum): no latent process models a sinusoid, whose Haar WV falls as ``tau^-2`` above its period
   exactly like QN's.  The leading scales up to the last one where the lines' WV
   (:func:`~fogdrift.noise.periodic.periodic_wvar`) exceeds
   :data:`~fogdrift.noise.periodic.LINE_SHARE_MAX` of the measured WV are excluded first (each reason names the
   line by its frequency), and a candidate with QN fails a hard check unless its QN WV stands
   :data:`~fogdrift.noise.periodic.Q_OVER_ENVELOPE` times above the lines' envelope at some used scale
   (:func:`~fogdrift.noise.periodic.q_stands_above_lines`, the rule the Allan fit applies to Q too).
1. **Short scales no candidate explains** (output low-pass filter, vibration, sample
   correlation of the electronics: the first octaves of the KVH DSP-1750 and LN-200
   curves) are detected, not hand-picked: starting from the first scale, every candidate
   is fitted (step 1) to the scales ``j >= j0``; if no candidate (with a non-degenerate fit:
   no parameter at a bound, no collapsed component) reproduces the first
   ``n_check`` used scales within ``|z| <= z_max`` (``z`` standardised by the model-based SD
   of the best-fitting candidate), scale ``j0`` is excluded, with the smallest ``|z|`` any
   candidate reached recorded as the reason, and the scan moves on.  It stops at the first
   ``j0`` some candidate explains, or after ``max_excluded`` scales.  After step 5 the chosen
   model's final (efficiently weighted) fit must explain the first ``n_check`` scales too,
   and, if no candidate passed the checks, not only through a GM whose WV peak lies below
   twice the first scale (a filter artefact: it cannot be told from WN there); otherwise
   scale ``j0`` is excluded with that reason and steps 1-5 are repeated.
2. Every candidate is fitted on the remaining scales with **one common Omega** = ``V^-1``
   (WIC values are only comparable under the same Omega), ``V`` the model-based covariance
   at the iterated GMWM estimate of a pilot choice (the smallest ``Q_1 + 2p`` under the
   common step-1 eta3 weights); then again with ``V`` at the iterated estimate of the
   candidate chosen in that pass, until the choice repeats (at most four passes; if no candidate
   passes under a V, the next candidate in the pilot ranking supplies V).  The V of an
   over-fitted curve (e.g. one bending down with the noise of the last octaves) is too small
   there and makes the right model look bad; the V of the chosen model is its efficient weight.
3. ``WIC = Q + 2 tr(Omega A (A^T Omega A)^-1 A^T Omega V)`` (= ``Q + 2p`` here).
4. **Sanity checks** reject a candidate, with the reason recorded: a parameter at a bound
   (variance -> 0, T_c -> 0 or beyond 1000x the largest scale) or a component explaining
   less than ``share_min`` of the WV at every scale ("hard"); a component that nowhere
   exceeds ``snr_min`` standard deviations of the WV estimate; a GM whose WV peak (at scale
   ``3.785 T_c``) is not at least one octave above the first and two octaves below the
   last scale used (its rise or decay is then not observed and it is indistinguishable from
   WN or RW: e.g. a slow GM bending the noisy last octaves down instead of a RW); a standardised residual ``|z| > z_max``; a run of same-sign
   innovation residuals (residuals whitened in scale order by the Cholesky factor of V)
   whose probability under independent signs is below ``run_alpha``; a free parameter with
   ``se(log) > se_log_max`` (not identified) ("soft").
5. The smallest WIC among the candidates that pass wins.  If none passes, the smallest WIC
   among those without hard failures is returned with ``passed_checks=False`` and a
   :class:`~fogdrift.errors.FogdriftWarning`.

References
----------
.. [GMWM] fogdrift GMWM method notes, ``shared/docs/gmwm-notes.md`` §5 and §8.
.. [Stebler2014] Y. Stebler, S. Guerrier, J. Skaloud, M.-P. Victoria-Feser, "Generalized method of
   wavelet moments for inertial navigation filter design", IEEE TAES 50(3), 2014.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError, FogdriftWarning, InsufficientDataError
from ..noise.rules import SLOPES, slope_claim
from ..noise.periodic import LINE_SHARE_MAX, Q_OVER_ENVELOPE, line_name, periodic_wvar, q_stands_above_lines
from .covariance import wvar_covariance
from .estimator import GMWMFit, Whitener, _bounds, _check_wv, _finish, _model_V, _step1
from .ieee import IEEEResult, to_ieee
from .processes import LatentModel, param_label, parse_model

__all__ = ["DEFAULT_CANDIDATES", "CandidateScore", "ExcludedScale", "SelectionResult", "select_model",
           "longest_run_pvalue"]

_GM_PEAK = 3.785  # the WV of a GM peaks at scale ~3.785 T_c
#: The words that open the hard reason of a QN candidate refused beside spectral lines (the fallback skips them).
_LINES_REASON = "hard: quantization not told apart from the spectral lines"

#: Default candidate set: WN with RW and one or two GMs, plus QN and drift variants.  FLICKER
#: models (e.g. "WN+FLICKER+RW") can be passed explicitly; they are not in the default set
#: because a flat stretch of a few octaves is equally well (and, for a Kalman filter, more
#: usefully) described by GMs, and on the KVH/LN-200 curves the flicker term collapses.
DEFAULT_CANDIDATES = (
    "WN", "WN+RW", "WN+GM", "WN+RW+GM", "WN+2GM", "WN+RW+2GM",
    "QN+WN", "QN+WN+RW", "QN+WN+GM", "QN+WN+RW+GM",
    "WN+RW+DR",
)


@dataclass(frozen=True)
class CandidateScore:
    """Score of one candidate model.

    Attributes
    ----------
    model : str
    n_params : int
    q, penalty, wic : float
        Objective under the common Omega, WIC penalty and WIC (NaN if not fitted).
    passed : bool
        True if no sanity check failed.
    reasons : tuple of str
        Why it was rejected ("hard: ..." / "soft: ...").
    fit : GMWMFit or None
    """

    model: str
    n_params: int
    q: float
    penalty: float
    wic: float
    passed: bool
    reasons: tuple
    fit: GMWMFit | None = field(default=None, repr=False)

    @property
    def hard_failure(self) -> bool:
        return any(r.startswith("hard") for r in self.reasons)

    def to_dict(self) -> dict:
        d = {"model": self.model, "n_params": self.n_params, "q": float(self.q), "penalty": float(self.penalty),
             "wic": float(self.wic), "passed": bool(self.passed), "reasons": list(self.reasons)}
        if self.fit is not None:
            d["theta"] = {k: float(v) for k, v in zip(self.fit.param_names, self.fit.theta)}
            d["se_log"] = {k: float(v) for k, v in zip(self.fit.param_names, self.fit.se_z)}
            d["j_pvalue"] = float(self.fit.j_pvalue)
        return d


@dataclass(frozen=True)
class ExcludedScale:
    """A short scale excluded automatically.

    Attributes
    ----------
    level : int
    scale_s : float
    best_abs_z : float
        The smallest max ``|z|`` over the first checked scales that any candidate reached (NaN for a scale
        excluded for a spectral line: no candidate is fitted there).
    best_model : str
        The candidate that came closest ("" for a spectral line).
    reason : str
    line_share : float or None
        For a scale excluded for spectral lines: the lines' WV over the measured WV there (a fraction); else None.
    """

    level: int
    scale_s: float
    best_abs_z: float
    best_model: str
    reason: str
    line_share: float | None = None

    def to_dict(self) -> dict:
        z = float(self.best_abs_z)
        d = {"level": int(self.level), "scale_s": float(self.scale_s), "best_abs_z": z if np.isfinite(z) else None,
             "best_model": self.best_model, "reason": self.reason}
        if self.line_share is not None:
            d["line_share"] = float(self.line_share)
        return d


@dataclass(frozen=True)
class SelectionResult:
    """Result of :func:`select_model`.

    Attributes
    ----------
    selected : str
        Chosen model.
    fit : GMWMFit
        Its fit under the common Omega.
    ieee : IEEEResult
        IEEE-952 reading of ``fit``.
    candidates : list of CandidateScore
        Every candidate, in the order given.
    excluded : list of ExcludedScale
        Short scales removed by the scan.
    levels_used : ndarray of int
    omega_source : str
    passed_checks : bool
        False if no candidate passed every sanity check (fallback choice).
    scan_note : str
        Non-empty when the exclusion scan stopped at ``max_excluded`` (says whether the first
        kept scales are still unexplained).
    """

    selected: str
    fit: GMWMFit
    ieee: IEEEResult
    candidates: list
    excluded: list
    levels_used: np.ndarray
    omega_source: str
    passed_checks: bool
    scan_note: str = ""

    @property
    def no_result(self) -> bool:
        """True when the selection has no result to sign: no candidate passed its checks among several (a model the
        user fixed alone keeps its values, with the warning that it failed)."""
        return not self.passed_checks and len(self.candidates) > 1

    def candidate(self, model) -> CandidateScore:
        """The score of one candidate (by model string)."""
        name = parse_model(model).name
        for c in self.candidates:
            if c.model == name:
                return c
        raise ConfigError(f"{name} was not a candidate; candidates: {[c.model for c in self.candidates]}")

    def to_dict(self) -> dict:
        return {
            "selected": self.selected,
            "fit": self.fit.to_dict(),
            "ieee": self.ieee.to_dict(),
            "candidates": [c.to_dict() for c in self.candidates],
            "excluded": [e.to_dict() for e in self.excluded],
            "levels_used": [int(v) for v in self.levels_used],
            "omega_source": self.omega_source,
            "passed_checks": bool(self.passed_checks),
            "scan_note": self.scan_note,
        }


# ----------------------------------------------------------------------------------------
# Checks
# ----------------------------------------------------------------------------------------
def longest_run_pvalue(n: int, run: int) -> float:
    """P(longest run of equal signs >= ``run``) in ``n`` independent fair signs.

    Examples
    --------
    >>> round(longest_run_pvalue(10, 10), 6)   # all ten equal: 2 / 2^10
    0.001953
    >>> longest_run_pvalue(10, 1)
    1.0
    """
    if run <= 1:
        return 1.0
    if run > n:
        return 0.0
    # count sequences (up to the first sign) whose runs are all < run
    ways = np.zeros(run)
    ways[1] = 1.0  # the first element: a run of length 1
    for _ in range(n - 1):
        new = np.zeros(run)
        new[1] = ways[1:].sum()  # sign changes
        new[2:] = ways[1:-1]  # run continues
        ways = new
    return float(1.0 - ways[1:].sum() / 2.0 ** (n - 1))


def _degenerate(mdl: LatentModel, theta, nu_hat, tau, share_min) -> bool:
    """True if a (step-1) fit has a parameter at a bound or a component below ``share_min`` everywhere."""
    lo, hi = _bounds(mdl, nu_hat, tau)
    z = np.log(theta)
    if np.any(z - lo < 1e-3) or np.any(hi - z < 1e-3):
        return True
    share = np.max(mdl.wv_components(theta, tau) / nu_hat[None, :], axis=1)
    return bool(np.any(share < share_min))


def _unresolved_fast_gms(fit: GMWMFit) -> list[str]:
    """GMs of a fit whose WV peak (scale 3.785 T_c) lies below twice the first scale used."""
    mdl = fit.latent_model
    out = []
    for lab, sl, key in zip(mdl.labels, mdl.slices, mdl.components):
        if key == "GM" and _GM_PEAK * fit.dt_s / fit.theta[sl.start] < 2.0 * fit.scale_s[0]:
            out.append(f"{lab} (T_c = {fit.dt_s / fit.theta[sl.start]:.3g} s)")
    return out


def _longest_run(x) -> int:
    s = np.sign(x)
    best = cur = 1
    for i in range(1, s.size):
        cur = cur + 1 if s[i] == s[i - 1] and s[i] != 0 else 1
        best = max(best, cur)
    return best


def _lines_reason(fit: GMWMFit, mdl: LatentModel, periodic) -> str | None:
    """The hard reason of a candidate with QN whose QN WV does not stand above the lines' envelope at any used
    scale (:func:`fogdrift.noise.periodic.q_stands_above_lines`); None when it does or there is no QN or line."""
    if periodic is None or "QN" not in mdl.components:
        return None
    q_wv = fit.component_wv()[list(mdl.components).index("QN")]
    env_each = periodic_wvar(periodic, fit.tau_samples, fit.dt_s, envelope=True, per_line=True)
    above, ratio = q_stands_above_lines(q_wv, env_each.sum(axis=0))
    if above:
        return None
    f_top = periodic.lines[int(np.argmax(env_each[:, 0]))][0]
    return (f"{_LINES_REASON}: QN's WV is at most {ratio:.2g}x the envelope of the lines' WV (sin^4 replaced by 1) "
            f"at the used scales {fit.scale_s[0]:.4g}-{fit.scale_s[-1]:.4g} s, not the {Q_OVER_ENVELOPE:g}x it must "
            f"stand above it; the {line_name(periodic, f_top)} falls as tau^-2 like QN and its wandering amplitude "
            "and frequency fill its nulls")


def _checks(fit: GMWMFit, mdl: LatentModel, *, z_max, se_log_max, run_alpha, share_min, snr_min,
            whiten, lo95=None, hi95=None, periodic=None) -> list[str]:
    """Why ``fit`` of candidate ``mdl`` is rejected ("hard: ..." / "soft: ..."; empty: it passes).

    ``lo95``/``hi95`` [(deg/h)^2]: the measured WV's 95 % interval at the fitted scales; with them a RW or DR
    that fails the sustained-slope rule (:func:`fogdrift.noise.rules.slope_claim`) is a hard failure;
    ``periodic``: the record's spectral lines, beside which a QN must stand above their envelope.
    """
    reasons = []
    by_lines = _lines_reason(fit, mdl, periodic)
    if by_lines:
        reasons.append(by_lines)
    if fit.at_bound:
        reasons.append(f"hard: at a bound: {', '.join(param_label(n) for n in fit.at_bound)}")
    comp = fit.component_wv()
    share = np.max(comp / fit.nu2_hat[None, :], axis=1)
    snr = np.max(comp / fit.sd_nu2[None, :], axis=1)
    for lab, sh, sn in zip(mdl.labels, share, snr):
        if sh < share_min:
            reasons.append(f"hard: {lab} explains at most {sh:.1e} of the WV at every scale (collapsed)")
        elif sn < snr_min:
            reasons.append(f"soft: {lab} changes the WV by at most {sn:.2g} SD at any scale (not detectable)")
    if not np.all(np.isfinite(fit.se_z)):
        bad = [n for n, s in zip(fit.param_names, fit.se_z) if not np.isfinite(s)]
        reasons.append(f"hard: not identified (singular information): {', '.join(param_label(n) for n in bad)}")
    if lo95 is not None and hi95 is not None:
        # a RW (DR) needs a sustained WV slope +1 (+2) over an octave: a hump is a GM, a flat stretch no RW
        for lab, key, row in zip(mdl.labels, mdl.components, comp):
            if key in ("RW", "DR"):
                claim = slope_claim(fit.scale_s, fit.nu2_hat, lo95, hi95, fit.nu2_fit, row, SLOPES[key],
                                    name=lab, curve="WV")
                if not claim.ok:
                    reasons.append(f"hard: {claim.reason}")
    if not fit.converged:
        reasons.append("soft: the optimiser did not report convergence")
    s_min, s_max = float(fit.scale_s[0]), float(fit.scale_s[-1])
    for lab, sl, key in zip(mdl.labels, mdl.slices, mdl.components):
        if key == "GM":
            tc = fit.dt_s / fit.theta[sl.start]
            peak = _GM_PEAK * tc
            if not (2.0 * s_min <= peak <= s_max / 4.0):
                reasons.append(f"soft: {lab} T_c = {tc:.3g} s puts its WV peak (scale {peak:.3g} s) less than two "
                               f"octaves inside the observed scales {s_min:.3g}-{s_max:.3g} s, so its "
                               f"{'decay' if peak > s_max / 4.0 else 'rise'} is not observed (then it is "
                               f"indistinguishable from {'RW' if peak > s_max / 4.0 else 'WN'})")
    zr = fit.z_resid
    j = int(np.argmax(np.abs(zr)))
    if abs(zr[j]) > z_max:
        reasons.append(f"soft: residual z = {zr[j]:.2f} at scale {fit.scale_s[j]:.4g} s (|z| > {z_max:g})")
    innov = whiten(fit.nu2_hat - fit.nu2_fit)
    run = _longest_run(innov)
    p_run = longest_run_pvalue(innov.size, run)
    if p_run < run_alpha:
        reasons.append(f"soft: {run} same-sign innovation residuals in a row (p = {p_run:.2g} < {run_alpha:g})")
    big = [(n, s) for n, s in zip(fit.param_names, fit.se_z) if np.isfinite(s) and s > se_log_max]
    if big:
        reasons.append(f"soft: not identified, standard error of the log above {se_log_max:g}: "
                       + ", ".join(f"{param_label(n)} {s:.2f}" for n, s in big))
    return reasons


# ----------------------------------------------------------------------------------------
# Selection
# ----------------------------------------------------------------------------------------
def _fit_step1_all(wv, models, idx, n_starts, prev=None):
    """Step 1 of every candidate that has enough scales; warm-started from ``prev`` if given."""
    out = {}
    for mdl in models:
        if idx.size < mdl.n_params + 2:
            continue
        start = prev[mdl][0] if prev is not None and mdl in prev else None
        out[mdl] = _step1(wv, mdl, idx, n_starts=n_starts, start=start)
    return out


def _line_scales(wv, periodic, j_max) -> list:
    """The leading scales left out for spectral lines: up to the last one where the lines' WV exceeds
    :data:`~fogdrift.noise.periodic.LINE_SHARE_MAX` of the measured WV, at most ``j_max`` of them."""
    if periodic is None:
        return []
    each = periodic_wvar(periodic, wv.tau_samples, wv.dt_s, per_line=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        share = each.sum(axis=0) / wv.nu2_dph2
    over = np.flatnonzero(share > LINE_SHARE_MAX)
    if over.size == 0:
        return []
    j_end = min(int(over[-1]) + 1, max(int(j_max), 0))
    last = float(wv.scale_s[over[-1]])
    out = []
    for j in range(j_end):
        name = line_name(periodic, periodic.lines[int(np.argmax(each[:, j]))][0])
        if share[j] > LINE_SHARE_MAX:
            why = (f"{name} dominates the wavelet variance here: the lines' WV is {100 * share[j]:.3g} % of the "
                   f"measured WV (more than {100 * LINE_SHARE_MAX:g} %), and no latent process models a line")
        else:
            why = (f"{name} reaches the wavelet variance up to scale {last:.4g} s (more than "
                   f"{100 * LINE_SHARE_MAX:g} % of the measured WV there; {100 * share[j]:.2g} % at this scale, "
                   "near a null of the line's Haar gain): the scales below it are left out with it")
        out.append(ExcludedScale(level=int(wv.level[j]), scale_s=float(wv.scale_s[j]), best_abs_z=float("nan"),
                                 best_model="", reason=why, line_share=float(share[j])))
    return out


def select_model(wvar, candidates=None, *, exclude_short=True, max_excluded=None, n_check=3, z_max=3.0,
                 se_log_max=1.0, run_alpha=0.01, share_min=0.01, snr_min=2.0, n_starts=4,
                 periodic=None) -> SelectionResult:
    """Choose a latent model by WIC with a common Omega, sanity checks and automatic short-scale exclusion.

    Parameters
    ----------
    wvar : WvarResult
        One axis.
    candidates : sequence of str, optional
        Model strings (default :data:`DEFAULT_CANDIDATES`).
    exclude_short : bool, keyword-only
        Scan for leading scales no candidate explains (see the module docstring).
    max_excluded : int, optional
        At most this many leading scales are excluded (default ``J // 3``).
    n_check : int
        Number of leading scales that must be explained.
    z_max : float
        Bound on standardised residuals (scan and checks).
    se_log_max : float
        Largest acceptable standard error of a log parameter.
    run_alpha : float
        Significance of the innovation run test.
    share_min : float
        A component must reach this fraction of the WV at some scale ("hard" check).
    snr_min : float
        A component must reach this many standard deviations of the WV estimate at some
        scale (otherwise it only lives in the noise of the longest scales).
    n_starts : int
        Starting points per candidate (:func:`~fogdrift.gmwm.estimator.gmwm_fit`).
    periodic : PeriodicContent, optional
        Spectral lines of the same rate (:func:`fogdrift.noise.periodic.periodic_content` of its spectrum): the
        leading scales they dominate are excluded and QN is claimed only above their envelope (step 0 of the
        module docstring).  None: no lines.

    Returns
    -------
    SelectionResult

    Examples
    --------
    >>> from fogdrift.gmwm import haar_wvar, simulate_latent
    >>> x = simulate_latent("WN+RW", [1.0, 1e-5], 2**15, seed=2)
    >>> sel = select_model(haar_wvar(x, 0.01), ["WN", "WN+RW", "WN+RW+GM"])
    >>> sel.selected, [c.model for c in sel.candidates if c.passed]
    ('WN+RW', ['WN+RW'])
    """
    wv = _check_wv(wvar)
    names = DEFAULT_CANDIDATES if candidates is None else candidates
    if isinstance(names, str):
        names = [names]
    models: list[LatentModel] = []
    for c in names:
        m = parse_model(c)
        if m not in models:
            models.append(m)
    if not models:
        raise ConfigError("candidates must name at least one model")
    J = len(wv)
    p_max = max(m.n_params for m in models)
    p_min = min(m.n_params for m in models)
    if J < p_min + 2:
        raise InsufficientDataError(f"{J} scales are too few for any candidate (need {p_min + 2})",
                                    needed=p_min + 2, got=J)
    # the scales the lines dominate go first, keeping enough for every candidate; the scan's own limit counts
    # from there
    excluded = _line_scales(wv, periodic, J - (p_max + 2))
    n_lines = len(excluded)
    max_ex = n_lines + (J // 3 if max_excluded is None else int(max_excluded))
    opts = dict(z_max=z_max, se_log_max=se_log_max, run_alpha=run_alpha, share_min=share_min, snr_min=snr_min,
                periodic=periodic)
    j0, step1 = n_lines, None
    while True:
        j0, step1 = _scan(wv, models, j0, step1, excluded, exclude_short=exclude_short, max_ex=max_ex,
                          n_check=n_check, p_max=p_max, n_starts=n_starts, z_max=z_max, share_min=share_min)
        idx = np.arange(j0, J)
        results, chosen, ok, src = _choose(wv, models, idx, step1, opts)
        # the final (efficiently weighted) fit must also explain the first scales, and not only
        # with a GM faster than the first scales resolve (an output-filter artefact, e.g. ADIS16405)
        nchk = min(n_check, idx.size)
        zfirst = float(np.max(np.abs(chosen.fit.z_resid[:nchk])))
        fast = [] if ok else _unresolved_fast_gms(chosen.fit)
        if not exclude_short or (zfirst <= z_max and not fast) or j0 >= max_ex or J - (j0 + 1) < p_max + 2:
            break
        if zfirst > z_max:
            why = (f"the selected model {chosen.model} leaves max |z| = {zfirst:.3g} > {z_max:g} over the "
                   f"first {nchk} scales from {wv.scale_s[j0]:.4g} s")
        else:
            why = (f"no candidate passed, and the closest ({chosen.model}) explains the first scales only with "
                   f"{', '.join(fast)}, whose WV peak lies below twice the first scale {wv.scale_s[j0]:.4g} s "
                   "(a short-scale artefact such as an output filter)")
        excluded.append(ExcludedScale(level=int(wv.level[j0]), scale_s=float(wv.scale_s[j0]), best_abs_z=zfirst,
                                      best_model=chosen.model, reason=why))
        j0 += 1
    note = ""
    if exclude_short and max_ex > n_lines and j0 >= max_ex:
        note = f"the exclusion scan stopped at its limit of {max_ex - n_lines} excluded short scales" + (
            f" beyond the {n_lines} the spectral lines dominate" if n_lines else "")
        if zfirst > z_max:
            note += (f"; the first kept scales are still not explained (max |z| = {zfirst:.3g}): read the result "
                     "with care")
        else:
            note += f"; the first kept scales are explained (max |z| = {zfirst:.3g})"
    if not ok:
        warnings.warn(
            f"no candidate passed every sanity check; {chosen.model} (smallest WIC among the candidates "
            f"without hard failures) is returned although it failed: {'; '.join(chosen.reasons)}"
            + (f" ({note})" if note else ""),
            FogdriftWarning, stacklevel=2,
        )
    return SelectionResult(
        selected=chosen.model, fit=chosen.fit, ieee=to_ieee(chosen.fit), candidates=results, excluded=excluded,
        levels_used=wv.level[idx], omega_source=src, passed_checks=ok, scan_note=note,
    )


def _scan(wv, models, j0, step1, excluded, *, exclude_short, max_ex, n_check, p_max, n_starts, z_max,
          share_min):
    """Advance ``j0`` past leading scales no non-degenerate candidate explains (appends to ``excluded``);
    returns ``(j0, step1 fits on the scales j0..J-1)``."""
    J = len(wv)
    fresh = step1 is None
    while True:
        idx = np.arange(j0, J)
        # the scan warm-starts from the previous level's fits only
        step1 = _fit_step1_all(wv, models, idx, n_starts if step1 is None else 0, prev=step1)
        if not step1:
            raise InsufficientDataError("too few scales remain for any candidate")
        if not exclude_short or j0 >= max_ex or J - (j0 + 1) < p_max + 2:
            break
        best = min(step1, key=lambda m: step1[m][1])
        nchk = min(n_check, idx.size)
        sd = np.sqrt(np.diag(wvar_covariance(wv.tau_samples[idx[:nchk]], wv.n_coef[idx[:nchk]],
                                             best.sdf(step1[best][0]), diagonal=True)) / wv.efficiency)
        scores = {}
        for mdl, (th1, *_rest) in step1.items():
            if _degenerate(mdl, th1, wv.nu2_dph2[idx], wv.tau_samples[idx].astype(float), share_min):
                continue  # a collapsed fit (e.g. WN -> 0 with a fast GM) does not "explain" anything
            nu = mdl.wv(th1, wv.tau_samples[idx[:nchk]])
            scores[mdl] = float(np.max(np.abs(wv.nu2_dph2[idx[:nchk]] - nu) / sd))
        if not scores:
            break
        closest = min(scores, key=scores.get)
        if scores[closest] <= z_max:
            break
        excluded.append(ExcludedScale(
            level=int(wv.level[j0]), scale_s=float(wv.scale_s[j0]), best_abs_z=scores[closest],
            best_model=closest.name,
            reason=(f"no candidate explains the scales from {wv.scale_s[j0]:.4g} s: the closest "
                    f"({closest.name}) leaves max |z| = {scores[closest]:.3g} > {z_max:g} over the first {nchk}"),
        ))
        j0 += 1
        fresh = False
    if not fresh:  # full multi-start on the final scales (plus the warm start)
        step1 = _fit_step1_all(wv, models, np.arange(j0, J), n_starts, prev=step1)
    return j0, step1


def _choose(wv, models, idx, step1, opts):
    """Common-Omega fits, checks and the WIC choice; returns (scores, chosen, passed, omega source)."""
    def score_all(ref: LatentModel):
        own = _finish(wv, ref, idx, *step1[ref])  # the reference's own iterated fit
        V = _model_V(ref, own.theta, wv, idx)
        src = f"common: V at the iterated fit of {ref.name}"
        whiten = Whitener(V=V)
        out = []
        for mdl in models:
            if mdl not in step1:
                out.append(CandidateScore(mdl.name, mdl.n_params, float("nan"), float("nan"), float("nan"),
                                          False, ("hard: too few scales for this model",)))
                continue
            fit = _finish(wv, mdl, idx, *step1[mdl], V=V, omega_source=src)
            reasons = _checks(fit, mdl, whiten=whiten, lo95=wv.ci_lo95_dph2[idx], hi95=wv.ci_hi95_dph2[idx],
                              **opts)
            out.append(CandidateScore(mdl.name, mdl.n_params, fit.q, fit.penalty, fit.wic, not reasons,
                                      tuple(reasons), fit))
        fitted = [c for c in out if c.fit is not None]
        passed = [c for c in fitted if c.passed]
        if passed:
            return out, min(passed, key=lambda c: c.wic), True, src
        # a candidate refused beside spectral lines is returned only when every candidate is (a QN model asked for)
        pool = ([c for c in fitted if not c.hard_failure]
                or [c for c in fitted if not any(r.startswith(_LINES_REASON) for r in c.reasons)] or fitted)
        return out, min(pool, key=lambda c: c.wic), False, src

    # pass 1: V of the pilot (smallest Q_1 + 2p under the common eta3 weights); then V of the
    # provisional choice, until the choice is stable (a V from an over-fitted curve mis-weights the
    # longest scales).  If nothing passes under a V, the next pilot in the ranking supplies V.
    ranking = sorted(step1, key=lambda m: step1[m][1] + 2.0 * m.n_params)
    ref, tried, fallback = ranking[0], [], None
    for _ in range(4):
        results, chosen, ok, src = score_all(ref)
        tried.append(ref)
        if fallback is None:
            fallback = (results, chosen, ok, src)
        new_ref = parse_model(chosen.model)
        if ok and (new_ref == ref or new_ref in tried):
            return results, chosen, ok, src
        if ok:
            ref = new_ref
            continue
        untried = [m for m in ranking if m not in tried]
        if not untried:
            break
        ref = untried[0]
    if ok:
        return results, chosen, ok, src
    return fallback
