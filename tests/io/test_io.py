"""Tests of fogdrift.io: formats, units, located errors, gaps, memory mapping, GyroRecord.

Independent checks used: the bundled recording's README (sample count, rate, per-axis means,
SHA-256), unit factors derived by hand (1 deg/s = 3600 deg/h, 0.1 arcsec per 10 ms = 10 deg/h),
NumPy reshape-means for block averages, and exact error strings written out in full.
"""

from __future__ import annotations

import gzip
import json
import math
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.errors import ConfigError, DataFormatError, FogdriftWarning, InsufficientDataError
from fogdrift.io import GyroRecord, block_average, file_sha256, from_array
from fogdrift.io import load as io_load
from fogdrift.io import load_segments as io_load_segments

DATA = Path(__file__).resolve().parents[2] / "data" / "psins_lasergyro_rlg" / "psins_lasergyro_rlg.csv.gz"


def load(path, **kw):
    """:func:`fogdrift.io.load` in deg/h and s unless the test gives units (a unit is never guessed; these
    tests are about formats, time, errors and records; tests/io/test_io_units.py tests the unit rules)."""
    kw.setdefault("unit", "deg/h")
    kw.setdefault("time_unit", "s")
    return io_load(path, **kw)


def load_segments(path, **kw):
    kw.setdefault("unit", "deg/h")
    kw.setdefault("time_unit", "s")
    return io_load_segments(path, **kw)


def write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def csv_table(t, cols, names=("t_s", "gx", "gy", "gz"), sep=","):
    lines = [sep.join(names)]
    for i in range(len(t)):
        lines.append(sep.join([repr(float(t[i]))] + [repr(float(c[i])) for c in cols]))
    return "\n".join(lines) + "\n"


@pytest.fixture
def rng():
    return np.random.default_rng(20240611)


@pytest.fixture
def small_csv(tmp_path, rng):
    n = 50
    t = np.arange(n) * 0.01
    cols = rng.normal(size=(3, n)) * 10.0
    return write(tmp_path, "g.csv", csv_table(t, cols)), t, cols


# ------------------------------------------------------------------------------------------
# The bundled real recording (values from data/psins_lasergyro_rlg/README.md)
# ------------------------------------------------------------------------------------------
def test_bundled_recording_matches_readme():
    rec = load(DATA)
    assert rec.n_samples == 184_718
    assert rec.n_axes == 3
    assert rec.axis_names == ("gx", "gy", "gz")
    assert rec.dt_s == pytest.approx(0.01, rel=1e-12)
    assert rec.fs_hz == pytest.approx(100.0, rel=1e-12)
    assert rec.t0_s == 0.0
    assert rec.duration_s == pytest.approx(1847.18, rel=1e-9)
    assert_allclose(rec.rate_dph.mean(axis=0), [-12.2715, 0.437694, 8.3569], atol=1e-4)
    # every value is a multiple of 10 deg/h (0.1 arcsec per 10 ms quantum; stored as counts*0.1/0.01)
    q = rec.rate_dph / 10.0
    assert_allclose(q, np.round(q), rtol=0, atol=1e-9)
    assert rec.input_unit == "deg/h" and rec.scale_to_dph == 1.0


def test_bundled_sha256_matches_readme():
    assert file_sha256(DATA) == "039800de6c285c4359a60090d7d4fa0d09aaea42949eee4b5adcf37a3e484734"


def test_bundled_block_average_to_1s():
    rec = load(DATA, columns="gz")
    avg = rec.block_average(1.0)
    assert avg.n_samples == 1847 and avg.dt_s == pytest.approx(1.0, rel=1e-12)
    expected = rec.rate_dph[: 1847 * 100, 0].reshape(1847, 100).mean(axis=1)
    assert_allclose(avg.rate_dph[:, 0], expected, rtol=1e-12)
    assert "block-averaged x100" in avg.notes[-1] and "dropped 18 trailing samples" in avg.notes[-1]


# ------------------------------------------------------------------------------------------
# Text formats
# ------------------------------------------------------------------------------------------
def test_csv_with_time_column(small_csv):
    p, t, cols = small_csv
    rec = load(p)
    assert rec.axis_names == ("gx", "gy", "gz")
    assert_array_equal(rec.rate_dph, np.column_stack(cols))
    assert rec.dt_s == pytest.approx(0.01, rel=1e-12)
    assert rec.source == str(p)
    assert not rec.rate_dph.flags.writeable


