"""Hostile inputs and conditions (issue 23, items 4-6): each ends in one clear line, never a traceback.

* decompression and parsing bombs (gzip text of NULs, one endless line, 300 M rows; an .npz that declares a 4 GiB
  member) are refused early, in bounded memory, naming the file, the limit and the variable that raises it.  The
  bombs are small files (gzip members repeated; a zip whose directory declares the size): nothing large is ever
  written to disk.  Memory is checked in a subprocess under ``RLIMIT_AS``;
* a .zip of CSV files, a non-.npy member in an .npz, a tiny file that starts with ``MATLAB``;
* ``--out`` a dangling symbolic link or a link loop (refused before the input is read), the disk filling up
  (no partial file, no temporary manifest left), a MemoryError inside a command.

Independent checks: the file system (listdir), the exit status and the output lines, the subprocess's peak RSS
(``VmHWM``, the program's own peak) and its wall time under hard caps.
"""

from __future__ import annotations

import errno
import gzip
import io
import json
import os
import struct
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.cli import _app as cli_app
from fogdrift.errors import ConfigError, DataFormatError, FogdriftError, ResourceError, ResourceLimitError
from fogdrift.io import load
from fogdrift.io.readers import limits
from fogdrift.output import MANIFEST, TMP_PREFIX, OutputDir, atomic_path, check_out_dir

runner = CliRunner()


def lines(text: str) -> list[str]:
    return [ln for ln in text.splitlines() if ln.strip()]


def gz_repeat(path: Path, chunk: bytes, times: int) -> Path:
    """A gzip file of ``times`` members, each ``chunk`` compressed: ``len(chunk) * times`` bytes of content in a
    file of ``times`` small members (GzipFile reads the members as one stream)."""
    member = gzip.compress(chunk, compresslevel=9, mtime=0)
    with open(path, "wb") as fh:
        for _ in range(times):
            fh.write(member)
    return path


def npz_declaring(path: Path, declared: int, n: int = 1000) -> Path:
    """A valid .npz of one float64 member whose zip headers (local and central) declare ``declared`` bytes."""
    buf = io.BytesIO()
    np.save(buf, np.zeros(n))
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("gx.npy", buf.getvalue())
    data = bytearray(path.read_bytes())
    data[22:26] = struct.pack("<I", declared)                  # local file header: uncompressed size
    cd = data.rfind(b"PK\x01\x02")
    data[cd + 24:cd + 28] = struct.pack("<I", declared)        # central directory: uncompressed size
    path.write_bytes(bytes(data))
    return path


CAPPED = """
import json, resource, sys, time
cap = int(sys.argv[2]) << 20
resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
from fogdrift.errors import FogdriftError
from fogdrift.io import load
t0 = time.perf_counter()
try:
    load(sys.argv[1], unit="deg/h", rate_hz=100.0, time_column=None)
    out = {"error": None}
except FogdriftError as exc:
    out = {"error": str(exc), "type": type(exc).__name__}
out["wall_s"] = time.perf_counter() - t0
# VmHWM: the peak of THIS program's memory (ru_maxrss keeps the forking pytest worker's peak across exec)
hwm = [ln for ln in open("/proc/self/status") if ln.startswith("VmHWM:")]
out["rss_mb"] = (int(hwm[0].split()[1]) if hwm else resource.getrusage(resource.RUSAGE_SELF).ru_maxrss) / 1024
print(json.dumps(out))
"""


