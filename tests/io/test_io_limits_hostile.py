"""Limits on every reader and every JSON/YAML input, encodings and compressions named, terminal output escaped
(issue 36, deliver 3).  Each limit is checked at its boundary (the last allowed value passes, the next is refused)
so an off-by-one or a dropped check fails here; never a traceback, one line naming the file, what and the limit.
"""

from __future__ import annotations

import bz2
import gzip
import io
import json
import lzma

import numpy as np
import pytest
from rich.console import Console
from typer.testing import CliRunner

from fogdrift import documents
from fogdrift.cli import app
from fogdrift.cli._safe import SafeConsole, visible
from fogdrift.errors import DataFormatError, ResourceLimitError
from fogdrift.io import load

runner = CliRunner()
TEXT = "t_s,gz[deg/s]\n" + "".join(f"{k * 0.01:.2f},{0.1 * (-1) ** k:.3f}\n" for k in range(400))


# ------------------------------------------------------------------------------------------
# Encodings and compressions named
# ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("data,named", [
    (TEXT.encode("utf-16"), "UTF-16 text (little-endian"),
    (TEXT.encode("utf-16-be").join([b"\xfe\xff", b""]), "UTF-16 text (big-endian"),
    (TEXT.encode("utf-32"), "UTF-32 text (little-endian"),
    (bz2.compress(TEXT.encode()), "bzip2-compressed"),
    (lzma.compress(TEXT.encode()), "xz-compressed"),
    (b"\x28\xb5\x2f\xfd" + bytes(64), "Zstandard-compressed"),
    (b"\x04\x22\x4d\x18" + bytes(64), "LZ4-compressed"),
])
def test_foreign_encodings_and_compressions_are_named(tmp_path, data, named):
    path = tmp_path / "log.csv"
    path.write_bytes(data)
    with pytest.raises(DataFormatError) as ei:
        load(path)
    text = str(ei.value)
    assert named in text and "expected UTF-8 (or ASCII) text, plain or gzip" in text and str(path) in text


def test_a_header_that_begins_with_bzh_is_text(tmp_path):
    path = tmp_path / "log.csv"
    path.write_text(TEXT.replace("t_s,gz", "t_s,BZh").replace("t_s,", "", 0))
    path.write_text("BZhx[deg/s],t_s\n" + "".join(f"{0.1 * (-1) ** k:.3f},{k * 0.01:.2f}\n" for k in range(400)))
    assert load(path).axis_names == ("BZhx",)


def test_the_cli_names_the_encoding_in_one_line(tmp_path):
    path = tmp_path / "log.csv"
    path.write_bytes(TEXT.encode("utf-16"))
    res = runner.invoke(app, ["allan", str(path), "--out", str(tmp_path / "o")])
    assert res.exit_code == 1 and len(res.output.strip().splitlines()) == 1, res.output
    assert "UTF-16 text" in res.output and "Traceback" not in res.output


# ------------------------------------------------------------------------------------------
# Columns (text fields, array columns, npz members) and the text preamble
# ------------------------------------------------------------------------------------------
def _wide_csv(path, n_cols, gz=False):
    head = ",".join(["t_s"] + [f"c{j}[deg/s]" for j in range(n_cols - 1)])
    rows = "".join(",".join([f"{k * 0.01:.2f}"] + ["0.1"] * (n_cols - 1)) + "\n" for k in range(40))
    body = (head + "\n" + rows).encode()
    path.write_bytes(gzip.compress(body) if gz else body)
    return path


def test_5000_columns_in_60_kb_of_gzip_are_refused_at_the_header(tmp_path):
    path = _wide_csv(tmp_path / "wide.csv.gz", 5001, gz=True)
    assert path.stat().st_size < 100_000
    with pytest.raises(ResourceLimitError) as ei:
        load(path)
    assert "5001 columns" in str(ei.value) and "expected at most 1024 (FOGDRIFT_MAX_COLUMNS" in str(ei.value)