def test_headerless_whitespace_file(tmp_path):
    p = write(tmp_path, "w.txt", "  1.5   -2.0\t 3\n4   5.25  6e-1\n\n7 8 9\n")
    rec = load(p, dt_s=0.5)
    assert rec.axis_names == ("col0", "col1", "col2")
    assert_array_equal(rec.rate_dph, [[1.5, -2.0, 3.0], [4.0, 5.25, 0.6], [7.0, 8.0, 9.0]])
    assert rec.dt_s == 0.5 and rec.t0_s == 0.0


def test_tab_file_with_header_names_containing_spaces(tmp_path):
    p = write(tmp_path, "g.tsv", "time\tgyro x\tgyro y\n10.0\t1\t2\n10.1\t3\t4\n10.2\t5\t6\n")
    rec = load(p, columns="gyro y")
    assert rec.axis_names == ("gyro y",)
    assert_array_equal(rec.rate_dph[:, 0], [2.0, 4.0, 6.0])
    assert rec.t0_s == 10.0 and rec.dt_s == pytest.approx(0.1, rel=1e-12)


@pytest.mark.parametrize("sep", [",", ";", "\t", " "])
def test_delimiters_round_trip(tmp_path, rng, sep):
    t = np.arange(20) * 0.002
    cols = rng.normal(size=(2, 20))
    p = write(tmp_path, "d.txt", csv_table(t, cols, names=("t", "a", "b"), sep=sep))
    auto = load(p)
    explicit = load(p, delimiter=sep)
    assert_array_equal(auto.rate_dph, np.column_stack(cols))
    assert_array_equal(explicit.rate_dph, auto.rate_dph)
    assert auto.fs_hz == pytest.approx(500.0, rel=1e-9)


def test_layout_detection(tmp_path):
    # whitespace data containing a tab is still whitespace-separated
    rec = load(write(tmp_path, "a.txt", "1 2\t3\n4 5\t6\n"), dt_s=1.0)
    assert_array_equal(rec.rate_dph, [[1, 2, 3], [4, 5, 6]])
    # a purely numeric first line is data, not a header
    rec = load(write(tmp_path, "b.csv", "1,2\n3,4\n"), dt_s=1.0)
    assert rec.n_samples == 2 and rec.axis_names == ("col0", "col1")
    # header with spaces in names, whitespace-free numbers: semicolon chosen from the data line
    rec = load(write(tmp_path, "c.txt", "time s;rate x\n0;1\n1;2\n"), time_column="time s")
    assert rec.axis_names == ("rate x",) and rec.dt_s == 1.0


def test_comments_and_gzip(tmp_path):
    text = "% PSINS-like preamble\n# another\nt,x\n0,1\n% interleaved\n0.1,2 # inline\n\n0.2,3\n"
    p = tmp_path / "c.csv.gz"
    with gzip.open(p, "wt") as fh:
        fh.write(text)
    rec = load(p)
    assert_array_equal(rec.rate_dph[:, 0], [1.0, 2.0, 3.0])
    assert rec.dt_s == pytest.approx(0.1)
    assert rec.notes[0].startswith("gzip text")


def test_non_numeric_in_unused_column_is_ignored(tmp_path):
    p = write(tmp_path, "s.csv", "t,x,status\n0,1,OK\n1,2,OK\n2,3,FAIL\n")
    rec = load(p, columns="x")
    assert_array_equal(rec.rate_dph[:, 0], [1.0, 2.0, 3.0])


def test_column_selection_by_name_and_index(small_csv):
    p, _, cols = small_csv
    by_name = load(p, columns="gx,gz")
    by_index = load(p, columns=[1, 3])
    by_digits = load(p, columns="1,3")
    assert by_name.axis_names == by_index.axis_names == by_digits.axis_names == ("gx", "gz")
    for rec in (by_name, by_index, by_digits):
        assert_array_equal(rec.rate_dph, np.column_stack([cols[0], cols[2]]))
    reordered = load(p, columns=["GZ", -3])  # case-insensitive name, negative index
    assert reordered.axis_names == ("gz", "gx")
    assert_array_equal(reordered.rate_dph, np.column_stack([cols[2], cols[0]]))


