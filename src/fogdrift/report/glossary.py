"""The report's glossary: every metric and table mark explained once (a table as data).

Each entry is ``(term, anchor, text)``; the HTML report renders them as a definition list at the end and
links to them by anchor.

The words for the Python names that reach user text (model parameters, noise-component keys, their unit
suffixes of :mod:`fogdrift.units`) live here too: :func:`plain_setting` writes ``arw_dprh 0.0662`` as
``N 0.0662 deg/√h``.  JSON files keep the Python names.
"""

from __future__ import annotations

__all__ = ["GLOSSARY", "NAME_WORDS", "glossary_entries", "plain_name", "plain_setting"]

GLOSSARY = (
    # noise identification
    ("Allan deviation σ(τ) [deg/h]", "adev",
     "Spread of the rate averaged over τ seconds, from differences of neighbouring averages (IEEE Std 952-1997 "
     "Annex C). Each noise term has its own slope in a log-log plot; error bars are 68 % intervals from the "
     "equivalent degrees of freedom."),
    ("Q, N, B, K, R", "terms",
     "The IEEE-952 noise coefficients: Q quantization [µrad], N angle random walk [deg/√h] (white rate noise; "
     "the angle error it leaves grows as N·√t), B bias instability [deg/h], K rate random walk [deg/h^1.5], "
     "R rate ramp [deg/h²]. Fitted jointly to the whole Allan curve (generalised least squares with the "
     "covariance of the estimates), not read off single slopes."),
    ("value [lo, hi]", "interval",
     "Estimate and its 95 % interval (profile likelihood over every plausible noise model, widened when the fit "
     "is poor). A lower bound of 0 means the data allow the term to vanish."),
    ("– (< x)", "absent",
     "The term is not in the selected noise model: the curve shows no sign of it in the fitted τ range; x is its "
     "one-sided 95 % upper bound. “–” alone: no bound could be computed."),
    ("n/e", "ne",
     "Not estimable: the record or the statistic cannot support a number (e.g. no flat floor for B inside the "
     "record); the reason is listed under “What this record cannot support”. “n/e (< x)” gives a bound."),
    ("B_min", "bmin",
     "The classical IEEE reading of bias instability: minimum of the fitted ADEV divided by 0.664. “curve still "
     "falling” means the minimum lies beyond the record, so only an upper bound is known."),
    ("selected noise model", "selected",
     "The set of terms chosen from all candidates by an information criterion (fewest terms that describe the "
     "curve); models within the criterion's window are “plausible” and widen the intervals."),
    ("χ²_red", "chi2",
     "Reduced chi-squared of the noise fit: χ² / degrees of freedom. About 1 when the IEEE-952 model describes "
     "the curve within its statistical scatter; much above 1 when it does not (e.g. platform vibration, a "
     "temperature trend). Quality: good (p ≥ 0.01), acceptable (χ²_red ≤ 4), poor otherwise."),
    ("fitted τ range", "taurange",
     "The span of averaging times used in the fit; τ left out (shaded in Fig. 3) is listed with the reason."),
    # compensation evidence
    ("heading error (angle error) [deg]", "heading",
     "What an engineer loses: after a static calibration (bias = mean of the preceding window), each compensator "
     "forecasts the drift free-running; the residual rate is integrated over the horizon to an angle. Rolling "
     "origins on the held-out test block; RMS over origins."),
    ("constant-bias compensation", "constbias",
     "The reference: subtract the calibration window's mean and nothing else (what a navigation system does "
     "after static alignment). A drift model is worth running only if it beats this."),
    ("ratio to constant bias", "ratio",
     "RMS heading error of a model divided by constant bias's at the same horizon and origins. The model reduces "
     "the error only at 0.95 or below AND when it is better at more than half of the non-overlapping origins; it "
     "makes it worse at 1.05 or above AND when worse at more than half. A forecast whose error is not finite or "
     "above 1000 x constant bias's reads “diverges”."),
    ("origins, independent origins", "origins",
     "Calibration origins of the rolling evaluation. Origins closer than the horizon share most of their "
     "integration window; only origins with non-overlapping horizons count as independent, and a verdict needs "
     "10 of them."),
    ("spread over origins", "spread",
     "Median and 90th percentile of |angle error| over origins, and the share of origins where the model's error "
     "is smaller than constant bias's."),
    ("Kalman 1σ envelope / inside", "envelope",
     "The Kalman filter's own predicted 1-σ angle error (median over origins) and the share of origins whose real "
     "error fell inside it: about 68 % when its noise model is calibrated; far above, over-cautious; far below, "
     "over-confident."),
    ("artefact check: gain, step, ramp", "artefacts",
     "Known rate signals (sinusoids, a step, a ramp; amplitude 3 × the block's std) are injected into the "
     "held-out block; the fraction that survives each compensator is its gain (1 = untouched). A compensator "
     "that removes more than 10 % of a real signal in a band where its Allan curve “improves” is flagged: that "
     "improvement is removal of real rate, which a static record cannot tell apart from drift."),
    # one-step metrics
    ("one-step prediction, persistence", "onestep",
     "Each model predicts the next drift sample from the samples before it. Persistence predicts “same as the "
     "last sample”: the baseline every model must beat."),
    ("wavelet drift (paper target) / causal drift", "targets",
     "The paper's target is the wavelet approximation of the test block, which uses future samples (non-causal): "
     "predicting it one step ahead is easier than anything a real-time compensator faces. The causal drift uses "
     "past samples only (what a compensator can see). The paper's measure is shown last and labelled."),
    ("RMSE, MAE, max|e| [deg/h]", "rmse",
     "Root-mean-square, mean absolute and largest one-step error on the test block. RMSE weighs a few large "
     "errors, MAE typical ones."),
    ("MASE", "mase",
     "Mean absolute scaled error: MAE divided by the in-sample MAE of persistence on the training block "
     "(Hyndman & Koehler 2006). Below 1: better than persistence was in training."),
    ("skill vs persistence", "skill",
     "1 − RMSE(model) / RMSE(persistence) on the same samples: 1 perfect, 0 as good as persistence, negative "
     "worse."),
    ("p0, p0_w, p0 as measured [%]", "p0",
     "The paper's precision p0 = 100·(1 − mean |e_k| / |y_k|). It divides by each sample of the drift, so where "
     "the drift crosses zero single terms explode: fogdrift returns NaN when min|y| < 0.1 × median|y| (always, "
     "the usual case for a drift whose bias was removed). p0_w = 100·(1 − Σ|e| / Σ|y|) has no such division. “p0 as measured” adds the bias "
     "and Earth rate back, as the paper presumably did; any predictor then approaches 100 %, which is why "
     "persistence's value is given beside it."),
    ("Table 2 rows", "table2",
     "Noise coefficients of the test block before and after compensation: “drift residual (paper)” = wavelet "
     "drift minus its one-step prediction (the paper's Table 2); “practical” = gyro output minus the one-step "
     "prediction from the causal drift. A practical row of a model flagged by the artefact check is marked: its "
     "“improvement” removes signal."),
    ("training-block bias, Earth rate", "bias",
     "The constant removed before modelling: the mean of the training block, after subtracting the Earth-rate "
     "projection when a latitude and axis orientation are given."),
)