def test_the_column_limit_at_its_boundary(tmp_path, monkeypatch):
    monkeypatch.setenv("FOGDRIFT_MAX_COLUMNS", "4")
    assert load(_wide_csv(tmp_path / "four.csv", 4)).n_axes == 3  # the last allowed count passes
    with pytest.raises(ResourceLimitError, match="5 columns"):
        load(_wide_csv(tmp_path / "five.csv", 5))
    monkeypatch.setenv("FOGDRIFT_MAX_COLUMNS", "0")  # 0: no limit
    assert load(_wide_csv(tmp_path / "five.csv", 5)).n_axes == 4


def test_an_array_of_20000_axes_is_refused_as_likely_transposed(tmp_path):
    np.save(tmp_path / "wide.npy", np.zeros((50, 20_000)))
    with pytest.raises(ResourceLimitError) as ei:
        load(tmp_path / "wide.npy", rate_hz=100, unit="deg/s")
    assert "20000 columns" in str(ei.value) and "50 rows x 20000 columns: stored transposed?" in str(ei.value)


def test_an_npz_of_3000_members_is_refused_before_reading_them(tmp_path, monkeypatch):
    np.savez(tmp_path / "many.npz", **{f"m{i}": np.zeros(4) for i in range(3000)})
    with pytest.raises(ResourceLimitError, match=r"3000 members \(arrays\); expected at most 1024"):
        load(tmp_path / "many.npz", rate_hz=100, unit="deg/s")
    monkeypatch.setenv("FOGDRIFT_MAX_COLUMNS", "2")
    np.savez(tmp_path / "two.npz", a=np.zeros(400), b=np.ones(400))
    np.savez(tmp_path / "three.npz", a=np.zeros(400), b=np.ones(400), c=np.ones(400))
    assert load(tmp_path / "two.npz", rate_hz=100, unit="deg/s").n_axes == 2
    with pytest.raises(ResourceLimitError, match="3 members"):
        load(tmp_path / "three.npz", rate_hz=100, unit="deg/s")


def test_a_file_of_comment_lines_stops_at_the_preamble_limit(tmp_path, monkeypatch):
    monkeypatch.setenv("FOGDRIFT_MAX_PREAMBLE", "1K")
    ok = tmp_path / "ok.csv"
    ok.write_text("# c\n" * 256 + TEXT)  # 1024 bytes of comments: allowed
    assert load(ok).n_samples == 400
    bad = tmp_path / "bad.csv"
    bad.write_text("# c\n" * 257 + TEXT)
    with pytest.raises(ResourceLimitError) as ei:
        load(bad)
    assert "no header or data row in the first 257 lines" in str(ei.value) and "FOGDRIFT_MAX_PREAMBLE" in str(ei.value)
    assert ":257" in str(ei.value)


# ------------------------------------------------------------------------------------------
# JSON/YAML documents
# ------------------------------------------------------------------------------------------
def test_depth_and_digits_at_their_boundaries():
    deep_ok = "[" * documents.MAX_DEPTH + "]" * documents.MAX_DEPTH
    assert documents.loads(deep_ok) is not None
    with pytest.raises(documents.DocumentError, match=r"nested more than 64 levels"):
        documents.loads("{\"a\":" + deep_ok + "}")
    assert documents.loads("9" * documents.MAX_DIGITS) == int("9" * 100)
    with pytest.raises(documents.DocumentError, match="a number of 101 digits"):
        documents.loads("[1,\n" + "9" * 101 + "]")
    # brackets and digits inside strings are text
    assert documents.loads(json.dumps({"s": "[" * 500 + "9" * 500})) == {"s": "[" * 500 + "9" * 500}


def test_the_line_of_the_offence_is_named(tmp_path):
    p = tmp_path / "spec.json"
    p.write_text('{\n "a": 1,\n "b": ' + "9" * 5000 + "\n}")
    with pytest.raises(documents.DocumentError) as ei:
        documents.read(p)
    assert str(ei.value).startswith(f"{p}:3: a number of 5000 digits")


def test_the_document_size_limit(tmp_path, monkeypatch):
    p = tmp_path / "a.json"
    p.write_text('{"a": 1}')  # 8 bytes
    monkeypatch.setenv("FOGDRIFT_MAX_DOCUMENT", "8")
    assert documents.read(p) == {"a": 1}
    monkeypatch.setenv("FOGDRIFT_MAX_DOCUMENT", "7")
    with pytest.raises(documents.DocumentError, match="8 bytes; expected a JSON/YAML document of at most 7 bytes"):
        documents.read(p)


