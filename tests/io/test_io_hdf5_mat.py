"""HDF5 and MATLAB readers: files written by h5py and scipy.io (and a v7.3 file laid out by h5py as MATLAB
writes it), values against the writer's, unit attributes, column choice, located errors, SHA-256.

Independent checks: the arrays the test wrote, hashlib over the file bytes, 1 deg/s = 3600 deg/h by hand.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.io import load

h5py = pytest.importorskip("h5py")
sio = pytest.importorskip("scipy.io")


@pytest.fixture
def rng():
    return np.random.default_rng(1313)


def sha(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


# ------------------------------------------------------------------------------------------
# HDF5
# ------------------------------------------------------------------------------------------
def test_hdf5_group_columns_units_and_temperature(tmp_path, rng):
    n = 500
    t = np.arange(n) * 0.01
    gyro = rng.normal(size=(n, 3))
    temp_k = 300.0 + 0.001 * np.arange(n)
    p = tmp_path / "log.h5"
    with h5py.File(p, "w") as f:
        g = f.create_group("imu")
        g.create_dataset("t", data=t).attrs["units"] = "s"
        d = g.create_dataset("gyro", data=gyro, compression="gzip")
        d.attrs["units"] = "deg/s"
        d.attrs["columns"] = ["gx", "gy", "gz"]
        g.create_dataset("temp", data=temp_k).attrs["unit"] = "K"
        g.create_dataset("calibration", data=np.eye(3))          # other length: left out
    rec = load(p, temperature="temp")
    assert rec.axis_names == ("gx", "gy", "gz")
    assert rec.dt_s == 0.01 and rec.input_unit == "deg/s"
    assert_allclose(rec.rate_dph, gyro * 3600.0, rtol=1e-15)
    assert_allclose(rec.temperature_c, temp_k - 273.15, rtol=0, atol=1e-12)
    assert rec.sha256 == sha(p)
    assert "left out /imu/calibration" in rec.notes[0]
    assert rec.metadata()["temperature"]["range_c"] == pytest.approx(0.499, abs=1e-9)
    # column selection as for CSV, and a given unit takes precedence over the attribute
    rec = load(p, reader_options={"dataset": "/imu"}, columns="gz", unit="deg/h", temperature="temp")
    assert_array_equal(rec.rate_dph[:, 0], gyro[:, 2])


def test_hdf5_contiguous_float64_is_memory_mapped(tmp_path, rng):
    x = rng.normal(size=(1000, 2))
    p = tmp_path / "a.hdf5"
    with h5py.File(p, "w") as f:
        f.create_dataset("data/rate", data=x)
    with pytest.raises(ConfigError, match=r"a\.hdf5: dataset /data/rate has no 'units' attribute.*unit=.*deg/s"):
        load(p, rate_hz=100.0)                  # units are never guessed
    rec = load(p, rate_hz=100.0, unit="deg/h")
    assert rec.axis_names == ("col0", "col1")
    assert_array_equal(rec.rate_dph, x)
    base = rec.rate_dph
    while base.base is not None and not isinstance(base, np.memmap):
        base = base.base
    assert isinstance(base, np.memmap)       # a view of the file, not a copy


def test_hdf5_external_link_reads_the_target_file_not_the_linking_one(tmp_path, rng):
    """A dataset behind an external link lives in another file: it was memory-mapped from the linking file at the
    target's offset (a record of the linking file's other bytes, exit 0); it is read through h5py."""
    x = 60.0 * rng.normal(size=(4000, 1))
    with h5py.File(tmp_path / "target.h5", "w") as f:
        f.create_dataset("pad", data=np.arange(3000.0))  # the target's offset differs from any in the linking file
        f.create_dataset("gyro", data=x).attrs["units"] = "deg/h"
    with h5py.File(tmp_path / "link.h5", "w") as f:
        f.create_dataset("other", data=np.full(8000, 1e4))
        f["gyro"] = h5py.ExternalLink("target.h5", "/gyro")
    rec = load(tmp_path / "link.h5", rate_hz=100.0, reader_options={"dataset": "gyro"})
    assert_array_equal(rec.rate_dph, x)


def test_hdf5_virtual_dataset_with_a_missing_source_is_refused(tmp_path, rng):
    """h5py reads the part of a virtual dataset whose source file is missing as its fill value (zeros)."""
    x = rng.normal(size=2000)
    with h5py.File(tmp_path / "part1.h5", "w") as f:
        f.create_dataset("a", data=x[:1000])
    layout = h5py.VirtualLayout(shape=(2000,), dtype="f8")
    layout[:1000] = h5py.VirtualSource("part1.h5", "a", shape=(1000,))
    layout[1000:] = h5py.VirtualSource("part2.h5", "a", shape=(1000,))
    with h5py.File(tmp_path / "v.h5", "w") as f:
        f.create_virtual_dataset("gz", layout, fillvalue=0.0).attrs["units"] = "deg/h"
    with pytest.raises(DataFormatError, match=r"v\.h5:/gz: virtual dataset /gz: its source file 'part2\.h5'"):
        load(tmp_path / "v.h5", rate_hz=100.0)
    with h5py.File(tmp_path / "part2.h5", "w") as f:  # every source present: read as written
        f.create_dataset("a", data=x[1000:])
    assert_array_equal(load(tmp_path / "v.h5", rate_hz=100.0).rate_dph[:, 0], x)


def test_hdf5_compound_dataset(tmp_path, rng):
    rows = np.zeros(200, dtype=[("time", "<f8"), ("wx", "<f4"), ("wz", ">f8")])
    rows["time"] = np.arange(200) * 0.5
    rows["wx"] = rng.normal(size=200)
    rows["wz"] = rng.normal(size=200)
    p = tmp_path / "c.h5"
    with h5py.File(p, "w") as f:
        f.create_dataset("records", data=rows).attrs["units"] = ["s", "rad/s", "rad/s"]
    rec = load(p)
    assert rec.axis_names == ("wx", "wz") and rec.dt_s == 0.5
    assert_allclose(rec.rate_dph[:, 1], rows["wz"] * 180 / np.pi * 3600, rtol=1e-15)


def test_hdf5_dataset_choice_errors_list_candidates(tmp_path):
    p = tmp_path / "two.h5"
    with h5py.File(p, "w") as f:
        f.create_dataset("a/x", data=np.arange(10.0))
        f.create_dataset("b/y", data=np.arange(10.0))
    with pytest.raises(DataFormatError, match=r"two\.h5: several datasets in several groups.*/a/x \(10,\).*dataset="):
        load(p, rate_hz=1.0)
    with pytest.raises(DataFormatError, match=r"two\.h5:/nope: no dataset or group '/nope'.*/b/y"):
        load(p, rate_hz=1.0, reader_options={"dataset": "/nope"})
    assert load(p, rate_hz=1.0, unit="deg/h", reader_options={"dataset": "b"}).axis_names == ("y",)


def test_hdf5_units_attribute_of_wrong_length_is_located(tmp_path):
    p = tmp_path / "u.h5"
    with h5py.File(p, "w") as f:
        f.create_dataset("g", data=np.ones((5, 3))).attrs["units"] = ["deg/s", "deg/s"]
    with pytest.raises(DataFormatError, match=r"u\.h5:/g: units attribute lists 2 units; expected 1 or one per column"):
        load(p, rate_hz=1.0)


def test_corrupt_hdf5_is_a_located_error(tmp_path, rng):
    p = tmp_path / "bad.h5"
    with h5py.File(p, "w") as f:
        f.create_dataset("g", data=rng.normal(size=(4000, 3)), chunks=(500, 3), compression="gzip")
    raw = bytearray(p.read_bytes())
    (tmp_path / "trunc.h5").write_bytes(bytes(raw[: len(raw) // 2]))
    with pytest.raises(DataFormatError, match=r"trunc\.h5: (unreadable|corrupt) HDF5 file|trunc\.h5: cannot read"):
        load(tmp_path / "trunc.h5", rate_hz=1.0)
    (tmp_path / "junk.h5").write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(200))
    with pytest.raises(DataFormatError, match=r"junk\.h5: unreadable HDF5 file; expected an HDF5 file, got OSError"):
        load(tmp_path / "junk.h5", rate_hz=1.0)


def test_missing_h5py_names_the_extra(tmp_path, monkeypatch):
    import fogdrift.io.readers.base as base

    p = tmp_path / "x.h5"
    with h5py.File(p, "w") as f:
        f.create_dataset("g", data=np.ones(4))
    real = base.importlib.import_module

    def fake(name, *a, **k):
        if name == "h5py":
            raise ImportError("No module named 'h5py'")
        return real(name, *a, **k)

    monkeypatch.setattr(base.importlib, "import_module", fake)
    with pytest.raises(base.MissingDependencyError, match=r"pip install 'fogdrift\[hdf5\]'"):
        load(p, rate_hz=1.0)


# ------------------------------------------------------------------------------------------
# MATLAB
# ------------------------------------------------------------------------------------------
def test_mat_v5_struct_matrix_and_vectors(tmp_path, rng):
    n = 300
    t = np.arange(n) * 0.02
    gx, gz = rng.normal(size=n), rng.normal(size=n)
    p = tmp_path / "s.mat"
    sio.savemat(p, {"imu": {"t": t, "gx": gx, "gz": gz, "temp": 25 + 0 * t}, "note": "static test"})
    with pytest.raises(ConfigError, match=r"s\.mat: time column 't' declares no unit; pass time_unit="):
        load(p, unit="deg/s", temperature="temp")
    rec = load(p, unit="deg/s", time_unit="s", temperature="temp")
    assert rec.axis_names == ("gx", "gz") and rec.dt_s == 0.02
    assert_allclose(rec.rate_dph, np.column_stack([gx, gz]) * 3600.0, rtol=1e-15)
    assert_array_equal(rec.temperature_c, 25.0)
    assert rec.sha256 == sha(p) and "MATLAB v5 file" in rec.notes

    m = rng.normal(size=(3, n))                      # channels in rows, as MATLAB users often store them
    sio.savemat(tmp_path / "m.mat", {"data": m, "fs": 50.0})
    with pytest.raises(ConfigError, match=r"m\.mat: MATLAB files carry no units; pass unit= \(deg/h, deg/s"):
        load(tmp_path / "m.mat", reader_options={"variable": "data"}, rate_hz=50.0)
    rec = load(tmp_path / "m.mat", reader_options={"variable": "data"}, rate_hz=50.0, unit="deg/h")
    assert rec.axis_names == ("col0", "col1", "col2")
    assert_array_equal(rec.rate_dph, m.T)
    assert any("read as 300 samples of 3 channels" in s for s in rec.notes)

    sio.savemat(tmp_path / "v.mat", {"t": t, "gy": gx})   # top-level vectors: named columns
    rec = load(tmp_path / "v.mat", unit="deg/h", time_unit="s")
    assert rec.axis_names == ("gy",) and rec.dt_s == 0.02


def test_mat_variable_errors(tmp_path, rng):
    p = tmp_path / "two.mat"
    sio.savemat(p, {"a": rng.normal(size=(10, 2)), "b": {"x": np.arange(10.0)}})
    with pytest.raises(DataFormatError, match=r"two\.mat: several variables.*a float64 \(10, 2\).*b \(struct: x\)"
                                              r".*variable="):
        load(p, rate_hz=1.0)
    with pytest.raises(DataFormatError, match=r"two\.mat:c: no variable 'c' in the file"):
        load(p, rate_hz=1.0, reader_options={"variable": "c"})
    assert load(p, rate_hz=1.0, unit="deg/h", reader_options={"variable": "b"}).axis_names == ("x",)


def _write_v73(path: Path, variables: dict):
    """A MATLAB v7.3 file as MATLAB writes it: a 512-byte user block with the MAT header, arrays transposed."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, value in variables.items():
            if isinstance(value, dict):
                g = f.create_group(name)
                g.attrs["MATLAB_class"] = np.bytes_("struct")
                for k, v in value.items():
                    d = g.create_dataset(k, data=np.atleast_2d(v).T.T if np.ndim(v) == 2 else np.atleast_2d(v))
                    d.attrs["MATLAB_class"] = np.bytes_("double")
            else:
                d = f.create_dataset(name, data=np.asarray(value).T)
                d.attrs["MATLAB_class"] = np.bytes_("double")
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
    with open(path, "r+b") as fh:
        fh.write(header.ljust(116, b" ") + bytes(8) + b"\x00\x02" + b"IM")


