"""Reading limits (:mod:`fogdrift.io.readers.limits`) pinned rule by rule (issue 24, mutation round 3).

Each limit is checked exactly at its bound and one above it, from hand-computed values (``2G`` = 2 x 2**30
bytes, the 16 MiB expansion floor, 8 bytes per float64 column); the line/row accounting of
:class:`~fogdrift.io.readers.limits.GuardedStream` is checked against ``bytes.splitlines``-style counts written
out by hand and must not depend on how the stream is read (chunks of 1, 2, 7, 64 bytes and whole).
"""

from __future__ import annotations

import io

import pytest

from fogdrift.errors import ConfigError, DataFormatError, ResourceLimitError
from fogdrift.io.readers import limits
from fogdrift.io.readers.limits import GuardedStream

ENVS = (limits.ENV_LINE, limits.ENV_ROWS, limits.ENV_EXPANSION, limits.ENV_MEMORY)
RAISE = "raise it with the environment variable {} (0: no limit) if the file is genuine"
CHUNKS = (1, 2, 7, 64, 1 << 20)


@pytest.fixture(autouse=True)
def clean_env(monkeypatch):
    for name in ENVS:
        monkeypatch.delenv(name, raising=False)
    return monkeypatch


# ---------------------------------------------------------------------------------------------------------------
# the variables


def test_names_and_defaults_by_hand(monkeypatch):
    assert ENVS == ("FOGDRIFT_MAX_LINE_BYTES", "FOGDRIFT_MAX_ROWS", "FOGDRIFT_MAX_EXPANSION", "FOGDRIFT_MAX_MEMORY")
    assert limits.EXPANSION_FLOOR == 16 * 1024 * 1024
    assert limits.max_line_bytes() == 1048576 and isinstance(limits.max_line_bytes(), int)
    assert limits.max_rows() == 1_000_000_000 and isinstance(limits.max_rows(), int)
    assert limits.max_expansion() == 50.0
    monkeypatch.setattr(limits, "_machine_memory", lambda: 10_000_001)
    assert limits.memory_budget() == 5_000_000 and isinstance(limits.memory_budget(), int)
    for name in ENVS:  # blank is unset
        monkeypatch.setenv(name, "   ")
    assert (limits.max_line_bytes(), limits.max_rows(), limits.max_expansion(), limits.memory_budget()) == \
        (1048576, 1_000_000_000, 50.0, 5_000_000)


@pytest.mark.parametrize("text, value", [
    ("512", 512), ("1k", 1024), ("1K", 1024), ("1.5k", 1536), ("2M", 2 << 20), ("2G", 2 << 30), ("1t", 1 << 40),
    ("2GiB", 2 << 30), ("2 gb", 2 << 30), ("3b", 3), (" 4 ", 4), ("1e3", 1000), ("1.5E+1K", 15 << 10), (".5k", 512),
])
def test_sizes_by_hand(monkeypatch, text, value):
    monkeypatch.setenv(limits.ENV_MEMORY, text)
    monkeypatch.setenv(limits.ENV_LINE, text)
    assert limits.memory_budget() == value and isinstance(limits.memory_budget(), int)
    assert limits.max_line_bytes() == value and isinstance(limits.max_line_bytes(), int)


def test_plain_numbers_and_zero_switches_off(monkeypatch):
    monkeypatch.setenv(limits.ENV_ROWS, "2.7")
    assert limits.max_rows() == 2  # int() of the number
    monkeypatch.setenv(limits.ENV_EXPANSION, "2.5")
    assert limits.max_expansion() == 2.5
    monkeypatch.setenv(limits.ENV_EXPANSION, "1e1")
    assert limits.max_expansion() == 10.0
    for name, get in ((limits.ENV_LINE, limits.max_line_bytes), (limits.ENV_ROWS, limits.max_rows),
                      (limits.ENV_EXPANSION, limits.max_expansion), (limits.ENV_MEMORY, limits.memory_budget)):
        for zero in ("0", "0.0", "0G"):
            if zero == "0G" and name in (limits.ENV_ROWS, limits.ENV_EXPANSION):
                continue
            monkeypatch.setenv(name, zero)
            assert get() is None, (name, zero)


