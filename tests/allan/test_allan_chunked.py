"""Out-of-core Allan variance: equal, bit for bit, to the in-memory engine (fogdrift.allan.allan_variance, the
oracle) on .npy, raw binary and HDF5 inputs with chunk sizes that force many chunks and the large-m path;
bounded allocations (tracemalloc); located errors; and the Haar wavelet variance against PyWavelets' MODWT.

Independent checks: the in-memory estimator on the whole array; pywt.swt (Haar, norm=True) with its 2^j - 1
wrapped coefficients removed.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.allan import allan_variance
from fogdrift.allan.chunked import allan_variance_chunked, haar_wavelet_variance_chunked
from fogdrift.errors import ConfigError, DataFormatError
from fogdrift.io import load
from fogdrift.io.chunked import open_source

FIELDS = ("tau_s", "m", "n_terms", "edf", "noise_alpha")


def _same(a, b):
    for f in FIELDS:
        assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)
    assert_array_equal(a.avar_dph2, b.avar_dph2)
    assert_array_equal(a.adev_lo95_dph, b.adev_lo95_dph)
    assert_array_equal(a.adev_hi68_dph, b.adev_hi68_dph)
    assert a.estimator == b.estimator and a.edf_rule == b.edf_rule and a.n_samples == b.n_samples


def _series(n, seed):
    rng = np.random.default_rng(seed)
    return 1.0e4 + rng.normal(size=n) + np.cumsum(rng.normal(scale=1e-3, size=n))   # offset + white + RW


@pytest.mark.parametrize("estimator, taus", [("overlapping", "octave"), ("overlapping", "decade"),
                                             ("non-overlapping", "octave")])
def test_npy_many_chunks_equals_in_memory(tmp_path, estimator, taus):
    y = _series(600_001, 1)                                    # m up to 150000: windows beyond the chunk
    np.save(tmp_path / "y.npy", y)
    src = open_source(tmp_path / "y.npy", rate_hz=100.0, unit="deg/h")
    got = allan_variance_chunked(src, taus=taus, estimator=estimator, chunk_samples=65536)
    _same(got, allan_variance(y, 0.01, taus=taus, estimator=estimator))


def test_npy_2d_columns_float32_and_fortran_order(tmp_path):
    y = _series(300_000, 2).reshape(-1, 3).astype(np.float32)
    np.save(tmp_path / "c.npy", y)
    np.save(tmp_path / "f.npy", np.asfortranarray(y))
    for name in ("c.npy", "f.npy"):
        src = open_source(tmp_path / name, rate_hz=10.0, column=1, unit="deg/s")
        ref = allan_variance(load(tmp_path / name, rate_hz=10.0, columns=1, unit="deg/s").axis(0), 0.1)
        _same(allan_variance_chunked(src, chunk_samples=65536), ref)
    with pytest.raises(ConfigError, match=r"3 columns; choose one with columns="):
        open_source(tmp_path / "c.npy", rate_hz=10.0, unit="deg/s")


def test_raw_binary_with_scale_increments_and_sequence(tmp_path):
    rng = np.random.default_rng(3)
    n = 400_000
    rec = np.zeros(n, dtype=[("seq", "<u2"), ("gx", "<i4"), ("gz", "<i4")])
    rec["seq"] = np.arange(n) % 65536
    rec["gz"] = rng.integers(-5000, 5000, size=n)
    p = tmp_path / "log.bin"
    p.write_bytes(b"H" * 24 + rec.tobytes())
    layout = "<u2 seq, <i4 gx, <i4 gz"
    src = open_source(p, column="gz", layout=layout, scale="gz=1e-4", header_bytes=24, unit="inc:arcsec",
                      rate_hz=200.0)
    ref = load(p, rate_hz=200.0, unit="inc:arcsec", columns="gz",
               reader_options={"layout": layout, "scale": "gz=1e-4", "header_bytes": 24})
    _same(allan_variance_chunked(src, chunk_samples=65536), allan_variance(ref.axis(0), ref.dt_s))
    rec["seq"][250_000:] += 3                                   # three records lost
    p.write_bytes(b"H" * 24 + rec.tobytes())
    src = open_source(p, column="gz", layout=layout, header_bytes=24, rate_hz=200.0, unit="inc:arcsec")
    with pytest.raises(DataFormatError, match=r"log\.bin:seq: sequence counter jumps from 53391 to 53395 at "
                                              r"record 250000"):
        allan_variance_chunked(src, chunk_samples=65536)


def test_hdf5_dataset_and_compound(tmp_path):
    h5py = pytest.importorskip("h5py")
    y = _series(200_000, 4)
    rows = np.zeros(y.size, dtype=[("t", "<f8"), ("gz", "<f4")])
    rows["gz"] = y
    with h5py.File(tmp_path / "a.h5", "w") as f:
        f.create_dataset("imu/rate", data=np.column_stack([y, -y]), chunks=(10_000, 2), compression="gzip")
        f.create_dataset("imu/records", data=rows).attrs["units"] = ["s", "deg/h"]
    with pytest.raises(ConfigError, match=r"a\.h5: no rate unit: HDF5 dataset /imu/rate declares none; pass unit="):
        open_source(tmp_path / "a.h5", dataset="/imu/rate", column=1, rate_hz=50.0)
    src = open_source(tmp_path / "a.h5", dataset="/imu/rate", column=1, rate_hz=50.0, unit="deg/h")
    _same(allan_variance_chunked(src, chunk_samples=65536), allan_variance(-y, 0.02))
    src = open_source(tmp_path / "a.h5", dataset="/imu/records", column="gz", rate_hz=50.0)   # declared deg/h
    _same(allan_variance_chunked(src, chunk_samples=65536), allan_variance(rows["gz"], 0.02))
    src = open_source(tmp_path / "a.h5", dataset="/imu/records", column="gz", rate_hz=50.0, unit="deg/s")
    _same(allan_variance_chunked(src, chunk_samples=65536), allan_variance(rows["gz"].astype(np.float64) * 3600.0, 0.02))


def test_memory_is_bounded_by_the_chunk(tmp_path):
    n, chunk = 600_000, 65536                                   # 10 chunks
    np.save(tmp_path / "big.npy", _series(n, 5).astype(np.float32))
    np.save(tmp_path / "warm.npy", _series(3 * chunk, 5).astype(np.float32))
    allan_variance_chunked(open_source(tmp_path / "warm.npy", rate_hz=100.0, unit="deg/h"),
                           chunk_samples=chunk)                 # compile outside the measurement
    src = open_source(tmp_path / "big.npy", rate_hz=100.0, unit="deg/h")
    tracemalloc.start()
    allan_variance_chunked(src, chunk_samples=chunk)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 13 * chunk * 8, peak                          # in memory: >= 2 * 8 * n = 9.6 MB


def test_errors_are_located(tmp_path):
    y = _series(100_000, 6)
    y[70_000] = np.nan
    np.save(tmp_path / "nan.npy", y)
    with pytest.raises(DataFormatError, match=r"nan\.npy:col0: non-finite value at sample 70000"):
        allan_variance_chunked(open_source(tmp_path / "nan.npy", rate_hz=1.0, unit="deg/h"), chunk_samples=65536)
    with pytest.raises(ConfigError, match=r"nan\.npy: no rate unit: npy float64 \(100000,\) declares none; pass unit="):
        open_source(tmp_path / "nan.npy", rate_hz=1.0)
    with pytest.raises(ConfigError, match=r"needs the sample rate; pass rate_hz="):
        open_source(tmp_path / "nan.npy", unit="deg/h")
    (tmp_path / "a.csv").write_text("t,x\n0,1\n1,2\n")
    with pytest.raises(ConfigError, match=r"supports \.npy, raw binary \(pass layout=\) and HDF5; got a text file"):
        open_source(tmp_path / "a.csv", rate_hz=1.0, unit="deg/h")
    with pytest.raises(ConfigError, match="estimator must be one of"):
        allan_variance_chunked(open_source(tmp_path / "nan.npy", rate_hz=1.0, unit="deg/h"), estimator="fast")
    with pytest.raises(ConfigError, match="noise_alpha must be"):
        allan_variance_chunked(open_source(tmp_path / "nan.npy", rate_hz=1.0, unit="deg/h"), noise_alpha="x")


def test_haar_wavelet_variance_against_pywavelets(tmp_path):
    pywt = pytest.importorskip("pywt")
    y = _series(2 ** 17, 7)                                    # pywt.swt needs a multiple of 2^level
    np.save(tmp_path / "y.npy", y)
    wv = haar_wavelet_variance_chunked(open_source(tmp_path / "y.npy", rate_hz=10.0, unit="deg/h"), levels=8,
                                       chunk_samples=65536)
    n = y.size
    ref = []
    for j in range(1, 9):
        d = pywt.swt(y - y.mean(), "haar", level=j, trim_approx=True, norm=True)[1]   # level-j detail
        ref.append(np.mean(d[: n - 2 ** j + 1] ** 2))          # drop the 2^j - 1 wrapped coefficients
    assert_allclose(wv.wv_dph2, ref, rtol=1e-9)
    assert_array_equal(wv.tau_s, 0.1 * 2 ** np.arange(8))
    assert_array_equal(wv.n_coefficients, n - 2 ** np.arange(1, 9) + 1)
