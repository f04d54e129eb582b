"""The artefact check (``evaluation/artefacts.py``) on compensators whose response is known in closed form
(mutation round 3, issue 24).

Every earlier test used persistence of the causal drift, which absorbs a ramp completely and claims an ADEV
improvement exactly where it removes signal; the read-outs that depend on a compensator *keeping part* of a
signal, or removing signal *without* a claim, were therefore never pinned.  The compensators here are
rate-input models (``input_kind = "rate"``, fed the rate itself, as the Kalman filter is) with a hand-known
one-step prediction:

* ``p[j] = c * mean(z[j-M .. j-1])`` (a fraction ``c`` of an M-sample moving mean; NaN for j < M, so the active
  block starts at k0 = max(M, causal window)).  After a ramp has filled its window the prediction rises with
  ``c`` times the ramp's slope, so the compensated output keeps the fraction ``1 - c`` of the slope; ``k``
  samples after a step it keeps ``1 - c * min(k, M) / M`` of it; a sinusoid keeps
  ``|1 - c/M sum_{m=1..M} exp(-2 pi i f m dt)|``.
* the same with an independent fixed noise added to the prediction: it removes signal (gain < 0.9) while its
  compensated ADEV is *higher* than the input's (no claimed improvement), so it must not be flagged.

The responses are differences of two compensated runs, so the held-out noise cancels (the compensators are
linear) and the hand values hold to rounding (rtol 1e-9).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from fogdrift.errors import ConfigError
from fogdrift.evaluation import artefact_check
from fogdrift.evaluation.artefacts import ALLAN_PEAK
from fogdrift.models import Persistence


class MovingFraction:
    """Rate-input compensator: prediction ``c * mean(z[j-M:j])`` (+ ``noise`` x a fixed N(0, 1) series)."""

    input_kind = "rate"

    def __init__(self, c, M, noise=0.0, seed=5, gaps=()):
        self.c, self.M, self.noise, self.seed, self.gaps = float(c), int(M), float(noise), seed, list(gaps)

    def filter(self, z, state=None):
        z = np.asarray(z, dtype=np.float64)
        n, M = z.size, self.M
        p = np.full(n, np.nan)
        if n > M:
            # direct sums (no running cumsum) so that the response to z + s minus that to z is exact to rounding
            p[M:] = self.c * np.lib.stride_tricks.sliding_window_view(z, M)[:-1].mean(axis=1)
        if self.noise:
            p = p + self.noise * np.random.default_rng(self.seed).normal(0.0, 1.0, n)
        p[self.gaps] = np.nan  # no prediction there
        return p, np.zeros(n), state


def _ma_gain(c, M, f, dt):
    m = np.arange(1, M + 1)
    return abs(1.0 - c / M * np.sum(np.exp(-2j * np.pi * f * m * dt)))


def _oadev(y, m):
    c = np.concatenate([[0.0], np.cumsum(y)])
    means = (c[m:] - c[:-m]) / m
    d = means[m:] - means[:-m]
    return math.sqrt(0.5 * np.mean(d * d))


# ---------------------------------------------------------------------------------------------------------------
# ramp


@pytest.mark.parametrize("dt", [1.0, 0.5])
def test_ramp_survival_of_a_compensator_that_keeps_part_of_it_is_that_fraction(dt):
    """p = 0.3 x (1000-sample moving mean): after the first 1000 samples of the ramp (the transient) the output
    keeps 0.7 of its slope.  Block 3500 samples, k0 = 1000: the fit over the second half of the active block
    (from sample 2250) is past the transient (ends at 2000), a fit from its first third (1833) or from its start
    is not; a quadratic's leading coefficient or the intercept is not the slope.
    Catches: ramp read with polyfit degree 2 / the intercept, the half window moved earlier, survival x slope."""
    z = np.random.default_rng(41).normal(0.0, 5.0, 3500)
    res = artefact_check(z, dt, {"keeps 70 %": MovingFraction(0.3, 1000)}, causal_window=128,
                         frequencies_hz=[0.01], step_delays_s=())
    assert_allclose(res.row("keeps 70 %").ramp_survival, 0.7, rtol=1e-9)
    assert res.row("constant bias").ramp_survival == 1.0


def test_ramp_survival_of_a_whole_ramp_keeper_and_of_the_constant_bias_row():
    """c = 0 keeps everything (survival 1), c = 1 (a moving mean) absorbs the slope (survival 0), at dt = 0.5 s;
    the constant-bias row states 1 for every read-out and flags nothing."""
    z = np.random.default_rng(42).normal(0.0, 2.0, 3000)
    res = artefact_check(z, 0.5, {"none": MovingFraction(0.0, 600), "all": MovingFraction(1.0, 600)},
                         causal_window=128, frequencies_hz=[0.01, 0.1])
    assert_allclose(res.row("none").ramp_survival, 1.0, rtol=1e-9)
    assert abs(res.row("all").ramp_survival) < 1e-9
    cb = res.row("constant bias")
    assert cb.ramp_survival == 1.0 and cb.flagged_hz == () and cb.gains == {0.01: 1.0, 0.1: 1.0}
    assert cb.step_survival == {d: 1.0 for d in res.step_delays_s} and cb.adev_ratio == {0.01: 1.0, 0.1: 1.0}
    assert [r.model for r in res.rows] == ["constant bias", "none", "all"]


# ---------------------------------------------------------------------------------------------------------------
# steps at dt = 0.5 s


def test_step_survival_at_half_a_second_is_read_at_the_delay_in_seconds():
    """p = 0.6 x (2050-sample moving mean) at dt = 0.5 s: k samples after the step the output keeps
    1 - 0.6 min(k, 2050) / 2050 of it, read as the mean over k +- w, w = max(1, round(0.05 delay / dt)).
    Delays 10, 100, 1000 s are k = 20, 200, 2000 samples (w = 1, 10, 100; the last window straddles the kink at
    2050, so w matters); k0 = 2050, the step at k0 + (8000 - k0) // 4 = 3537; the last delay that fits is
    (8000 - 1 - 3537) x 0.5 = 2231 s, 2231.5 s (k_step + k = n) is dropped.
    Catches: delays x dt instead of / dt, the averaging window x dt, the step at 1/5 of the block, the drop
    rule with <=."""
    dt, n, M, c = 0.5, 8000, 2050, 0.6
    z = np.random.default_rng(43).normal(0.0, 5.0, n)
    res = artefact_check(z, dt, {"ma": MovingFraction(c, M)}, causal_window=128, frequencies_hz=[0.01],
                         step_delays_s=(10.0, 100.0, 1000.0, 2231.0, 2231.5))
    assert res.step_delays_s == (10.0, 100.0, 1000.0, 2231.0)

    def surv(k):
        return 1.0 - c * min(k, M) / M

    for delay in (10.0, 100.0, 1000.0, 2231.0):
        k, w = int(round(delay / dt)), max(1, int(round(0.05 * delay / dt)))
        want = np.mean([surv(j) for j in range(k - w, k + w + 1)])
        assert_allclose(res.row("ma").step_survival[delay], want, rtol=1e-9)
    assert res.row("ma").step_survival[10.0] == pytest.approx(1 - c * 20 / M, rel=1e-9)
    # the last one (2231 s) is past the kink: 1 - c
    assert res.row("ma").step_survival[2231.0] == pytest.approx(1 - c, rel=1e-9)


# ---------------------------------------------------------------------------------------------------------------
# default band and boundaries


def test_default_band_at_half_a_second_starts_at_exactly_two_periods():
    """dt = 0.5 s, persistence (k0 = 128), n = 2128: the active block is 2000 samples = 1000 s, so 0.002 Hz has
    exactly 2 periods and is kept (edge), 0.001 Hz is not; Nyquist 1 Hz is kept.  The block as 4000 s (samples / dt)
    would keep 0.001 Hz, one sample less (999.5 s) would drop 0.002 Hz.
    Catches: the band's duration as samples / dt, an off-by-one in the active block, a strict two-period rule."""
    z = np.random.default_rng(44).normal(0.0, 5.0, 2128)
    res = artefact_check(z, 0.5, {"persistence": Persistence().fit([0.0])}, causal_window=128)
    assert res.frequencies_hz == [0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0]
    assert len(res.notes) == 1  # nothing dropped from the default band
    # the band is the ACTIVE block's: k0 = 1000 (a 1000-sample moving mean), n = 3000: again 1000 s, not the
    # record's 1500 s nor n + k0 = 2000 s (which would list 0.001 Hz, then drop it with a note)
    res = artefact_check(np.random.default_rng(44).normal(0.0, 5.0, 3000), 0.5, {"ma": MovingFraction(0.5, 1000)},
                         causal_window=128)
    assert res.frequencies_hz == [0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0] and len(res.notes) == 1
    # the same edge for a given list: 0.002 Hz kept, 0.0019 Hz dropped with a note
    res = artefact_check(z, 0.5, {"persistence": Persistence().fit([0.0])}, causal_window=128,
                         frequencies_hz=[0.0019, 0.002, 1.0, 1.01])
    assert res.frequencies_hz == [0.002, 1.0]
    assert res.notes[1] == ("frequencies [0.0019, 1.01] Hz dropped (fewer than 2 periods in the block, or above "
                            "Nyquist)")