@pytest.mark.parametrize("name, text, sizes", [
    (limits.ENV_ROWS, "2M", False), (limits.ENV_ROWS, "-1", False), (limits.ENV_EXPANSION, "ten", False),
    (limits.ENV_EXPANSION, "5x", False), (limits.ENV_MEMORY, "2X", True), (limits.ENV_MEMORY, "-5", True),
    (limits.ENV_LINE, "1 2", True), (limits.ENV_LINE, "k", True), (limits.ENV_MEMORY, "2Gb extra", True),
])
def test_a_bad_value_is_one_line_naming_the_variable(monkeypatch, name, text, sizes):
    monkeypatch.setenv(name, text)
    get = {limits.ENV_ROWS: limits.max_rows, limits.ENV_EXPANSION: limits.max_expansion,
           limits.ENV_MEMORY: limits.memory_budget, limits.ENV_LINE: limits.max_line_bytes}[name]
    with pytest.raises(ConfigError) as info:
        get()
    unit = " (bytes, or with K, M, G, T: 512M, 2G)" if sizes else ""
    assert str(info.value) == f"environment variable {name}={text.strip()!r}: expected a number >= 0{unit}"


@pytest.mark.parametrize("name, text", [(limits.ENV_MEMORY, "1e400"), (limits.ENV_MEMORY, "1e310G"),
                                        (limits.ENV_ROWS, "1e999"), (limits.ENV_EXPANSION, "9e308e1")])
def test_an_overflowing_value_is_one_line_not_a_traceback(monkeypatch, name, text):
    """``FOGDRIFT_MAX_MEMORY=1e400`` parsed to infinity and failed later in ``int()`` with an OverflowError
    traceback (issue 36); it is refused where it is read, naming the variable."""
    monkeypatch.setenv(name, text)
    get = {limits.ENV_ROWS: limits.max_rows, limits.ENV_EXPANSION: limits.max_expansion,
           limits.ENV_MEMORY: limits.memory_budget}[name]
    with pytest.raises(ConfigError, match=name) as info:
        get()
    assert "\n" not in str(info.value)


def test_machine_memory_is_the_smaller_of_ram_and_rlimit_as(monkeypatch):
    import os
    import resource

    pages = {"SC_PHYS_PAGES": 1000, "SC_PAGE_SIZE": 4096}
    monkeypatch.setattr(os, "sysconf", lambda key: pages[key])
    monkeypatch.setattr(resource, "getrlimit", lambda which: (resource.RLIM_INFINITY, resource.RLIM_INFINITY))
    assert limits._machine_memory() == 4_096_000
    monkeypatch.setattr(resource, "getrlimit", lambda which: (1_000_000, resource.RLIM_INFINITY)
                        if which == resource.RLIMIT_AS else (1, 1))
    assert limits._machine_memory() == 1_000_000 and limits.memory_budget() == 500_000
    monkeypatch.setattr(resource, "getrlimit", lambda which: (5_000_000, 5_000_000))  # above the RAM: the RAM
    assert limits._machine_memory() == 4_096_000
    monkeypatch.setattr(resource, "getrlimit", lambda which: (0, 0))  # 0 is no limit
    assert limits._machine_memory() == 4_096_000

    def no_sysconf(key):
        raise ValueError(key)

    monkeypatch.setattr(os, "sysconf", no_sysconf)
    monkeypatch.setattr(resource, "getrlimit", lambda which: (resource.RLIM_INFINITY, resource.RLIM_INFINITY))
    assert limits._machine_memory() == 8 << 30  # the fallback
    monkeypatch.setattr(resource, "getrlimit", lambda which: (3 << 30, resource.RLIM_INFINITY))
    assert limits._machine_memory() == 3 << 30

    def no_rlimit(which):
        raise OSError(which)

    monkeypatch.setattr(resource, "getrlimit", no_rlimit)
    assert limits._machine_memory() == 8 << 30


@pytest.mark.parametrize("n, text", [
    (0, "0 bytes"), (512, "512 bytes"), (1023, "1023 bytes"), (1023.9, "1023 bytes"), (1024, "1 KiB"),
    (1536, "1.5 KiB"), ((1 << 20) - 1, "1.02e+03 KiB"), (1 << 20, "1 MiB"), (1234567, "1.18 MiB"),
    (1 << 30, "1 GiB"), (3 << 29, "1.5 GiB"), (1 << 40, "1 TiB"), (5 << 40, "5 TiB"), (2000 << 40, "2e+03 TiB"),
])
def test_format_bytes_by_hand(n, text):
    assert limits.format_bytes(n) == text


