"""IEEE-952 noise identification from an Allan-family curve (Allan, Hadamard, modified Allan).

The model (IEEE Std 952-1997 Annex C; method notes §2.2-2.5): the five terms are independent, so their variances
add.  For the Allan variance (sigma in deg/h, tau in s)::

    sigma^2(tau) = A_Q tau^-2 + A_N tau^-1 + A_B + A_K tau + A_R tau^2,
    A_Q = 3 Q^2,  A_N = N^2,  A_B = (2 ln2 / pi) B^2,  A_K = K^2 / 3,  A_R = R^2 / 2.

:func:`fit_noise` chooses which terms the data support and estimates them with intervals that are honest about
the correlation between taus, the model choice and the fit quality (:mod:`.identify`); it always returns the fit
quality and the reason for every term it does not resolve.

Modules: :mod:`.terms` (the term table and each statistic's laws: one home of these facts), :mod:`.covariance`
(model-based covariance of Allan-family estimates at any averaging factors), :mod:`.engine` (the score objective,
solver, profile intervals), :mod:`.identify` (model selection, fit range, intervals, words), :mod:`.readouts`
(the classic slope read-outs as a labelled cross-check), :mod:`.result` (:class:`NoiseFit`, :class:`NoiseTerm`),
:mod:`.convert` (A <-> coefficients, the paper's Table 1).
"""

from __future__ import annotations

import numpy as np

from ..allan import edf_simple
from ..errors import ConfigError
from .convert import coefficients_from_A, paper_table1_from_A
from .identify import POOR_CHI2_RED, identify, thin_taus
from .periodic import null_taus, periodic_content
from .quantity import express as express_quantity
from .readouts import Readout, slope_readouts
from .result import TERM_STATUSES, NoiseFit, NoiseTerm
from .terms import (
    DISPLAY_UNITS,
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
    power_terms,
    term_spec,
)
from ..units import B_FACTOR

__all__ = [
    "express_quantity",
    "fit_noise",
    "identify",
    "NoiseFit",
    "NoiseTerm",
    "TERM_STATUSES",
    "Readout",
    "slope_readouts",
    "thin_taus",
    "POOR_CHI2_RED",
    "TERMS",
    "TERM_UNITS",
    "TERM_HEADERS",
    "DISPLAY_UNITS",
    "TERM_TABLE",
    "TermSpec",
    "term_spec",
    "TermLaw",
    "VARIANCE_LAWS",
    "UNESTIMABLE",
    "default_terms",
    "laws_of",
    "coefficients_from_A",
    "paper_table1_from_A",
    "B_FACTOR",
]


def _strides(allan):
    """Start-index stride of each estimate: 1 overlapping, m non-overlapping, b fast (from the term count)."""
    est = getattr(allan, "estimator", "overlapping")
    m = np.asarray(getattr(allan, "m", np.ones(len(allan.tau_s))), dtype=np.float64)
    if est == "overlapping" or not hasattr(allan, "n_terms"):
        return None
    if est == "non-overlapping":
        return m
    n = float(allan.n_samples)
    k = np.maximum(np.asarray(allan.n_terms, dtype=np.float64) - 1.0, 1.0)
    return np.maximum(1.0, np.rint((n - 2 * m) / k))