def test_block_of_exactly_four_causal_windows_is_accepted_one_sample_less_refused():
    z = np.random.default_rng(45).normal(0.0, 5.0, 512)
    res = artefact_check(z, 1.0, {"persistence": Persistence().fit([0.0])}, causal_window=128,
                         frequencies_hz=[0.1])
    assert res.frequencies_hz == [0.1] and res.axis == "" and res.dt_s == 1.0
    msg = "the artefact check needs a finite 1-D block of at least 4 causal windows (512 samples); got (511,)"
    with pytest.raises(ConfigError) as info:
        artefact_check(z[:511], 1.0, {}, causal_window=128)
    assert str(info.value) == msg
    with pytest.raises(ConfigError, match=r"got \(2, 512\)"):
        artefact_check(np.stack([z, z]), 1.0, {}, causal_window=128)
    bad = z.copy()
    bad[7] = np.nan
    with pytest.raises(ConfigError, match="finite 1-D block"):
        artefact_check(bad, 1.0, {}, causal_window=128)
    bad[7] = np.inf
    with pytest.raises(ConfigError, match="finite 1-D block"):
        artefact_check(bad, 1.0, {}, causal_window=128)


def test_the_claim_is_read_at_both_ends_of_the_octave_curve_and_none_outside():
    """dt = 1 s, active block 3072 - 128 = 2944 samples: octave taus 1 .. 512 s.  f = 0.371 Hz reads tau = 1 s
    and f = 0.371 / 512 Hz tau = 512 s (both ends, inclusive); f = 0.371 / 540 Hz (tau 540 s, beyond the curve,
    2.02 periods in the block) has no claim (None) and is never flagged, whatever its gain.  The values are
    ADEV(compensated) / ADEV(original) at m = 1 and 512, recomputed here from the analytic persistence output.
    Catches: strict ends of the curve (the claim at the first or last tau dropped)."""
    from fogdrift.models.causal_predictor import causal_weights

    W, n = 128, 3072
    z = np.random.default_rng(46).normal(0.0, 5.0, n) + np.cumsum(np.random.default_rng(47).normal(0.0, 0.5, n))
    freqs = [ALLAN_PEAK / 1.0, ALLAN_PEAK / 512.0, ALLAN_PEAK / 540.0]
    res = artefact_check(z, 1.0, {"persistence": Persistence().fit([0.0])}, causal_window=W, frequencies_hz=freqs)
    g = causal_weights(W, "db2", 4, "symmetric")
    comp = z[W:] - np.lib.stride_tricks.sliding_window_view(z, W)[:-1] @ g
    row = res.row("persistence")
    assert res.frequencies_hz == freqs
    assert_allclose(row.adev_ratio[freqs[0]], _oadev(comp, 1) / _oadev(z[W:], 1), rtol=1e-9)
    if math.log(512.0) == float(np.log(np.array([512.0]))[0]):  # the edge is exact where both logs agree
        assert_allclose(row.adev_ratio[freqs[1]], _oadev(comp, 512) / _oadev(z[W:], 512), rtol=1e-9)
    assert row.adev_ratio[freqs[2]] is None
    assert row.gains[freqs[2]] < 0.5 and freqs[2] not in row.flagged_hz  # removes it, but no claim there
    assert row.to_dict()["adev_ratio_at_0.371_over_f"][str(freqs[2])] is None


