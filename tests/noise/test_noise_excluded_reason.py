"""Left-out short taus are blamed on a spectral line only where that line shapes the curve there."""

from __future__ import annotations

import numpy as np

from fogdrift.noise.notes import LINE_SHARE, _lines_that_matter
from fogdrift.noise.periodic import PeriodicContent
from fogdrift.noise.spectral import sinusoid_avar


def _content(*lines):
    ref = max(lines, key=lambda x: x[1])
    return PeriodicContent(lines=tuple((f, (a / ref[1]) ** 2) for f, a in lines), ref_freq_hz=ref[0],
                           ref_amplitude_dph=ref[1], periods_s=tuple(1 / f for f, _ in lines))


def test_a_slow_weak_line_is_not_the_reason_for_short_taus():
    # ADIS16405 imu1 gx: a 0.56-Hz line of 23.7 deg/h beside white noise N = 2.4 deg/sqrt(h) (144 deg/h/sqrt(Hz))
    tau = np.array([0.01, 0.02, 0.04, 0.08])
    y = 144.0**2 / tau
    assert _lines_that_matter(_content((0.5647, 23.7)), tau, y) == []


def test_a_line_that_shapes_the_curve_is_named_with_its_real_frequency():
    tau = np.array([0.01, 0.02, 0.04, 0.08])
    y = 10.0**2 / tau + sinusoid_avar(tau, 300.0, 20.0)
    named = _lines_that_matter(_content((20.0, 300.0), (0.5647, 5.0)), tau, y)
    assert named == ["spectral line at 20 Hz, 300 deg/h"]


def test_the_share_threshold_is_the_rule():
    tau = np.array([0.05 / 2])  # half a period of a 20-Hz line: sin^4 = 1
    line = sinusoid_avar(tau, 1.0, 20.0)[0]
    just_in = line / LINE_SHARE * 0.999   # the line is just above LINE_SHARE of the measured variance
    just_out = line / LINE_SHARE * 1.001
    assert _lines_that_matter(_content((20.0, 1.0)), tau, np.array([just_in]))
    assert not _lines_that_matter(_content((20.0, 1.0)), tau, np.array([just_out]))