def test_time_column_explicit_and_none(tmp_path):
    p = write(tmp_path, "h.txt", "5.0 1\n5.5 2\n6.0 3\n")
    rec = load(p, time_column=0)
    assert rec.axis_names == ("col1",) and rec.dt_s == 0.5 and rec.t0_s == 5.0
    rec2 = load(p, time_column=None, rate_hz=4.0)
    assert rec2.n_axes == 2 and rec2.dt_s == 0.25


# ------------------------------------------------------------------------------------------
# Units
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "unit, to_input",
    [
        ("deg/s", lambda dph: dph / 3600.0),
        ("rad/s", lambda dph: dph / 3600.0 * math.pi / 180.0),
        ("rad/h", lambda dph: dph * math.pi / 180.0),
        ("arcsec/s", lambda dph: dph),
        ("inc:deg", lambda dph: dph / 3600.0 * 0.01),  # deg per 10 ms sample
        ("inc:rad", lambda dph: dph / 3600.0 * 0.01 * math.pi / 180.0),
        ("inc:arcsec", lambda dph: dph * 0.01),  # arcsec per 10 ms
    ],
)
def test_unit_round_trip(tmp_path, rng, unit, to_input):
    rate_dph = rng.normal(size=(40, 2)) * 20.0
    t = np.arange(40) * 0.01
    p = write(tmp_path, "u.csv", csv_table(t, to_input(rate_dph).T, names=("t", "a", "b")))
    rec = load(p, unit=unit)
    assert_allclose(rec.rate_dph, rate_dph, rtol=1e-12)
    assert rec.input_unit == unit
    arr = from_array(to_input(rate_dph), dt_s=0.01, unit=unit)
    assert_allclose(arr.rate_dph, rate_dph, rtol=1e-12)


def test_increment_arcsec_quantum_is_10_dph(tmp_path):
    p = write(tmp_path, "i.txt", "0.1\n0.1\n0.2\n")
    rec = load(p, dt_s=0.01, unit="inc:arcsec")
    assert_allclose(rec.rate_dph[:, 0], [10.0, 10.0, 20.0], rtol=1e-14)
    assert rec.scale_to_dph == pytest.approx(100.0)


def test_unknown_unit_lists_valid_ones(small_csv):
    with pytest.raises(ConfigError, match=r"unknown unit 'deg/min'.*deg/s.*inc:arcsec"):
        load(small_csv[0], unit="deg/min")
    with pytest.raises(ConfigError, match="inc:rad"):
        from_array([1.0, 2.0], dt_s=1.0, unit="inc:grad")


# ------------------------------------------------------------------------------------------
# Located errors in text files
# ------------------------------------------------------------------------------------------
def test_missing_file(tmp_path):
    p = tmp_path / "nope.csv"
    with pytest.raises(DataFormatError) as ei:
        load(p, dt_s=1.0)
    assert str(ei.value) == f"{p}: file not found; expected an existing file, got no such path"
    with pytest.raises(DataFormatError, match="file not found"):
        file_sha256(p)


def test_empty_file_and_comments_only(tmp_path):
    with pytest.raises(DataFormatError, match="empty file.*got 0 bytes"):
        load(write(tmp_path, "e.csv", ""), dt_s=1.0)
    with pytest.raises(DataFormatError, match="empty file.*only blank or comment lines"):
        load(write(tmp_path, "c.csv", "# nothing\n\n% here\n"), dt_s=1.0)


def test_header_only(tmp_path):
    p = write(tmp_path, "h.csv", "# comment\nt_s,gx\n")
    with pytest.raises(DataFormatError) as ei:
        load(p)
    assert str(ei.value) == (
        f"{p}: no data rows after the header on line 2; expected at least one numeric row, got only the header"
    )


def test_non_numeric_cell_is_located(tmp_path):
    p = write(tmp_path, "n.csv", "t_s,gx,gy\n0,1,2\n# note\n0.1,3,abc\n0.2,5,6\n")
    with pytest.raises(DataFormatError) as ei:
        load(p)
    e = ei.value
    assert (e.line, e.column) == (4, "gy")
    assert str(e) == f"{p}:4:gy: non-numeric value; expected a number, got 'abc'"