# ---------------------------------------------------------------------------------------------------------------
# the flag


def _flag_case():
    z = np.random.default_rng(48).normal(0.0, 5.0, 8000)
    models = {"half": MovingFraction(0.5, 1), "half + noise": MovingFraction(0.5, 1, noise=5.0)}
    freqs = [0.001, 0.01, 0.05, 0.2, 0.5]
    return z, models, freqs


def test_flag_needs_both_a_claimed_improvement_and_removed_signal():
    """p = 0.5 z[j-1]: gain |1 - 0.5 exp(-2 pi i f)| (0.50 at 0.001 Hz, 0.97 at 0.2 Hz, 1.5 at 0.5 Hz) and on white
    noise a compensated ADEV 0.50-0.67 x the input's at 0.001-0.05 Hz: flagged where the gain is below 0.9 (0.001,
    0.01, 0.05 Hz).  The same prediction plus an independent N(0, 5^2) series removes the same signal (the noise
    cancels in the response) but its ADEV is 0.99-1.44 x the input's (no claim): flagged nowhere.  At 0.5 Hz
    (tau 0.74 s, below the curve) neither has a claim.
    Catches: `and` -> `or` in the flag (gain alone flags), the default claim_ratio 0.9 -> 1.9, removal ignored."""
    z, models, freqs = _flag_case()
    res = artefact_check(z, 1.0, models, causal_window=128, frequencies_hz=freqs)
    for label in models:
        for f in freqs:
            assert_allclose(res.row(label).gains[f], _ma_gain(0.5, 1, f, 1.0), rtol=1e-9)
    half, noisy = res.row("half"), res.row("half + noise")
    assert half.flagged_hz == (0.001, 0.01, 0.05)
    assert all(half.adev_ratio[f] < 0.9 for f in (0.001, 0.01, 0.05))
    assert half.adev_ratio[0.5] is None and noisy.adev_ratio[0.5] is None
    assert all(0.95 < noisy.adev_ratio[f] < 1.5 for f in freqs[:-1])  # no claim: between 0.9 and 1.9
    assert noisy.flagged_hz == ()
    assert_allclose(half.ramp_survival, 0.5, rtol=1e-9)


