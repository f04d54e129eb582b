"""Tests of fogdrift.io's reader layer: format selection, SHA-256 while reading, declared units,
time units, text variants (BOM, decimal comma, line endings) and a reader added from outside.

Independent checks: hashlib.sha256 over the file bytes (and the bundled README's SHA-256),
unit factors by hand (1 deg/s = 3600 deg/h; 10 ms steps = 0.01 s), numbers written by the test
itself, and exact error strings.
"""

from __future__ import annotations

import gzip
import hashlib
import json
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.io import from_array, load_segments, registry
from fogdrift.io import load as io_load
from fogdrift.io.readers.base import Table

DATA = Path(__file__).resolve().parents[2] / "data" / "psins_lasergyro_rlg" / "psins_lasergyro_rlg.csv.gz"
README_SHA256 = "039800de6c285c4359a60090d7d4fa0d09aaea42949eee4b5adcf37a3e484734"
CLI_FLAGS = {"unit": "--unit", "rate_hz": "--rate", "time_column": "--time-column", "columns": "--columns",
             "gaps": "--gaps", "time_unit": "--time-unit", "model_rate_hz": "--model-rate"}
LOAD_MODULE = sys.modules["fogdrift.io.load"]  # the attribute fogdrift.io.load is the function


@pytest.fixture
def rng():
    return np.random.default_rng(20240612)


def load(path, **kw):
    """:func:`fogdrift.io.load` in deg/h and s unless the test gives units (the unit tests call ``io_load``)."""
    kw.setdefault("unit", "deg/h")
    kw.setdefault("time_unit", "s")
    return io_load(path, **kw)