def test_non_numeric_cell_headerless_gives_field_number(tmp_path):
    p = write(tmp_path, "n.txt", "1 2\n3 x4\n")
    with pytest.raises(DataFormatError) as ei:
        load(p, dt_s=1.0)
    assert str(ei.value) == f"{p}:2:2: non-numeric value; expected a number, got 'x4'"


@pytest.mark.parametrize("bad", ["nan", "inf", "-Infinity"])
def test_nan_or_inf_is_located(tmp_path, bad):
    p = write(tmp_path, "f.csv", f"t,x,y\n% c\n0,1,2\n1,3,{bad}\n")
    with pytest.raises(DataFormatError) as ei:
        load(p)
    assert (ei.value.line, ei.value.column) == (4, "y")
    assert "non-finite value; expected a finite number, got" in str(ei.value)


def test_ragged_rows(tmp_path):
    p = write(tmp_path, "r.csv", "t,x,y\n0,1,2\n1,3\n")
    with pytest.raises(DataFormatError) as ei:
        load(p)
    assert str(ei.value) == (
        f"{p}:3:y: wrong number of fields (comma-separated); expected 3 fields as in the header on line 1, got 2"
    )
    p2 = write(tmp_path, "r2.txt", "0 1\n1 2\n2 3 4\n")
    with pytest.raises(DataFormatError, match=r"r2\.txt:3:3: wrong number of fields.*expected 2 fields.*got 3"):
        load(p2, dt_s=1.0)


def test_unsorted_time(tmp_path):
    p = write(tmp_path, "u.csv", "t,x\n0,1\n0.1,2\n0.05,3\n0.2,4\n")
    with pytest.raises(DataFormatError) as ei:
        load(p)
    assert (ei.value.line, ei.value.column) == (4, "t")
    assert "time goes backwards; expected strictly increasing time, got 0.05 s after 0.1 s on line 3" in str(ei.value)


def test_duplicate_timestamp(tmp_path):
    p = write(tmp_path, "d.csv", "t,x\n0,1\n0.1,2\n0.1,3\n")
    with pytest.raises(DataFormatError) as ei:
        load(p)
    assert str(ei.value) == (
        f"{p}:4:t: duplicate timestamp; expected strictly increasing time, got 0.1 s again (as on line 3)"
    )


def _gappy_csv(tmp_path):
    # 100 Hz, samples 0-9, gap after 9 (next at 0.15 s), samples until 0.24, gap, 0.50-0.59
    t = np.concatenate([np.arange(10) * 0.01, 0.15 + np.arange(10) * 0.01, 0.50 + np.arange(10) * 0.01])
    x = np.arange(30, dtype=float)
    return write(tmp_path, "gap.csv", csv_table(np.round(t, 6), [x], names=("t", "x"))), t, x


def test_gap_error_names_line_time_and_size(tmp_path):
    p, _, _ = _gappy_csv(tmp_path)
    with pytest.raises(DataFormatError) as ei:
        load(p)
    e = ei.value
    assert (e.line, e.column) == (12, "t")  # header + 10 rows, so sample 10 is on line 12
    msg = str(e)
    assert "gap in time of 0.06 s (6 sample intervals) between t=0.09 s and t=0.15 s" in msg
    assert "2 gap(s) in total" in msg
    assert msg.endswith("expected steps of at most 1.5 x 0.01 s, got 0.06 s")


def test_load_segments_splits_at_gaps(tmp_path):
    p, t, x = _gappy_csv(tmp_path)
    segs = load_segments(p)
    assert [s.n_samples for s in segs] == [10, 10, 10]
    assert [s.t0_s for s in segs] == pytest.approx([0.0, 0.15, 0.50])
    for k, s in enumerate(segs):
        assert_array_equal(s.rate_dph[:, 0], x[10 * k: 10 * k + 10])
        assert s.dt_s == pytest.approx(0.01)
    assert segs[0].notes[-1] == "segment 1 of 3: samples 0-9 (lines 2-11)"
    assert segs[1].notes[-1] == "segment 2 of 3: samples 10-19 (lines 12-21), after a gap of 0.06 s"
    with pytest.raises(InsufficientDataError, match="all 3 gap-free segments are shorter") as ei:
        load_segments(p, min_samples=11)
    assert (ei.value.needed, ei.value.got) == (11, 10)
    with pytest.raises(DataFormatError, match="gap in time"):
        load_segments(p, gaps="error")


