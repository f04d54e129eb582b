"""Spectral lines, periodic components and output roll-off (fogdrift.noise.spectral), proved on seeded simulations
with counts and against independent references: the Fourier series of a sawtooth, allantools' overlapping Allan
deviation of a noiseless sinusoid, scipy.signal.welch, Percival & Walden's closed-form Welch EDF."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from scipy.signal import butter, lfilter, welch

from fogdrift.errors import ConfigError, DataFormatError, InsufficientDataError
from fogdrift.noise import spectral as sp
from fogdrift.noise.spectral import analyse_spectrum, sinusoid_avar
from fogdrift.simulate import simulate

N_SEEDS = 100
N_SHORT = 2**14


def _lowpassed(rng, n):
    b, a = butter(4, 0.3)  # corner at 0.3 Nyquist
    return lfilter(b, a, rng.standard_normal(n + 300))[300:]


# every generator: (rng, seed) -> rate [deg/h] at 100 Hz, no line
LINE_FREE = {
    "white": lambda rng, s: 30.0 * rng.standard_normal(N_SHORT),
    "random walk + white": lambda rng, s: simulate(N_SHORT, 0.01, arw_dprh=0.1, rrw_dphrh=50.0, seed=s),
    "quantization": lambda rng, s: simulate(N_SHORT, 0.01, q_urad=50.0, seed=s),
    "low-passed white": lambda rng, s: _lowpassed(rng, N_SHORT),
    "flicker": lambda rng, s: simulate(N_SHORT, 0.01, bias_instability_dph=1.0, seed=s),
}


@pytest.mark.parametrize("kind", list(LINE_FREE))
def test_family_wise_false_alarm_rate_on_line_free_noise(kind):
    # nominal 1 %: over 100 seeds P(>= 4 records with a line) = 1.8 % if the rate were exactly 1 %
    gen = LINE_FREE[kind]
    with_line = 0
    rolloffs = 0
    for s in range(N_SEEDS):
        summ = analyse_spectrum(gen(np.random.default_rng(10_000 + s), s), 0.01, false_alarm=0.01)
        with_line += bool(summ.lines)
        rolloffs += summ.rolloff_hz is not None
        assert summ.searched_bins > 0 and summ.false_alarm == 0.01
    assert with_line <= 3, f"{kind}: {with_line} of {N_SEEDS} line-free records got a line"
    if kind == "low-passed white":
        assert rolloffs == N_SEEDS
    else:  # white, rising (quantization) and red spectra show no output filter
        assert rolloffs == 0


def test_reported_p_value_is_family_wise():
    # at false_alarm = 0.5 some white records get a (false) line; its p-value is the family-wise one, so it is
    # spread over (0, 0.5], not the per-bin value (which would be ~0.5 / number of bins)
    ps = []
    for s in range(40):
        summ = analyse_spectrum(np.random.default_rng(500 + s).standard_normal(N_SHORT), 0.01, false_alarm=0.5)
        ps += [ln.p_value for ln in summ.lines]
    assert 4 <= len(ps) <= 30
    assert max(ps) <= 0.5 and np.median(ps) > 0.05


def _tone_records(fs_hz, f0_hz, share, n_seeds=N_SEEDS, n=N_SHORT):
    """White noise (std 1) plus a sinusoid holding ``share`` of the variance: yields (record, amplitude)."""
    amp = math.sqrt(2.0 * share / (1.0 - share))
    t = np.arange(n) / fs_hz
    for s in range(n_seeds):
        rng = np.random.default_rng(s)
        yield rng.standard_normal(n) + amp * np.sin(2 * np.pi * f0_hz * t + rng.uniform(0, 2 * np.pi)), amp


@pytest.mark.parametrize("fs_hz, f0_hz", [(100.0, 20.0), (250.0, 90.0)])
def test_tone_detected_with_frequency_and_amplitude(fs_hz, f0_hz):
    found, f_err_bins, a_err = 0, [], []
    for y, amp in _tone_records(fs_hz, f0_hz, share=0.10):
        summ = analyse_spectrum(y, 1.0 / fs_hz)
        near = [ln for ln in summ.lines if abs(ln.freq_hz - f0_hz) < 0.02 * f0_hz]
        if near:
            found += 1
            ln = near[0]
            f_err_bins.append(abs(ln.freq_hz - f0_hz) / summ.resolution_hz)
            a_err.append(ln.amplitude_dph / amp - 1.0)
            assert ln.power_dph2 == pytest.approx(ln.amplitude_dph**2 / 2.0)
            assert not ln.broad and ln.harmonic_of is None and ln.p_value < 1e-6
    assert found >= 95
    f_err_bins, a_err = np.array(f_err_bins), np.array(a_err)
    # a tone is within a quarter of a Welch bin (0.12 % of 20 Hz): a flipped or missing interpolation is not
    assert np.mean(f_err_bins <= 0.25) >= 0.95
    assert np.all(f_err_bins * fs_hz / 2**9 / f0_hz < 0.02)
    # amplitude from the integrated line power: unbiased, 95 % of the seeds within 10 %
    assert abs(np.median(a_err)) < 0.02
    assert np.mean(np.abs(a_err) <= 0.10) >= 0.95


def test_two_lines_at_72_and_90_hz_are_both_found_and_not_harmonics():
    t = np.arange(N_SHORT) / 250.0
    for s in range(20):
        rng = np.random.default_rng(s)
        y = rng.standard_normal(N_SHORT) + 0.4 * np.sin(2 * np.pi * 72.0 * t) + 0.3 * np.sin(2 * np.pi * 90.0 * t + 1)
        summ = analyse_spectrum(y, 1.0 / 250.0)
        freqs = sorted(ln.freq_hz for ln in summ.lines)
        assert len(freqs) == 2
        assert freqs[0] == pytest.approx(72.0, rel=0.005) and freqs[1] == pytest.approx(90.0, rel=0.005)
        assert len(summ.components) == 2 and all(ln.harmonic_of is None for ln in summ.lines)
        assert summ.lines[0].freq_hz == pytest.approx(72.0, rel=0.005)  # sorted by power: 0.4 > 0.3
        assert sorted(summ.periods_s()) == pytest.approx([1 / 90.0, 1 / 72.0], rel=0.005)


def test_sawtooth_phase_ramp_is_one_component_with_its_period_and_fourier_powers():
    fs_hz, period_s, a = 200.0, 0.24, 1.0
    n = 2**15
    t = np.arange(n) / fs_hz
    for s in range(10):
        rng = np.random.default_rng(s)
        saw = a * (2.0 * ((t / period_s + rng.uniform()) % 1.0) - 1.0)  # peak a, variance a^2/3
        summ = analyse_spectrum(rng.standard_normal(n) + saw, 1.0 / fs_hz)
        assert len(summ.components) == 1
        comp = summ.components[0]
        assert comp.period_s == pytest.approx(period_s, rel=0.005)
        assert comp.fundamental_hz == pytest.approx(1.0 / period_s, rel=0.005)
        assert summ.periods_s() == (comp.period_s,)
        assert comp.lines[0].harmonic_of is None and len(comp.lines) >= 4
        harm = [int(round(ln.freq_hz / comp.fundamental_hz)) for ln in comp.lines]
        assert harm[0] == 1 and harm == sorted(harm)
        assert all(ln.harmonic_of == comp.fundamental_hz for ln in comp.lines[1:])
        # Fourier series of the sawtooth: harmonic h has amplitude 2a/(pi h), power 2a^2/(pi h)^2
        expect = sum(2.0 * a * a / (math.pi * h) ** 2 for h in harm)
        assert comp.power_dph2 == pytest.approx(expect, rel=0.15)
        assert summ.rolloff_hz is None
    assert "periodic error with period 0.240 s (4.17 Hz and" in summ.describe()[0]


@pytest.mark.parametrize("f0_hz", [2.0, 20.0])
def test_sinusoid_avar_against_allantools_on_a_noiseless_sinusoid(f0_hz):
    allantools = pytest.importorskip("allantools")
    dt = 0.01
    t = np.arange(200_000) * dt
    y = 3.0 * np.sin(2 * np.pi * f0_hz * t + 0.3)
    period_m = round(1.0 / (f0_hz * dt))
    m = np.array([1, 2, 3, period_m // 2, period_m, 2 * period_m, 3 * period_m + period_m // 4])
    m = np.unique(m[m >= 1])
    taus, dev, _, _ = allantools.oadev(y, rate=1.0 / dt, data_type="freq", taus=m * dt)
    got = sinusoid_avar(taus, 3.0, f0_hz, dt_s=dt)
    on = np.isclose((taus * f0_hz) % 1.0, 0.0, atol=1e-9) | np.isclose((taus * f0_hz) % 1.0, 1.0, atol=1e-9)
    assert on.any() and (~on).any()
    np.testing.assert_allclose(got[~on], dev[~on] ** 2, rtol=2e-3)
    envelope = 9.0 / (np.pi * f0_hz * taus) ** 2
    assert np.all(dev[on] ** 2 < 1e-9 * envelope[on]) and np.all(got[on] < 1e-9 * envelope[on])  # nulls at k / f0
    cont = sinusoid_avar(taus, 3.0, f0_hz)
    if f0_hz * dt <= 0.02:  # the continuous Annex C law is the sampled one when f0 dt << 1
        np.testing.assert_allclose(cont[~on], dev[~on] ** 2, rtol=3e-3)
    else:  # at 20 Hz in 100 Hz it is off by the Dirichlet factor (pi f dt / sin(pi f dt))^2 at m = 1
        ratio = cont[0] / dev[0] ** 2
        assert ratio == pytest.approx((math.sin(math.pi * f0_hz * dt) / (math.pi * f0_hz * dt)) ** 2, rel=2e-3)


def test_sinusoid_avar_bad_input():
    with pytest.raises(ConfigError, match="tau_s"):
        sinusoid_avar([0.0, 1.0], 1.0, 1.0)
    with pytest.raises(ConfigError, match="freq_hz"):
        sinusoid_avar([1.0], 1.0, -2.0)


@pytest.mark.parametrize("wn, corner_hz", [(0.3, 15.0), (0.1, 5.0)])
def test_rolloff_of_a_butterworth_low_pass_at_its_corner(wn, corner_hz):
    b, a = butter(4, wn)
    for s in range(5):
        y = 10.0 * lfilter(b, a, np.random.default_rng(s).standard_normal(N_SHORT + 300))[300:]
        summ = analyse_spectrum(y, 0.01)
        assert summ.rolloff_hz == pytest.approx(corner_hz, rel=0.10)
        assert summ.rolloff_db >= 6.0
        assert not summ.lines
    assert any(d.startswith("output low-pass: the rate PSD falls") and "Nyquist (50 Hz)" in d for d in summ.describe())


def test_no_rolloff_with_a_tone_on_white_noise():
    for y, _ in _tone_records(100.0, 20.0, share=0.2, n_seeds=10):
        summ = analyse_spectrum(y, 0.01)
        assert summ.rolloff_hz is None and summ.rolloff_db is None


def test_broad_vibration_peak_is_found_with_its_power():
    # white noise plus narrow-band random vibration (a 2nd-order resonance at 17 Hz, Q = 20) holding ~30 % of the
    # variance: too wide for the Welch bins of a long record, found at a coarser resolution
    from scipy.signal import iirpeak

    fs_hz, n = 100.0, 2**18
    b, a = iirpeak(17.0, 20.0, fs=fs_hz)
    for s in range(3):
        rng = np.random.default_rng(s)
        vib = lfilter(b, a, rng.standard_normal(n + 2000))[2000:]
        vib *= math.sqrt(0.3 / 0.7) / vib.std()
        summ = analyse_spectrum(rng.standard_normal(n) + vib, 1.0 / fs_hz)
        ln = summ.lines[0]
        assert ln.freq_hz == pytest.approx(17.0, rel=0.02)
        assert ln.broad and ln.width_hz > 4 * summ.resolution_hz
        # the power standing out of the local floor: most of it (a resonance's skirts merge into the floor), never more
        assert 0.6 * np.var(vib) <= ln.power_dph2 <= 1.1 * np.var(vib)
        assert "broad spectral peak" in summ.describe()[0]


def test_float32_input_gives_the_same_lines():
    y, _ = next(_tone_records(100.0, 20.0, share=0.1, n_seeds=1))
    a = analyse_spectrum(y, 0.01)
    b = analyse_spectrum(y.astype(np.float32), 0.01)
    assert len(a.lines) == len(b.lines) == 1
    assert b.lines[0].freq_hz == pytest.approx(a.lines[0].freq_hz, rel=1e-5)


@pytest.mark.parametrize("n", [0, 10, 255])
def test_short_record_gives_an_empty_summary_with_the_reason(n):
    summ = analyse_spectrum(np.ones(n) + np.arange(n), 0.01)
    assert summ.lines == () and summ.components == () and summ.rolloff_hz is None
    assert str(sp.MIN_SAMPLES) in summ.note and f"{n} samples" in summ.note
    assert summ.describe() == [summ.note]
    json.dumps(summ.to_dict(), allow_nan=False)


def test_constant_record_gives_an_empty_summary():
    summ = analyse_spectrum(np.full(4096, 8.4), 0.01)
    assert summ.lines == () and "constant" in summ.note


@pytest.mark.parametrize("kwargs, err, text", [
    (dict(y=[0.0, float("nan")] * 200, dt_s=0.01), DataFormatError, r"y\[1\] is nan"),
    (dict(y=np.zeros((300, 2)), dt_s=0.01), DataFormatError, "1-D"),
    (dict(y=["a"] * 300, dt_s=0.01), DataFormatError, "numeric"),
    (dict(y=np.zeros(300), dt_s=0.0), ConfigError, "dt_s"),
    (dict(y=np.zeros(300), dt_s=0.01, false_alarm=0.0), ConfigError, "false_alarm"),
    (dict(y=np.zeros(300), dt_s=0.01, false_alarm=1.0), ConfigError, "false_alarm"),
    (dict(y=np.zeros(300), dt_s=0.01, max_lines=0), ConfigError, "max_lines"),
])
def test_bad_input_is_one_clear_error(kwargs, err, text):
    with pytest.raises(err, match=text) as info:
        analyse_spectrum(**kwargs)
    assert "\n" not in str(info.value)


def test_max_lines_keeps_the_strongest():
    t = np.arange(N_SHORT) / 100.0
    y = np.random.default_rng(1).standard_normal(N_SHORT)
    for k, f in enumerate((5.0, 13.0, 29.0, 41.0)):
        y = y + (1.0 - 0.2 * k) * np.sin(2 * np.pi * f * t)
    summ = analyse_spectrum(y, 0.01, max_lines=2)
    assert [round(ln.freq_hz) for ln in summ.lines] == [5, 13]
    powers = [ln.power_dph2 for ln in analyse_spectrum(y, 0.01).lines]
    assert powers == sorted(powers, reverse=True) and len(powers) == 4


def test_summary_json_is_strict_and_sentences_carry_units():
    y, _ = next(_tone_records(100.0, 20.0, share=0.1, n_seeds=1))
    summ = analyse_spectrum(y, 0.01)
    d = json.loads(json.dumps(summ.to_dict(), allow_nan=False))
    assert d["lines"][0]["freq_hz"] == pytest.approx(20.0, rel=0.005) and d["rolloff_hz"] is None
    assert d["periods_s"] == [pytest.approx(0.05, rel=0.005)]
    line = summ.describe()[0]
    assert line.startswith("spectral line at 20.0") and " Hz, amplitude " in line and " deg/h" in line
    assert "false-alarm rate 1 % over" in line and "p < 1e-6" in line


def test_welch_edf_is_percival_walden_292c_and_matches_the_measured_variance():
    for k in (2, 7, 31, 300):
        assert sp.welch_edf(256, k) == pytest.approx(36 * k * k / (19 * k - 1), rel=2e-3)
    # the EDF describes the spread of the estimate: var(P/S) = 2 / nu on white noise (200 records)
    rng = np.random.default_rng(3)
    n, nper = 2**13, 256
    vals = []
    for _ in range(200):
        f, p, k = sp._welch(rng.standard_normal(n), 1.0, nper)
        vals.append(p[5:-5] / 2.0)  # one-sided density of unit white noise at fs = 1 is 2
    nu = sp.welch_edf(nper, k)
    assert np.var(np.concatenate(vals)) == pytest.approx(2.0 / nu, rel=0.05)


def test_chunked_welch_equals_one_scipy_welch_call():
    x = np.random.default_rng(4).standard_normal(50_000)
    f, p, k = sp._welch(x, 100.0, 512, chunk_samples=4096)  # 8 segments per chunk, 7 chunks
    f2, p2 = welch(x, fs=100.0, window="hann", nperseg=512, noverlap=256, detrend="constant")
    assert k == (50_000 - 512) // 256 + 1
    np.testing.assert_allclose(p, p2, rtol=1e-10)
    np.testing.assert_array_equal(f, f2)


def test_welch_matches_scipy_for_odd_segments_an_offset_and_a_tone():
    """The Welch of :mod:`fogdrift.noise.spectral` is written on scipy.fft (importing scipy.signal costs 0.9 s per
    command); scipy.signal.welch is its oracle: odd segment lengths (no Nyquist bin), an offset subtracted chunk
    by chunk, a tone on a large mean, several chunks."""
    from scipy.signal import get_window

    for nper in (7, 64, 255, 1024):
        np.testing.assert_allclose(sp._window(nper), get_window("hann", nper), rtol=0, atol=1e-15)
    t = np.arange(20_011)
    x = 50.0 + np.random.default_rng(7).standard_normal(t.size) + 2.0 * np.sin(0.7 * t)
    for nper, chunk in ((255, 1000), (1024, 1 << 21), (333, 2000)):
        f, p, k = sp._welch(x, 4.0, nper, chunk_samples=chunk, offset=50.25)
        f2, p2 = welch(x - 50.25, fs=4.0, window="hann", nperseg=nper, noverlap=nper // 2, detrend="constant")
        assert k == (x.size - nper) // (nper - nper // 2) + 1
        np.testing.assert_allclose(p, p2, rtol=1e-12)
        np.testing.assert_allclose(f, f2, rtol=1e-15)


def test_nperseg_gives_at_least_32_segments_and_a_bounded_length():
    for n in (256, 2**14, 10**6, 10**8):
        nper = sp._nperseg(n)
        assert nper & (nper - 1) == 0 and 64 <= nper <= 65536
        assert (n - nper) // (nper // 2) + 1 >= 32 or nper == 64


@pytest.mark.parametrize("n", [5_000, 40, 2])
def test_welch_psd_is_one_scipy_welch_of_the_whole_record(n):
    """The PSD the workflow hands to the report (Fig. 2) is the line search's Welch: one scipy.signal.welch call
    on the mean-removed record with the segment length of :func:`analyse_spectrum` (the whole of a record shorter
    than one segment)."""
    x = 3.0 + np.random.default_rng(n).standard_normal(n)
    f, p = sp.welch_psd(x, 0.01)
    nper = min(sp._nperseg(n), n)
    f_ref, p_ref = welch(x - x.mean(), fs=100.0, window="hann", nperseg=nper, noverlap=nper // 2)
    np.testing.assert_allclose(f, f_ref, rtol=1e-15)
    np.testing.assert_allclose(p, p_ref, rtol=1e-9, atol=1e-15 * float(p_ref.max()))
    with pytest.raises(InsufficientDataError):
        sp.welch_psd([1.0], 0.01)
    with pytest.raises(ConfigError):
        sp.welch_psd(x, 0.0)
