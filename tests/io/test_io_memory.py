"""Memory of the load -> spectrum path (issue 23 item 4): no full-length float64 temporaries.

Values are checked bit for bit against the operation they replace (``raw.astype(float64) * scale``,
``np.var``, ``welch(x - x.mean())``); memory by ``tracemalloc``, which sees NumPy's data buffers: a peak of
one output array passes, a second full-length array (the old path) fails.
"""

from __future__ import annotations

import math
import mmap
import os
import tracemalloc

import numpy as np
import pytest

import fogdrift.io as fio
from fogdrift.errors import DataFormatError
from fogdrift.io import _checks
from fogdrift.io._checks import to_dph
from fogdrift.io.readers import npy as npy_reader
from fogdrift.noise import spectral


def _peak_bytes(fn, *args, **kwargs):
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        base = tracemalloc.get_traced_memory()[0]
        out = fn(*args, **kwargs)
        peak = tracemalloc.get_traced_memory()[1] - base
    finally:
        tracemalloc.stop()
    return out, peak


# ---------------------------------------------------------------- io: one float64 array per conversion

def test_to_dph_float32_one_array_bit_identical():
    n = 1 << 21
    raw = np.random.default_rng(0).standard_normal((n, 1)).astype(np.float32) * np.float32(0.37)
    scale = 3600.0  # deg/s -> deg/h
    out, peak = _peak_bytes(to_dph, raw, scale)
    ref = raw.astype(np.float64) * scale
    assert out.dtype == np.float64 and out.shape == (n, 1)
    assert np.array_equal(out.view(np.uint64), ref.view(np.uint64))  # bit for bit
    assert 8 * n <= peak < 8 * n * 1.25  # the output only; a float64 copy then a product would be 16 n


def test_to_dph_per_column_scale_and_ints():
    raw = np.array([[1, -2], [3, 2**53 + 1]], dtype=np.int64)
    scale = np.array([3600.0, 0.5])
    ref = raw.astype(np.float64) * scale
    assert np.array_equal(to_dph(raw, scale), ref)
    assert to_dph(raw, 1.0).tolist() == [[1.0, -2.0], [3.0, float(2**53)]]  # int64 -> float64 rounding kept


def test_to_dph_float64_unit_scale_is_the_input():
    a = np.arange(6.0).reshape(3, 2)
    assert to_dph(a, 1.0) is a


def test_npy_reader_keeps_the_memory_map(tmp_path):
    p = tmp_path / "x.npy"
    np.save(p, np.arange(10, dtype=np.float32))
    table = npy_reader.open_table(p)
    assert table.data.dtype == np.float32 and table.data.shape == (10, 1)
    assert isinstance(table.data.base, np.memmap) or isinstance(table.data, np.memmap)


@pytest.mark.parametrize("unit, scale", [("deg/h", 1.0), ("deg/s", 3600.0), ("rad/s", 3600.0 * 180.0 / math.pi)])
def test_load_float32_npy_values(tmp_path, unit, scale):
    x = (np.random.default_rng(1).standard_normal(5000) * 3.0).astype(np.float32)
    p = tmp_path / "g.npy"
    np.save(p, x)
    rec = fio.load(p, unit=unit, rate_hz=100)
    ref = x.astype(np.float64) * scale
    got = rec.rate_dph[:, 0]
    assert rec.rate_dph.dtype == np.float64
    assert np.max(np.abs(got - ref) / np.abs(ref)) <= 1e-15  # the unit's own factor, to its last digits
    if unit == "deg/s":
        assert np.array_equal(got, x.astype(np.float64) * 3600.0)  # bit for bit


def test_load_float32_npy_nonfinite_is_located(tmp_path):
    x = np.ones(100, dtype=np.float32)
    x[42] = np.nan  # the reader now hands on float32: the scan must still find it, at the right sample
    p = tmp_path / "nan.npy"
    np.save(p, x)
    with pytest.raises(DataFormatError, match=r"non-finite value at sample 42; .* got nan"):
        fio.load(p, unit="deg/s", rate_hz=100)


def test_load_int16_npy_values(tmp_path):
    x = np.array([-32768, -1, 0, 1, 32767] * 10, dtype=np.int16)
    p = tmp_path / "i.npy"
    np.save(p, x)
    rec = fio.load(p, unit="deg/s", rate_hz=10)
    assert rec.rate_dph[:5, 0].tolist() == [-32768 * 3600.0, -3600.0, 0.0, 3600.0, 32767 * 3600.0]