def test_load_with_gaps_split_returns_longest_with_warning(tmp_path):
    t = np.concatenate([np.arange(5) * 0.1, 1.0 + np.arange(8) * 0.1])
    p = write(tmp_path, "g.csv", csv_table(np.round(t, 6), [np.arange(13.0)], names=("t", "x")))
    with pytest.warns(FogdriftWarning, match="2 gap-free segments; returning the longest"):
        rec = load(p, gaps="split")
    assert rec.n_samples == 8 and rec.t0_s == pytest.approx(1.0)
    assert_array_equal(rec.rate_dph[:, 0], np.arange(5.0, 13.0))
    with pytest.warns(FogdriftWarning, match=r"dropped 1 segment.*segment 1 \(samples 0-4 \(lines 2-6\), 5 samples\)"):
        segs = load_segments(p, min_samples=6)
    assert len(segs) == 1 and segs[0].notes[-1].startswith("segment 2 of 2: samples 5-12")


def test_unknown_column_name_and_index(small_csv):
    p = small_csv[0]
    with pytest.raises(DataFormatError) as ei:
        load(p, columns="gx,gq")
    assert str(ei.value).startswith(f"{p}:gq: unknown column 'gq'; expected one of ['t_s', 'gx', 'gy', 'gz']")
    with pytest.raises(DataFormatError, match=r"unknown column 7; expected .* index 0\.\.3"):
        load(p, columns=[7])
    with pytest.raises(DataFormatError, match="unknown column 'clock'"):
        load(p, time_column="clock")


def test_duplicate_header_name(tmp_path):
    p = write(tmp_path, "d.csv", "# c\nt,x,x\n0,1,2\n")
    with pytest.raises(DataFormatError) as ei:
        load(p)
    assert str(ei.value) == f"{p}:2:x: duplicate column name in header; expected unique names, got 'x' twice"


def test_column_conflicts(small_csv):
    p = small_csv[0]
    with pytest.raises(ConfigError, match="time column"):
        load(p, columns="t_s,gx")
    with pytest.raises(ConfigError, match="twice"):
        load(p, columns="gx,1")


def test_too_few_samples(tmp_path):
    p = write(tmp_path, "s.csv", "t,x\n0,1\n0.1,2\n0.2,3\n")
    with pytest.raises(InsufficientDataError) as ei:
        load(p, min_samples=5)
    assert (ei.value.needed, ei.value.got) == (5, 3)
    one = write(tmp_path, "one.csv", "t,x\n0,1\n")
    with pytest.raises(InsufficientDataError) as ei:
        load(one)
    assert (ei.value.needed, ei.value.got) == (2, 1)


@pytest.mark.parametrize("kw", [{"dt_s": 0}, {"dt_s": -0.01}, {"dt_s": float("nan")}, {"rate_hz": 0.0},
                                {"rate_hz": "fast"}])
def test_non_positive_interval(tmp_path, kw):
    p = write(tmp_path, "x.txt", "1\n2\n3\n")
    with pytest.raises(ConfigError, match="must be"):
        load(p, **kw)
    with pytest.raises(ConfigError, match="dt_s must be a finite number > 0"):
        from_array([1.0, 2.0], dt_s=0.0)


def test_missing_interval_names_both_options(tmp_path):
    p = write(tmp_path, "x.txt", "1\n2\n3\n")
    with pytest.raises(ConfigError) as ei:
        load(p)
    assert str(ei.value) == (
        f"{p}: cannot tell the sample interval: no time column (none named t / t_s / time / time_s / timestamp; "
        "name one with time_column=) and no sample rate given; pass the sample rate in Hz as rate_hz="
    )
    assert ei.value.render({"rate_hz": "--rate", "time_column": "--time-column"}).endswith(
        "name one with --time-column) and no sample rate given; pass the sample rate in Hz as --rate"
    )