# ---------------------------------------------------------------------------------------------------------------
# the checks, exactly at the bound and one above


def test_rows_at_and_one_above_the_limit(monkeypatch):
    monkeypatch.setenv(limits.ENV_ROWS, "10")
    limits.check_rows(10, "f.csv")
    with pytest.raises(ResourceLimitError) as info:
        limits.check_rows(11, "f.csv")
    e = info.value
    assert e.limit == "FOGDRIFT_MAX_ROWS" and e.path == "f.csv" and e.line is None
    assert e.reason == f"11 rows; expected at most 10 (FOGDRIFT_MAX_ROWS); {RAISE.format('FOGDRIFT_MAX_ROWS')}"
    with pytest.raises(ResourceLimitError, match=r"f\.csv.*12 records.*at most 10"):
        limits.check_rows(12, "f.csv", what="records")
    monkeypatch.setenv(limits.ENV_ROWS, "0")
    limits.check_rows(10 ** 15, "f.csv")


def test_memory_at_and_one_above_the_budget(monkeypatch):
    monkeypatch.setenv(limits.ENV_MEMORY, "1K")
    limits.check_memory(1024, "f.npz", "member 'a'")
    with pytest.raises(ResourceLimitError) as info:
        limits.check_memory(1025, "f.npz", "member 'a'")
    e = info.value
    assert e.limit == "FOGDRIFT_MAX_MEMORY" and e.path == "f.npz"
    assert e.reason == ("member 'a' needs 1 KiB of memory; expected at most the memory budget 1 KiB "
                        f"(FOGDRIFT_MAX_MEMORY); {RAISE.format('FOGDRIFT_MAX_MEMORY')}")
    with pytest.raises(ResourceLimitError, match="needs 2 KiB of memory"):
        limits.check_memory(2048, "f.npz", "x")
    monkeypatch.setenv(limits.ENV_MEMORY, "0")
    limits.check_memory(1 << 60, "f.npz", "x")


