"""fogdrift.screen on stationary noise: false alarms as stated (fogdrift.screen.MEASURED_FALSE_ALARMS)."""

import pytest

from fogdrift.screen import MEASURED_FALSE_ALARMS, screen_record
from fogdrift.simulate import simulate

N, DT = 2**16, 0.1

NOISES = {
    "white": dict(arw_dprh=0.02),
    "white + flicker": dict(arw_dprh=0.02, bias_instability_dph=0.3),
    # the random walk dominates each window's level (edf ~ 70 instead of ~250): its wander is no disturbance
    "white + strong random walk": dict(arw_dprh=0.02, rrw_dphrh=100.0),
}


def _alarms(name, rate):
    """Records of 20 seeded ones in which the screen at ``false_alarm=rate`` reports any interval."""
    return sum(not screen_record(simulate(N, DT, seed=500 + seed, **NOISES[name]), DT, false_alarm=rate).stationary
               for seed in range(20))


@pytest.mark.parametrize("name", list(NOISES))
def test_false_alarms_at_the_default_rate_are_the_documented_ones(name):
    alarms = _alarms(name, 0.05)
    assert (name, 0.05, 20, alarms) in MEASURED_FALSE_ALARMS, alarms
    assert alarms <= 2


@pytest.mark.slow
@pytest.mark.parametrize("name", list(NOISES))
def test_false_alarms_at_one_percent_stay_within_one_of_20(name):
    alarms = _alarms(name, 0.01)
    assert (name, 0.01, 20, alarms) in MEASURED_FALSE_ALARMS, alarms
    assert alarms <= 1