def test_time_column_versus_rate_option(small_csv):
    p = small_csv[0]  # time step 0.01 s
    assert load(p, rate_hz=100.5).dt_s == pytest.approx(1 / 100.5)  # 0.5 % off: option wins
    with pytest.raises(DataFormatError) as ei:
        load(p, rate_hz=200.0)
    assert str(ei.value) == (
        f"{p}:t_s: time column disagrees with the given sample interval (omit rate_hz= to take it from the time "
        "column); expected a median step within 1 % of 0.005 s (200 Hz), got 0.01 s (100.0% off)"
    )
    with pytest.raises(ConfigError, match="disagree"):
        load(p, dt_s=0.01, rate_hz=50.0)


def test_bad_options(small_csv):
    p = small_csv[0]
    with pytest.raises(ConfigError, match="gaps"):
        load(p, gaps="ignore")
    with pytest.raises(ConfigError, match="delimiter"):
        load(p, delimiter="|")
    with pytest.raises(ConfigError, match="min_samples"):
        load(p, min_samples=0)
    with pytest.raises(TypeError, match="colums"):  # an explicit signature: Python names the typo
        load_segments(p, colums="gx")


# ------------------------------------------------------------------------------------------
# .npy / .npz
# ------------------------------------------------------------------------------------------
def test_npy_1d_and_2d(tmp_path, rng):
    x = rng.normal(size=200)
    np.save(tmp_path / "a.npy", x)
    rec = load(tmp_path / "a.npy", rate_hz=50.0)
    assert rec.axis_names == ("col0",) and rec.dt_s == 0.02
    assert_array_equal(rec.rate_dph[:, 0], x)
    tab = np.column_stack([np.arange(200) * 0.005 + 3.0, rng.normal(size=(200, 3))])
    np.save(tmp_path / "b.npy", tab)
    rec2 = load(tmp_path / "b.npy", time_column=0, columns=[1, 3], unit="deg/s")
    assert rec2.axis_names == ("col1", "col3") and rec2.t0_s == 3.0
    assert rec2.dt_s == pytest.approx(0.005)
    assert_allclose(rec2.rate_dph, tab[:, [1, 3]] * 3600.0, rtol=1e-15)


def test_npz_named_columns_and_single_2d(tmp_path, rng):
    gx, gy = rng.normal(size=(2, 30))
    np.savez(tmp_path / "n.npz", time=np.arange(30) * 0.1, gx=gx, gy=gy)
    rec = load(tmp_path / "n.npz")
    assert rec.axis_names == ("gx", "gy") and rec.dt_s == pytest.approx(0.1)
    assert_array_equal(rec.rate_dph, np.column_stack([gx, gy]))
    np.savez(tmp_path / "m.npz", data=np.column_stack([gx, gy]))
    rec2 = load(tmp_path / "m.npz", dt_s=1.0, columns="col1")
    assert_array_equal(rec2.rate_dph[:, 0], gy)
    np.savez(tmp_path / "bad.npz", gx=gx, gy=gy[:-1])
    with pytest.raises(DataFormatError, match="bad.npz:gy: array 'gy' has 29 samples; expected 30"):
        load(tmp_path / "bad.npz", dt_s=1.0)


def test_npy_nan_gives_sample_index(tmp_path):
    a = np.zeros((20000, 3))
    a[12345, 2] = np.nan
    p = tmp_path / "nan.npy"
    np.save(p, a)
    with pytest.raises(DataFormatError) as ei:
        load(p, dt_s=1.0)
    e = ei.value
    assert e.line is None and e.column == "col2"
    assert str(e) == f"{p}:col2: non-finite value at sample 12345; expected a finite number, got nan"


def test_npz_unsorted_time_gives_sample_index(tmp_path):
    t = np.arange(10.0)
    t[6] = 4.5
    np.savez(tmp_path / "t.npz", t=t, x=np.ones(10))
    with pytest.raises(DataFormatError, match=r"t\.npz:t: time goes backwards at sample 6; .* on sample 5"):
        load(tmp_path / "t.npz")


