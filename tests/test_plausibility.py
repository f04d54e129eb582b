"""Plausibility checks: a log read with the wrong unit is caught and the likely unit named.

Independent checks: simulations with known ARW over many seeds (fogdrift.simulate, IEEE-952 laws), the data
READMEs (ADIS16405: deg/s, ARW ~ 2.4 deg/sqrt(h), turn-on bias ~ 0.3-0.45 deg/s; MTi-G: rad/s, ARW ~ 2;
bundled RLG: deg/h, Earth rate visible in the means) and hand-computed unit factors (1 deg/s = 3600 deg/h).
The real ADIS16405 and MTi-G logs are not bundled (CC BY-NC-SA); their tests run where the shared data folder
exists (FOGDRIFT_SHARED_DATA, default /work/shared/data), a simulated ADIS-like triad runs everywhere.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import numpy as np
import pytest

from fogdrift.errors import FogdriftWarning
from fogdrift.io import from_array, load
from fogdrift.plausibility import (ARW_MAX_DPRH, ARW_MIN_DPRH, check_record, noise_floor, warn_implausible)
from fogdrift.simulate import simulate

SHARED = Path(os.environ.get("FOGDRIFT_SHARED_DATA", "/work/shared/data"))
ADIS = SHARED / "adis16405_static" / "adis16405_imu1.csv.gz"
MTIG = SHARED / "mtig_cont_imu1" / "mtig_cont_imu1.csv.gz"
needs_shared = pytest.mark.skipif(not ADIS.exists() or not MTIG.exists(),
                                  reason=f"shared gyro logs not found under {SHARED}")


def rules(findings):
    return sorted(f.rule for f in findings)


@pytest.mark.parametrize("seed", range(6))
def test_noise_floor_recovers_the_arw_of_white_noise(seed):
    x = simulate(100_000, 0.01, arw_dprh=0.3, seed=seed)
    floor = noise_floor(x, 0.01)
    assert floor.estimate == pytest.approx(0.3, rel=0.1)
    assert floor.lo68 <= floor.estimate <= floor.hi68


@pytest.mark.parametrize("seed", range(6))
def test_noise_floor_is_an_upper_bound_of_n_with_other_terms(seed):
    # Q and K add to sigma^2 at every tau: the floor stays at or above N (within estimation noise)
    x = simulate(200_000, 0.01, q_urad=20.0, arw_dprh=0.05, rrw_dphrh=2.0, seed=seed)
    floor = noise_floor(x, 0.01)
    assert floor.hi68 >= 0.05 and floor.estimate >= 0.9 * 0.05


def _adis_like(unit_scale_dps=1.0, seed=0):
    """A static MEMS triad in deg/s like the ADIS16405 README: ARW 2.4 deg/sqrt(h), 0.3-0.45 deg/s turn-on bias,
    0.05 deg/s LSB."""
    sigma_dps = 2.4 * 60 / np.sqrt(0.01) / 3600  # white rate noise per 10 ms sample [deg/s]
    rng = np.random.default_rng(seed)
    cols = [np.round((b + rng.normal(0.0, sigma_dps, 100_000)) / 0.05) * 0.05 for b in (0.40, -0.42, -0.29)]
    return np.column_stack(cols) * unit_scale_dps


def test_mems_triad_in_deg_s_read_as_deg_h_is_caught():
    x = _adis_like()
    ok = check_record(from_array(x, dt_s=0.01, unit="deg/s", axis_names=("gx", "gy", "gz")))
    assert ok == []
    wrong = check_record(from_array(x, dt_s=0.01, unit="deg/h", axis_names=("gx", "gy", "gz")))
    assert rules(wrong) == ["earth-rate"]
    assert wrong[0].likely_units[0] == "deg/s"
    assert "15.04 deg/h" in wrong[0].message and "check {opt:unit}" in wrong[0].message
    assert "check --unit" in wrong[0].render({"unit": "--unit"})


def test_one_axis_of_a_mems_log_read_as_deg_h_is_not_caught():
    # a limitation, stated: without the Earth-rate rule a 6e-4 deg/sqrt(h) axis could be a navigation-grade FOG
    x = _adis_like()[:, 2]
    assert check_record(from_array(x, dt_s=0.01, unit="deg/h")) == []


@pytest.mark.parametrize("unit", ["deg/s", "rad/s"])
def test_deg_h_log_read_in_a_larger_unit_is_too_noisy(bundled_record, unit):
    # the bundled RLG is in deg/h (data README); read as deg/s its noise floor is 3600 times too high
    numbers = np.asarray(bundled_record.rate_dph)  # what the file holds
    findings = check_record(from_array(numbers, dt_s=0.01, unit=unit, axis_names=bundled_record.axis_names))
    assert "white-noise" in rules(findings)
    assert all(f.likely_units == ("deg/h",) for f in findings)
    if unit == "rad/s":
        assert "range" in rules(findings)


def test_bundled_recording_in_its_unit_is_plausible(bundled_record):
    assert check_record(bundled_record) == []


def test_quiet_and_noisy_limits():
    quiet = simulate(50_000, 0.01, arw_dprh=ARW_MIN_DPRH / 20, seed=3)
    noisy = simulate(50_000, 0.01, arw_dprh=ARW_MAX_DPRH * 20, seed=4)
    fine = simulate(50_000, 0.01, arw_dprh=0.01, seed=5)
    assert rules(check_record(from_array(quiet, dt_s=0.01))) == ["white-noise"]
    assert rules(check_record(from_array(noisy, dt_s=0.01))) == ["white-noise"]
    assert check_record(from_array(fine, dt_s=0.01)) == []


def test_sample_rate_that_looks_like_a_time_unit_mistake():
    x = simulate(2_000, 10.0, arw_dprh=0.5, seed=1)  # a 100 Hz log whose ms time stamps were read as s: 0.1 Hz
    findings = check_record(from_array(x, dt_s=10.0))
    assert rules(findings) == ["sample-rate"]
    assert "check time_unit=" in findings[0].render() and "in ms read as s" in findings[0].message


def test_warn_implausible_issues_one_warning_per_finding():
    numbers = simulate(20_000, 0.01, arw_dprh=0.5, seed=2)  # deg/h in the file, read as deg/s
    with warnings.catch_warnings(record=True) as log:
        warnings.simplefilter("always")
        found = warn_implausible(from_array(numbers, dt_s=0.01, unit="deg/s"))
    assert len(found) == 1 and len(log) == 1 and issubclass(log[0].category, FogdriftWarning)
    assert "unit=" in str(log[0].message) and "{opt:" not in str(log[0].message)


@needs_shared
def test_real_adis16405_log_read_with_the_wrong_unit():
    wrong = check_record(load(ADIS, unit="deg/h"))  # the issue's case: N = 6e-4 deg/sqrt(h) printed silently
    assert rules(wrong) == ["earth-rate"] and wrong[0].likely_units == ("deg/s",)
    assert check_record(load(ADIS, unit="deg/s")) == []
    too_big = check_record(load(ADIS, unit="rad/s"))
    assert rules(too_big) == ["white-noise"] and too_big[0].likely_units == ("deg/s",)


@needs_shared
def test_real_mtig_log_read_as_deg_h():
    found = check_record(load(MTIG, unit="deg/h"))
    assert rules(found) == ["white-noise"]
    assert "rad/s" in found[0].likely_units  # the README's unit (ARW ~ 2 deg/sqrt(h))
    assert check_record(load(MTIG, unit="rad/s")) == []
