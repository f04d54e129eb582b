"""Shared fixtures. Every random draw in the suite is seeded; data are found relative to this file."""

from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
BUNDLED = REPO / "data" / "psins_lasergyro_rlg" / "psins_lasergyro_rlg.csv.gz"


@pytest.fixture(scope="session")
def bundled_path() -> Path:
    return BUNDLED


@pytest.fixture(scope="session")
def bundled_record():
    from fogdrift.io import load

    return load(BUNDLED)