@pytest.fixture()
def hostile(tmp_path):
    (tmp_path / "big.json").write_text('{"a": ' + "9" * 5000 + "}")
    (tmp_path / "deep.json").write_text("[" * 100_000 + "]" * 100_000)
    (tmp_path / "deep.yaml").write_text("a: " + "[" * 100_000 + "]" * 100_000)
    t = np.arange(4000) * 0.01
    x = np.random.default_rng(0).normal(0, 0.01, t.size)
    np.savetxt(tmp_path / "log.csv", np.column_stack([t, x]), delimiter=",", header="t_s,gz[deg/s]", comments="",
               fmt="%.8g")
    (tmp_path / "bundle").mkdir()
    (tmp_path / "bundle" / "manifest.json").write_text("[" * 100_000 + "]" * 100_000)
    return tmp_path


@pytest.mark.parametrize("args,doc", [
    (["export", "--gyro", "{d}/big.json"], "big.json:1: a number of 5000 digits"),
    (["export", "--gyro", "{d}/deep.json"], "deep.json:1: lists/mappings nested more than 64"),
    (["allan", "{d}/log.csv", "--spec", "{d}/deep.yaml"], "deep.yaml:1: lists/mappings nested more than 64"),
    (["allan", "{d}/log.csv", "--spec", "{d}/big.json"], "big.json:1: a number of 5000 digits"),
    (["plan", "--model", "{d}/big.json"], "big.json:1: a number of 5000 digits"),
    (["consistency", "{d}/log.csv", "--held-out", "{d}/log.csv", "--components", "{d}/deep.json"],
     "--components: "),
    (["compensate", "{d}/bundle", "{d}/log.csv"], "manifest.json:1: lists/mappings nested more than 64"),
])
def test_every_json_yaml_input_refuses_hostile_documents_in_one_line(hostile, args, doc):
    argv = [a.format(d=hostile) for a in args] + ["--out", str(hostile / "out")]
    res = runner.invoke(app, argv)
    text = res.output.strip()
    assert res.exit_code == 1 and len(text.splitlines()) == 1 and text.startswith("error: "), text
    assert doc in text and "Traceback" not in text


def test_a_model_file_of_a_bundle_is_read_within_the_limits(tmp_path):
    from fogdrift.errors import ModelFileError
    from fogdrift.models import load_model

    (tmp_path / "ar.json").write_text('{"format": "fogdrift-model", "x": ' + "[" * 1000 + "]" * 1000 + "}")
    with pytest.raises(ModelFileError, match="nested more than 64 levels"):
        load_model(tmp_path / "ar.json")


# ------------------------------------------------------------------------------------------
# Terminal output escaped
# ------------------------------------------------------------------------------------------
def test_control_characters_are_shown_escaped_and_styles_still_render():
    buf = io.StringIO()
    con = SafeConsole(file=buf, force_terminal=True, color_system="standard", width=200)
    from rich.text import Text

    con.print(Text("warning: ", style="bold yellow") + Text("\x1b[2J\x1b]0;pwned\x07gz\u202e"))
    out = buf.getvalue()
    assert "\\x1b[2J\\x1b]0;pwned" in out and "gz\\u202e" in out  # (rich drops the bell itself)
    assert "\x1b[2J" not in out and "\x07" not in out and "\u202e" not in out
    assert "\x1b[1;33m" in out or "\x1b[33;1m" in out  # rich's own styling is still there
    plain = io.StringIO()
    Console(file=plain, force_terminal=True, highlight=False).print(Text("\x1b[31mred"))
    assert "\x1b[31m" in plain.getvalue()  # what a plain Console would have let through
    assert visible("a\tb") == "a\tb"


def test_a_column_name_with_escape_sequences_is_printed_escaped(tmp_path):
    path = tmp_path / "ansi.csv"
    x = np.random.default_rng(2).normal(0, 0.01, 4000)
    path.write_text("t_s,\x1b[31mgz\x1b[0m[deg/s]\n" + "".join(f"{k * 0.01:.2f},{v:.6f}\n" for k, v in enumerate(x)))
    res = runner.invoke(app, ["allan", str(path), "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    assert "\x1b" not in res.output and "(\\x1b[31mgz\\x1b[0m)" in res.output