def test_flag_thresholds_are_the_arguments():
    """claim_ratio 1.2 flags the noisy compensator where its gain is below 0.9 and its claim below 1.2 (0.001 and
    0.01 Hz: 0.99 and 1.18; 1.21 at 0.05 Hz); removal 0.6 (gain below 0.4) flags nothing, the gains are >= 0.5;
    removal 0.47 (gain below 0.53) flags 0.001 and 0.01 Hz (gains 0.500 and 0.502; 0.547 at 0.05 Hz)."""
    z, models, freqs = _flag_case()
    res = artefact_check(z, 1.0, models, causal_window=128, frequencies_hz=freqs, claim_ratio=1.2)
    assert res.row("half + noise").flagged_hz == (0.001, 0.01)
    res = artefact_check(z, 1.0, models, causal_window=128, frequencies_hz=freqs, removal=0.6)
    assert res.row("half").flagged_hz == () and res.row("half + noise").flagged_hz == ()
    res = artefact_check(z, 1.0, models, causal_window=128, frequencies_hz=freqs, removal=0.47)
    assert res.row("half").flagged_hz == (0.001, 0.01)


# ---------------------------------------------------------------------------------------------------------------
# small rules


def test_a_sample_without_a_prediction_is_left_uncompensated():
    """A compensator that predicts 0 except at three samples inside the active block where it has no prediction
    (NaN): those samples are left as they are (p = 0), so its output is the input and its ADEV ratio is exactly 1
    at every tau, its gains 1.  Catches: a missing prediction replaced by anything but 0."""
    z = np.random.default_rng(49).normal(0.0, 5.0, 3000)
    res = artefact_check(z, 1.0, {"gappy": MovingFraction(0.0, 10, gaps=[1500, 1501, 2900])}, causal_window=128,
                         frequencies_hz=[0.002, 0.02, 0.2])
    row = res.row("gappy")
    assert all(row.adev_ratio[f] == pytest.approx(1.0, rel=1e-12) for f in (0.002, 0.02, 0.2))
    assert all(row.gains[f] == pytest.approx(1.0, rel=1e-9) for f in (0.002, 0.02, 0.2))


def test_default_band_is_the_1_2_5_series_from_1_mhz_to_5_khz():
    """The series spans 10^-3 .. 5 x 10^3 Hz (k = -3 .. 3): at dt = 20 us (Nyquist 25 kHz) it ends at 5 kHz, at
    dt = 0.1 ms (Nyquist 5 kHz, inclusive) too, at dt = 0.125 ms (4 kHz) at 2 kHz."""
    from fogdrift.evaluation.artefacts import default_frequencies

    top = [0.001 * m * 10.0 ** k for k in range(7) for m in (1, 2, 5)]
    top = [float(f"{f:.12g}") for f in top]
    assert default_frequencies(2e-5, 3600.0) == top
    assert default_frequencies(1e-4, 3600.0) == top
    assert default_frequencies(1.25e-4, 3600.0) == top[:-1]


