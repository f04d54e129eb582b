"""``fogdrift compensate`` at its edges: reading through :mod:`fogdrift.io` (units, the .npy stream, one parse),
the bias re-estimated under a bundle that removed the Earth rate, and the atomic output edge (Ctrl-C).

Independent references: every expected number is written out by hand from the log's own numbers, the bundle's
bias and the Earth rate w_ie sin(L) computed here from w_ie = 7.2921150e-5 rad/s (not from fogdrift.units).
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.bundle import load_bundle, write_bundle
from fogdrift.compensate import compensate_file
from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.io import from_array
from fogdrift.output import MANIFEST, TMP_PREFIX
from fogdrift.pipeline import AnalysisConfig, run_models
from fogdrift.signal import record_units
from fogdrift.simulate import simulate

LAT = 45.0
#: w_ie sin(45 deg) in deg/h, by hand: 7.2921150e-5 rad/s * (180 / pi) deg/rad * 3600 s/h * sin(pi / 4)
EARTH_UP_45 = 7.2921150e-5 * 180.0 / math.pi * 3600.0 * math.sin(math.pi / 4)
BIAS = 40.0  # deg/h, the training log's bias before the Earth rate


@pytest.fixture(scope="module")
def bundle(tmp_path_factory):
    """A 1-Hz deg/h bundle of one axis 'gz' pointing up at 45 deg latitude (the Earth rate removed)."""
    x = simulate(4000, 1.0, arw_dprh=0.05, rrw_dphrh=0.5, bias_dph=BIAS + EARTH_UP_45, seed=3)
    rec = from_array(x, dt_s=1.0, unit="deg/h", axis_names=("gz",))
    cfg = AnalysisConfig(models=("ar",), latitude_deg=LAT, earth_axes={"gz": "up"})
    out = tmp_path_factory.mktemp("bundle") / "bundle"
    write_bundle(out, run_models(rec, cfg), cfg, rec)
    return out


def _csv(path, header, x, dt=1.0):
    t = np.arange(x.shape[0]) * dt
    np.savetxt(path, np.column_stack([t, x]), delimiter=",", header=header, comments="", fmt="%.17g")
    return path


def _log_unit(summary):
    """(unit as read, factor to deg/h) of the compensated log, as compensation.json states them (its signal)."""
    u = record_units(summary, "compensation.json")
    return u.input_unit, u.scale_to_internal


def _read(out):
    with np.load(Path(out) / "compensated.npz") as z:
        return {k: z[k] for k in z.files}


def _kw(**kw):
    return dict(dict(heading=False, artefacts=False, figures=False, model="bias"), **kw)


def test_the_bundle_removed_the_earth_rate_by_hand(bundle):
    ax = load_bundle(bundle).axis("gz")
    assert ax.earth_rate_dph == pytest.approx(EARTH_UP_45, rel=1e-9)
    assert EARTH_UP_45 == pytest.approx(10.635, abs=1e-3)


def test_unit_on_a_log_that_declares_another_unit(bundle, tmp_path):
    """Declared deg/s, bundle deg/h: refused without --unit; --unit deg/s converts (x3600 in, /3600 out); --unit
    deg/h takes precedence over the declared unit (the numbers are read as deg/h), as for every command."""
    b = load_bundle(bundle).axis("gz").bias_dph
    v = 0.0125 + 1e-4 * np.sin(np.arange(600) / 7.0)  # deg/s as the file says
    log = _csv(tmp_path / "s.csv", "t_s,gz[deg/s]", v)
    with pytest.raises(ConfigError) as info:
        compensate_file(bundle, log, tmp_path / "o0", **_kw())
    assert "declares unit deg/s but the bundle was trained on deg/h; pass --unit deg/s" in \
        info.value.render({"unit": "--unit"})

    res = compensate_file(bundle, log, tmp_path / "o1", **_kw(unit="deg/s"))
    got = _read(tmp_path / "o1")
    assert _log_unit(res.summary) == ("deg/s", 3600.0) and str(got["unit"]) == "deg/s"
    np.testing.assert_allclose(got["compensated"][:, 0], v - b / 3600.0, rtol=0, atol=1e-13)
    assert (tmp_path / "o1" / "compensated.csv").read_text().splitlines()[0] == "t_s,gz[deg/s],gz_drift[deg/s]"

    res = compensate_file(bundle, log, tmp_path / "o2", **_kw(unit="deg/h"))
    got = _read(tmp_path / "o2")
    assert _log_unit(res.summary) == ("deg/h", 1.0) and str(got["unit"]) == "deg/h"
    np.testing.assert_allclose(got["compensated"][:, 0], v - b, rtol=0, atol=1e-12)
    assert any("declares deg/s; its numbers are read as deg/h" in m for m in res.messages)
    assert (tmp_path / "o2" / "compensated.csv").read_text().splitlines()[0] == "t_s,gz[deg/h],gz_drift[deg/h]"


def test_increment_unit_scale_is_carried_from_the_reader(bundle, tmp_path):
    """inc:arcsec per 0.1-s sample: 5 arcsec per sample = 50 arcsec/s = 50 deg/h (1 arcsec/s = 3600 arcsec/h =
    1 deg/h), so the reader's factor is 1 / 0.1 s = 10 deg/h per (arcsec per sample), and the output, in the log's
    unit, divides by that same factor: 5 - b / 10."""
    b = load_bundle(bundle).axis("gz").bias_dph
    v = np.full(3000, 5.0)
    log = _csv(tmp_path / "inc.csv", "t_s,gz", v, dt=0.1)
    res = compensate_file(bundle, log, tmp_path / "o", **_kw(unit="inc:arcsec", accept_rate=True))
    assert _log_unit(res.summary)[1] == pytest.approx(10.0, rel=1e-12)
    assert res.summary["block_average_factor"] == 10
    chan = res.summary["signal"]["channels"][0]
    assert chan["unit_as_read"] == "inc:arcsec" and chan["unit_source"] == "option"
    assert res.summary["signal"]["sampling"]["dt_source"] == "time column"
    # the log's interval is written once, in its signal description; model_dt_s is the bundle's models' interval
    assert res.summary["signal"]["sampling"]["dt_s"] == pytest.approx(0.1) and "native_dt_s" not in res.summary
    assert res.summary["model_dt_s"] == load_bundle(bundle).model_dt_s
    # the log's unit and factor likewise: in its channels only
    assert not {"unit", "scale_to_dph", "input_unit"} & set(res.summary)
    assert _log_unit(json.loads((tmp_path / "o" / "compensation.json").read_text())) == _log_unit(res.summary)
    np.testing.assert_allclose(_read(tmp_path / "o")["compensated"][:, 0], 5.0 - b / 10.0, atol=1e-12)


def test_bias_re_estimated_under_a_bundle_that_removed_the_earth_rate(bundle, tmp_path):
    """bias = mean of the first S s - w_ie sin(L); the output keeps the Earth rate: x - bias after the window."""
    bb = load_bundle(bundle).axis("gz").bias_dph
    n, s = 1200, 300
    x = 55.0 + EARTH_UP_45 + 0.3 * np.cos(np.arange(n) * 0.37)  # a new turn-on bias of 55 deg/h
    log = _csv(tmp_path / "e.csv", "t_s,gz[deg/h]", x)
    res = compensate_file(bundle, log, tmp_path / "o", **_kw(bias=f"re-estimate:{s}"))
    ax = res.summary["axes"][0]
    level = math.fsum(x[:s]) / s
    assert ax["bias_plus_earth_dph"] == pytest.approx(level, rel=1e-13)
    assert ax["bias_dph"] == pytest.approx(level - EARTH_UP_45, rel=1e-12)
    assert ax["earth_rate_dph"] == pytest.approx(EARTH_UP_45, rel=1e-9)
    comp = _read(tmp_path / "o")["compensated"][:, 0]
    np.testing.assert_allclose(comp[:s], x[:s] - bb, atol=1e-9)  # calibrating: the bundle's bias
    np.testing.assert_allclose(comp[s:], x[s:] - (level - EARTH_UP_45), atol=1e-9)
    assert np.mean(comp[s:]) == pytest.approx(EARTH_UP_45, abs=0.05)  # the Earth rate stays in the output
    line = next(m for m in res.messages if m.startswith("bias:"))
    assert "minus the Earth rate" in line and f"{level - EARTH_UP_45:.6g}" in line


def test_a_log_without_a_unit_is_parsed_once_and_refused_without_unit(bundle, tmp_path, monkeypatch):
    io_load = sys.modules["fogdrift.io.load"]  # the module (fogdrift.io.load is also the function's name)

    calls = []
    real = io_load._load_records
    monkeypatch.setattr(io_load, "_load_records", lambda path, opts: calls.append(path) or real(path, opts))
    log = _csv(tmp_path / "plain.csv", "t_s,gz", np.full(200, 45.0))
    with pytest.raises(ConfigError) as info:
        compensate_file(bundle, log, tmp_path / "o1", **_kw())
    assert "pass --unit deg/h (the bundle was trained on deg/h)" in info.value.render({"unit": "--unit"})
    assert len(calls) == 1 and not (tmp_path / "o1" / "compensated.csv").exists()
    calls.clear()
    compensate_file(bundle, log, tmp_path / "o2", **_kw(unit="deg/h"))
    assert len(calls) == 1


def test_npy_stream_needs_a_unit_and_checks_the_time_base(bundle, tmp_path):
    x = np.full(500, 45.0)
    np.save(tmp_path / "r.npy", x)
    with pytest.raises(ConfigError) as info:
        compensate_file(bundle, tmp_path / "r.npy", tmp_path / "o1", **_kw(rate_hz=1.0, axis_map="col0=gz"))
    assert "pass --unit deg/h (the bundle was trained on deg/h)" in info.value.render({"unit": "--unit"})
    b = load_bundle(bundle).axis("gz").bias_dph
    compensate_file(bundle, tmp_path / "r.npy", tmp_path / "o2",
                    **_kw(rate_hz=1.0, unit="deg/s", axis_map="col0=gz", chunk_samples=77))
    np.testing.assert_allclose(_read(tmp_path / "o2")["compensated"][:, 0], 45.0 - b / 3600.0, atol=1e-13)
    # a time column whose rate halves after 300 samples (1 s -> 2 s steps): refused at opening, before any work,
    # by its span (the last stamp is read first)
    t = np.concatenate([np.arange(300.0), 300.0 + 2 * np.arange(200.0)])
    np.save(tmp_path / "t.npy", np.column_stack([t, x]))
    with pytest.raises(DataFormatError, match=r"time column spans 698 s, but its 500 samples at 1 s span 499 s"):
        compensate_file(bundle, tmp_path / "t.npy", tmp_path / "o3",
                        **_kw(unit="deg/h", time_column="col0", axis_map="col1=gz", chunk_samples=128))
    assert not (tmp_path / "o3" / "compensated.csv").exists()
    assert not list((tmp_path / "o3").glob(TMP_PREFIX + "*"))


def test_outputs_are_atomic_and_listed_in_a_manifest(bundle, tmp_path):
    log = _csv(tmp_path / "m.csv", "t_s,gz[deg/h]", 45.0 + np.sin(np.arange(300) * 0.9))
    compensate_file(bundle, log, tmp_path / "o", heading=False, artefacts=False, model="bias")
    doc = json.loads((tmp_path / "o" / MANIFEST).read_text())
    assert doc["complete"] is True and doc["command"] == "compensate"
    assert set(doc["files"]) == {"compensated.csv", "compensated.npz", "compensation.json", "compensation_allan.png"}
    assert not list((tmp_path / "o").glob(TMP_PREFIX + "*"))


def test_cli_unit_flag_and_the_deprecated_alias(bundle, tmp_path):
    from fogdrift.cli import app

    log = _csv(tmp_path / "plain.csv", "t_s,gz", 45.0 + np.sin(np.arange(300) * 0.9))
    runner = CliRunner()
    base = ["compensate", str(bundle), str(log), "--model", "bias", "--no-heading", "--no-artefacts"]
    r = runner.invoke(app, base + ["--out", str(tmp_path / "o1")])
    assert r.exit_code == 1 and "Traceback" not in r.output
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and "pass --unit deg/h (the bundle was trained on deg/h)" in lines[0]
    r = runner.invoke(app, base + ["--unit", "deg/h", "--out", str(tmp_path / "o2")])
    assert r.exit_code == 0, r.output
    r = runner.invoke(app, base + ["--apply-unit", "deg/h", "--out", str(tmp_path / "o3")])
    assert r.exit_code == 0, r.output
    assert len([ln for ln in r.output.splitlines() if "deprecated" in ln]) == 1
    assert "--apply-unit is deprecated; use --unit" in r.output
    np.testing.assert_array_equal(_read(tmp_path / "o2")["compensated"], _read(tmp_path / "o3")["compensated"])
    r = runner.invoke(app, ["compensate", "--help"])
    assert "--unit" in r.output and "--apply-unit" not in r.output and "--layout" in r.output


def test_ctrl_c_while_the_csv_is_written_leaves_no_partial_file(bundle, tmp_path):
    """SIGINT to a real process once its temporary CSV has rows: exit 130, one 'interrupted:' line, no CSV (or NPZ)
    under a final name, no temporary file left."""
    n = 3_000_000
    np.save(tmp_path / "big.npy", np.full(n, 45.0))
    out = tmp_path / "o"
    # A test run started as a background job of a non-interactive shell has SIGINT ignored and the child inherits
    # it (the CLI respects that, as a shell asks: the run then finished with exit 0); restore Python's handler
    # first, as tests/cli/test_cli_safety.py's BOOT does.
    boot = ("import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); sys.argv[0] = 'fogdrift'; "
            "from fogdrift.cli import main; main()")
    cmd = [sys.executable, "-c", boot, "compensate", str(bundle), str(tmp_path / "big.npy"), "--rate", "1",
           "--unit", "deg/h", "--axis-map", "col0=gz", "--model", "bias", "--no-heading", "--no-artefacts",
           "--chunk", "2000", "--out", str(out)]
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2] / "src"))
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        deadline = time.monotonic() + 300
        started = False
        while time.monotonic() < deadline and proc.poll() is None:
            tmp = list(out.glob(TMP_PREFIX + "*compensated.csv")) if out.is_dir() else []
            if tmp and tmp[0].exists() and tmp[0].stat().st_size > 100_000:
                started = True
                break
            time.sleep(0.01)
        assert started, "the temporary CSV never grew (the run ended or never started writing)"
        proc.send_signal(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr
    lines = [ln for ln in stderr.splitlines() if ln.startswith("interrupted:")]
    assert len(lines) == 1 and ("no partial file left" in lines[0] or "nothing was written" in lines[0]), stderr
    assert "compensated.csv" not in lines[0].split("; not written")[0].split(str(out))[-1], lines[0]
    assert not (out / "compensated.csv").exists() and not (out / "compensated.npz").exists()
    assert not list(out.glob(TMP_PREFIX + "*"))
    manifest = out / MANIFEST
    assert not manifest.exists() or json.loads(manifest.read_text())["complete"] is False


def test_cli_gaps_longest_compensates_the_longest_segment(bundle, tmp_path):
    from fogdrift.cli import app

    t = np.concatenate([np.arange(300.0), 310.0 + np.arange(500.0)])  # an 11-s gap after sample 299
    v = 45.0 + np.sin(np.arange(t.size) * 0.9)
    np.savetxt(tmp_path / "gap.csv", np.column_stack([t, v]), delimiter=",", header="t_s,gz[deg/h]", comments="",
               fmt="%.10g")
    base = ["compensate", str(bundle), str(tmp_path / "gap.csv"), "--model", "bias", "--no-heading", "--no-artefacts"]
    r = CliRunner().invoke(app, base + ["--out", str(tmp_path / "o1")])
    assert r.exit_code == 1 and "gap in time" in r.output and "--gaps" in r.output
    r = CliRunner().invoke(app, base + ["--gaps", "longest", "--out", str(tmp_path / "o2")])
    assert r.exit_code == 0, r.output
    warn = [ln for ln in r.output.splitlines() if ln.startswith("warning:")]
    assert len(warn) == 1 and "2 segments between gaps; compensating the longest (500 samples" in warn[0]
    got = _read(tmp_path / "o2")
    b = load_bundle(bundle).axis("gz").bias_dph
    np.testing.assert_allclose(got["t_s"], 310.0 + np.arange(500.0))
    np.testing.assert_allclose(got["compensated"][:, 0], v[300:] - b, atol=1e-9)


def test_relative_out_folder_holds_the_files_itself(bundle, tmp_path, monkeypatch):
    """--out o (relative): the files are o/compensated.csv ..., not o/o/... (an OutputDir takes a relative path as
    one inside its folder, so compensate writes through absolute paths)."""
    from fogdrift.cli import app

    _csv(tmp_path / "r.csv", "t_s,gz[deg/h]", 45.0 + np.sin(np.arange(300) * 0.9))
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(app, ["compensate", str(bundle), "r.csv", "--model", "bias", "--no-heading",
                                 "--no-artefacts", "--out", "o"])
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == sorted(
        [MANIFEST, "compensated.csv", "compensated.npz", "compensation.json", "compensation_allan.png"])
    assert "wrote o/compensated.csv, o/compensated.npz" in r.output
    doc = json.loads((tmp_path / "o" / "compensation.json").read_text())
    assert doc["files"]["csv"] == "o/compensated.csv"


# ---------------------------------------------------------------------------------------------------------------
# the .npy stream's time base (io.chunked.open_rows), each rule on a case where only it applies


def _stream(tmp_path, t, *, chunk=64, **kw):
    from fogdrift.io.chunked import open_rows

    x = np.full(t.size, 45.0)
    np.save(tmp_path / "s.npy", np.column_stack([t, x]))
    src = open_rows(tmp_path / "s.npy", time_column="col0", unit="deg/h", **kw)
    return src, [c for c in src.chunks(chunk)]


def test_stream_time_rules_each_on_its_own_case(tmp_path):
    # uniform 10-ms grid in ms with time_unit="ms": dt 0.01 s, t in s
    src, chunks = _stream(tmp_path, 10.0 * np.arange(200) + 5.0, time_unit="ms")
    assert src.dt_s == pytest.approx(0.01, rel=1e-12) and src.t0_s == pytest.approx(0.005)
    np.testing.assert_allclose(np.concatenate([t for t, _ in chunks]), 0.005 + 0.01 * np.arange(200), rtol=1e-12)
    assert src.signal.sampling.dt_source == "time column" and src.signal.sampling.time_unit == "ms"
    # one step of 0.5 s among steps of 1 s (no scatter, no gap): a short step (a rate change), in the FIRST chunk
    t = np.cumsum(np.r_[0.0, np.ones(4), 0.5, np.ones(194)])
    with pytest.raises(DataFormatError, match=r"time step at sample 5 is 0.5 s"):
        _stream(tmp_path, t)
    # steps alternating 0.5 / 1.5 s (the median hides it): refused at opening, as scattered steps
    t = np.cumsum(np.r_[0.0, np.tile([0.5, 1.5], 100)])
    with pytest.raises(DataFormatError, match=r"scatter by 50 %"):
        _stream(tmp_path, t)
    # steps 0.9 / 1.1 s: each within the step limits, but they scatter by 10 % (median absolute deviation)
    t = np.cumsum(np.r_[0.0, np.tile([0.9, 1.1], 100)])
    with pytest.raises(DataFormatError, match=r"scatter by 10 %"):
        _stream(tmp_path, t)
    # 300 steps of 1 s then 199 of 1.4 s: median 1, no scatter (most steps are exact), no gap (1.4 < 1.5), but the
    # span 300 + 199 x 1.4 = 578.6 s against (500 - 1) x 1 = 499 s: refused at opening (the last stamp is read first)
    t = np.cumsum(np.r_[0.0, np.ones(300), np.full(199, 1.4)])
    with pytest.raises(DataFormatError, match=r"spans 578.6 s, but its 500 samples at 1 s span 499 s"):
        _stream(tmp_path, t)
    # blocks at 1.25 s and 0.8 s steps between 1-s stretches, balanced to the same span: every step passes, the span
    # matches, but the stamps run off the straight line from the first to the last: refused in the stream where they
    # first pass the limit (20 intervals: 300 + 81 x 1.25 against 381)
    t = np.cumsum(np.r_[0.0, np.tile(np.r_[np.ones(300), np.full(100, 1.25), np.ones(300), np.full(125, 0.8)], 4)])
    with pytest.raises(DataFormatError, match=r"time stamps run 20.25 s \(20.2 sample intervals\) ahead of a uniform "
                                              r"grid at sample 381"):
        _stream(tmp_path, t)
    # a rate given that disagrees with the time column by more than 1 %
    with pytest.raises(DataFormatError, match="disagrees with the given sample interval"):
        _stream(tmp_path, np.arange(100.0), rate_hz=1.05)


def test_a_non_unit_configuration_error_is_not_turned_into_the_unit_refusal(bundle, tmp_path):
    # a .npy without a time column and without --rate: the interval is what is missing, not the unit
    np.save(tmp_path / "r.npy", np.full(100, 45.0))
    with pytest.raises(ConfigError) as info:
        compensate_file(bundle, tmp_path / "r.npy", tmp_path / "o", **_kw(unit="deg/h", axis_map="col0=gz"))
    assert "cannot tell the sample interval" in str(info.value)
    with pytest.raises(ConfigError) as info:  # both missing: the unit is asked for first, suggesting the bundle's
        compensate_file(bundle, tmp_path / "r.npy", tmp_path / "o", **_kw(axis_map="col0=gz"))
    assert "pass unit= deg/h (the bundle was trained on deg/h)" in str(info.value)


def test_a_constant_log_gets_its_figure_without_a_warning(bundle, tmp_path):
    import warnings

    log = _csv(tmp_path / "c.csv", "t_s,gz[deg/h]", np.full(300, 45.0))  # ADEV 0 at every tau
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # matplotlib's "no positive values ... log-scaled" would be one
        res = compensate_file(bundle, log, tmp_path / "o", heading=False, artefacts=False, model="bias")
    assert (tmp_path / "o" / "compensation_allan.png").stat().st_size > 5_000 and "figure" in res.files


def test_bad_chunk_is_refused_before_anything_is_touched(bundle, tmp_path):
    from fogdrift.cli import app

    log = _csv(tmp_path / "r.csv", "t_s,gz[deg/h]", 45.0 + np.sin(np.arange(300) * 0.9))
    base = ["compensate", str(bundle), str(log), "--model", "bias", "--no-heading", "--no-artefacts", "--out",
            str(tmp_path / "o")]
    assert CliRunner().invoke(app, base).exit_code == 0
    before = sorted(p.name for p in (tmp_path / "o").iterdir())
    r = CliRunner().invoke(app, base + ["--chunk", "0"])
    assert r.exit_code == 1 and "Traceback" not in r.output
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert lines == ["error: --chunk must be an integer >= 1 (rows read at a time); got 0"]
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == before  # the earlier run's files are still there