def capped_load(path: Path, cap_mb: int = 1024, env=None) -> dict:
    """Load ``path`` in a subprocess whose address space is capped at ``cap_mb`` MiB; its outcome as a dict.

    A MemoryError or any other exception ends the subprocess with a traceback: the test then fails on rc."""
    proc = subprocess.run([sys.executable, "-c", CAPPED, str(path), str(cap_mb)], capture_output=True, text=True,
                          timeout=300, env={**os.environ, **(env or {})})
    assert proc.returncode == 0, proc.stderr[-2000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


# ------------------------------------------------------------------------------------------
# 1. Bounded decompression and parsing
# ------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_gzip_of_nuls_is_refused_at_once_in_bounded_memory(tmp_path):
    p = gz_repeat(tmp_path / "nul.csv.gz", b"\x00" * (16 << 20), 128)   # 2 GiB of NUL bytes in a 2 MB file
    assert p.stat().st_size < 3 << 20
    out = capped_load(p, 1024)
    assert out["type"] == "DataFormatError" and out["error"].startswith(f"{p}:1: NUL byte"), out
    assert out["rss_mb"] < 400 and out["wall_s"] < 60, out   # caps far above the measured 33 MB, 0.05 s


def test_gzip_of_nuls_is_a_located_error(tmp_path):
    p = gz_repeat(tmp_path / "nul.csv.gz", b"t_s,gx\n0,1\n" + b"\x00" * 4096, 1)
    with pytest.raises(DataFormatError, match=r"nul\.csv\.gz:3: NUL byte at byte 12 of the decompressed content"):
        load(p, unit="deg/h")


@pytest.mark.slow
def test_gzip_with_one_2_gib_line_is_refused_after_the_line_limit(tmp_path):
    p = gz_repeat(tmp_path / "line.csv.gz", b"1" * (16 << 20), 128)     # one line of 2 GiB, no line break
    out = capped_load(p, 1024)
    assert out["type"] == "ResourceLimitError", out
    assert out["error"].startswith(f"{p}:1: line longer than 1 MiB") and "FOGDRIFT_MAX_LINE_BYTES" in out["error"]
    assert out["rss_mb"] < 400 and out["wall_s"] < 60, out


def test_line_limit_names_the_line_and_is_raised_by_its_variable(tmp_path, monkeypatch):
    p = tmp_path / "long.csv"
    p.write_text("t_s,gx\n0,1\n0.01,12." + "5" * 5000 + "\n0.02,3\n")
    monkeypatch.setenv(limits.ENV_LINE, "4096")
    with pytest.raises(ResourceLimitError) as ei:
        load(p, unit="deg/h")
    assert str(ei.value).startswith(f"{p}:3: line longer than 4 KiB") and ei.value.limit == "FOGDRIFT_MAX_LINE_BYTES"
    assert "\n" not in str(ei.value)
    monkeypatch.setenv(limits.ENV_LINE, "8K")   # raised: the file loads (a bug that counted a line too many or
    rec = load(p, unit="deg/h")                 # compared with >= would refuse a 5 KiB line here)
    assert rec.n_samples == 3 and rec.rate_dph[1, 0] == pytest.approx(12 + 5 / 9)


def test_line_limit_counts_cr_and_crlf_line_ends(tmp_path, monkeypatch):
    monkeypatch.setenv(limits.ENV_LINE, "64")
    body = "".join(f"{i * 0.01:.2f},{i}" + eol for i, eol in enumerate(["\r", "\r\n", "\n"] * 30))
    p = tmp_path / "eol.csv"
    p.write_bytes(("t_s,gx\r\n" + body).encode())
    assert load(p, unit="deg/h").n_samples == 90        # 90 short lines, none taken as one long line
    p.write_bytes(("t_s,gx\r\n" + body + "9.00," + "1" * 70 + "\r").encode())
    with pytest.raises(ResourceLimitError, match=r"eol\.csv:92: line longer than 64 bytes"):
        load(p, unit="deg/h")


@pytest.mark.slow
def test_300_million_rows_in_3_mb_stop_early_in_bounded_memory_and_time(tmp_path):
    p = gz_repeat(tmp_path / "rows.csv.gz", b"0.01,1\n" * (1 << 20), 300)   # 315 M rows, 3.1 MB
    assert p.stat().st_size < 4 << 20
    out = capped_load(p, 1536)
    assert out["type"] == "ResourceLimitError" and "FOGDRIFT_MAX_EXPANSION" in out["error"], out
    assert out["error"].startswith(f"{p}: gzip content exceeds"), out
    # measured 6.6 s and 391 MB (the first 50 x 3.1 MB parsed); without the limit: > 400 s and 3.7 GB, killed
    assert out["rss_mb"] < 1000 and out["wall_s"] < 120, out


def test_rows_and_memory_budget_stop_the_read_early(tmp_path, monkeypatch):
    p = gz_repeat(tmp_path / "rows.csv.gz", b"0.01,1\n" * 10000, 30)      # 300 000 rows
    monkeypatch.setenv(limits.ENV_EXPANSION, "0")
    monkeypatch.setenv(limits.ENV_ROWS, "100000")
    with pytest.raises(ResourceLimitError, match=r"rows\.csv\.gz: more than 100000 lines; expected at most 100000 "
                                                 r"\(FOGDRIFT_MAX_ROWS\)"):
        load(p, unit="deg/h", rate_hz=100.0, time_column=None)
    monkeypatch.setenv(limits.ENV_ROWS, "0")
    monkeypatch.setenv(limits.ENV_MEMORY, "1M")   # 2 columns x 8 bytes: 65536 lines fit in 1 MiB
    with pytest.raises(ResourceLimitError) as ei:
        load(p, unit="deg/h", rate_hz=100.0, time_column=None)
    assert "more than 65536 lines of 2 columns" in str(ei.value) and ei.value.limit == "FOGDRIFT_MAX_MEMORY"
    monkeypatch.setenv(limits.ENV_MEMORY, "5M")   # 300 000 x 2 x 8 = 4.6 MiB: fits
    assert load(p, unit="deg/h", rate_hz=100.0, time_column=None).n_samples == 300_000


def test_expansion_limit_against_the_gzip_size(tmp_path, monkeypatch):
    p = gz_repeat(tmp_path / "z.csv.gz", b"0.01,1\n" * (1 << 20), 4)      # 28 MiB from ~30 KB
    with pytest.raises(ResourceLimitError, match="FOGDRIFT_MAX_EXPANSION"):
        load(p, unit="deg/h", rate_hz=100.0, time_column=None)
    monkeypatch.setenv(limits.ENV_EXPANSION, "2000")
    assert load(p, unit="deg/h", rate_hz=100.0, time_column=None).n_samples == 4 << 20


def test_a_real_compressed_log_is_well_inside_the_expansion_limit(bundled_path):
    raw = gzip.decompress(bundled_path.read_bytes())
    assert len(raw) / bundled_path.stat().st_size < limits.DEFAULT_EXPANSION / 5   # 5.5 for the RLG log
    assert load(bundled_path, unit="deg/h").n_samples > 0


@pytest.mark.slow
def test_npz_declaring_4_gib_is_refused_before_decompressing(tmp_path):
    p = npz_declaring(tmp_path / "bomb.npz", 0xFFFF_FFFF)
    out = capped_load(p, 512)
    assert out["type"] == "ResourceLimitError" and "refused before decompressing" in out["error"], out
    assert out["rss_mb"] < 300, out


def test_npz_declared_sizes_are_checked_against_the_file(tmp_path):
    p = npz_declaring(tmp_path / "bomb.npz", 0xFFFF_FFFF)
    with pytest.raises(ResourceLimitError) as ei:
        load(p, unit="deg/h", rate_hz=100.0)
    msg = str(ei.value)
    assert msg.startswith(f"{p}: the .npz file's 1 member(s): 4 GiB declared in a") and "FOGDRIFT_MAX_EXPANSION" in msg
    # a member whose .npy header declares more data than the member holds: refused before its array is allocated
    q = tmp_path / "lie.npz"
    buf = io.BytesIO()
    np.save(buf, np.zeros(10))
    head = buf.getvalue()
    hlen = int.from_bytes(head[8:10], "little")
    header = head[10:10 + hlen].replace(b"'shape': (10,), ", b"'shape': (999999999,), ")
    header = header.rstrip(b" \n")[:hlen - 1].ljust(hlen - 1) + b"\n"
    raw = head[:10] + header + head[10 + hlen:]
    with zipfile.ZipFile(q, "w") as z:
        z.writestr("gx.npy", raw)
    with pytest.raises(DataFormatError, match=r"array 'gx' declares shape \(999999999,\) \(7999999992 bytes\) "
                                              r"but its member holds 80 bytes"):
        load(q, unit="deg/h", rate_hz=100.0)


def test_npz_within_the_limits_still_loads(tmp_path):
    p = tmp_path / "ok.npz"
    rng = np.random.default_rng(3)
    np.savez_compressed(p, t_s=np.arange(500) * 0.01, gx=rng.normal(size=500), gy=rng.normal(size=500))
    rec = load(p, unit="deg/h")
    assert rec.axis_names == ("gx", "gy") and rec.n_samples == 500 and rec.dt_s == pytest.approx(0.01)
    with np.load(p) as z:
        np.testing.assert_array_equal(rec.rate_dph[:, 1], z["gy"])


def test_memory_budget_refuses_a_large_npz_member(tmp_path, monkeypatch):
    p = tmp_path / "big.npz"
    np.savez(p, gx=np.zeros(200_000))           # 1.6 MB stored uncompressed: within any expansion limit
    monkeypatch.setenv(limits.ENV_MEMORY, "1M")
    with pytest.raises(ResourceLimitError, match=r"needs 1\.53 MiB of memory; expected at most the memory budget "
                                                 r"1 MiB \(FOGDRIFT_MAX_MEMORY\)"):
        load(p, unit="deg/h", rate_hz=100.0)


def test_a_bad_limit_value_is_one_line_naming_the_variable(tmp_path, monkeypatch):
    p = tmp_path / "a.csv"
    p.write_text("t_s,gx\n0,1\n0.01,2\n")
    monkeypatch.setenv(limits.ENV_MEMORY, "lots")
    with pytest.raises(ConfigError, match=r"environment variable FOGDRIFT_MAX_MEMORY='lots': expected a number"):
        load(p, unit="deg/h")


def test_sizes_in_limit_variables():
    env = {limits.ENV_MEMORY: "1.5G"}
    old = {k: os.environ.get(k) for k in env}
    os.environ.update(env)
    try:
        assert limits.memory_budget() == int(1.5 * (1 << 30))
    finally:
        for k, v in old.items():
            os.environ.pop(k) if v is None else os.environ.__setitem__(k, v)


# ------------------------------------------------------------------------------------------
# 2. Readers: one located line for archives and files that are not what they seem
# ------------------------------------------------------------------------------------------
def test_a_zip_of_a_csv_is_not_taken_as_npz(tmp_path):
    for name in ("log.zip", "log.npz"):
        p = tmp_path / name
        with zipfile.ZipFile(p, "w") as z:
            z.writestr("log.csv", "t,gx\n0,1\n0.01,2\n")
        with pytest.raises(DataFormatError) as ei:
            load(p, unit="deg/h")
        assert str(ei.value) == (f"{p}: a zip archive of 'log.csv', not a NumPy .npz file; expected .npy members "
                                 "(a zipped CSV or text log: extract it and load that file)")


def test_a_non_npy_member_in_an_npz_is_named(tmp_path):
    p = tmp_path / "x.npz"
    buf = io.BytesIO()
    np.save(buf, np.arange(5.0))
    with zipfile.ZipFile(p, "w") as z:
        z.writestr("gx.npy", buf.getvalue())
        z.writestr("notes.txt", "hello")
    with pytest.raises(DataFormatError) as ei:
        load(p, unit="deg/h", rate_hz=100.0)
    assert str(ei.value).startswith(f"{p}:notes.txt: member 'notes.txt' of the .npz file is not a .npy array")


@pytest.mark.parametrize("body", [b"MATLAB", b"MATLAB" + b"\x00" * 20, b"MATLAB 5.0 MAT-file" + b" " * 60,
                                  b"MATLAB 5.0" + b"x" * 100, b"MATLAB 5.0 MAT-file".ljust(120) + b"\x00\x01IM"])
def test_a_tiny_file_starting_with_matlab_is_one_line(tmp_path, body):
    p = tmp_path / "m.mat"
    p.write_bytes(body)
    assert len(body) < 128
    with pytest.raises(DataFormatError) as ei:
        load(p, unit="deg/h", rate_hz=100.0)
    assert str(ei.value).startswith(f"{p}: unreadable MATLAB file; expected a v4/v5/v7 .mat file, got ")
    assert "\n" not in str(ei.value)


def test_matlab_variable_over_the_memory_budget_is_refused_before_loading(tmp_path, monkeypatch):
    scipy_io = pytest.importorskip("scipy.io")
    p = tmp_path / "big.mat"
    scipy_io.savemat(p, {"gx": np.zeros(300_000)}, do_compression=True)
    monkeypatch.setenv(limits.ENV_MEMORY, "2M")
    with pytest.raises(ResourceLimitError, match=r"variable 'gx' \(1, 300000\) as float64 needs 2\.29 MiB"):
        load(p, unit="deg/h", rate_hz=100.0)


# ------------------------------------------------------------------------------------------
# 3. --out: links that lead nowhere, a full disk, memory
# ------------------------------------------------------------------------------------------
@pytest.fixture
def npy_log(tmp_path) -> Path:
    p = tmp_path / "log.npy"
    np.save(p, np.random.default_rng(7).normal(size=4000))
    return p


@pytest.fixture
def no_load(monkeypatch):
    def fail(self, path=None):
        raise AssertionError("the input file was read before --out was refused")
    monkeypatch.setattr(cli_app.LoadOptions, "load", fail)


def test_out_a_dangling_link_is_refused_before_any_work(tmp_path, npy_log, no_load):
    link = tmp_path / "out"
    link.symlink_to(tmp_path / "nowhere")
    result = runner.invoke(app, ["allan", str(npy_log), "--unit", "deg/h", "--rate", "100", "--out", str(link)])
    assert result.exit_code == 1 and "Traceback" not in result.output, result.output
    assert lines(result.output) == [f"error: --out {link} is a symbolic link to {tmp_path / 'nowhere'}, which does "
                                    "not exist (a dangling link); remove or fix the link, or choose another folder"]


def test_out_a_link_loop_is_refused_before_any_work(tmp_path, npy_log, no_load):
    a, b = tmp_path / "a", tmp_path / "b"
    a.symlink_to(b)
    b.symlink_to(a)
    for out in (a, a / "sub" / "run"):
        result = runner.invoke(app, ["allan", str(npy_log), "--unit", "deg/h", "--rate", "100", "--out", str(out)])
        assert result.exit_code == 1 and "Traceback" not in result.output, result.output
        assert len(lines(result.output)) == 1 and f"{a} is a symbolic link loop" in result.output


def test_out_through_a_link_to_a_folder_is_fine(tmp_path):
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    assert check_out_dir(tmp_path / "link" / "run").name == "run"


def _disk_full_savefig(self, fname, *args, **kwargs):
    Path(fname).write_bytes(b"\x89PNG\r\n partial")
    raise OSError(errno.ENOSPC, "No space left on device")


def test_disk_full_is_one_line_and_leaves_no_partial_file(tmp_path, npy_log, monkeypatch):
    import matplotlib.figure

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", _disk_full_savefig)
    out = tmp_path / "o"
    result = runner.invoke(app, ["allan", str(npy_log), "--unit", "deg/h", "--rate", "100", "--out", str(out)])
    assert result.exit_code == 1 and "Traceback" not in result.output
    err = [ln for ln in lines(result.output) if ln.startswith("error:")]
    assert len(err) == 1 and lines(result.output)[-1] == err[0]
    assert err[0].startswith(f"error: --out {out}: cannot write allan.png: No space left on device (ENOSPC); wrote 2 "
                             "complete file(s)")
    assert "no partial file left" in err[0] and "free space" in err[0]
    assert sorted(os.listdir(out)) == [MANIFEST, "allan.csv", "allan.json"]
    man = json.loads((out / MANIFEST).read_text())
    assert man["complete"] is False and man["files"] == ["allan.json", "allan.csv"]


def test_disk_full_while_writing_the_manifest_leaves_no_temporary(tmp_path, monkeypatch):
    calls = {"n": 0}
    real = Path.write_text

    def write_text(self, data, *args, **kwargs):
        if self.name.startswith(TMP_PREFIX) and self.name.endswith(MANIFEST):
            calls["n"] += 1
            if calls["n"] >= 2:                  # the first manifest fits; the one after the first file does not
                real(self, "", *args, **kwargs)  # a 0-byte temporary, as a full disk leaves it
                raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, data, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", write_text)
    out = tmp_path / "o"
    with pytest.raises(ResourceError) as ei:
        with OutputDir(out, command="allan") as od:
            with od.file("a.csv") as tmp:
                tmp.write_bytes(b"1,2\n")
    assert str(ei.value).startswith(f"out= {out}: cannot write a.csv: No space left on device (ENOSPC)")
    assert [p for p in os.listdir(out) if p.startswith(TMP_PREFIX)] == []


def test_atomic_path_outside_an_output_folder_on_a_full_disk(tmp_path):
    target = tmp_path / "t.csv"
    with pytest.raises(ResourceError, match=r"cannot write t\.csv: No space left on device"):
        with atomic_path(target) as tmp:
            tmp.write_text("x")
            raise OSError(errno.ENOSPC, "No space left on device")
    assert os.listdir(tmp_path) == []


def test_a_memory_error_in_a_command_is_one_line(tmp_path, npy_log, monkeypatch):
    import fogdrift.workflows.allan

    def exhausted(*args, **kwargs):
        raise MemoryError()

    monkeypatch.setattr(fogdrift.workflows.allan, "run_allan", exhausted)  # the allan workflow the command runs
    out = tmp_path / "o"
    result = runner.invoke(app, ["allan", str(npy_log), "--unit", "deg/h", "--rate", "100", "--out", str(out)])
    assert result.exit_code == 1 and "Traceback" not in result.output, result.output
    err = [ln for ln in lines(result.output) if ln.startswith("error:")]
    assert len(err) == 1 and lines(result.output)[-1] == err[0]
    assert err[0].startswith(f"error: out of memory in 'fogdrift allan' on {npy_log.absolute()}; nothing was "
                             f"written to {out}") and err[0].endswith("run it with more memory (a process limit: "
                                                                       "ulimit -v), or on a shorter log")


def test_errors_of_every_reader_limit_name_the_file(tmp_path, monkeypatch):
    """Each limit's error starts with the file's path (and line where there is one) and names its variable."""
    monkeypatch.setenv(limits.ENV_ROWS, "3")
    cases = []
    p = tmp_path / "r.csv"
    p.write_text("t_s,gx\n0,1\n0.01,2\n0.02,3\n0.03,4\n")
    cases.append((p, {}))
    q = tmp_path / "r.npz"
    np.savez(q, gx=np.zeros(5))
    cases.append((q, {"rate_hz": 100.0}))
    for path, kw in cases:
        with pytest.raises(FogdriftError) as ei:
            load(path, unit="deg/h", **kw)
        assert str(ei.value).startswith(f"{path}") and "FOGDRIFT_MAX_ROWS" in str(ei.value), str(ei.value)


def test_npy_conversion_to_float64_is_held_to_the_memory_budget(tmp_path, monkeypatch):
    p = tmp_path / "f32.npy"
    np.save(p, np.zeros(200_000, dtype=np.float32))        # 0.8 MB on disk, 1.6 MB as float64
    monkeypatch.setenv(limits.ENV_MEMORY, "1M")
    with pytest.raises(ResourceLimitError, match=r"the float32 array \(200000,\) as float64 needs 1\.53 MiB"):
        load(p, unit="deg/h", rate_hz=100.0)
    q = tmp_path / "f64.npy"
    np.save(q, np.zeros(200_000))                          # float64: memory-mapped, never copied: no budget
    assert load(q, unit="deg/h", rate_hz=100.0).n_samples == 200_000


def test_a_bomb_through_the_cli_is_one_line_naming_the_variable(tmp_path, monkeypatch):
    p = gz_repeat(tmp_path / "rows.csv.gz", b"0.01,1\n" * (1 << 20), 4)
    out = tmp_path / "o"
    result = runner.invoke(app, ["allan", str(p), "--unit", "deg/h", "--rate", "100", "--out", str(out)])
    assert result.exit_code == 1 and "Traceback" not in result.output
    assert lines(result.output) == [ln for ln in lines(result.output) if ln.startswith("error:")]
    assert len(lines(result.output)) == 1 and f"error: {p}: gzip content exceeds" in result.output
    assert "FOGDRIFT_MAX_EXPANSION" in result.output and not out.exists()


def test_the_line_by_line_scan_packs_rows_in_blocks_and_keeps_every_row(tmp_path):
    # a non-numeric cell in an unused column sends the file through the line-by-line scan (rows packed into float64
    # blocks of 65536): 70 001 rows cross a block boundary; every value and every line number must survive it
    n = 70_001
    gx = np.arange(n, dtype=np.float64) * 0.5
    body = "".join(f"{i * 0.01:.2f},{float(gx[i])!r},{'x' if i == 3 else 1}\n" for i in range(n))
    p = tmp_path / "scan.csv"
    p.write_text("# a comment line\nt_s,gx,note\n" + body)
    rec = load(p, columns="gx", unit="deg/h")
    assert rec.n_samples == n
    np.testing.assert_array_equal(rec.rate_dph[:, 0], gx)
    bad = tmp_path / "scan_bad.csv"
    bad.write_text("t_s,gx,note\n" + body + f"{n * 0.01:.2f},oops,1\n")
    with pytest.raises(DataFormatError, match=rf"scan_bad\.csv:{n + 2}:gx: non-numeric value"):
        load(bad, columns="gx", unit="deg/h")


def test_matlab_v73_variable_declaring_gigabytes_is_refused_before_reading(tmp_path):
    h5py = pytest.importorskip("h5py")
    p = tmp_path / "bomb.mat"
    with h5py.File(p, "w", userblock_size=512) as f:
        ds = f.create_dataset("gx", shape=(1, 1 << 29), dtype="<f8", chunks=(1, 1 << 20), compression="gzip")
        ds.attrs["MATLAB_class"] = b"double"         # 4 GiB declared, no chunk written: a few KB on disk
    with open(p, "r+b") as fh:
        fh.write(b"MATLAB 7.3 MAT-file, Platform: GLNXA64".ljust(128, b" "))
    assert p.stat().st_size < 64 << 10
    with pytest.raises(ResourceLimitError) as ei:
        load(p, unit="deg/h", rate_hz=100.0)
    assert str(ei.value).startswith(f"{p}: ") and ("FOGDRIFT_MAX_EXPANSION" in str(ei.value)
                                                   or "FOGDRIFT_MAX_MEMORY" in str(ei.value))


def test_hdf5_dataset_declaring_gigabytes_is_refused_before_reading(tmp_path, monkeypatch):
    h5py = pytest.importorskip("h5py")
    monkeypatch.setenv(limits.ENV_MEMORY, "0")   # the expansion limit alone, whatever this machine's memory
    p = tmp_path / "bomb.h5"
    with h5py.File(p, "w") as f:
        f.create_dataset("gx", shape=(1 << 29,), dtype="<f8", chunks=(1 << 20,), compression="gzip")
    assert p.stat().st_size < 64 << 10
    with pytest.raises(ResourceLimitError) as ei:
        load(p, unit="deg/h", rate_hz=100.0)
    assert str(ei.value).startswith(f"{p}: the arrays of 1 used column(s): 4 GiB declared in a ")
    assert "refused before decompressing" in str(ei.value)


CAPPED_CLI = """
import resource, sys
cap = int(sys.argv[1]) << 20
resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
sys.argv = ["fogdrift"] + sys.argv[2:]
from fogdrift.cli import main
main()
"""


@pytest.mark.slow
@pytest.mark.parametrize("cap_mb", [450, 600])
def test_allan_under_a_memory_cap_ends_in_one_line_or_succeeds(tmp_path, cap_mb):
    # a real MemoryError (or ENOMEM from mmap, or a shared library that cannot be mapped) wherever the cap bites:
    # the run succeeds or ends with exactly one 'error:' line, never a traceback (issue 23: a traceback under a cap)
    p = tmp_path / "f32.npy"
    np.save(p, np.random.default_rng(9).normal(size=10_000_000).astype(np.float32))   # 40 MB
    out = tmp_path / "o"
    proc = subprocess.run([sys.executable, "-c", CAPPED_CLI, str(cap_mb), "allan", str(p), "--unit", "deg/h",
                           "--rate", "100", "--out", str(out)], capture_output=True, text=True, timeout=600,
                          env={**os.environ, "COLUMNS": "200"})
    assert "Traceback" not in proc.stderr + proc.stdout, proc.stderr[-3000:]
    assert proc.returncode in (0, 1), proc.stderr[-3000:]
    if proc.returncode == 1:
        err = [ln for ln in lines(proc.stderr) if ln.strip()]
        assert len(err) == 1 and err[0].startswith("error: ") and ("memory" in err[0]), proc.stderr
        assert [q for q in (os.listdir(out) if out.exists() else []) if q.startswith(TMP_PREFIX)] == []


def test_a_dependency_that_cannot_be_mapped_for_memory_is_not_called_missing(monkeypatch):
    import importlib

    from fogdrift.io.readers.base import MissingDependencyError, require

    def fail(name):
        raise ImportError("libarrow_substrait.so.2600: failed to map segment from shared object")

    monkeypatch.setattr(importlib, "import_module", fail)
    with pytest.raises(ResourceError) as ei:
        require("pyarrow", "fleet", "writing the batch summary (Parquet)")
    assert not isinstance(ei.value, MissingDependencyError)
    assert "'pyarrow', which is installed but could not be loaded: out of memory" in str(ei.value)
    assert "pip install" not in str(ei.value)


def test_a_write_refused_for_another_reason_is_a_config_error_naming_the_file(tmp_path):
    out = tmp_path / "o"
    with pytest.raises(ConfigError) as ei:
        with OutputDir(out, command="noise") as od:
            with od.file("sub/noise.json") as tmp:
                tmp.write_text("{}")
                raise PermissionError(errno.EACCES, "Permission denied")
    assert not isinstance(ei.value, ResourceError)
    assert str(ei.value).startswith(f"out= {out}: cannot write sub/noise.json: Permission denied (EACCES); "
                                     f"nothing was written to {out}")
    assert not [p for p in out.rglob("*") if p.name.startswith(TMP_PREFIX)]


def test_raw_binary_records_are_held_to_the_row_limit_and_memory_budget(tmp_path, monkeypatch):
    p = tmp_path / "imu.bin"
    rec = np.zeros(100_000, dtype=[("seq", "<u2"), ("gx", "<i4"), ("gy", "<i4")])
    rec["seq"] = np.arange(100_000) % 65536
    p.write_bytes(rec.tobytes())
    opts = {"reader_options": {"layout": "<u2 seq, <i4 gx, <i4 gy"}, "unit": "deg/h", "rate_hz": 100.0}
    monkeypatch.setenv(limits.ENV_ROWS, "99999")
    with pytest.raises(ResourceLimitError, match=r"imu\.bin: 100000 records; expected at most 99999"):
        load(p, **opts)
    monkeypatch.setenv(limits.ENV_ROWS, "100000")
    monkeypatch.setenv(limits.ENV_MEMORY, "1M")    # gx, gy used (the counter is time): 100 000 x 2 x 8 = 1.53 MiB
    with pytest.raises(ResourceLimitError, match=r"100000 records x 2 used field\(s\) as float64 needs 1\.53 MiB"):
        load(p, **opts)
    monkeypatch.setenv(limits.ENV_MEMORY, "2M")
    assert load(p, **opts).n_samples == 100_000


def test_a_batch_file_whose_workers_died_is_an_error_row_in_words():
    from fogdrift.fleet import runner
    from fogdrift.fleet.tasks import FileTask

    class KilledWorker(Exception):  # distributed's exception, by name (the fleet extra may be absent)
        pass

    task = FileTask(path="/d/u0.npy", file="u0.npy", out_dir="/o/u0.npy", rel_out="u0.npy", command="allan",
                    settings={}, settings_sha256="0" * 64)
    exc = KilledWorker("Attempted to run task 'fogdrift-0-abc' on 4 different workers, but all those workers died "
                       "while running it.")
    (row,) = runner._error_rows(task, exc)
    assert row["status"] == "error" and row["error"] == (
        "KilledWorker: the worker process running u0.npy died, on 4 workers in turn (out of memory is the usual "
        "cause: run it alone, or with fewer --workers)")
    (row,) = runner._error_rows(task, ValueError("x"))
    assert row["error"] == "ValueError: x (the task or its worker failed)"


def test_batch_json_is_strict_json(tmp_path, monkeypatch):
    pytest.importorskip("pyarrow")
    from fogdrift.fleet import commands, run_batch
    from fogdrift.fleet.tasks import MANIFEST as BATCH_JSON

    real = commands.command_spec

    class Spec:
        def __init__(self, spec):
            self._spec = spec
            self.name = spec.name

        def run(self, record, settings, out):
            rows = self._spec.run(record, settings, out)
            return [dict(r, N_lo95_dprh=float("nan")) for r in rows]   # an interval the fit could not bound

        def __getattr__(self, name):
            return getattr(self._spec, name)

    monkeypatch.setattr("fogdrift.fleet.tasks.command_spec", lambda name: Spec(real(name)), raising=False)
    monkeypatch.setattr(commands, "command_spec", lambda name: Spec(real(name)))
    p = tmp_path / "u.npy"
    np.save(p, np.random.default_rng(4).normal(size=4000))
    run_batch([p], tmp_path / "o", settings={"load": {"unit": "deg/h", "rate_hz": 100.0}}, scheduler="serial")
    text = (tmp_path / "o" / "u.npy" / BATCH_JSON).read_text()
    doc = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-standard JSON constant {c}"))
    assert doc["rows"][0]["N_lo95_dprh"] is None
