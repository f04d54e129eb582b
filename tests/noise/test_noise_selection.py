"""The default noise identification against known truth: coverage, false claims, grid independence, filters.

Simulations: :func:`fogdrift.simulate.simulate` (exact IEEE-952 Allan laws), seeds 0..49 per design.  The
requirements are the issue's: 95 % intervals cover every present term in >= 90 % of seeds, an absent term is
claimed (lower bound > 0) in <= 5 %, N within 5 %, grid-independent results.  With 50 seeds a true 95 %
coverage gives >= 45 covered in 97 % of suites and a true 2 % false-claim rate stays <= 2 in 92 %: the bounds
below have slack for sampling, not for a broken method (a plain EDF-weighted fit covers K in ~85 %).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

from fogdrift.allan import allan_variance
from fogdrift.noise import fit_noise
from fogdrift.simulate import simulate

TERMS = ("Q", "N", "B", "K", "R")
KEY = {"q_urad": "Q", "arw_dprh": "N", "bias_instability_dph": "B", "rrw_dphrh": "K", "ramp_dph2": "R"}

#: name -> (dt_s, n_samples, simulate kwargs); each term dominates at least two octaves of tau.
DESIGNS = {
    "WN+RW": (0.01, 2**21, dict(arw_dprh=0.031, rrw_dphrh=0.42)),
    "WN+flicker+RW": (0.1, 2**20, dict(arw_dprh=0.02, bias_instability_dph=0.2, rrw_dphrh=0.4)),
    "QN+WN+RW+ramp": (0.01, 2**21, dict(q_urad=2.0, arw_dprh=0.02, rrw_dphrh=0.3, ramp_dph2=0.38)),
}
N_SEEDS = 50


def _fit(x, dt, taus="octave"):
    r = allan_variance(x, dt, taus=taus)
    return fit_noise(r)


@pytest.fixture(scope="module", params=sorted(DESIGNS))
def design_runs(request):
    dt, n, kw = DESIGNS[request.param]
    truth = {KEY[k]: v for k, v in kw.items()}
    fits = [_fit(simulate(n, dt, seed=seed, **kw), dt) for seed in range(N_SEEDS)]
    return request.param, truth, fits


@pytest.mark.slow
def test_intervals_cover_present_terms_and_do_not_claim_absent_ones(design_runs):
    name, truth, fits = design_runs
    for t in TERMS:
        tv = truth.get(t, 0.0)
        covered = sum((f.terms[t].lo95 or 0.0) <= tv <= f.terms[t].hi95 for f in fits)
        claimed = sum((f.terms[t].lo95 or 0.0) > 0 for f in fits)
        if tv > 0:
            assert covered >= 0.9 * N_SEEDS, (name, t, covered)
        else:
            assert claimed <= 0.05 * N_SEEDS, (name, t, claimed)


@pytest.mark.slow
def test_angle_random_walk_within_five_percent(design_runs):
    _, truth, fits = design_runs
    errs = [abs(f.terms["N"].value / truth["N"] - 1) for f in fits]
    assert max(errs) < 0.05


@pytest.mark.slow
def test_rate_random_walk_when_it_dominates_over_a_decade():
    """N = 0.031 deg/sqrt(h), K = 1.2 deg/h^1.5, 5.8 h at 100 Hz: K dominates 166 s .. 5243 s (1.5 decades).
    K is in the selected model in >= 75 % of seeds, its median error there is < 25 %, and where a ramp is
    chosen instead (the long-tau end cannot always tell tau^1 from tau^2), K's interval still holds the truth.
    (With K = 0.42, dominating 1.06 decades, K is reported in 16 of 20 seeds with a median error of 21 %.)"""
    dt, n, k_true = 0.01, 2**21, 1.2
    errs, missing_covered, n_missing = [], 0, 0
    for seed in range(20):
        f = _fit(simulate(n, dt, seed=seed, arw_dprh=0.031, rrw_dphrh=k_true), dt)
        k = f.terms["K"]
        if k.value is not None:
            errs.append(abs(k.value / k_true - 1))
        else:
            n_missing += 1
            missing_covered += (k.lo95 or 0.0) <= k_true <= k.hi95
    assert len(errs) >= 15 and np.median(errs) < 0.25, errs
    assert missing_covered == n_missing


@pytest.mark.slow
def test_results_do_not_depend_on_the_tau_grid():
    dt, n, kw = DESIGNS["WN+RW"]
    for seed in range(6):
        x = simulate(n, dt, seed=seed, **kw)
        fits = {g: _fit(x, dt, g) for g in ("octave", 100, 1000)}
        ref = fits["octave"]
        for g in (100, 1000):
            for t in ("N", "K"):
                a, b = ref.terms[t], fits[g].terms[t]
                width = a.hi95 - (a.lo95 or 0.0)
                assert abs(a.hi95 - b.hi95) <= 0.25 * width, (seed, g, t)
                assert abs((a.lo95 or 0) - (b.lo95 or 0)) <= 0.25 * width, (seed, g, t)
                if ref.selected == fits[g].selected and a.value is not None:
                    assert abs(a.value - b.value) <= 0.25 * width, (seed, g, t)


@pytest.mark.parametrize("cutoff_hz, seconds", [(25, 30), (25, 300), (40, 30), (40, 300), (60, 30), (60, 300)])
def test_output_filter_is_left_out_and_n_is_unbiased(cutoff_hz, seconds):
    fs, arw = 250.0, 0.011
    n = int(fs * seconds)
    x = simulate(n, 1 / fs, arw_dprh=arw, seed=7)
    alpha = np.exp(-2 * np.pi * cutoff_hz / fs)  # first-order low-pass, unit DC gain
    y = lfilter([1 - alpha], [1, -alpha], x)
    from fogdrift.noise.spectral import analyse_spectrum

    spec = analyse_spectrum(y, 1 / fs)
    f = fit_noise(allan_variance(y, 1 / fs), spectrum=spec)
    n_term = f.terms["N"]
    assert n_term.lo95 <= arw <= n_term.hi95
    assert f.excluded
    # "filter" only where the spectrum shows the roll-off; without a spectrum the word is never used
    assert ("filter" in f.excluded[0]["reason"]) == (spec.rolloff_hz is not None)
    g = _fit(y, 1 / fs)
    assert all("filter" not in e["reason"] for e in g.excluded)


def test_the_plausible_window_does_not_depend_on_rounding():
    """A superset of the selected model whose extra terms come out 0 has the selected model's chi-squared: its IC
    lies exactly ``plausible_delta`` (three extra terms x penalty 2) from the best, on the window's edge.  The same
    curve fitted again with every variance moved by a few units in the last place gives the same plausible models
    and the same candidate flags (a plain ``ic <= best + delta`` left such ties to the order of a sum), and every
    candidate at the edge is inside it (``<=``)."""
    import dataclasses

    at_edge = 0
    for seed in range(8):
        r = allan_variance(simulate(2**18, 0.01, seed=seed, arw_dprh=0.031, rrw_dphrh=0.42), 0.01, taus="octave")
        nudged = dataclasses.replace(r, var=r.var * (1 + 2.0**-50))
        fits = [fit_noise(r).to_dict(), fit_noise(nudged).to_dict()]
        assert fits[0]["plausible"] == fits[1]["plausible"]
        flags = [{tuple(c["terms"]): c["plausible"] for c in f["candidates"]} for f in fits]
        assert flags[0] == flags[1]
        for c in fits[0]["candidates"]:
            if abs(c["delta_ic"] - 6.0) < 1e-7 and set(fits[0]["selected"]) <= set(c["terms"]):
                at_edge += 1
                assert c["plausible"], c
    assert at_edge > 0