def test_mat_v73_through_h5py(tmp_path, rng):
    n = 400
    data = rng.normal(size=(n, 3))
    p = tmp_path / "big.mat"
    _write_v73(p, {"gyro": data, "imu": {"gx": data[:, 0], "t": np.arange(n) * 0.1}})
    rec = load(p, reader_options={"variable": "gyro"}, rate_hz=10.0, unit="deg/h")
    assert_array_equal(rec.rate_dph, data)
    assert "MATLAB v7.3 file" in rec.notes
    rec = load(p, reader_options={"variable": "imu"}, unit="deg/h", time_unit="s")
    assert rec.axis_names == ("gx",) and rec.dt_s == 0.1
    assert_array_equal(rec.rate_dph[:, 0], data[:, 0])
    assert rec.sha256 == sha(p)


def test_corrupt_mat_is_a_located_error(tmp_path, rng):
    p = tmp_path / "c.mat"
    sio.savemat(p, {"x": rng.normal(size=(1000, 3))})
    raw = p.read_bytes()
    (tmp_path / "cut.mat").write_bytes(raw[: len(raw) - 5000])
    with pytest.raises(DataFormatError, match=r"cut\.mat: unreadable MATLAB file; expected a v4/v5/v7 \.mat file"):
        load(tmp_path / "cut.mat", rate_hz=1.0)
    _write_v73(tmp_path / "h.mat", {"x": rng.normal(size=(1000, 3))})
    raw = (tmp_path / "h.mat").read_bytes()
    (tmp_path / "hcut.mat").write_bytes(raw[:1200])
    with pytest.raises(DataFormatError, match=r"hcut\.mat: unreadable MATLAB v7\.3 file"):
        load(tmp_path / "hcut.mat", rate_hz=1.0)
