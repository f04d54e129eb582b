"""Units are never guessed: a rate unit and a time unit come from the caller or from the file, else an error.

Independent checks: hand-computed conversions (1 deg/s = 3600 deg/h, 10 ms steps = 0.01 s) and the bundled
recording's README (deg/h, t_s in seconds, per-axis means).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from fogdrift.errors import ConfigError
from fogdrift.io import load, load_segments, time_unit_of_name

CLI_FLAGS = {"unit": "--unit", "time_unit": "--time-unit", "rate_hz": "--rate", "time_column": "--time-column"}
DATA = Path(__file__).resolve().parents[2] / "data" / "psins_lasergyro_rlg" / "psins_lasergyro_rlg.csv.gz"


def write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_no_rate_unit_is_refused_naming_the_option(tmp_path):
    p = write(tmp_path, "g.csv", "t_s,gx,gy\n0,1,2\n0.01,3,4\n")
    with pytest.raises(ConfigError) as ei:
        load(p)
    msg = str(ei.value)
    assert msg.startswith(f"{p}: no rate unit: the file declares none for gx, gy; pass unit= (deg/h, deg/s,")
    assert "declare it in the header as gx[deg/s]" in msg and "\n" not in msg
    assert "pass --unit (deg/h" in ei.value.render(CLI_FLAGS)
    with pytest.raises(ConfigError, match="no rate unit"):
        load_segments(p)
    assert load(p, unit="deg/s").rate_dph[0].tolist() == [3600.0, 7200.0]


def test_no_rate_unit_is_refused_before_the_data_are_read(tmp_path):
    # a broken data row after the header: the missing unit is reported, not the row (the check comes first)
    p = write(tmp_path, "g.csv", "t_s,gx\n0,1\n0.01,abc\n")
    with pytest.raises(ConfigError, match="no rate unit"):
        load(p)


def test_arrays_need_a_unit_too(tmp_path):
    np.save(tmp_path / "a.npy", np.ones((4, 2)))
    with pytest.raises(ConfigError, match="no rate unit: the file declares none for col0, col1"):
        load(tmp_path / "a.npy", rate_hz=10.0)
    assert load(tmp_path / "a.npy", rate_hz=10.0, unit="deg/h").n_axes == 2


def test_bundled_recording_needs_its_unit():
    with pytest.raises(ConfigError, match="no rate unit"):
        load(DATA, columns="gz")
    rec = load(DATA, unit="deg/h")  # data/README.md: deg/h; t_s declares seconds by its name
    assert rec.dt_s == pytest.approx(0.01, rel=1e-12)
    assert_allclose(rec.rate_dph.mean(axis=0), [-12.2715, 0.437694, 8.3569], atol=1e-4)
    assert "time column 't_s' in s" in rec.notes


@pytest.mark.parametrize("name", ["t", "time", "timestamp", "TIME"])
def test_time_column_without_unit_is_refused(tmp_path, name):
    p = write(tmp_path, "g.csv", f"{name},gz[deg/s]\n0,1\n10,2\n20,3\n")
    with pytest.raises(ConfigError) as ei:
        load(p)
    msg = str(ei.value)
    assert f"time column {name!r} declares no unit; pass time_unit= (s, ms, us, ns)" in msg
    assert f"or name it {name}[s] or {name}_s in the header" in msg
    rendered = ei.value.render(CLI_FLAGS)
    assert "pass --time-unit (s, ms, us, ns)" in rendered and "--time-column none" in rendered
    assert "--rate" in rendered
    # the same log in ms: 10 ms steps are 0.01 s, not 10 s
    rec = load(p, time_unit="ms")
    assert rec.dt_s == pytest.approx(0.01, rel=1e-12) and rec.fs_hz == pytest.approx(100.0)
    assert_allclose(rec.rate_dph[:, 0], [3600.0, 7200.0, 10800.0])
    # without the time column no time unit is needed
    assert load(p, time_column=None, columns="gz", rate_hz=100.0).n_samples == 3


@pytest.mark.parametrize("header, dt", [("t_s", 10.0), ("time_ms", 0.01), ("stamp_us", 1e-5), ("t_ns", 1e-8),
                                        ("t[ms]", 0.01), ("time [us]", 1e-5)])
def test_time_unit_declared_by_name_suffix_or_brackets(tmp_path, header, dt):
    p = write(tmp_path, "g.csv", f"{header},gz[deg/h]\n0,1\n10,2\n20,3\n")
    rec = load(p, time_column=0)
    assert rec.dt_s == pytest.approx(dt, rel=1e-12)


def test_given_time_unit_wins_over_the_name(tmp_path):
    p = write(tmp_path, "g.csv", "t_s,gz[deg/h]\n0,1\n10,2\n20,3\n")
    assert load(p, time_unit="ms").dt_s == pytest.approx(0.01)


def test_time_unit_of_name():
    assert [time_unit_of_name(n) for n in ("t_s", "time_ms", "T_US", "t_ns", "t", "_s", "gz_dps", "t_s2")] == \
        ["s", "ms", "us", "ns", None, None, None, None]


@pytest.mark.parametrize("name, dt", [("t_ms", 0.01), ("time_us", 1e-5), ("timestamp_ns", 1e-8)])
def test_time_column_with_a_unit_suffix_is_found_automatically(tmp_path, name, dt):
    # before units were required, "t_ms" was read as a rate axis named t_ms
    p = write(tmp_path, "g.csv", f"{name},gz[deg/h]\n0,1\n10,2\n20,3\n")
    rec = load(p)
    assert rec.axis_names == ("gz",) and rec.dt_s == pytest.approx(dt, rel=1e-12)
