"""Shared fixtures. Every random draw in the suite is seeded; data are found relative to this file."""

from __future__ import annotations

from pathlib import Path

import os

import pytest
from hypothesis import HealthCheck, settings

# Hypothesis is derandomized by default (scipy's conftest pattern): the suite draws the same examples on every
# run and every machine.  FOGDRIFT_HYPOTHESIS=explore gives a randomized, longer search for local bug hunting.
settings.register_profile("fogdrift", derandomize=True, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("explore", derandomize=False, deadline=None, max_examples=1000,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("FOGDRIFT_HYPOTHESIS", "fogdrift"))

REPO = Path(__file__).resolve().parents[1]
BUNDLED = REPO / "data" / "psins_lasergyro_rlg" / "psins_lasergyro_rlg.csv.gz"


@pytest.fixture(scope="session")
def bundled_path() -> Path:
    return BUNDLED


@pytest.fixture(scope="session")
def bundled_record():
    from fogdrift.io import load

    return load(BUNDLED, unit="deg/h")  # the file declares no unit (data/README.md: deg/h)
