"""Spectral lines in the GMWM (``fogdrift noise``): a sinusoid's Haar wavelet variance falls as tau^-2 above its
period exactly like quantization noise, so without the spectrum GMWM reads a tone or a sawtooth as QN+WN.

Seeded simulations, 2^17 samples each:

* white rate noise + a 20-Hz tone in a 100-Hz log, and white + a 0.24-s sawtooth (4.17 Hz and its harmonics) in a
  200-Hz log: QN is selected in no seed (<= 5 % of 20, i.e. none), the line-dominated leading scales are excluded
  with a reason that names the line within 2 % of its real frequency, and every QN candidate fails the hard
  "quantization not told apart from the spectral lines" check;
* white + genuine quantization (QN as :func:`fogdrift.gmwm.simulate_latent` draws it) still gets QN, without a line
  and beside a weak line whose envelope QN stands far above; white noise alone selects exactly what it selects
  without the spectrum.

Without the rule (``periodic=None``) the tone and sawtooth records get QN+WN in most seeds
(``test_without_the_lines_the_tone_and_sawtooth_are_read_as_qn`` keeps that premise checked).
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from fogdrift.gmwm import haar_wvar, select_model, simulate_latent
from fogdrift.gmwm.analysis import analyse_gmwm
from fogdrift.noise.periodic import Q_OVER_ENVELOPE
from fogdrift.noise.spectral import analyse_spectrum

N = 2**17
SEEDS = range(20)


def _tone(seed, amp=8.0, f_hz=20.0, dt=0.01, sigma=4.0):
    """White rate noise (SD ``sigma`` deg/h per sample) + a tone of amplitude ``amp`` deg/h, random phase."""
    r = np.random.default_rng(seed)
    return sigma * r.normal(size=N) + amp * np.sin(2 * np.pi * f_hz * np.arange(N) * dt + r.uniform(0, 2 * np.pi))


def _saw(seed, amp=3.0, period_s=0.24, dt=0.005, sigma=4.0):
    """White rate noise + a sawtooth (phase-ramp error) of peak ``amp`` deg/h and period ``period_s``."""
    r = np.random.default_rng(seed)
    t = np.arange(N) * dt + r.uniform(0, period_s)
    return sigma * r.normal(size=N) + amp * (2 * ((t / period_s) % 1.0) - 1)


def _qn(seed, q2=4.0, sigma2=1.0):
    """White + genuine quantization noise, ``x = sqrt(12 q2) (U_t - U_{t-1})`` [(deg/h)^2 parameters]."""
    return simulate_latent("QN+WN", [q2, sigma2], N, seed=seed)


def _gmwm(x, dt):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a fallback choice warns; the tests read passed_checks instead
        return analyse_gmwm("x", x, dt)


def _named_freqs(sel) -> list[float]:
    """Every frequency [Hz] the selection's words name (excluded scales and candidate reasons)."""
    text = " ".join([e.reason for e in sel.excluded] + [r for c in sel.candidates for r in c.reasons])
    return [float(v) for v in re.findall(r"([0-9.]+) Hz", text)]


