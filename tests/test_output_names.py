"""Distinct inputs and axes get distinct output names: names that one sanitiser maps to the same file name are
refused where they are made, never silently overwritten (fogdrift._util.safe_name / check_distinct_names)."""

from __future__ import annotations

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift._util import check_distinct_names, safe_name
from fogdrift.cli import app
from fogdrift.errors import ConfigError
from fogdrift.io import from_array


@pytest.mark.parametrize("a, b", [("g x", "g_x"), ("gx", "GX"), ("g/x", "g_x"), ("é", "_")])
def test_colliding_names_are_refused(a, b):
    assert safe_name(a).lower() == safe_name(b).lower()
    with pytest.raises(ConfigError, match=f"{a!r} and {b!r} would share the output name"):
        check_distinct_names([a, b])
    with pytest.raises(ConfigError, match="would share the output name"):
        from_array(np.zeros((10, 2)), dt_s=1.0, axis_names=[a, b])


def test_distinct_names_pass_and_map_to_distinct_parts():
    names = ["gx", "gy", "g z", "gyro-1", "gyro.2"]
    check_distinct_names(names)
    assert len({safe_name(n) for n in names}) == len(names)
    assert safe_name("../../etc/passwd") == "etc_passwd" and "/" not in safe_name("a/b")


def test_allan_refuses_axes_that_would_share_files(tmp_path):
    p = tmp_path / "log.csv"
    rows = "\n".join(f"{k * 0.01:.2f},{np.sin(k)},{np.cos(k)}" for k in range(500))
    p.write_text("t_s,g x,g_x\n" + rows + "\n")
    res = CliRunner().invoke(app, ["allan", str(p), "--unit", "deg/h", "--out", str(tmp_path / "o")])
    assert res.exit_code != 0 and "Traceback" not in res.output
    line = res.output.strip().splitlines()[-1]
    assert "'g x' and 'g_x' would share the output name 'g_x'" in line and "--columns" in line
    assert not (tmp_path / "o").exists()
    ok = CliRunner().invoke(app, ["allan", str(p), "--unit", "deg/h", "--columns", "g x", "--out", str(tmp_path / "o")])
    assert ok.exit_code == 0, ok.output


def test_an_out_name_longer_than_the_file_system_allows_is_one_line(tmp_path):
    """An ``--out`` of 300 bytes made ``Path.exists`` raise ENAMETOOLONG inside the folder check: a traceback
    (issue 36).  Now one line naming the flag, the name (shortened) and its length, before any work."""
    import numpy as np

    log = tmp_path / "a.npy"
    np.save(log, np.random.default_rng(0).standard_normal(4096))
    out = tmp_path / ("x" * 300)
    res = CliRunner().invoke(app, ["allan", str(log), "--rate", "100", "--unit", "deg/h", "--out", str(out)])
    assert res.exit_code != 0 and "Traceback" not in res.output
    err = [ln for ln in res.output.splitlines() if ln.startswith("error:")]
    assert len(err) == 1 and "--out" in err[0] and "300 bytes" in err[0] and "too long" in err[0], res.output
    assert not any(p.name.startswith("x") for p in tmp_path.iterdir())
