"""fogdrift.screen: the characters ``vibration burst`` and ``warm-up`` (fogdrift.screen_kinds), on seeded records with
known truth (white + flicker at 10 Hz, 2^16 samples).  These rules only name what the detectors found, so the
false-alarm rate on stationary noise stays the measured one (tests/test_screen_false_alarms.py)."""

import numpy as np
import pytest

from fogdrift.allan.segments import allan_variance_segments
from fogdrift.noise import fit_noise
from fogdrift.screen import screen_record
from fogdrift.simulate import simulate

N, DT, L = 2**16, 0.1, 256


def _quiet(seed):
    y = simulate(N, DT, arw_dprh=0.02, bias_instability_dph=0.3, seed=seed)
    return y, np.std(np.diff(y)) / np.sqrt(2)


def _vibration(seed):
    """A band-limited oscillation (0.5-4 Hz, slowly wandering phase) of 5-10x the quiet deviation, switched on for
    5-20 % of the record at a constant amplitude.  Returns the record and the true (start, stop)."""
    rng = np.random.default_rng(2000 + seed)
    y, q = _quiet(seed)
    k = rng.uniform(5, 10)
    dur = int(rng.uniform(0.05, 0.2) * N)
    a = int(rng.integers(0, N - dur))
    phase = 2 * np.pi * rng.uniform(0.5, 4.0) * np.arange(dur) * DT + np.cumsum(rng.normal(scale=0.05, size=dur))
    y[a:a + dur] += np.sqrt(2 * (k * k - 1)) * q * np.sin(phase)
    return y, a, a + dur


def _warm_up(seed):
    """An exponential settling ``A exp(-t/T)`` from the first sample, |A| 3-10x the quiet sample deviation, T 2-8 % of
    the record.  Returns the record, T [s], A and t1 [s], the time at which the exponential falls to the scatter of
    one 256-sample window mean of the white noise (where the screen should end the warm-up)."""
    rng = np.random.default_rng(3000 + seed)
    y, q = _quiet(seed)
    T = rng.uniform(0.02, 0.08) * N * DT
    A = rng.uniform(3, 10) * q * rng.choice([-1.0, 1.0])
    y += A * np.exp(-np.arange(N) * DT / T)
    return y, T, A, T * np.log(abs(A) / (q / np.sqrt(L)))


def test_vibration_bursts_are_found_and_named_in_at_least_19_of_20_seeds():
    named = 0
    for seed in range(20):
        y, a, b = _vibration(seed)
        r = screen_record(y, DT)
        hit = [d for d in r.intervals if abs(d.start - a) <= 0.05 * N and abs(d.stop - b) <= 0.05 * N]
        named += bool(hit) and hit[0].kind == "vibration burst"
    assert named >= 19, named


def test_vibration_burst_that_decays_is_a_transient():
    # the same oscillation with an envelope falling by e^-2 over the interval (a wave train): not steady
    y, q = _quiet(4)
    a, dur = 20_000, 8000
    y[a:a + dur] += 10 * q * np.exp(-2 * np.arange(dur) / dur) * np.sin(2 * np.pi * 1.5 * np.arange(dur) * DT)
    r = screen_record(y, DT)
    assert [d.kind for d in r.intervals] == ["transient"], r.text()


def test_warm_up_is_named_from_the_first_sample_to_where_it_settles_in_at_least_19_of_20_seeds():
    named, ends = 0, []
    for seed in range(20):
        y, T, A, t1 = _warm_up(seed)
        r = screen_record(y, DT)
        d = r.intervals[0] if r.intervals else None
        ok = d is not None and d.kind == "warm-up" and d.start == 0 and 0.6 * t1 <= d.end_s <= 1.6 * t1
        ok = ok and np.sign(d.step) == -np.sign(A) and len(r.intervals) == 1  # settling towards the final level
        named += ok
        if d is not None:
            ends.append(d.end_s / t1)
    assert named >= 19, (named, ends)


def test_quiet_part_after_a_warm_up_gives_the_sensors_noise():
    for seed in (0, 1):
        y, T, A, t1 = _warm_up(seed)
        r = screen_record(y, DT)
        assert r.quiet_segments[0][0] >= r.intervals[0].stop  # the warm-up is cut
        fit = fit_noise(allan_variance_segments(y, DT, r.quiet_segments))
        t = fit.terms["N"]
        assert t.status == "resolved" and t.lo95 <= 0.02 <= t.hi95, (seed, t.lo95, t.hi95)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sharp_step_near_the_start_stays_a_level_step(seed):
    y, q = _quiet(seed)
    p = 2500 + 400 * seed  # 4-5 % of the record, inside the warm-up's search region
    y[p:] += 6 * q
    r = screen_record(y, DT)
    assert [d.kind for d in r.intervals] == ["level step"], r.text()