def test_row_lookup_names_the_missing_model():
    z = np.random.default_rng(50).normal(0.0, 5.0, 600)
    res = artefact_check(z, 1.0, {}, causal_window=128, frequencies_hz=[0.1], axis="gx")
    assert [r.model for r in res.rows] == ["constant bias"] and res.axis == "gx"
    with pytest.raises(KeyError) as info:
        res.row("persistence")
    assert info.value.args == ("persistence",)


def test_no_claim_where_the_allan_deviation_cannot_be_computed():
    """The claim's reader gives None (no claim, never flagged) when either ADEV cannot be computed (here a
    compensated block that overflowed to inf); inside the curve it interpolates the log ratio."""
    from fogdrift.evaluation.artefacts import _adev_ratio_fn

    base = np.random.default_rng(51).normal(0.0, 1.0, 256)
    at = _adev_ratio_fn(base, np.where(np.arange(256) == 9, np.inf, base), 1.0)
    assert at(1.0) is None and at(4.0) is None
    at = _adev_ratio_fn(base, 2.0 * base, 1.0)
    assert at(1.0) == pytest.approx(2.0, rel=1e-12) and at(3.0) == pytest.approx(2.0, rel=1e-12)
    assert at(0.99) is None and at(1e4) is None


# ---------------------------------------------------------------------------------------------------------------
# compensators whose response depends on the signal's size or on its whole past


class Square:
    """Rate-input, nonlinear: prediction ``k * z[j-1]**2`` (NaN at j = 0)."""

    input_kind = "rate"

    def __init__(self, k):
        self.k = float(k)

    def filter(self, z, state=None):
        z = np.asarray(z, dtype=np.float64)
        p = np.full(z.size, np.nan)
        p[1:] = self.k * z[:-1] ** 2
        return p, np.zeros(z.size), state


class CumulativeMean:
    """Rate-input with an infinite memory (a bias re-estimated from all the past): ``c * mean(z[:j])``."""

    input_kind = "rate"

    def __init__(self, c):
        self.c = float(c)

    def filter(self, z, state=None):
        z = np.asarray(z, dtype=np.float64)
        p = np.full(z.size, np.nan)
        p[1:] = self.c * np.cumsum(z)[:-1] / np.arange(1, z.size)
        return p, np.zeros(z.size), state