def sha(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


def write(tmp_path: Path, name: str, text: str, encoding="utf-8") -> Path:
    p = tmp_path / name
    p.write_bytes(text.encode(encoding))
    return p


@pytest.fixture
def no_second_read(monkeypatch):
    """Make the fallback whole-file hash fail: a load that passes hashed the bytes it parsed."""
    def fail(path):
        raise AssertionError(f"{path} was read a second time just for its hash")
    monkeypatch.setattr(LOAD_MODULE, "file_sha256", fail)


# ------------------------------------------------------------------------------------------
# SHA-256 recorded while reading
# ------------------------------------------------------------------------------------------
def test_bundled_gzip_sha256_recorded_while_reading(no_second_read):
    rec = load(DATA)
    assert rec.sha256 == README_SHA256  # the compressed file's bytes, as sha256sum prints
    assert rec.metadata()["sha256"] == README_SHA256
    assert json.loads(json.dumps(rec.metadata()))["sha256"] == README_SHA256


@pytest.mark.parametrize("text", [
    "t,x\n0,1\n0.1,2\n0.2,3\n",                  # numpy.loadtxt fast path
    "t,x,s\n0,1,OK\n0.1,2,OK\n0.2,3,FAIL\n",     # line-by-line path (non-numeric unused column)
    "% c\nt,x\n0,1\n% c\n0.1,2\n0.2,3\n",        # second loadtxt attempt (% comments)
    "t,x\n0,1\n",                                # tiny file, read to its end by the header probe
])
def test_text_sha256_without_second_read(tmp_path, no_second_read, text):
    p = write(tmp_path, "a.csv", text)
    rec = load(p, columns="x", dt_s=0.1, min_samples=1)
    assert rec.sha256 == sha(p)
    gz = tmp_path / "a.csv.gz"
    gz.write_bytes(gzip.compress(text.encode(), mtime=0))
    assert load(gz, columns="x", dt_s=0.1, min_samples=1).sha256 == sha(gz)


def test_array_sha256(tmp_path, no_second_read, rng):
    np.save(tmp_path / "a.npy", rng.normal(size=(50, 2)))
    np.savez(tmp_path / "b.npz", t=np.arange(50) * 0.1, x=rng.normal(size=50))
    assert load(tmp_path / "a.npy", dt_s=1.0).sha256 == sha(tmp_path / "a.npy")
    assert load(tmp_path / "b.npz").sha256 == sha(tmp_path / "b.npz")


def test_sha256_survives_segments_and_record_operations(tmp_path):
    t = np.r_[np.arange(5) * 0.1, 2.0 + np.arange(6) * 0.1]
    p = write(tmp_path, "g.csv", "t,x,y\n" + "".join(f"{v:.1f},{k},{-k}\n" for k, v in enumerate(t)))
    segs = load_segments(p, unit="deg/h", time_unit="s")
    assert [s.sha256 for s in segs] == [sha(p)] * 2
    r = segs[1]
    assert r.slice(1, 4).sha256 == r.select("y").sha256 == r.block_average(0.2).sha256 == sha(p)
    assert from_array([1.0, 2.0], dt_s=1.0).sha256 is None
    assert from_array([1.0, 2.0], dt_s=1.0).metadata()["sha256"] is None


# ------------------------------------------------------------------------------------------
# Format selection
# ------------------------------------------------------------------------------------------
def test_magic_bytes_beat_the_extension(tmp_path, rng):
    x = rng.normal(size=20)
    np.save(tmp_path / "x.npy", x)
    (tmp_path / "x.npy").rename(tmp_path / "looks_like.csv")
    rec = load(tmp_path / "looks_like.csv", dt_s=1.0)
    assert_array_equal(rec.rate_dph[:, 0], x)
    assert rec.notes[0].startswith("npy array")
    p = write(tmp_path, "text.npy", "1\n2\n")
    with pytest.raises(DataFormatError, match=r"text\.npy: unreadable \.npy file"):
        load(p, dt_s=1.0)


def test_text_without_extension_is_sniffed(tmp_path):
    rec = load(write(tmp_path, "gyro_log", "t x\n0 1\n0.5 2\n"))
    assert rec.dt_s == 0.5 and rec.notes[0].startswith("text, whitespace-separated")


def test_unknown_format_names_file_and_known_formats(tmp_path):
    p = tmp_path / "rec.bin"
    p.write_bytes(bytes(range(16)) * 4)
    with pytest.raises(DataFormatError) as ei:
        load(p, dt_s=1.0)
    msg = str(ei.value)
    assert msg.startswith(f"{p}: unknown file format; expected one of npy (NumPy .npy array: .npy); ")
    assert "npz (NumPy .npz archive: .npz)" in msg and "text (CSV/TXT text, optionally gzip: .csv, .txt" in msg
    assert msg.endswith("got first bytes 00 01 02 03 04 05 06 07")
    assert ei.value.path == str(p)


def test_directory_is_not_a_file(tmp_path):
    with pytest.raises(DataFormatError, match="not a regular file; expected a data file or a directory in a known"):
        load(tmp_path, dt_s=1.0)


def test_format_and_reader_options(tmp_path):
    p = write(tmp_path, "odd.bin", "a;b\n1;2\n3;4\n")
    assert load(p, dt_s=1.0, format="text").n_samples == 2
    rec = load(p, dt_s=1.0, reader_options={"delimiter": ";"})
    assert rec.axis_names == ("a", "b")
    with pytest.raises(ConfigError, match=r"unknown format 'xls'; expected one of \['npy', 'npz', 'hdf5', 'mat', "
                                          r"'rosbag1', 'rosbag2', 'mseed', 'binary', 'text'\]"):
        load(p, dt_s=1.0, format="xls")
    with pytest.raises(ConfigError, match=r"unknown reader option\(s\) \['dataset'\] for text files"):
        load(p, dt_s=1.0, reader_options={"dataset": "/imu"})
    with pytest.raises(ConfigError, match="delimiter given twice"):
        load(p, dt_s=1.0, delimiter=";", reader_options={"delimiter": ";"})
    with pytest.raises(ConfigError, match="reader_options must be a mapping"):
        load(p, dt_s=1.0, reader_options=["delimiter"])


# ------------------------------------------------------------------------------------------
# A reader added from outside: one module + one registry line
# ------------------------------------------------------------------------------------------
def _gyrobin_module():
    """A toy binary format: b"GYRO", uint32 n, then n float64 times [s] and n x 2 float64 rates [deg/s]."""
    mod = types.ModuleType("fogdrift_tests.gyrobin")

    class GyrobinTable(Table):
        format = "gyrobin"
        row_kind = "record"

    def open_table(path, *, scale=1.0):
        raw = Path(path).read_bytes()
        n = int(np.frombuffer(raw, dtype="<u4", count=1, offset=4)[0])
        body = np.frombuffer(raw, dtype="<f8", offset=8).reshape(3, n)
        return GyrobinTable(path, names=["wx", "wy"], units=["deg/s", "deg/s"], data=body[1:].T * scale,
                            time_s=body[0], sha256=hashlib.sha256(raw).hexdigest())

    mod.open_table = open_table
    return mod


@pytest.fixture
def gyrobin(monkeypatch):
    monkeypatch.setitem(sys.modules, "fogdrift_tests.gyrobin", _gyrobin_module())
    spec = registry.ReaderSpec("gyrobin", "fogdrift_tests.gyrobin", magic=(b"GYRO",), extensions=(".gyb",),
                               options=("scale",), description="toy gyro records")
    monkeypatch.setattr(registry, "READERS", registry.READERS + (spec,))

    def make(path, t, rates):
        path.write_bytes(b"GYRO" + np.uint32(len(t)).tobytes() + np.concatenate([t, *np.asarray(rates)]).astype("<f8")
                         .tobytes())
        return path
    return make


def test_plugged_in_reader_gets_time_units_and_locations(tmp_path, gyrobin, rng):
    t = 100.0 + np.arange(40) * 0.005
    w = rng.normal(size=(2, 40))
    p = gyrobin(tmp_path / "a.raw", t, w)  # selected by its magic bytes
    rec = io_load(p)
    assert rec.axis_names == ("wx", "wy") and rec.t0_s == 100.0
    assert rec.dt_s == pytest.approx(0.005, rel=1e-12)
    assert_allclose(rec.rate_dph, w.T * 3600.0, rtol=1e-15)  # declared deg/s
    assert rec.input_unit == "deg/s" and rec.declared_units == ("deg/s", "deg/s")
    assert rec.sha256 == sha(p)
    assert rec.notes[0] == "gyrobin array, 40 records x 2 columns"
    assert_allclose(io_load(p, reader_options={"scale": 2.0}).rate_dph, w.T * 7200.0, rtol=1e-15)
    assert io_load(p, time_column=None, rate_hz=10.0).dt_s == 0.1
    t_bad = t.copy()
    t_bad[7] = t_bad[5]
    with pytest.raises(DataFormatError) as ei:
        io_load(gyrobin(tmp_path / "b.gyb", t_bad, w))
    assert str(ei.value) == (f"{tmp_path / 'b.gyb'}: time goes backwards at record 7; expected strictly increasing "
                             f"time, got {float(t[5])!r} s after {float(t[6])!r} s on record 6")
    w_bad = w.copy()
    w_bad[1, 12] = np.inf
    with pytest.raises(DataFormatError, match=r"b\.gyb:wy: non-finite value at record 12; expected a finite number"):
        io_load(gyrobin(tmp_path / "b.gyb", t, w_bad))


# ------------------------------------------------------------------------------------------
# Units declared in the header; time units
# ------------------------------------------------------------------------------------------
def test_declared_rate_unit_used_when_none_given(tmp_path):
    p = write(tmp_path, "u.csv", "t_s,gx[deg/s],gy [deg/s]\n0,0.001,-0.5\n0.01,0.002,0.25\n0.02,0.003,1\n")
    rec = io_load(p)
    assert rec.axis_names == ("gx", "gy") and rec.input_unit == "deg/s"
    assert_allclose(rec.rate_dph, [[3.6, -1800.0], [7.2, 900.0], [10.8, 3600.0]], rtol=1e-14)
    assert rec.declared_units == ("deg/s", "deg/s")
    assert [c["declared_unit"] for c in rec.metadata()["signal"]["channels"]] == ["deg/s", "deg/s"]
    assert "unit 'deg/s' declared in the file" in rec.notes
    # a given unit wins (no behaviour change), and the record says so
    given = io_load(p, unit="deg/h")
    assert_array_equal(given.rate_dph, [[0.001, -0.5], [0.002, 0.25], [0.003, 1.0]])
    assert "the file declares {'gx': 'deg/s', 'gy': 'deg/s'}; unit 'deg/h' given takes precedence" in given.notes
    # columns can be named with or without the unit
    assert io_load(p, columns="gy[deg/s]").axis_names == io_load(p, columns="GY").axis_names == ("gy",)


def test_declared_increment_unit_uses_the_interval(tmp_path):
    p = write(tmp_path, "i.csv", "t_s,dtheta[inc:arcsec]\n0,0.1\n0.01,0.2\n")
    rec = io_load(p)
    assert_allclose(rec.rate_dph[:, 0], [10.0, 20.0], rtol=1e-14)  # 0.1 arcsec per 10 ms = 10 deg/h


def test_mixed_or_unknown_declared_units(tmp_path):
    p = write(tmp_path, "m.csv", "# units\nt,gx[deg/s],gy[rad/s],temp[degC]\n0,1,2,20\n1,1,2,21\n")
    with pytest.raises(DataFormatError) as ei:
        io_load(p, columns="gx,gy")
    assert str(ei.value) == (
        f"{p}:2:gy: rate columns declare different units; expected one unit for all rate columns (choose them "
        "with columns= or pass unit=), got {'gx': 'deg/s', 'gy': 'rad/s'}"
    )
    assert "(choose them with --columns or pass --unit)" in ei.value.render(CLI_FLAGS)
    with pytest.raises(DataFormatError) as ei:
        io_load(p, columns="temp")
    assert str(ei.value) == (
        f"{p}:2:temp: unknown unit 'degC' declared in the header; expected one of ['deg/h', 'deg/s', 'rad/s', "
        "'rad/h', 'arcsec/s', 'inc:deg', 'inc:rad', 'inc:arcsec'] (or pass unit=), got 'degC'"
    )
    assert io_load(p, columns="temp", unit="deg/h", time_unit="s").n_samples == 2  # a given unit needs no declared one
    assert_allclose(io_load(p, columns="gy", time_unit="s").rate_dph[:, 0], 2 * 180 / np.pi * 3600, rtol=1e-14)
    # a column without a declared unit next to one with a unit is ambiguous too
    q = write(tmp_path, "n.csv", "t,gx[deg/s],gy\n0,1,2\n1,1,2\n")
    with pytest.raises(DataFormatError, match=r"n\.csv:1:gy: rate columns declare different units"):
        io_load(q)


@pytest.mark.parametrize("unit, factor", [("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)])
def test_declared_and_given_time_units(tmp_path, unit, factor):
    steps = np.arange(4) * 10.0  # 10 time units per sample
    body = "".join(f"{v:g},{k}\n" for k, v in enumerate(steps + 5.0))
    declared = io_load(write(tmp_path, "d.csv", f"t[{unit}],x\n" + body), unit="deg/h")
    given = io_load(write(tmp_path, "g.csv", "t,x[deg/h]\n" + body), time_unit=unit)
    for rec in (declared, given):
        assert rec.dt_s == pytest.approx(10 * factor, rel=1e-12) and rec.t0_s == pytest.approx(5 * factor, rel=1e-12)
        assert f"time column 't' in {unit}" in rec.notes
    over = io_load(write(tmp_path, "o.csv", f"t[{unit}],x\n" + body), time_unit="s", unit="deg/h")
    assert over.dt_s == 10.0
    assert f"the file declares time unit '{unit}'; time_unit 's' given takes precedence" in over.notes


def test_time_unit_errors(tmp_path):
    p = write(tmp_path, "t.csv", "t[min],x[deg/h]\n0,1\n1,2\n")
    with pytest.raises(DataFormatError) as ei:
        io_load(p)
    assert str(ei.value) == (f"{p}:1:t: unknown time unit 'min' declared in the header; expected one of "
                             "['s', 'ms', 'us', 'ns'] (or pass time_unit=), got 'min'")
    assert io_load(p, time_unit="s").dt_s == 1.0
    with pytest.raises(ConfigError, match=r"unknown time unit 'h'; expected one of \['s', 'ms', 'us', 'ns'\]"):
        io_load(p, time_unit="h")


# ------------------------------------------------------------------------------------------
# Text variants
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("gz", [False, True])
def test_utf8_bom_header(tmp_path, gz):
    raw = "\ufefft_s,gx\n0,1\n0.01,2\n".encode()
    p = tmp_path / ("b.csv.gz" if gz else "b.csv")
    p.write_bytes(gzip.compress(raw) if gz else raw)
    rec = load(p)
    assert rec.axis_names == ("gx",) and rec.dt_s == 0.01
    assert_array_equal(rec.rate_dph[:, 0], [1.0, 2.0])


@pytest.mark.parametrize("sep, name", [(";", "semicolon"), ("\t", "tab"), (" ", "whitespace")])
@pytest.mark.parametrize("header", [True, False])
def test_decimal_comma(tmp_path, sep, name, header):
    rows = [["0,00", "1,5", "-2,25e-1"], ["0,01", "2", "3,125"], ["0,02", "-0,5", "4"]]
    text = ("t" + sep + "a" + sep + "b\n" if header else "") + "".join(sep.join(r) + "\n" for r in rows)
    p = write(tmp_path, "d.csv", text)
    rec = load(p, time_column=0)
    assert_array_equal(rec.rate_dph, [[1.5, -0.225], [2.0, 3.125], [-0.5, 4.0]])
    assert rec.dt_s == 0.01
    assert rec.notes[0].startswith(f"text, {name}-separated, decimal comma")
    if header:  # the line-by-line path too (a status column that is not numeric)
        q = write(tmp_path, "e.csv", "".join(ln + sep + "ok\n" for ln in text.splitlines()))
        assert_array_equal(load(q, time_column=0, columns=[1, 2]).rate_dph, rec.rate_dph)
    if sep == ";":
        assert_array_equal(load(p, time_column=0, delimiter=";").rate_dph, rec.rate_dph)


def test_decimal_comma_not_shown_in_first_row_is_a_located_error(tmp_path):
    p = write(tmp_path, "d.csv", "t;x\n0;1\n0,01;2,5\n")
    with pytest.raises(DataFormatError) as ei:
        load(p)
    e = ei.value
    assert (e.line, e.column) == (3, "t")
    assert "decimal comma" in str(e) and str(e).endswith("expected a number, got '0,01'")


def test_thousands_separators_are_refused_never_read_as_decimal_commas(tmp_path):
    """Tab-separated counts "1,137": beside a decimal point ("0.01") they are thousands separators, refused at the
    cell (read as 1.137 before); without any decimal point they could be either, refused at the first data row."""
    p = write(tmp_path, "c.tsv", "t_s\tgx\n0.00\t1,137\n0.01\t1,582\n0.02\t998\n")
    with pytest.raises(DataFormatError) as ei:
        load(p)
    assert (ei.value.line, ei.value.column) == (2, "gx") and "thousands separator" in str(ei.value)
    q = write(tmp_path, "d.tsv", "t\tgx\n0\t1,137\n1\t1,582\n")
    with pytest.raises(DataFormatError) as ei:
        load(q, time_column=0)
    assert ei.value.line == 2 and "'1,137'" in str(ei.value) and "(1137)" in str(ei.value) and "(1.137)" in str(ei.value)
    # a decimal comma that is no thousands group ("0,010" starts with 0, "1,5" has one decimal) stays a decimal comma
    r = write(tmp_path, "e.tsv", "t\tgx\n0,010\t1,137\n0,020\t1,5\n")
    assert_array_equal(load(r, time_column=0).rate_dph[:, 0], [1.137, 1.5])


@pytest.mark.parametrize("eol", ["\n", "\r\n", "\r", "mixed"])
def test_line_endings(tmp_path, eol):
    lines = ["# c", "t,x", "0,1", "0.5,2", "1,3"]
    if eol == "mixed":
        text = "".join(ln + e for ln, e in zip(lines, ["\r\n", "\n", "\r", "\r\n", "\n"]))
    else:
        text = eol.join(lines) + eol
    p = tmp_path / "e.csv"
    p.write_bytes(text.encode())
    rec = load(p)
    assert_array_equal(rec.rate_dph[:, 0], [1.0, 2.0, 3.0])
    assert rec.dt_s == 0.5
    q = tmp_path / "f.csv"
    q.write_bytes(text.replace("0.5,2", "0.5,abc").encode())
    with pytest.raises(DataFormatError) as ei:
        load(q)
    assert (ei.value.line, ei.value.column) == (4, "x")


# ------------------------------------------------------------------------------------------
# Messages for two audiences; overflow on conversion
# ------------------------------------------------------------------------------------------
def test_option_hints_render_for_the_cli(tmp_path):
    t = np.r_[np.arange(3) * 0.1, 1.0 + np.arange(3) * 0.1]
    p = write(tmp_path, "g.csv", "t,x\n" + "".join(f"{v:.1f},{k}\n" for k, v in enumerate(t)))
    with pytest.raises(DataFormatError) as ei:
        load(p)
    assert "(1 gap(s) in total; set gaps= to use the gap-free segments)" in str(ei.value)
    assert "(1 gap(s) in total; set --gaps to use the gap-free segments)" in ei.value.render(CLI_FLAGS)
    with pytest.raises(ConfigError) as ei:
        load(p, columns="t,x")
    assert ei.value.render(CLI_FLAGS).endswith("(to read it as rate data, pass --time-column none)")
    with pytest.raises(DataFormatError) as ei:
        load(p, columns="y")
    assert ei.value.render(CLI_FLAGS) == (f"{p}:y: unknown column 'y'; expected one of ['t', 'x'] or an index 0..1 "
                                          "in --columns, got 'y'")
    with pytest.raises(DataFormatError) as ei:
        load(p, time_column="clock")
    assert "in --time-column, got 'clock'" in ei.value.render(CLI_FLAGS)
    for exc in (ei.value,):
        assert "{opt:" not in str(exc)


def test_overflow_in_unit_conversion_is_located(tmp_path):
    p = write(tmp_path, "o.csv", "t,x\n0,1\n1,1e306\n")
    with pytest.raises(DataFormatError) as ei:
        load(p, unit="deg/s")
    assert (ei.value.line, ei.value.column) == (3, "x")
    assert "overflows in deg/h" in str(ei.value) and str(ei.value).endswith("got 1e+306 deg/s")
    with pytest.raises(DataFormatError, match=r"<array>:axis0: value at sample 1 overflows in deg/h"):
        from_array([1.0, 1e306], dt_s=1.0, unit="deg/s")