# ---------------------------------------------------------------- spectral: blockwise variance, offset Welch

def test_variance_one_block_is_np_var_bit_for_bit():
    x = np.random.default_rng(2).standard_normal(10_001) * 7.0 + 1e3
    assert spectral._variance(x, x.mean()) == np.var(x)


@pytest.mark.parametrize("block", [1, 7, 4096])
def test_variance_blockwise_against_exact_sum(block):
    x = np.random.default_rng(3).standard_normal(20_000) * 0.5 + 123.0
    mean = x.mean()
    exact = math.fsum((v - mean) ** 2 for v in x.tolist()) / x.size  # population variance (divisor n)
    got = spectral._variance(x, mean, block)
    assert abs(got - exact) <= 1e-12 * exact
    assert abs(got - np.var(x)) <= 1e-12 * exact


def test_variance_hand_value():
    x = np.array([1.0, 2.0, 3.0, 4.0])  # mean 2.5, squared deviations 2.25 + 0.25 + 0.25 + 2.25 = 5
    assert spectral._variance(x, 2.5, 3) == 1.25


def test_variance_memory_is_one_block():
    n, block = 1 << 22, 1 << 16
    x = np.random.default_rng(4).standard_normal(n)
    _, peak = _peak_bytes(spectral._variance, x, x.mean(), block)
    assert peak <= 8 * block * 3  # two blocks at most (the next before the last is freed); np.var: 8 n (32 MiB)


def test_welch_offset_equals_welch_of_the_centred_record():
    x = np.random.default_rng(5).standard_normal(50_000) + 40.0
    mean = x.mean()
    f0, p0, n0 = spectral._welch(x - mean, 100.0, 1024, chunk_samples=8192)
    f1, p1, n1 = spectral._welch(x, 100.0, 1024, chunk_samples=8192, offset=mean)
    assert n0 == n1 and np.array_equal(f0, f1)
    assert np.array_equal(p0, p1)  # same element-wise subtraction: bit for bit


def test_analyse_spectrum_variance_blockwise(monkeypatch):
    t = np.arange(1 << 16) * 0.01
    x = np.random.default_rng(6).standard_normal(t.size) + 2.0 * np.sin(2 * np.pi * 7.0 * t) + 50.0
    one = spectral.analyse_spectrum(x, 0.01)
    monkeypatch.setattr(spectral, "VAR_BLOCK", 1000)
    many = spectral.analyse_spectrum(x, 0.01)
    assert one.variance_dph2 == np.var(x)
    assert abs(many.variance_dph2 - np.var(x)) <= 1e-12 * np.var(x)
    assert [ln.freq_hz for ln in many.lines] == [ln.freq_hz for ln in one.lines]


# ---------------------------------------------------------------- io: mapped pages dropped after the scans

def _resident_bytes():
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * mmap.PAGESIZE


@pytest.mark.parametrize("cols, scale", [([0], 3600.0), ([0, 2], 1.0), ([1, 2], np.array([2.0, 0.5]))])
def test_to_dph_memmap_chunks_bit_identical(tmp_path, monkeypatch, cols, scale):
    raw = (np.random.default_rng(7).standard_normal((1001, 3)) * 5.0).astype(np.float32)
    p = tmp_path / "m.npy"
    np.save(p, raw)
    monkeypatch.setattr(_checks, "CHUNK_ROWS", 4)  # 64-row chunks: 16 chunks, the last one short
    mm = np.load(p, mmap_mode="r")
    got = to_dph(_checks.take_columns(mm, cols), scale)
    ref = raw[:, cols].astype(np.float64) * scale
    assert type(got) is np.ndarray and got.dtype == np.float64
    assert np.array_equal(got, ref)
    assert np.array_equal(np.asarray(mm), raw)  # the map still reads the same after its pages were dropped


@pytest.mark.skipif(not os.path.exists("/proc/self/statm") or not hasattr(mmap, "MADV_DONTNEED"),
                    reason="needs Linux /proc and madvise")