def _inflation(allan):
    """Variance of each estimate relative to the overlapping estimator's, for non-overlapping or strided ("fast")
    sampling: the ratio of their white-FM EDFs (SP 1065 Table 5), whatever noise type the local slope suggests
    (the ratio is a property of the sampling; a misread slope at the last tau must not make it explode)."""
    est = getattr(allan, "estimator", "overlapping")
    if est == "overlapping":
        return None

    n = int(allan.n_samples)
    out = []
    for m, k in zip(np.asarray(allan.m, dtype=np.int64), np.asarray(allan.n_terms, dtype=np.int64)):
        m = int(m)
        if 2 * m > n:
            out.append(1.0)
            continue
        ovl = edf_simple(n + 1, m, 0)
        if est == "non-overlapping":
            kk = n // m
            own = edf_simple(kk + 1, 1, 0) if kk >= 2 else 1.0
        else:  # fast: the overlapping sum over every b-th start index
            b = max(1, int(round((n - 2 * m) / max(int(k) - 1, 1))))
            own = min(ovl, edf_simple(n // b + 1, max(1, m // b), 0)) if m // b >= 1 and 2 * (m // b) <= n // b else ovl
        out.append(max(1.0, ovl / max(own, 1e-12)))
    return np.asarray(out)


def fit_noise(allan, *, terms=None, tau_range_s=None, max_per_octave=1, ic_penalty=2.0,
              plausible_delta=6.0, spectrum=None, markov=False) -> NoiseFit:
    """Identify the IEEE-952 noise terms of an Allan-family curve.

    Parameters
    ----------
    allan : AllanResult or a curve object
        Needs ``statistic``, ``tau_s`` [s], ``var`` [(deg/h)^2 or (m/s^2)^2], ``dev_hi95`` [its root], ``n_samples`` and
        ``dt_s`` [s]; ``m`` (averaging factors) if present.  A published curve (taus, variances, upper 95 %
        bounds, record length) can be given the same way, or its arrays passed to :func:`identify`.
    terms : sequence of str or None, keyword-only
        ``None`` (default): the model is selected from the data among every subset of the terms the statistic can
        estimate.  A sequence fixes the model (no selection), e.g. ``("N", "K")``.
    tau_range_s : (float or None, float or None) or None, keyword-only
        Fit range [s]; ``None`` leaves out short taus that no model describes automatically (and says why).
    max_per_octave, ic_penalty, plausible_delta : keyword-only
        Working points per octave, IC penalty per term, IC window of the plausible models (see
        :func:`fogdrift.noise.identify`).
    spectrum : SpectrumSummary or None, keyword-only
        The spectrum of the same rate series (:func:`fogdrift.noise.spectral.analyse_spectrum`): its lines become
        the candidate S term (one fitted scale, the lines' relative powers fixed from the spectrum), the curve's
        taus at whole multiples of each period are fitted too (where ``allan`` holds them), notes name the real
        frequencies, and a short-tau shape is called an output filter only where it shows a roll-off.  None (a
        published curve): no S term, and no shape is called a filter.
    markov : bool, keyword-only
        Try the exponentially correlated (Gauss-Markov) term M (only without fixed ``terms``).  Default False, so
        the callers that build models from ``A`` (the Kalman filter, model bundles: power-law terms only) see the
        same fit as before; :func:`fogdrift.pipeline.analyse_allan` (``fogdrift allan``, the reports) turns it on.

    Returns
    -------
    NoiseFit
        With the slope read-outs of the whole curve (Allan deviation only) as a cross-check.

    Raises
    ------
    ConfigError
        A term the statistic cannot estimate (R with hdev), an unknown term or statistic.
    InsufficientDataError
        Too few taus in the fit range.

    Examples
    --------
    >>> from fogdrift.simulate import simulate
    >>> from fogdrift.allan import allan_variance
    >>> y = simulate(2**18, 0.1, arw_dprh=0.01, seed=3)
    >>> fit = fit_noise(allan_variance(y, 0.1))
    >>> round(fit.terms["N"].value, 3), fit.terms["N"].status, fit.quality
    (0.01, 'resolved', 'good')
    >>> [t for t in "QBKR" if fit.terms[t].status == "resolved"]  # white noise only: nothing else is claimed
    []
    """
    statistic = getattr(allan, "statistic", "adev")
    laws = laws_of(statistic)
    if terms is not None:
        if isinstance(terms, str):
            terms = tuple(t for t in terms.replace("+", ",").split(",") if t.strip())
        terms = tuple(str(t).strip().upper() for t in terms)
        names = power_terms()
        bad = [t for t in terms if t not in names]
        if bad or not terms or len(set(terms)) != len(terms):
            raise ConfigError(f"terms must be distinct names from {names}, got {terms!r} (option {{opt:terms}})")
        terms = tuple(t for t in names if t in terms)
    var = np.asarray(allan.var, dtype=np.float64)
    hi = np.asarray(allan.dev_hi95, dtype=np.float64) ** 2

    content = periodic_content(spectrum)
    keep = None
    if content is not None:
        t = np.asarray(allan.tau_s, dtype=np.float64)
        keep = null_taus(content.periods_s, float(allan.dt_s), float(t.min()), float(t.max()))
    fit = identify(allan.tau_s, var, int(allan.n_samples), float(allan.dt_s), var_hi95=hi,
                   m=getattr(allan, "m", None), statistic=statistic, terms=terms, tau_range_s=tau_range_s,
                   max_per_octave=max_per_octave, ic_penalty=ic_penalty, plausible_delta=plausible_delta,
                   var_inflation=_inflation(allan), strides=_strides(allan), periodic=content, keep_tau_s=keep,
                   markov=markov, spectrum_given=spectrum is not None,
                   rolloff_hz=None if spectrum is None else getattr(spectrum, "rolloff_hz", None))
    if statistic == "adev":
        fit.readouts = slope_readouts(allan.tau_s, np.sqrt(var), fit)
        if fit.no_fit:  # a printed bound is never below the measured read-out of the same term
            for name, ro in fit.readouts.items():
                t = fit.terms.get(name)
                if (t is not None and t.status == "no_fit" and ro.value is not None and t.hi95 is not None
                        and ro.unit == t.unit and ro.value > t.hi95):
                    fit.terms[name] = NoiseTerm(name, t.value, t.unit, t.lo95, ro.value, t.status, t.reason)
    del laws
    return fit