def test_expansion_allowed_by_hand(monkeypatch):
    floor = 16 << 20
    assert limits.expansion_allowed(1) == floor
    assert limits.expansion_allowed(floor // 50) == floor  # 50 x stored below the floor
    assert limits.expansion_allowed(1 << 20) == 50 << 20
    monkeypatch.setenv(limits.ENV_EXPANSION, "2")
    assert limits.expansion_allowed(4 << 20) == floor and limits.expansion_allowed(10 << 21) == 40 << 20
    monkeypatch.setenv(limits.ENV_EXPANSION, "0")
    assert limits.expansion_allowed(1) is None


def test_expansion_at_and_one_above_the_limit(monkeypatch):
    stored = 1 << 20  # 1 MiB on disk: 50 MiB allowed
    limits.check_expansion(50 << 20, stored, "b.npz", "member 'x.npy'")
    with pytest.raises(ResourceLimitError) as info:
        limits.check_expansion((50 << 20) + 1, stored, "b.npz", "member 'x.npy'")
    e = info.value
    assert e.limit == "FOGDRIFT_MAX_EXPANSION" and e.path == "b.npz"
    assert e.reason == ("member 'x.npy': 50 MiB declared in a 1 MiB file (50 times its size); expected at most 50 "
                        "times (FOGDRIFT_MAX_EXPANSION, beyond the first 16 MiB); refused before decompressing "
                        f"(a decompression bomb?); {RAISE.format('FOGDRIFT_MAX_EXPANSION')}")
    limits.check_expansion(16 << 20, 1, "b.npz", "m")  # the floor, from a 1-byte file
    with pytest.raises(ResourceLimitError, match=r"in a 1 bytes file \(1.68e\+07 times its size\)"):
        limits.check_expansion((16 << 20) + 1, 1, "b.npz", "m")
    with pytest.raises(ResourceLimitError, match=r"in a 0 bytes file \(1.68e\+07 times"):  # no division by 0
        limits.check_expansion((16 << 20) + 1, 0, "b.npz", "m")
    monkeypatch.setenv(limits.ENV_EXPANSION, "0")
    limits.check_expansion(1 << 50, 1, "b.npz", "m")


# ---------------------------------------------------------------------------------------------------------------
# line breaks and the guarded stream


@pytest.mark.parametrize("chunk, n", [
    (b"", 0), (b"abc", 0), (b"\n", 1), (b"\r", 1), (b"\r\n", 1), (b"\n\r", 2), (b"\r\r\n", 2), (b"a\nb\r\nc\rd", 3),
    (b"\r\n\r\n", 2), (b"x\r", 1), (b"\rx", 1), (b"\n\n\n", 3), (b"\r\r", 2),
])
def test_count_breaks_by_hand(chunk, n):
    assert limits._count_breaks(chunk) == n


def _read(data: bytes, k: int, **kw) -> GuardedStream:
    gs = GuardedStream(io.BytesIO(data), "t.csv", **kw)
    buf = bytearray(k)
    got = b""
    while True:
        n = gs.readinto(buf)
        if not n:
            break
        got += bytes(buf[:n])
    assert got == data  # the bytes pass through unchanged
    return gs


TEXT = b"t,gz\n1,2\r\n3,4\r5,6\n\n7,8\r\r\n9"  # breaks: \n, \r\n, \r, \n, \n, \r, \r\n = 7; last line '9'


@pytest.mark.parametrize("k", CHUNKS)
def test_lines_and_bytes_do_not_depend_on_the_chunk_size(k):
    gs = _read(TEXT, k)
    assert gs.lines == 7 and gs.total == len(TEXT) and gs.current == 1
    assert gs.readable() is True
    gs = _read(TEXT + b"\r", k)
    assert gs.lines == 8 and gs.current == 0
    gs = _read(b"abcdef", k)
    assert gs.lines == 0 and gs.current == 6 and gs.total == 6


def _err(data, k, **kw) -> ResourceLimitError | DataFormatError | None:
    try:
        _read(data, k, **kw)
    except DataFormatError as exc:
        return exc
    return None


@pytest.mark.parametrize("k", CHUNKS)
def test_line_limit_exactly_at_and_one_above(monkeypatch, k):
    monkeypatch.setenv(limits.ENV_LINE, "10")
    ok = b"a\n" + b"x" * 10 + b"\r\n" + b"y" * 10 + b"\r" + b"z" * 10  # three lines of exactly 10 bytes
    assert _err(ok, k) is None
    msg = ("line longer than 10 bytes (more than 10 bytes without a line break); expected at most 10 bytes per line "
           f"(FOGDRIFT_MAX_LINE_BYTES); {RAISE.format('FOGDRIFT_MAX_LINE_BYTES')}")
    for data, line in ((b"a\n" + b"x" * 11 + b"\nb\n", 2), (b"x" * 11, 1), (b"a\rb\r\n" + b"y" * 11 + b"\r", 3),
                       (b"a\nb\n" + b"z" * 11, 3), (b"q" * 11 + b"\n", 1), (b"a\n" + b"x" * 9 + b"\nb\n" + b"w" * 11
                                                                         + b"\nc\n", 4)):
        e = _err(data, k)
        assert isinstance(e, ResourceLimitError), (data, k)
        assert e.limit == "FOGDRIFT_MAX_LINE_BYTES" and e.line == line and e.reason == msg, (data, k, e.line)
    monkeypatch.setenv(limits.ENV_LINE, "0")
    assert _err(b"x" * 5000, k) is None


def test_survivors_of_the_workqueue_rerun(monkeypatch):
    """The five non-equivalent mutants the re-run with NUMBA_THREADING_LAYER=workqueue decided as survivors."""
    import resource

    monkeypatch.setenv(limits.ENV_ROWS, "1E3")  # a plain number takes an upper-case exponent too
    assert limits.max_rows() == 1000
    monkeypatch.setenv(limits.ENV_EXPANSION, "2.5E1")
    assert limits.max_expansion() == 25.0
    monkeypatch.delenv(limits.ENV_ROWS)
    monkeypatch.setattr(limits.os, "sysconf", lambda key: {"SC_PHYS_PAGES": 1000, "SC_PAGE_SIZE": 4096}[key])
    monkeypatch.setattr(resource, "getrlimit", lambda which: (1, resource.RLIM_INFINITY))
    assert limits._machine_memory() == 1  # a soft limit of one byte is a limit (only 0 means none)
    monkeypatch.undo()
    for name in ENVS:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv(limits.ENV_MEMORY, "10")
    assert GuardedStream(io.BytesIO(b""), "p", bytes_per_row=1).max_lines == 10  # 10 bytes / 1 byte per row
    monkeypatch.delenv(limits.ENV_MEMORY)
    monkeypatch.setenv(limits.ENV_LINE, "10")
    for k in CHUNKS:  # a first line that is empty: no CR came before the first LF
        e = _err(b"\n" + b"x" * 11 + b"\n", k)
        assert isinstance(e, ResourceLimitError) and e.line == 2, (k, e)
        assert _read(b"\n\n", k).lines == 2
    monkeypatch.setenv(limits.ENV_LINE, "0")  # no line limit, a file with breaks: chunks longer than anything
    for k in CHUNKS:
        gs = _read(b"a\n" + b"x" * 5000 + b"\r\nb", k)
        assert gs.lines == 2 and gs.current == 1 and gs.max_line is None


def test_a_long_line_inside_one_chunk_is_found_with_its_line_number(monkeypatch):
    monkeypatch.setenv(limits.ENV_LINE, "4")
    # read whole: the long line (5 bytes) lies between two breaks inside one chunk longer than the limit
    for data, line in ((b"ab\ncd\nEEEEE\nf\n", 3), (b"ab\r\ncd\r\nEEEEE\r\nf\r\n", 3), (b"a\rEEEEE\rb\r", 2),
                       (b"a\nbb\nccc\nEEEEE\ndddd\n" + b"x\n" * 10, 4), (b"a\nEEEEE\nb\nFFFFFF\nc\n", 2)):
        for k in (len(data), 64):
            e = _err(data, k)
            assert isinstance(e, ResourceLimitError) and e.line == line, (data, k, e)
            assert "more than 4 bytes without a line break" in e.reason
    assert _err(b"a\nbbbb\ncccc\ndddd\n" * 3, 64) is None
    e = _err(b"a\nbbbb\nEEEEE\nc\n", 64)  # a line exactly at the limit before the long one
    assert isinstance(e, ResourceLimitError) and e.line == 3
    e = _err(b"a\nEEEEE\n", 64)  # two breaks in the chunk: the line between them
    assert isinstance(e, ResourceLimitError) and e.line == 2
    assert _err(b"abcd\nefgh", 64) is None and _err(b"ab\rcd", 64) is None  # one break: nothing inside


@pytest.mark.parametrize("k", CHUNKS)
def test_rows_exactly_at_and_one_above(monkeypatch, k):
    monkeypatch.setenv(limits.ENV_ROWS, "5")
    assert _err(b"1\n2\n3\n4\n5\n", k) is None
    assert _err(b"1\r\n2\r\n3\r\n4\r\n5\r\n6", k) is None  # 5 breaks; the last line is not counted yet
    e = _err(b"1\n2\n3\n4\n5\n6\n", k)
    assert isinstance(e, ResourceLimitError) and e.limit == "FOGDRIFT_MAX_ROWS" and e.path == "t.csv"
    assert e.reason == (f"more than 5 lines; expected at most 5 (FOGDRIFT_MAX_ROWS); stopped while reading; "
                        f"{RAISE.format('FOGDRIFT_MAX_ROWS')}")
    e = _err(b"1\r2\r3\r4\r5\r6\r", k)
    assert isinstance(e, ResourceLimitError) and e.limit == "FOGDRIFT_MAX_ROWS"


@pytest.mark.parametrize("k", (1, 7, 64))
def test_memory_limits_the_lines_by_bytes_per_row(monkeypatch, k):
    monkeypatch.setenv(limits.ENV_MEMORY, "80")  # 80 bytes / (2 columns x 8 bytes) = 5 lines
    assert _err(b"1,2\n" * 5, k, bytes_per_row=16) is None
    e = _err(b"1,2\n" * 6, k, bytes_per_row=16)
    assert isinstance(e, ResourceLimitError) and e.limit == "FOGDRIFT_MAX_MEMORY" and e.path == "t.csv"
    assert e.reason == ("more than 5 lines of 2 columns: the table would need more than 80 bytes of memory; expected "
                        "at most the memory budget 80 bytes (FOGDRIFT_MAX_MEMORY); stopped while reading; "
                        f"{RAISE.format('FOGDRIFT_MAX_MEMORY')}")
    assert _err(b"1,2\n" * 6, k, bytes_per_row=0) is None  # no memory check without a row size
    monkeypatch.setenv(limits.ENV_ROWS, "3")  # the rows limit is the smaller one now: it is the one named
    e = _err(b"1,2\n" * 6, k, bytes_per_row=16)
    assert e.limit == "FOGDRIFT_MAX_ROWS" and "more than 3 lines;" in e.reason
    monkeypatch.setenv(limits.ENV_ROWS, "5")  # equal: the rows limit is named
    e = _err(b"1,2\n" * 6, k, bytes_per_row=16)
    assert e.limit == "FOGDRIFT_MAX_ROWS" and "more than 5 lines;" in e.reason
    monkeypatch.setenv(limits.ENV_ROWS, "0")  # rows off: the memory budget still counts
    e = _err(b"1,2\n" * 6, k, bytes_per_row=16)
    assert e.limit == "FOGDRIFT_MAX_MEMORY"
    monkeypatch.setenv(limits.ENV_MEMORY, "0")
    assert _err(b"1,2\n" * 60, k, bytes_per_row=16) is None


def test_guarded_stream_limits_as_attributes(monkeypatch):
    monkeypatch.setenv(limits.ENV_MEMORY, "100")
    gs = GuardedStream(io.BytesIO(b""), "p", bytes_per_row=24)
    assert gs.max_lines == 4 and gs.budget == 100 and gs.bytes_per_row == 24 and gs.max_total is None
    assert gs.max_line == 1 << 20 and gs.stored is None and gs.path == "p"
    gs = GuardedStream(io.BytesIO(b""), "p")
    assert gs.max_lines == 1_000_000_000 and gs.budget is None
    gs = GuardedStream(io.BytesIO(b""), "p", stored_bytes=1 << 20)
    assert gs.max_total == 50 << 20 and gs.stored == 1 << 20


def test_expansion_stops_the_decompression_one_byte_above(monkeypatch):
    monkeypatch.setenv(limits.ENV_EXPANSION, "1")
    stored = 17 << 20  # 17 MiB stored at ratio 1: 17 MiB allowed (above the 16 MiB floor)
    body = (b"1234567\n" * ((17 << 20) // 8))
    assert len(body) == 17 << 20
    gs = _read(body, 1 << 20, stored_bytes=stored)
    assert gs.lines == (17 << 20) // 8
    e = _err(body + b"9", 1 << 20, stored_bytes=stored)
    assert isinstance(e, ResourceLimitError) and e.limit == "FOGDRIFT_MAX_EXPANSION"
    assert e.reason == (f"gzip content exceeds 17 MiB after {(17 << 20) // 8} lines (more than 1 times the file's "
                        "17 MiB); expected at most 1 times (FOGDRIFT_MAX_EXPANSION, beyond the first 16 MiB): stopped "
                        f"while decompressing (a decompression bomb?); {RAISE.format('FOGDRIFT_MAX_EXPANSION')}")
    assert _err(body + b"9", 1 << 20) is None  # not compressed: no expansion limit


@pytest.mark.parametrize("k", (1, 7, 64, 9000))
def test_nul_bytes_in_the_first_8000_bytes_are_refused_with_their_place(k):
    data = b"t,gz\r\n1,2\n3,4\r5\x006\n"
    e = _err(data, k, binary_check=True)
    assert type(e) is DataFormatError and e.line == 4 and e.path == "t.csv"
    assert e.reason == ("NUL byte at byte 16 of the decompressed content; expected text (gzip holds binary data, not "
                        "a CSV/TXT log)")
    assert _err(data, k) is None  # not asked to check
    assert _err(b"\x00", k, binary_check=True).reason.startswith("NUL byte at byte 1 ")
    head = b"1,2\n" * 1999 + b"333"  # 7999 bytes
    assert _err(head + b"\x00", k, binary_check=True).line == 2000  # the 8000th byte is still checked
    assert _err(head + b"4\x00", k, binary_check=True) is None  # the 8001st is not


def test_close_closes_the_inner_streams_and_swallows_their_errors():
    class Bad(io.BytesIO):
        def close(self):
            super().close()
            raise OSError("corrupt trailer")

    inner, under = Bad(b"1\n"), io.BytesIO(b"")
    gs = GuardedStream(inner, "p", closing=(under,))
    gs.close()
    assert gs.closed and inner.closed and under.closed
    gs.close()  # twice is fine
    assert gs.closed