def test_npy_float64_dph_is_memory_mapped_without_copy(tmp_path, rng):
    n = 1_000_000
    x = rng.normal(size=n)
    p = tmp_path / "big.npy"
    np.save(p, x)
    del x
    tracemalloc.start()
    try:
        rec = load(p, rate_hz=100.0)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert rec.rate_dph.shape == (n, 1)
    assert peak < 1_000_000, f"peak traced memory {peak} B for an 8 MB file: data were copied"
    assert _backed_by_memmap(rec.rate_dph)
    assert not rec.rate_dph.flags.owndata and not rec.rate_dph.flags.writeable
    mm = np.load(p, mmap_mode="r")
    assert rec.rate_dph[123456, 0] == mm[123456]
    # other units necessarily copy
    conv = load(p, rate_hz=100.0, unit="deg/s")
    assert not _backed_by_memmap(conv.rate_dph)
    assert conv.rate_dph[123456, 0] == mm[123456] * 3600.0


def _backed_by_memmap(a) -> bool:
    while a is not None:
        if isinstance(a, np.memmap):
            return True
        a = getattr(a, "base", None)
    return False


def test_npy_float32_is_converted(tmp_path):
    np.save(tmp_path / "f.npy", np.array([1.5, 2.5, 3.5], dtype=np.float32))
    rec = load(tmp_path / "f.npy", dt_s=1.0)
    assert rec.rate_dph.dtype == np.float64
    assert_array_equal(rec.rate_dph[:, 0], [1.5, 2.5, 3.5])


def test_corrupt_or_unsupported_arrays(tmp_path):
    np.save(tmp_path / "s.npy", np.array(["a", "b"]))
    with pytest.raises(DataFormatError, match="dtype"):
        load(tmp_path / "s.npy", dt_s=1.0)
    np.save(tmp_path / "c.npy", np.zeros((2, 2, 2)))
    with pytest.raises(DataFormatError, match=r"shape \(2, 2, 2\)"):
        load(tmp_path / "c.npy", dt_s=1.0)
    (tmp_path / "z.npz").write_bytes(b"PK\x03\x04 not really a zip")
    with pytest.raises(DataFormatError, match="unreadable .npz"):
        load(tmp_path / "z.npz", dt_s=1.0)
    np.save(tmp_path / "e.npy", np.zeros(0))
    with pytest.raises(DataFormatError, match="no data"):
        load(tmp_path / "e.npy", dt_s=1.0)


# ------------------------------------------------------------------------------------------
# from_array and GyroRecord
# ------------------------------------------------------------------------------------------
def test_from_array_validation():
    x = np.ones((10, 2))
    x[7, 1] = np.inf
    with pytest.raises(DataFormatError) as ei:
        from_array(x, dt_s=0.1, axis_names=["a", "b"])
    assert str(ei.value) == "<array>:b: non-finite value at sample 7; expected a finite number, got inf"
    with pytest.raises(DataFormatError, match="sample 3"):
        from_array([0.0, 1.0, 2.0, float("nan")], dt_s=1.0)
    with pytest.raises(DataFormatError, match="shape"):
        from_array(np.zeros((2, 2, 2)), dt_s=1.0)
    with pytest.raises(DataFormatError, match="not numeric"):
        from_array(["a", "b"], dt_s=1.0)
    with pytest.raises(InsufficientDataError):
        from_array(np.zeros((0, 3)), dt_s=1.0)
    with pytest.raises(ConfigError, match="axis_names"):
        from_array(np.zeros((4, 2)), dt_s=1.0, axis_names=["a"])
    with pytest.raises(ConfigError, match="axis_names"):
        from_array(np.zeros((4, 2)), dt_s=1.0, axis_names=["a", "a"])


def test_from_array_does_not_copy_float64_dph():
    x = np.arange(12.0).reshape(6, 2)
    rec = from_array(x, dt_s=0.5, axis_names=("x", "y"))
    assert np.shares_memory(rec.rate_dph, x)
    assert x.flags.writeable and not rec.rate_dph.flags.writeable
    with pytest.raises(ValueError):
        rec.rate_dph[0, 0] = 1.0
    assert rec.source == "<array>" and rec.n_samples == 6 and rec.duration_s == 3.0


