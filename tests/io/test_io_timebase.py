"""The time base is checked, not assumed: a rate change, alternating or scattered steps and a span that does not
match ``(n - 1) dt`` are refused with one located line (the median step would otherwise be taken silently)."""

from __future__ import annotations

import numpy as np
import pytest

from fogdrift.errors import DataFormatError
from fogdrift.io import load
from fogdrift.io.timebase import (DT_TOLERANCE, GRID_DRIFT_FRACTION, GRID_DRIFT_INTERVALS, JITTER_TOLERANCE,
                                  SHORT_STEP_FACTOR)


def _write(path, t, seed=0):
    x = np.random.default_rng(seed).normal(size=t.size)
    np.savetxt(path, np.c_[t, x], delimiter=",", header="t_s,gz", comments="", fmt="%.12g")
    return path


def _err(path, **kw) -> DataFormatError:
    with pytest.raises(DataFormatError) as e:
        load(path, unit="deg/h", **kw)
    return e.value


def test_a_rate_change_is_refused_at_its_line(tmp_path):
    # 2000 samples at 100 Hz, then 3000 at 50 Hz: the median step (0.02 s) would make it "100 s at 50 Hz"
    t = np.r_[np.arange(2000) * 0.01, 20.0 + np.arange(3000) * 0.02]
    e = _err(_write(tmp_path / "a.csv", t))
    assert e.line == 3 and "0.5 sample intervals" in str(e) and "2000 step(s)" in str(e)
    # the other way round (more samples at 100 Hz): the 50-Hz steps are gaps
    t = np.r_[np.arange(3000) * 0.01, 30.0 + np.arange(2000) * 0.02]
    assert "gap in time" in str(_err(_write(tmp_path / "b.csv", t)))


def test_alternating_steps_are_refused(tmp_path):
    t = np.cumsum(np.tile([0.001, 0.019], 3000))  # 52.6 Hz by the median, 100 Hz on average
    e = _err(_write(tmp_path / "a.csv", t))
    assert "alternate" in str(e) and "--time-column" not in str(e)  # the library names the keyword
    assert "time_column" in str(e) and "rate_hz" in str(e)


def test_scattered_steps_are_refused_and_small_jitter_passes(tmp_path):
    rng = np.random.default_rng(1)
    t = np.cumsum(0.01 * (1 + rng.uniform(-0.2, 0.2, 6000)))  # +-20 %: MAD 10 % of dt
    e = _err(_write(tmp_path / "a.csv", t))
    assert "scatter by" in str(e) and f"within {100 * JITTER_TOLERANCE:g} %" in str(e)
    # +-8 % uniform: MAD 4 % (< 5 %), no step below 0.7 dt: a uniform grid with jittery stamps
    t = np.cumsum(0.01 * (1 + rng.uniform(-0.08, 0.08, 6000)))
    rec = load(_write(tmp_path / "b.csv", t), unit="deg/h")
    assert rec.dt_s == pytest.approx(0.01, rel=0.01)


def test_a_span_that_does_not_match_n_dt_is_refused(tmp_path):
    # 4000 steps of dt, then 2000 of 1.04 dt: the median step is dt and its deviation 0, no step is short or a
    # gap, but the span is 1.3 % longer than (n - 1) dt (a slow clock for a third of the log)
    t = np.r_[0.0, np.cumsum(np.r_[np.full(4000, 0.01), np.full(2000, 0.0104)])]
    e = _err(_write(tmp_path / "a.csv", t))
    assert "time column spans" in str(e) and "+1.33 %" in str(e)


def test_blocks_at_other_rates_that_pass_every_step_check_are_refused(tmp_path):
    """100 Hz stretches with blocks at 125 Hz and 80 Hz between them, balanced so that the span matches n dt: the
    median step is dt with no deviation, no step is short (0.8 dt) or a gap (1.25 dt), yet the stamps run 1.25 s
    off the uniform grid -- the samples of a 125-Hz block are not 0.01 s apart."""
    steps = []
    for _ in range(6):
        steps += [0.01] * 2000 + [0.008] * 625 + [0.01] * 2000 + [0.0125] * 500
    t = np.r_[0.0, np.cumsum(steps)]
    e = _err(_write(tmp_path / "a.csv", t))
    assert "uniform grid" in str(e) and "125 sample intervals" in str(e) and "rate changes within the log" in str(e)
    # where the stamps are farthest off: after a 125-Hz block, before the 80-Hz block brings them back
    assert 2000 + 625 <= (e.line - 2) % 5125 <= 2000 + 625 + 2000


def test_a_drifting_oscillator_and_accumulated_jitter_pass(tmp_path):
    # 300 ppm quadratic drift of the sample clock over 2e5 samples: 0.075 % of the span off a straight line
    i = np.arange(200_000)
    t = i * 0.01 * (1 + 3e-4 * (i / i[-1]) ** 2)
    assert load(_write(tmp_path / "a.csv", t), unit="deg/h").n_samples == i.size
    # the threshold: just inside passes, just outside is refused (the larger of 20 intervals and 0.1 % of the span)
    n, dt = 20_000, 0.01
    bump = np.sin(np.pi * np.arange(n) / (n - 1))  # 0 at both ends: the span is n dt exactly
    limit = max(GRID_DRIFT_INTERVALS * dt, GRID_DRIFT_FRACTION * (n - 1) * dt)
    for k, ok in ((0.95, True), (1.05, False)):
        path = _write(tmp_path / f"b{k}.csv", np.arange(n) * dt + k * limit * bump)
        if ok:
            assert load(path, unit="deg/h").n_samples == n
        else:
            assert "uniform grid" in str(_err(path))


def test_the_thresholds_are_the_documented_ones(tmp_path):
    dt = 0.01
    # a step just below SHORT_STEP_FACTOR dt is refused; one just above passes (the rule, not a constant)
    for factor, ok in ((SHORT_STEP_FACTOR - 0.02, False), (SHORT_STEP_FACTOR + 0.02, True)):
        steps = np.full(999, dt)
        steps[500] = factor * dt
        steps[501] = (2 - factor) * dt  # keep the span
        path = _write(tmp_path / f"s{factor}.csv", np.r_[0.0, np.cumsum(steps)])
        if ok:
            assert load(path, unit="deg/h").n_samples == 1000
        else:
            assert _err(path).line == 503
    assert DT_TOLERANCE == 0.01


def test_gap_free_segments_are_checked_one_by_one(tmp_path):
    # a real gap (split) between two uniform stretches is fine with gaps="split"
    t = np.r_[np.arange(3000) * 0.01, 100.0 + np.arange(3000) * 0.01]
    from fogdrift.io import load_segments

    segs = load_segments(_write(tmp_path / "a.csv", t), unit="deg/h")
    assert [s.n_samples for s in segs] == [3000, 3000]


def test_the_bundled_and_shared_logs_pass(bundled_path):
    assert load(bundled_path, unit="deg/h").dt_s == pytest.approx(0.01)