def test_drop_mapped_pages_releases_resident_pages(tmp_path):
    n = 8 << 20  # 32 MiB of float32
    p = tmp_path / "big.npy"
    np.save(p, np.ones(n, dtype=np.float32))
    mm = np.load(p, mmap_mode="r").reshape(-1, 1)
    assert float(mm.sum(dtype=np.float64)) == n  # every page resident now
    before = _resident_bytes()
    _checks.drop_mapped_pages(mm)
    after = _resident_bytes()
    assert before - after >= 0.9 * 4 * n
    assert float(mm[n // 2, 0]) == 1.0  # read again from the file


def test_drop_mapped_pages_ignores_plain_arrays():
    a = np.ones((10, 2))
    _checks.drop_mapped_pages(a)
    assert a.sum() == 20.0


# ---------------------------------------------------------------- a command's memory need against the budget

from fogdrift.errors import ResourceLimitError  # noqa: E402
from fogdrift.io.readers import command_memory as cm  # noqa: E402
from fogdrift.io.readers import limits  # noqa: E402


@pytest.mark.parametrize("command", sorted(cm.COMMAND_BYTES_PER_SAMPLE))
def test_the_need_grows_with_the_samples_and_counts_every_axis(command):
    ns = [0, 1, 10**4, 10**6, 10**7, 10**8, 10**9]
    needs = [cm.command_memory_need(command, n) for n in ns]
    assert needs[0] == cm.FIXED_BYTES and all(b > a for a, b in zip(needs, needs[1:]))
    for axes in (2, 3, 6):  # a record of k axes costs k times the per-sample part (a missing factor fails)
        assert cm.command_memory_need(command, 10**7, axes) - cm.FIXED_BYTES == \
            axes * (cm.command_memory_need(command, 10**7, 1) - cm.FIXED_BYTES)
    # the constants as measured: at 10^8 samples every command is above the 10^8-sample float64 record (0.8 GB)
    assert cm.command_memory_need(command, 10**8) > cm.FIXED_BYTES + 8 * 10**8


def test_the_refusal_names_the_need_the_budget_and_the_variable(monkeypatch):
    need = cm.command_memory_need("analyze", 10**8, 3)
    monkeypatch.setenv(limits.ENV_MEMORY, str(need - 1))
    with pytest.raises(ResourceLimitError) as ei:
        cm.check_command_memory("analyze", 10**8, 3, path="x.npy")
    msg = str(ei.value)
    assert ei.value.limit == "FOGDRIFT_MAX_MEMORY" and "\n" not in msg and msg.startswith("x.npy")
    assert f"needs about {limits.format_bytes(need)}" in msg and "3 axes" in msg
    assert f"memory budget {limits.format_bytes(need - 1)} (FOGDRIFT_MAX_MEMORY)" in msg
    monkeypatch.setenv(limits.ENV_MEMORY, str(need))
    cm.check_command_memory("analyze", 10**8, 3)  # at the budget: allowed
    monkeypatch.setenv(limits.ENV_MEMORY, "0")
    cm.check_command_memory("analyze", 10**12, 6)  # 0: no limit


def test_every_record_a_command_holds_is_counted(monkeypatch):
    from fogdrift.io import from_array

    train = from_array(np.zeros((1000, 2)), dt_s=0.01, axis_names=["gx", "gy"])
    held = from_array(np.zeros((3000, 1)), dt_s=0.01, axis_names=["gx"])
    need = cm.command_memory_need("consistency", 4000, 2)
    monkeypatch.setenv(limits.ENV_MEMORY, str(need - 1))
    cm.check_records_memory("consistency", train)  # the training log alone fits
    with pytest.raises(ResourceLimitError, match="4000 samples x 2 axes"):
        cm.check_records_memory("consistency", train, held)
    monkeypatch.setenv(limits.ENV_MEMORY, str(need))
    cm.check_records_memory("consistency", train, None, held)


def test_the_workflows_refuse_before_any_work(monkeypatch):
    """The check comes first: the plausibility check (the first work of every workflow) is never reached."""
    from fogdrift import pipeline
    from fogdrift.io import from_array
    from fogdrift.workflows import allan, analyze, noise

    def no_work(*a, **k):
        raise AssertionError("work started before the memory check")

    monkeypatch.setattr(allan, "check_record", no_work)
    monkeypatch.setattr(analyze, "check_record", no_work)
    monkeypatch.setattr(pipeline, "treat_outliers", no_work)
    monkeypatch.setattr(pipeline, "_model_record", no_work)
    rec = from_array(np.zeros((5000, 1)), dt_s=0.01, axis_names=["gz"])
    monkeypatch.setenv(limits.ENV_MEMORY, str(cm.FIXED_BYTES))  # the fixed part fits, no record does
    for call in (lambda: allan.run_allan(rec), lambda: noise.run_noise(rec), lambda: analyze.run_analyze(rec),
                 lambda: pipeline.run_allan(rec), lambda: pipeline.run_separation(rec),
                 lambda: pipeline.run_models(rec), lambda: pipeline.run_analysis(rec)):
        with pytest.raises(ResourceLimitError, match="FOGDRIFT_MAX_MEMORY"):
            call()


@pytest.mark.parametrize("command", ["allan", "noise", "analyze", "separate", "model", "consistency", "export"])
def test_a_command_over_the_budget_is_one_line_and_writes_nothing(tmp_path, monkeypatch, command):
    from typer.testing import CliRunner

    from fogdrift.cli import app

    p = tmp_path / "g.npy"
    np.save(p, np.random.default_rng(0).standard_normal(20_000))  # float64: memory-mapped, the reader needs nothing
    out = tmp_path / "o"
    monkeypatch.setenv(limits.ENV_MEMORY, str(cm.FIXED_BYTES))  # above the reader's need, below the command's
    args = [command, str(p), "--unit", "deg/h", "--rate", "100", "--out", str(out)]
    if command == "consistency":
        args += ["--held-out", str(p)]
    result = CliRunner().invoke(app, args)
    text = [ln for ln in result.output.splitlines() if ln.strip() and ln.startswith("error:")]
    assert result.exit_code == 1 and "Traceback" not in result.output, result.output
    assert len(text) == 1 and "FOGDRIFT_MAX_MEMORY" in text[0] and "refused before any work" in text[0], result.output
    assert not out.exists() or not any(out.iterdir())


def test_consistency_counts_its_held_out_logs_before_the_fit(monkeypatch):
    from fogdrift.io import from_array
    from fogdrift.workflows import consistency

    def no_work(*a, **k):
        raise AssertionError("the fit started before the memory check")

    monkeypatch.setattr(consistency, "model_components", no_work)
    train = from_array(np.zeros((10**5, 1)), dt_s=0.01, axis_names=["gz"])
    held = [from_array(np.zeros((10**5, 1)), dt_s=0.01, axis_names=["gz"]) for _ in range(2)]
    need = cm.command_memory_need("consistency", 3 * 10**5)
    assert need - 1 > cm.command_memory_need("allan", 10**5)  # the training log's fit alone would fit
    monkeypatch.setenv(limits.ENV_MEMORY, str(need - 1))
    with pytest.raises(ResourceLimitError, match="consistency on 300000 samples"):
        consistency.run_consistency(train, held)


#: Peak RSS [kB, /usr/bin/time -v] measured on one-axis float32 .npy logs (bench/RESULTS.md, "Memory of every command
#: at 10^8 samples"); consistency read the log twice (training and held-out), so its samples count twice.
MEASURED_KB = {
    "allan": {10**6: 287_620, 10**7: 523_404, 16 * 10**6: 716_592, 10**8: 1_391_876},
    "separate": {10**6: 333_916, 10**7: 523_028, 16 * 10**6: 717_168, 10**8: 1_391_724},
    "model": {10**6: 270_588, 10**7: 523_508, 16 * 10**6: 717_076, 10**8: 1_392_000},
    "noise": {10**6: 287_856, 10**7: 546_052, 16 * 10**6: 739_360, 10**8: 1_414_612},
    "analyze": {10**6: 322_956, 10**7: 524_236, 16 * 10**6: 717_716, 10**8: 1_392_968},
    "consistency": {2 * 10**6: 284_248, 2 * 10**7: 573_032, 32 * 10**6: 767_920, 2 * 10**8: 2_632_956},
}


@pytest.mark.parametrize("command", sorted(MEASURED_KB))
def test_the_estimate_is_above_every_measured_peak_and_not_far_above_at_the_largest(command):
    assert set(MEASURED_KB) == set(cm.COMMAND_BYTES_PER_SAMPLE)
    for n, kb in MEASURED_KB[command].items():
        assert cm.command_memory_need(command, n) >= kb * 1024, (command, n)
    n, kb = max(MEASURED_KB[command].items())
    assert cm.command_memory_need(command, n) <= 1.3 * kb * 1024  # conservative, not wildly so
