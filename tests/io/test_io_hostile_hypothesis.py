"""Every reader against hostile bytes (issue 23, item 6): nothing but a project error escapes ``fogdrift.io.load``.

For every format in :data:`fogdrift.io.registry.READERS`: the reader's magic prefix followed by a random tail, random
bytes under the reader's extension, and (formats without magic bytes) random bytes through the reader forced by
name; a ROS 2 bag directory with a random ``metadata.yaml``.  Each load returns a record or raises a
:class:`~fogdrift.errors.FogdriftError` whose message is one line and names the file; anything else (IndexError,
MemoryError, a parser's own exception) fails the test.  ``tests/io/test_io_fuzz.py`` covers text and NumPy contents in
depth; this module covers the breadth of the registry.

Budget: ``HOSTILE_EXAMPLES`` (default 100) examples per magic prefix, half that per extension and per forced
reader, derandomized (about 20 s).  The long run
(``FOGDRIFT_HOSTILE_EXAMPLES=400``: 7 200 examples, derandomized; with ``FOGDRIFT_HYPOTHESIS=explore``
randomized) is run by hand; its counts are in the commit messages of this module.
"""

from __future__ import annotations

import os
import warnings

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fogdrift.errors import FogdriftError, FogdriftWarning
from fogdrift.io import GyroRecord, load
from fogdrift.io.registry import READERS

HOSTILE_EXAMPLES = int(os.environ.get("FOGDRIFT_HOSTILE_EXAMPLES", "100"))
HOSTILE = settings(max_examples=HOSTILE_EXAMPLES, deadline=None,
                   derandomize=os.environ.get("FOGDRIFT_HYPOTHESIS") != "explore",  # conftest's profiles
                   suppress_health_check=[HealthCheck.too_slow])
#: Half the budget for the cases that reach the same parsers by another door (extension, format forced by name).
HOSTILE_HALF = settings(HOSTILE, max_examples=max(HOSTILE_EXAMPLES // 2, 1))

#: Options that let a load reach past the unit and rate checks to the parser's depths.
OPTIONS = st.sampled_from([{"unit": "deg/h", "rate_hz": 100.0}, {"unit": "deg/h"}, {"unit": "deg/h", "dt_s": 0.01,
                           "time_column": None}, {}])

#: A layout for the raw binary reader, which has no magic bytes nor extension (it is chosen by its layout).
BINARY_OPTIONS = {"reader_options": {"layout": "<u2 seq, <i2 gx, <f4 gy", "header_bytes": 3}}

TAILS = st.one_of(
    st.binary(max_size=600),
    st.binary(min_size=1, max_size=16).map(lambda b: b * 64),          # repeated patterns: counts, sizes, offsets
    st.sampled_from([b"", b"\x00" * 120, b"\xff" * 120, b" " * 200, b"\n" * 50]),
)

_MAGIC = [(spec.name, m) for spec in READERS for m in spec.magic]
#: One extension per reader (a reader's extensions all lead to it: ``.log`` and ``.csv`` take the same path).
_EXT = [(spec.name, spec.extensions[0]) for spec in READERS if spec.extensions]


def check(path, options) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FogdriftWarning)
        warnings.simplefilter("ignore", UserWarning)   # third-party parsers' own warnings are not errors
        warnings.simplefilter("ignore", RuntimeWarning)
        try:
            rec = load(path, **options)
        except FogdriftError as exc:
            msg = str(exc)
            assert msg and "\n" not in msg and "{opt:" not in msg, msg
            assert str(path) in msg, msg
            return
    assert isinstance(rec, GyroRecord) and rec.n_samples >= 1


def test_every_reader_is_covered():
    names = {spec.name for spec in READERS}
    covered = {n for n, _ in _MAGIC} | {n for n, _ in _EXT} | {"binary"}
    assert names <= covered, names - covered


@pytest.mark.parametrize("name,magic", _MAGIC, ids=[f"{n}-{m[:6]!r}" for n, m in _MAGIC])
@HOSTILE
@given(tail=TAILS, options=OPTIONS)
def test_magic_prefix_and_random_tail(tmp_path_factory, name, magic, tail, options):
    spec = next(s for s in READERS if s.name == name)
    ext = spec.extensions[0] if spec.extensions else ".bin"
    p = tmp_path_factory.mktemp(name) / f"f{ext}"
    p.write_bytes(magic + tail)
    check(p, options)


@pytest.mark.parametrize("name,ext", _EXT, ids=[f"{n}-{e}" for n, e in _EXT])
@HOSTILE_HALF
@given(body=TAILS, options=OPTIONS)
def test_random_bytes_under_the_extension(tmp_path_factory, name, ext, body, options):
    p = tmp_path_factory.mktemp(name) / f"f{ext}"
    p.write_bytes(body)
    check(p, options)


@pytest.mark.parametrize("name", [s.name for s in READERS if s.name not in ("rosbag2",)])
@HOSTILE_HALF
@given(body=TAILS)
def test_random_bytes_through_the_reader_forced_by_name(tmp_path_factory, name, body):
    p = tmp_path_factory.mktemp(name) / "f.dat"
    p.write_bytes(body)
    options = dict(BINARY_OPTIONS) if name == "binary" else {"format": name}
    check(p, {**options, "unit": "deg/h", "rate_hz": 100.0})


@HOSTILE
@given(metadata=st.one_of(st.binary(max_size=400), st.text(max_size=300).map(str.encode),
                          st.sampled_from([b"rosbag2_bagfile_information:\n  version: 5\n",
                                           b"rosbag2_bagfile_information:\n  relative_file_paths: [../../etc]\n",
                                           b"- [", b"a: &a [*a]\n"])),
       db=st.binary(max_size=200))
def test_ros2_bag_directory_with_random_metadata(tmp_path_factory, metadata, db):
    d = tmp_path_factory.mktemp("bag") / "bag"
    d.mkdir()
    (d / "metadata.yaml").write_bytes(metadata)
    (d / "bag_0.db3").write_bytes(b"SQLite format 3\x00" + db)
    check(d, {"unit": "deg/h", "rate_hz": 100.0})
