"""Plausibility checks: a log read with the wrong unit is caught and the likely unit named.

Independent checks: simulations with known ARW over many seeds (fogdrift.simulate, IEEE-952 laws), the data
READMEs (ADIS16405: deg/s, ARW ~ 2.4 deg/sqrt(h), turn-on bias ~ 0.3-0.45 deg/s; MTi-G: rad/s, ARW ~ 2;
bundled RLG: deg/h, Earth rate visible in the means) and hand-computed unit factors (1 deg/s = 3600 deg/h).
The real ADIS16405 and MTi-G logs are not bundled (CC BY-NC-SA); their tests run where the shared data folder
exists (FOGDRIFT_SHARED_DATA, default /work/shared/data), a simulated ADIS-like triad runs everywhere.
"""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from fogdrift.errors import FogdriftWarning
from fogdrift.io import from_array, load
from fogdrift.plausibility import (ARW_MAX_DPRH, ARW_MIN_DPRH, check_record, gyro_class, noise_floor,
                                   warn_implausible)
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
    # a limitation, stated: the single-axis MEMS log (rad/s) read as deg/h has a floor of 9.4e-6 deg/sqrt(h), the
    # figure of a seismic-grade FOG; with one axis no Earth-rate check applies, so no unit can be ruled out
    found = check_record(load(MTIG, unit="deg/h"))
    assert found == []
    assert gyro_class(noise_floor(load(MTIG, unit="deg/h").axis("gx"), 0.01).estimate) == "seismic / strategic grade"
    assert check_record(load(MTIG, unit="rad/s")) == []


# Seismic / strategic grade (issue 20).  A rotational-seismology FOG has N ~ 1e-5..1e-4 deg/sqrt(h) (module
# docstring of fogdrift.plausibility); only a floor quieter than any portable gyro (< 1e-6 deg/sqrt(h)) or a
# contradicting fact (a quiet triad without the Earth rate) is warned.  1 rad/s = 180/pi * 3600 deg/h by hand.
DPH_PER_RAD_S = 180.0 / np.pi * 3600.0


def _seismic_triad_rad_s(arw_dprh=5.5e-5, seed=0):
    """A static seismic-grade FOG triad at 48 deg N (Earth rate on north and up, a 1e-3 deg/h bias), in rad/s."""
    earth_dph = 15.041067 * np.array([0.0, np.cos(np.radians(48.0)), np.sin(np.radians(48.0))])  # E, N, U
    cols = [simulate(60_000, 0.01, arw_dprh=arw_dprh, bias_dph=e + 1e-3, seed=seed + k)
            for k, e in enumerate(earth_dph)]
    return np.column_stack(cols) / DPH_PER_RAD_S


def test_seismic_grade_triad_in_its_unit_is_plausible():
    x = _seismic_triad_rad_s()
    assert check_record(from_array(x, dt_s=0.01, unit="rad/s", axis_names=("gx", "gy", "gz"))) == []
    # one axis alone (the east one, no Earth rate) is plausible too
    assert check_record(from_array(x[:, 0], dt_s=0.01, unit="rad/s")) == []


def test_seismic_grade_triad_read_in_a_smaller_unit_is_caught():
    x = _seismic_triad_rad_s()
    # rad/s read as deg/h: 206265 times quieter, 2.7e-10 deg/sqrt(h), below every gyro built
    as_dph = check_record(from_array(x, dt_s=0.01, unit="deg/h", axis_names=("gx", "gy", "gz")))
    assert "white-noise" in rules(as_dph)
    quiet = next(f for f in as_dph if f.rule == "white-noise")
    assert "quieter than any gyro built" in quiet.message and "implausibly" not in quiet.message
    assert "rad/s" in quiet.likely_units
    # rad/s read as deg/s: 57 times quieter and the Earth rate 57 times too small: the triad rule fires
    as_dps = check_record(from_array(x, dt_s=0.01, unit="deg/s", axis_names=("gx", "gy", "gz")))
    assert "earth-rate" in rules(as_dps)
    assert all("rad/s" in f.likely_units for f in as_dps)


@pytest.mark.parametrize("seed", range(3))
def test_quiet_warning_starts_a_decade_below_seismic_grade(seed):
    # single axes (no Earth-rate rule): 3e-6 deg/sqrt(h) is a portable gyro's class, 3e-7 is not
    portable = simulate(60_000, 0.01, arw_dprh=3e-6, seed=seed)
    ring_laser = simulate(60_000, 0.01, arw_dprh=3e-7, seed=seed)
    assert check_record(from_array(portable, dt_s=0.01)) == []
    found = check_record(from_array(ring_laser, dt_s=0.01))
    assert rules(found) == ["white-noise"]
    assert "metre-scale ring lasers" in found[0].message and "implausibly" not in found[0].message


def test_tactical_fog_in_rad_s_read_as_deg_h_names_the_unit_and_its_class():
    numbers = simulate(60_000, 0.01, arw_dprh=0.06, seed=7) / DPH_PER_RAD_S  # 2.9e-7 deg/sqrt(h) as deg/h
    found = check_record(from_array(numbers, dt_s=0.01, unit="deg/h"))
    assert rules(found) == ["white-noise"] and "rad/s" in found[0].likely_units
    named = re.search(r"rad/s \(N <= ([0-9.]+) deg/√h, tactical grade or better\)", found[0].message)
    assert named and float(named.group(1)) == pytest.approx(0.06, rel=0.1)


@pytest.mark.parametrize("n_dprh, name", [
    (5e-9, "quieter than any gyro built"), (2e-8, "metre-scale ring lasers"), (5.5e-5, "seismic / strategic grade"),
    (5e-4, "seismic / strategic grade"), (5e-3, "navigation grade"), (0.05, "tactical grade"),
    (0.3, "tactical grade"), (2.4, "industrial / consumer grade"), (500.0, "noisier than any gyro")])
def test_gyro_class_edges(n_dprh, name):
    assert name in gyro_class(n_dprh)