def test_record_axis_select_slice():
    x = np.arange(30.0).reshape(10, 3)
    rec = from_array(x, dt_s=0.1, axis_names=("gx", "gy", "gz"))
    assert_array_equal(rec.axis("gy"), x[:, 1])
    assert_array_equal(rec.axis(-1), x[:, 2])
    assert_array_equal(rec.axis("0"), x[:, 0])
    with pytest.raises(ConfigError, match=r"unknown axis 'gq'; expected one of \['gx', 'gy', 'gz'\]"):
        rec.axis("gq")
    with pytest.raises(ConfigError, match="unknown axis 3"):
        rec.axis(3)
    sub = rec.select(["gz", "gx"])
    assert sub.axis_names == ("gz", "gx")
    assert_array_equal(sub.rate_dph, x[:, [2, 0]])
    assert rec.select("gy,gz").axis_names == ("gy", "gz")
    with pytest.raises(ConfigError, match="twice"):
        rec.select("gx,0")
    s = rec.slice(3, 8)
    assert s.n_samples == 5 and s.t0_s == pytest.approx(0.3)
    assert_array_equal(s.rate_dph, x[3:8])
    assert s.notes[-1] == "slice: samples 3-7 of 10"
    assert rec.slice(-4, 10).t0_s == pytest.approx(0.6)
    for bad in [(5, 5), (0, 11), (8, 3)]:
        with pytest.raises(ConfigError, match="out of range"):
            rec.slice(*bad)


def test_record_block_average():
    x = np.arange(22.0).reshape(11, 2)
    rec = from_array(x, dt_s=0.01)
    avg = rec.block_average(0.03)
    assert avg.n_samples == 3 and avg.dt_s == pytest.approx(0.03, rel=1e-12)
    assert_array_equal(avg.rate_dph, x[:9].reshape(3, 3, 2).mean(axis=1))
    assert avg.notes[-1] == "block-averaged x3 (0.01 s -> 0.03 s), dropped 2 trailing samples"
    assert rec.block_average(0.01) is rec
    with pytest.raises(ConfigError, match=r"not an integer multiple.*expected e\.g\. 0\.02 s \(x2\) or 0\.03 s \(x3\)"):
        rec.block_average(0.025)
    with pytest.raises(ConfigError, match=r"0\.01 s \(x1\)"):
        rec.block_average(0.004)
    with pytest.raises(InsufficientDataError) as ei:
        rec.block_average(0.12)
    assert (ei.value.needed, ei.value.got) == (12, 11)


def test_block_average_function():
    assert_array_equal(block_average([1.0, 2.0, 3.0, 4.0, 5.0], 2), [1.5, 3.5])
    y = np.arange(12.0).reshape(6, 2)
    assert_array_equal(block_average(y, 3), [[2.0, 3.0], [8.0, 9.0]])
    with pytest.raises(ConfigError):
        block_average(y, 0)
    with pytest.raises(ConfigError):
        block_average(y, 2.0)
    with pytest.raises(InsufficientDataError):
        block_average(y, 7)


def test_metadata_is_json_serialisable(small_csv):
    rec = load(small_csv[0], unit="inc:arcsec")
    meta = rec.metadata()
    back = json.loads(json.dumps(meta))
    assert back["n_samples"] == 50 and back["n_axes"] == 3
    assert back["axis_names"] == ["gx", "gy", "gz"]
    ch = back["signal"]["channels"][0]
    assert ch["unit_as_read"] == "inc:arcsec" and ch["scale_to_internal"] == pytest.approx(100.0)
    assert back["signal"]["sampling"]["rate_hz"] == pytest.approx(100.0)
    assert ch["internal_unit"] == "deg/h"
    assert set(meta) >= {"source", "t0_s", "notes", "duration_s", "signal"}


def test_record_constructor_checks():
    with pytest.raises(ConfigError, match="shape"):
        GyroRecord(data_internal=np.zeros(5), dt_s=1.0, axis_names=("a",), source="<array>", input_unit="deg/h",
                   scale_to_internal=1.0)
    with pytest.raises(ConfigError, match="axis_names"):
        GyroRecord(data_internal=np.zeros((5, 2)), dt_s=1.0, axis_names=("a",), source="<array>", input_unit="deg/h",
                   scale_to_internal=1.0)
    with pytest.raises(ConfigError, match="dt_s"):
        GyroRecord(data_internal=np.zeros((5, 1)), dt_s=-1.0, axis_names=("a",), source="<array>", input_unit="deg/h",
                   scale_to_internal=1.0)