@pytest.mark.parametrize("dt", [1.0, 0.5])
def test_ramp_survival_of_a_nonlinear_compensator_depends_on_the_ramp_as_stated(dt):
    """p = k z[j-1]^2 on a (nearly) zero record with A = 2 deg/h: the ramp rises by a = A / (n - k0) per sample from k0
    (0 at k0), so over the fit (active samples i = 1936 .. 3871 from k0, n = 4000, k0 = 128) the output is
    a i - k a^2 (i - 1)^2, whose least-squares slope is a - 2 k a^2 (mean(i) - 1): survival
    1 - 2 k a (2903.5 - 1), the same at every dt.  Catches: the ramp's size (slope x or / (n - k0) dt, n + k0),
    its origin (t + k0 dt, k0 / dt), a ramp divided by t."""
    n, k0, A, k = 4000, 128, 2.0, 1.0 / 6.0
    z = 1e-9 * np.random.default_rng(54).normal(0.0, 1.0, n)  # (the noise's cross term 2 k z s is ~1e-9 of it)
    res = artefact_check(z, dt, {"square": Square(k)}, causal_window=128, amplitude_dph=A,
                         frequencies_hz=[0.01], step_delays_s=())
    a = A / (n - k0)
    i_mean = ((n - k0) // 2 + (n - k0 - 1)) / 2.0
    assert i_mean == 2903.5
    assert_allclose(res.row("square").ramp_survival, 1.0 - 2.0 * k * a * (i_mean - 1.0), rtol=1e-6)


def test_a_compensator_with_an_infinite_memory_sees_only_the_injected_signals():
    """p = 0.8 mean(z[:j]) (n = 3000, dt = 1 s, W = 128 so k0 = 128): the injected ramp is 0 before k0 and
    A (i - k0) / (n - k0) from k0, the step A from k_step = k0 + (n - k0) // 4 = 846; the response is
    s - 0.8 cummean(s) (written out here from the prediction), its step survival k samples after the step
    1 - 0.8 A k / ((K + k) A) with K = 846 averaged over +-w, its ramp survival the least-squares slope of the
    response over the second half of the active block / the ramp's slope.
    Catches: anything added to the ramp before it starts, the step at another place in the block."""
    n, W, c = 3000, 128, 0.8
    z = np.random.default_rng(52).normal(0.0, 5.0, n)
    res = artefact_check(z, 1.0, {"cm": CumulativeMean(c)}, causal_window=W, frequencies_hz=[0.01],
                         step_delays_s=(10.0, 100.0, 1000.0))
    A = res.amplitude_dph
    k0, K = 128, 128 + (n - 128) // 4
    assert K == 846
    row = res.row("cm")
    for delay in (10.0, 100.0, 1000.0):
        k, w = int(delay), max(1, int(round(0.05 * delay)))
        want = np.mean([1.0 - c * j / (K + j) for j in range(k - w, k + w + 1)])
        assert_allclose(row.step_survival[delay], want, rtol=1e-7)
    i = np.arange(n)
    s = np.where(i >= k0, A * (i - k0) / (n - k0), 0.0)
    resp = s.copy()
    resp[1:] -= c * np.cumsum(s)[:-1] / np.arange(1, n)
    half = slice(k0 + (n - k0) // 2, n)
    want = np.polyfit(i[half].astype(float), resp[half], 1)[0] / (A / (n - k0))
    assert 0.1 < want < 0.9
    assert_allclose(row.ramp_survival, want, rtol=1e-7)


def test_ramp_read_over_the_second_half_of_the_active_block():
    """p = 0.5 x (1000-sample moving mean), n = 3000 = 3 k0: the second half of the active block starts exactly
    where the ramp's transient ends (sample 2000), survival 0.5; a fit from (n + k0) // 2 would have no samples."""
    z = np.random.default_rng(53).normal(0.0, 5.0, 3000)
    res = artefact_check(z, 1.0, {"ma": MovingFraction(0.5, 1000)}, causal_window=128, frequencies_hz=[0.01],
                         step_delays_s=())
    assert_allclose(res.row("ma").ramp_survival, 0.5, rtol=1e-9)


def test_a_compensator_that_never_predicts_is_refused_with_one_line():
    """A 700-sample moving mean on a 600-sample block predicts nothing, a 597-sample one only the last 3 samples:
    InsufficientDataError naming both (the callers turn it into "artefact check skipped"), not a
    ZeroDivisionError; one that predicts the last 4 samples is not named, and alone it is read."""
    from fogdrift.errors import InsufficientDataError

    z = np.random.default_rng(55).normal(0.0, 1.0, 600)
    with pytest.raises(InsufficientDataError) as info:
        artefact_check(z, 1.0, {"ok": MovingFraction(0.5, 10), "four": MovingFraction(0.5, 596),
                                "three": MovingFraction(0.5, 597), "never": MovingFraction(0.5, 700)},
                       causal_window=128)
    assert str(info.value) == ("the artefact check needs compensated samples to read: no prediction from three, "
                               "never before sample 600 of the 600-sample block")
    assert (info.value.needed, info.value.got) == (4, 0)
    res = artefact_check(z, 1.0, {"late": MovingFraction(0.0, 596)}, causal_window=128, step_delays_s=())
    assert res.frequencies_hz == [0.5]  # Nyquist: 2 periods in 4 samples
    assert res.row("late").ramp_survival == pytest.approx(1.0, rel=1e-9)


def test_flag_thresholds_are_strict():
    """A claim exactly at claim_ratio is no claim, a gain exactly at 1 - removal removes no more than allowed.
    Thresholds set to the values measured at 0.01 Hz (1 - (1 - g) == g exactly for g in [0.5, 1], Sterbenz):
    only 0.001 Hz (strictly below both) stays flagged."""
    z, models, freqs = _flag_case()
    res = artefact_check(z, 1.0, models, causal_window=128, frequencies_hz=freqs)
    g, v = res.row("half").gains[0.01], res.row("half + noise").adev_ratio[0.01]
    assert 0.5 <= g <= 1.0 and 1.0 - (1.0 - g) == g
    res = artefact_check(z, 1.0, models, causal_window=128, frequencies_hz=freqs, removal=1.0 - g)
    assert res.row("half").flagged_hz == (0.001,)
    res = artefact_check(z, 1.0, models, causal_window=128, frequencies_hz=freqs, claim_ratio=v)
    assert res.row("half + noise").flagged_hz == (0.001,)
