"""The fast CSV path (pyarrow's reader, issue 35) gives loadtxt's array bit for bit, and everything else falls back.

:meth:`fogdrift.io.readers.text.TextTable._read_fast` reads a plain numeric comma/tab/semicolon file; any file it
does not take (comments, blank cells, NaN, quotes, ragged rows, a decimal comma, whitespace-separated) is read,
and its errors are reported, exactly as before (:data:`~fogdrift.io.readers.text.FAST_CSV` = False is the old path).
"""

from __future__ import annotations

import gzip
import os
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pyarrow")

from fogdrift.errors import DataFormatError  # noqa: E402
from fogdrift.io import load  # noqa: E402
from fogdrift.io.readers import text  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
ADIS = Path(os.environ.get("FOGDRIFT_ADIS", REPO.parent / "shared/data/adis16405_static"))


def _both(path: Path):
    """(fast table, old table) of one file, each read in full."""
    out = []
    for fast in (True, False):
        table = text.open_table(path)
        old = text.FAST_CSV
        text.FAST_CSV = fast
        try:
            table.read(set(range(table.n_fields)))
        finally:
            text.FAST_CSV = old
        out.append(table)
    return out


def _bits(a):
    return np.ascontiguousarray(a).view(np.int64)


def _same(path: Path, *, fast_taken: bool = True):
    fast, old = _both(path)
    assert fast.data.shape == old.data.shape
    assert np.array_equal(_bits(fast.data), _bits(old.data))
    assert fast.sha256 == old.sha256 and fast.sha256
    assert (text.open_table(path)._read_fast() is not None) is fast_taken


@pytest.mark.parametrize("name", ["imu1", "imu3_accel"])
def test_shared_adis_logs_bit_for_bit(name):
    path = ADIS / f"adis16405_{name}.csv.gz"
    if not path.exists():
        pytest.skip(f"{path} not present")
    _same(path)


def test_bundled_rlg_bit_for_bit():
    _same(REPO / "data/psins_lasergyro_rlg/psins_lasergyro_rlg.csv.gz")


def _numbers(n=20000, seed=7):
    rng = np.random.default_rng(seed)
    v = rng.standard_normal((n, 3)) * 10.0 ** rng.integers(-12, 12, size=(n, 3))
    v[::97, 0] = 0.0
    v[1::89, 1] = 5e-324  # subnormal
    v[2::83, 2] = -1.7976931348623157e308
    return v


@pytest.mark.parametrize("fmt", ["repr", "%.17g", "%.6e", "%.3f", "%d"])
@pytest.mark.parametrize("delim", [",", "\t", ";"])
def test_generated_files_bit_for_bit(tmp_path, fmt, delim):
    v = _numbers()
    cell = repr if fmt == "repr" else (lambda x: fmt % x)
    if fmt == "%d":
        v = np.trunc(np.clip(v, -1e15, 1e15))
    lines = [delim.join(["t[s]", "gx[deg/s]", "gy"])] + [delim.join(cell(float(x)) for x in row) for row in v]
    lines[5] = delim.join(["-0", "+1.5", ".25"])  # signs and bare decimal points
    path = tmp_path / "g.csv.gz"
    with gzip.open(path, "wt", newline="") as fh:
        fh.write("# a comment line before the header\n" + "\r\n".join(lines) + "\r\n")
    _same(path)
    plain = tmp_path / "g.csv"
    plain.write_text("\n".join(lines[1:]) + "\n\n")  # no header, a trailing blank line
    _same(plain)


FALLBACKS = {
    "comment": "a,b\n1,2\n3,4 # note\n5,6\n",
    "percent comment": "a,b\n1,2\n% note\n5,6\n",
    "nan": "a,b\n1,2\nnan,4\n5,6\n",
    "inf": "a,b\n1,2\n3,inf\n5,6\n",
    "blank cell in a used column": "a,b\n1,2\n,4\n5,6\n",
    "quoted": 'a,b\n1,2\n"3",4\n5,6\n',
    "ragged": "a,b\n1,2\n3,4,5\n5,6\n",
    "short row": "a,b\n1,2\n3\n5,6\n",
    "word": "a,b\n1,2\n3,x\n5,6\n",
    "decimal comma": "a;b\n1,5;2\n3,5;4\n",
    "whitespace": "a b\n1 2\n3 4\n",
    "lone CR header": "a,b\r1,2\r3,4\r",
}


@pytest.mark.parametrize("case", sorted(FALLBACKS))
def test_what_the_fast_path_does_not_take_is_read_or_refused_as_before(tmp_path, case):
    path = tmp_path / "f.csv"
    path.write_bytes(FALLBACKS[case].encode())
    assert text.open_table(path)._read_fast() is None
    results = []
    for fast in (True, False):
        old = text.FAST_CSV
        text.FAST_CSV = fast
        try:
            rec = load(path, unit="deg/s", rate_hz=10.0, time_column="none")
            results.append(("ok", rec.rate_dph.tobytes()))
        except DataFormatError as exc:
            results.append(("error", str(exc)))
        finally:
            text.FAST_CSV = old
    assert results[0] == results[1]


def test_a_reading_limit_is_the_same_error(tmp_path, monkeypatch):
    path = tmp_path / "big.csv.gz"
    with gzip.open(path, "wt") as fh:
        fh.write("a,b\n" + "".join(f"{i},{i * 0.5}\n" for i in range(5000)))
    monkeypatch.setenv("FOGDRIFT_MAX_ROWS", "1000")
    errors = []
    for fast in (True, False):
        monkeypatch.setattr(text, "FAST_CSV", fast)
        with pytest.raises(DataFormatError) as exc:
            load(path, unit="deg/s", rate_hz=10.0, time_column="none")
        errors.append(str(exc.value))
    assert errors[0] == errors[1]
