"""level_scan() and choose_level(): the one implementation of the automatic level.

Oracles: allantools (overlapping ADEV), simulated drift + white noise with known truth,
and the drift operator's frequency response (power of a sinusoid kept in the drift).
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from fogdrift import lifting as L
from fogdrift.errors import ConfigError, InsufficientDataError
from fogdrift.lifting.levels import _oadev_octaves

DT_S = 0.1


def _simulated(seed, n=2**16, period=512, amp=1.0, rw=0.005, sigma=1.0):
    rng = np.random.default_rng(seed)
    t = np.arange(n)
    drift = amp * np.sin(2 * np.pi * t / period) + rw * np.cumsum(rng.standard_normal(n))
    return drift, drift + sigma * rng.standard_normal(n)


def test_oadev_helper_matches_allantools():
    allantools = pytest.importorskip("allantools")
    y = np.random.default_rng(3).standard_normal(5000)
    taus, adev = _oadev_octaves(y, DT_S)
    t2, ad2, _, _ = allantools.oadev(y, rate=1 / DT_S, data_type="freq", taus=taus)
    np.testing.assert_allclose(t2, taus)
    np.testing.assert_allclose(adev, ad2, rtol=1e-9)


@pytest.mark.parametrize(
    "period,kept", [(16, 0.0), (32, 0.387), (64, 0.938), (128, 0.9955), (256, 0.9997)]
)
def test_sinusoid_power_kept_in_drift(period, kept):
    # db2, J = 4, N = 256, periodization: fraction of the power of sin(2 pi t / period) that the
    # drift keeps (reference values of the method notes, §1.7).  From a period of 4 * 2**J on
    # it does not depend on the phase; at 2 * 2**J = 32 (the band edge) it does: 0.007 .. 0.93.
    t = np.arange(256)
    x = np.sin(2 * np.pi * t / period)
    drift, _ = L.separate(x, "db2", level=4)
    assert float(drift @ drift / (x @ x)) == pytest.approx(kept, abs=1e-3)
    if period >= 64:
        y = np.cos(2 * np.pi * t / period + 0.3)
        dy, _ = L.separate(y, "db2", level=4)
        assert float(dy @ dy / (y @ y)) == pytest.approx(kept, abs=1e-3)


def test_noise_part_recovers_arw_and_drift_rmse():
    sigma = 1.0
    true_drift, x = _simulated(11, sigma=sigma)
    arw_true = sigma * math.sqrt(DT_S) / 60.0  # deg/sqrt(h)
    diags = L.level_scan(x, DT_S, "db2", max_level=6)
    d4 = diags[3]
    assert d4.level == 4
    assert d4.cutoff_hz == pytest.approx(1 / (2**5 * DT_S))
    assert d4.noise_arw_dprh == pytest.approx(arw_true, rel=0.05)
    drift, _ = L.separate(x, "db2", level=4)
    rmse = float(np.sqrt(np.mean((drift - true_drift) ** 2)))
    # ~1/2**J of the white variance stays in the drift -> rmse ~ sigma/4 at J = 4
    # (measured 0.0592 of the variance, sqrt = 0.243); the 512-sample sinusoid keeps >99 %.
    assert 0.2 * sigma <= rmse <= 0.3 * sigma
    assert json.loads(json.dumps(d4.to_dict()))["level"] == 4


@pytest.mark.parametrize("wavelet", ["db2", "db4"])
@pytest.mark.parametrize("period,amp", [(256, 1.0), (256, 5.0), (1024, 1.0)])
def test_choose_level_on_known_drift(period, amp, wavelet):
    # a period of 4*2**J samples keeps 94 % of its power in the drift (db2), so the right
    # level is log2(period) - 2 or one below it.  (Not haar: its wide transition band leaks
    # the sinusoid into the noise part gradually; on the 256-sample period the rule picks 4 or 7.)
    _, x = _simulated(21, period=period, amp=amp, rw=0.02, sigma=2.0)
    diags = L.level_scan(x, DT_S, wavelet, max_level=11)
    j = L.choose_level(diags)
    right = int(math.log2(period)) - 2
    assert j in (right - 1, right)
    assert [d.level for d in diags] == list(range(1, 12))


def test_white_noise_slopes():
    x = np.random.default_rng(9).standard_normal(2**15)
    diags = L.level_scan(x, DT_S)
    for d in diags[1:]:
        assert -0.62 <= d.noise_inband_slope <= -0.45
    assert L.choose_level(diags) == diags[-1].level
    # the overall slope is pulled towards -1 by the high-pass (documented in choose_level)
    assert diags[0].noise_adev_slope < -0.9


def test_choose_level_rule_and_errors():
    def diag(level, inband):
        return L.LevelDiagnostic(level, 1.0, -0.5, 0.1, 1.0, 1.0, inband)

    # level 1 always passes; the scan stops at the first level whose slope exceeds -0.5 + tol
    assert L.choose_level([diag(3, -0.5), diag(1, 0.9), diag(2, -0.45), diag(4, -0.3), diag(5, -0.5)]) == 3
    assert L.choose_level([diag(1, -0.5), diag(2, -0.35)], tol=0.2) == 2
    assert L.choose_level([diag(1, -0.5), diag(2, float("nan"))]) == 1
    with pytest.raises(ConfigError):
        L.choose_level([])
    with pytest.raises(InsufficientDataError):
        L.level_scan(np.zeros(19), DT_S)
    with pytest.raises(ConfigError, match="maximum"):
        L.level_scan(np.zeros(100), DT_S, max_level=9)
