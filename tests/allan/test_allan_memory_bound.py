"""Issue 23 item 4: the Allan stage of the commands does not build the float64 angle array (8 (N + 1) bytes) for
long series; it takes the out-of-core sums over the array already in memory.

Measured with tracemalloc (Python and NumPy allocations), not wall time: the in-memory path needs at least the
angle array on top of the input; the out-of-core path stays within its windows, a fraction of it.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from fogdrift.allan import sums as pipeline_sums
from fogdrift.allan.sums import AllanSums

N = 1 << 22            # 32 MB of float64 input
CHUNK = 1 << 18        # start indices per out-of-core chunk: windows of a few MB


def _peak_bytes(y, **kw):
    """(tracemalloc peak of the sums pass, the AllanSums), after one unmeasured pass (numba compilation or cache
    loading allocates too)."""
    warm = AllanSums(y, 0.01, **kw)
    warm.compute((warm.grid("octave"),))
    sums = AllanSums(y, 0.01, **kw)
    m = sums.grid("octave")
    tracemalloc.start()
    try:
        sums.compute((m,))
        return tracemalloc.get_traced_memory()[1], sums
    finally:
        tracemalloc.stop()


@pytest.fixture(scope="module")
def series():
    return np.random.default_rng(7).normal(3.0, 100.0, N)


def test_in_memory_path_holds_the_angle_array(series, monkeypatch):
    # the control: below the threshold the angle array (8 (N + 1) bytes) is allocated
    monkeypatch.setattr(pipeline_sums, "CHUNKED_MIN_SAMPLES", N + 1)
    peak, sums = _peak_bytes(series)
    assert not sums.chunked
    assert peak >= 8 * (N + 1)


@pytest.mark.parametrize("estimator", ["overlapping", "non-overlapping"])
def test_long_series_sums_stay_within_their_windows(series, monkeypatch, estimator):
    monkeypatch.setattr(pipeline_sums, "CHUNKED_MIN_SAMPLES", N)
    monkeypatch.setattr(pipeline_sums, "OUT_OF_CORE_CHUNK", CHUNK)
    peak, sums = _peak_bytes(series, estimator=estimator)
    assert sums.chunked
    assert peak < 8 * N // 2, f"{peak / 1e6:.1f} MB for a {8 * N / 1e6:.0f} MB input"
    assert peak <= 12 * CHUNK * 8 + 4 * 8 * (N // 65536 + 1) * 4   # the engine's window bound + block tables


def test_threshold_is_where_the_angle_array_is_large():
    # 2^24 samples: a 134 MB angle array; the commands' 10^8-sample case (0.8 GB) is far above it
    assert pipeline_sums.CHUNKED_MIN_SAMPLES <= 1 << 24
    assert pipeline_sums.OUT_OF_CORE_CHUNK % 65536 == 0