def glossary_entries() -> list:
    """``[(term, anchor, text), ...]`` in reading order.

    Examples
    --------
    >>> [a for _, a, _ in glossary_entries()][:3]
    ['adev', 'terms', 'interval']
    """
    return list(GLOSSARY)


#: Words and unit of the Python names that reach user text: ``name: (words, unit)``.  Names not listed are
#: read by their unit suffix (:data:`SUFFIX_UNITS`) with underscores as spaces.
NAME_WORDS = {
    # noise components of the Kalman model (fogdrift.models.statespace) and the IEEE-952 terms
    "arw_dprh": ("N", "deg/√h"),
    "q_urad": ("Q", "µrad"),
    "bias_instability_dph": ("B", "deg/h"),
    "rrw_dphrh": ("K", "deg/h^1.5"),
    "ramp_dph2": ("R", "deg/h²"),
    "sigma_dph": ("σ", "deg/h"),
    "tc_s": ("correlation time", "s"),
    "white": ("white noise", ""),
    "quantization": ("quantization noise", ""),
    "random_walk": ("rate random walk", ""),
    "gauss_markov": ("Gauss–Markov", ""),
    "ramp": ("rate ramp", ""),
    "allan": ("Allan", ""),
    "gmwm": ("GMWM", ""),
    # model hyper-parameters whose words are not their name's
    "bias_prior_dph": ("bias prior 1σ", "deg/h"),
    "dt_s": ("time step", "s"),
    "max_order": ("largest order", ""),
    "val_fraction": ("validation fraction", ""),
    "clip_norm": ("gradient clip norm", ""),
    "ago_frame": ("AGO frame", ""),
}

#: Unit suffixes of fogdrift's names (:mod:`fogdrift.units`), longest first.
SUFFIX_UNITS = (("_dphrh", "deg/h^1.5"), ("_dprh", "deg/√h"), ("_dph2", "deg/h²"), ("_dph", "deg/h"),
                ("_dps", "deg/s"), ("_urad", "µrad"), ("_arcsec", "arcsec"), ("_deg", "deg"), ("_hz", "Hz"),
                ("_s", "s"))


def plain_name(name: str) -> tuple[str, str]:
    """``(words, unit)`` for a Python name (unit ``""`` when it has none).

    Examples
    --------
    >>> plain_name("arw_dprh"), plain_name("learning_rate"), plain_name("window_s")
    (('N', 'deg/√h'), ('learning rate', ''), ('window', 's'))
    """
    if name in NAME_WORDS:
        return NAME_WORDS[name]
    for suffix, unit in SUFFIX_UNITS:
        if name.endswith(suffix) and len(name) > len(suffix):
            return name[: -len(suffix)].replace("_", " "), unit
    return name.replace("_", " "), ""


def plain_setting(name: str, value, fmt=str) -> str:
    """``name value`` in words with the unit after the value; ``None`` reads "default".

    Examples
    --------
    >>> plain_setting("arw_dprh", 0.0662), plain_setting("learning_rate", None), plain_setting("batch_size", 2048)
    ('N 0.0662 deg/√h', 'learning rate default', 'batch size 2048')
    """
    words, unit = plain_name(name)
    if value is None:
        return f"{words} default"
    return f"{words} {fmt(value)}" + (f" {unit}" if unit else "")