CASES = {  # name: (simulator, dt [s], true fundamental [Hz])
    "tone 20 Hz at 100 Hz": (_tone, 0.01, 20.0),
    "sawtooth 0.24 s at 200 Hz": (_saw, 0.005, 1 / 0.24),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_line_is_not_read_as_quantization_20_seeds(case):
    sim, dt, f0 = CASES[case]
    with_qn, unnamed, unrefused = [], [], []
    for seed in SEEDS:
        ax = _gmwm(sim(seed), dt)
        sel = ax.selection
        assert ax.periodic is not None, seed  # the spectrum found the line
        if "QN" in sel.selected:
            with_qn.append(seed)
        if not any(abs(f / f0 - 1) < 0.02 for f in _named_freqs(sel)):
            unnamed.append(seed)
        line_excl = [e for e in sel.excluded if e.line_share is not None]
        assert line_excl, seed
        assert all("spectral line at" in e.reason for e in line_excl)
        c = sel.candidate("QN+WN")
        if not (c.hard_failure and any("not told apart from the spectral lines" in r for r in c.reasons)):
            unrefused.append(seed)
    assert with_qn == [], f"QN selected in seeds {with_qn} of {len(SEEDS)}"
    assert unnamed == [], f"the line within 2 % of {f0:.4g} Hz not named in seeds {unnamed}"
    assert unrefused == [], f"QN+WN not refused beside the line in seeds {unrefused}"


def test_the_excluded_scales_are_the_leading_ones_the_tone_dominates():
    sel = _gmwm(_tone(0), 0.01).selection
    ex = [e for e in sel.excluded if e.line_share is not None]
    # leading and contiguous, ending at the last scale where the tone's WV is above 5 % of the measured WV
    assert [e.level for e in ex] == list(range(1, len(ex) + 1))
    assert ex[-1].line_share > 0.05 and ex[0].line_share > 0.05
    assert int(sel.levels_used[0]) > ex[-1].level
    assert re.search(r"spectral line at 20(\.0+)? Hz dominates the wavelet variance here: the lines' WV is "
                     r"[0-9.]+ % of the measured WV \(more than 5 %\)", ex[0].reason)
    d = ex[0].to_dict()
    assert d["best_abs_z"] is None and d["line_share"] == pytest.approx(ex[0].line_share)


def test_without_the_lines_the_tone_and_sawtooth_are_read_as_qn():
    """The premise: the same records without the spectrum's lines (``periodic=None``) get QN in most seeds."""
    for sim, dt, _ in CASES.values():
        got = []
        for seed in range(4):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                got.append(select_model(haar_wvar(sim(seed), dt)).selected)
        assert sum("QN" in m for m in got) >= 3, got


def test_genuine_quantization_keeps_its_qn_without_a_line():
    hits = 0
    for seed in range(10):
        ax = _gmwm(_qn(seed), 0.01)
        assert ax.periodic is None  # no line in the spectrum: the selection is the one without it
        hits += ax.selection.selected.startswith("QN+WN") and ax.selection.passed_checks
    assert hits >= 9, hits


def test_genuine_quantization_beside_a_weak_line_keeps_its_qn():
    """QN (q2 = 4 (deg/h)^2) with a 0.3-deg/h tone at 20 Hz: QN's WV stands ~46x above the tone's envelope
    (``6 q2 sin^2(pi f dt) / (4 P)``, ``P = a^2 / 2``), so the rule keeps it (it refuses QN only below
    Q_OVER_ENVELOPE x the envelope, not beside every line)."""
    hits = 0
    for seed in range(6):
        x = _qn(seed) + 0.3 * np.sin(2 * np.pi * 20.0 * np.arange(N) * 0.01 + seed)
        ax = _gmwm(x, 0.01)
        assert ax.periodic is not None and abs(ax.periodic.ref_freq_hz / 20.0 - 1) < 0.02
        c = ax.selection.candidate("QN+WN")
        assert not any("not told apart from the spectral lines" in r for r in c.reasons)
        hits += ax.selection.selected.startswith("QN+WN")
    assert hits >= 5, hits
    assert Q_OVER_ENVELOPE == 10.0


def test_white_noise_alone_selects_what_it_selects_without_the_spectrum():
    for seed in range(6):
        x = 4.0 * np.random.default_rng(seed).normal(size=N)
        ax = _gmwm(x, 0.01)
        if ax.periodic is not None:  # a false alarm of the line search (1 % per record): nothing to compare
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ref = select_model(haar_wvar(x, 0.01))
        assert ax.selection.selected == ref.selected
        assert [e.level for e in ax.selection.excluded] == [e.level for e in ref.excluded]


def test_a_spectrum_handed_in_or_none():
    x = _tone(3)
    spec = analyse_spectrum(x, 0.01)
    a = _gmwm(x, 0.01)
    b = analyse_gmwm("x", x, 0.01, spectrum=spec)
    assert b.periodic == a.periodic and b.selection.selected == a.selection.selected
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        c = analyse_gmwm("x", x, 0.01, spectrum=None)
    assert c.periodic is None and not any(e.line_share is not None for e in c.selection.excluded)
    assert b.to_dict()["spectral_lines"] and c.to_dict()["spectral_lines"] == []
