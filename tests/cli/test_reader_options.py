"""Reader options have one home: the ``READERS`` table (issue 21 item 2).

Each reader option is declared once in :mod:`fogdrift.io.registry` (a :class:`ReaderOption`: name, type, help,
flag); :mod:`fogdrift.cli._app` builds the CLI flags, :class:`LoadOptions`, ``FLAGS`` and
``LoadOptions.reader_options()`` from it.  Independent references: the flags and help texts the commands printed
before the table was the one home (written out below by hand), and a toy reader plugged in from outside whose
option values are checked where they arrive (type and value).
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest
from typer.main import get_command
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.cli._app import FLAGS, LOAD_PARAMS, READER_FLAGS, LoadOptions
from fogdrift.errors import ConfigError
from fogdrift.io import registry
from fogdrift.io.registry import READERS, ReaderOption, ReaderSpec, cli_options

#: The reader flags and help texts of every command before issue 21 (cli/_app.py LOAD_PARAMS, by hand).
BEFORE = {
    "--temperature": "Temperature column [deg C] carried with the log (bag: a sensor_msgs/Temperature topic; "
                     "miniSEED: a channel).",
    "--topic": "Bag: the sensor_msgs/Imu topic.",
    "--stamp": "Bag: time from 'header' stamps or 'receive' time.",
    "--dataset": "HDF5: dataset or group path, e.g. /imu.",
    "--variable": "MATLAB .mat: variable name.",
    "--gain": "miniSEED: counts per unit, or a StationXML/dataless/RESP response file.",
    "--layout": "Raw binary record as NumPy dtype items, e.g. '<u4 seq, <i4 gx, <i4 gy, <i4 gz'.",
    "--scale": "Raw binary: LSB factor for every field, or per field 'gx=1e-4,temp=0.01'.",
    "--header-bytes": "Raw binary: bytes before the first record.",
    "--sequence": "Raw binary: sequence-counter field (default seq/counter/...; 'none').",
}


def _params(command):
    return {opt: p for p in get_command(app).commands[command].params for opt in p.opts}


@pytest.mark.parametrize("command", ["allan", "noise", "separate", "model", "analyze", "batch", "compensate",
                                     "consistency", "export", "plan"])
def test_every_registry_option_is_a_flag_of_every_reading_command(command):
    params = _params(command)
    for opt in cli_options():
        assert opt.flag in params, (command, opt.flag)
        assert params[opt.flag].help == opt.help
        assert params[opt.flag].default is None
    for flag, text in BEFORE.items():              # the flags and help texts of before, unchanged
        assert params[flag].help == text, (command, flag)


def test_allan_help_lists_every_registry_flag_with_its_help():
    out = CliRunner().invoke(app, ["allan", "--help"], env={"COLUMNS": "400"}).output
    flat = " ".join(out.split())
    for opt in cli_options():
        assert opt.flag in out
        assert " ".join(opt.help.split()) in flat


def test_shared_option_is_one_declaration_and_one_flag():
    holders = [s.name for s in READERS if "temperature" in s.options]
    assert {"rosbag1", "rosbag2", "mseed"} <= set(holders)
    assert [str(o) for o in cli_options()].count("temperature") == 1
    flags = [o.flag for o in cli_options()]
    assert len(flags) == len(set(flags))
    assert [n for n, _, _ in LOAD_PARAMS].count("temperature") == 1
    assert FLAGS["temperature"] == "--temperature"


def test_flag_spelling_and_declaration_checks():
    assert ReaderOption("header_bytes", int, "x").flag == "--header-bytes"
    assert ReaderOption("t", str, "x", flag="--tee").flag == "--tee"
    opt = ReaderOption("topic", str, "x")
    assert opt == "topic" and {opt: 1} == {"topic": 1} and repr(opt) == "'topic'"   # it is the name
    with pytest.raises(AttributeError):
        opt.help = "y"
    with pytest.raises(ConfigError, match="type must be str, int or float"):
        ReaderOption("x", list, "help")
    with pytest.raises(ConfigError, match="a help text is required"):
        ReaderOption("x", str, " ")
    with pytest.raises(ConfigError, match="flag must start with '--'"):
        ReaderOption("x", str, "h", flag="-x")
    with pytest.raises(ConfigError, match="Python identifier"):
        ReaderOption("x-y", str, "h")


def test_one_option_declared_twice_differently_is_refused():
    a = ReaderSpec("a", "a", options=(ReaderOption("gain", str, "A: gain."),))
    b = ReaderSpec("b", "b", options=(ReaderOption("gain", float, "A: gain."),))
    with pytest.raises(ConfigError, match=r"reader option 'gain' is declared twice differently"):
        cli_options((a, b))
    c = ReaderSpec("c", "c", options=(ReaderOption("other", str, "C.", flag="--gain"),))
    with pytest.raises(ConfigError, match=r"share the flag --gain"):
        cli_options((a, c))
    # the same declaration in two lines is one option; a plain string is the library's alone (no flag)
    d = ReaderSpec("d", "d", options=(a.options[0], "delimiter"))
    assert [str(o) for o in cli_options((a, d))] == ["gain"]


def test_reader_options_are_the_set_ones_and_temperature_is_a_load_keyword():
    opts = LoadOptions(file="x.bag", topic="/imu", header_bytes=12, temperature="T")
    assert opts.reader_options() == {"topic": "/imu", "header_bytes": 12}
    kw = opts.load_kwargs()
    assert kw["temperature"] == "T" and kw["reader_options"] == {"topic": "/imu", "header_bytes": 12}
    assert set(kw) == {"columns", "rate_hz", "unit", "time_unit", "time_column", "temperature", "format",
                       "reader_options"}
    assert LoadOptions(file="x.csv").reader_options() == {}
    assert [str(o) for o in READER_FLAGS][0] == "temperature"       # a load() keyword: before --format in --help


def test_flags_known_to_error_messages():
    for name, flag in {"horizons": "--horizons", "calibration": "--calibration", "origin_step": "--origin-step",
                       "spec": "--spec", "header_bytes": "--header-bytes", "topic": "--topic"}.items():
        assert FLAGS[name] == flag


def test_option_for_another_format_is_one_line(tmp_path):
    p = tmp_path / "log.csv"
    p.write_text("t_s,gz[deg/h]\n" + "".join(f"{0.01 * i:.2f},{i % 3}\n" for i in range(200)))
    res = CliRunner().invoke(app, ["allan", str(p), "--topic", "/imu", "--out", str(tmp_path / "o")],
                             env={"COLUMNS": "200"})
    assert res.exit_code == 1
    assert "unknown reader option(s) ['topic'] for text files" in res.output
    assert "Traceback" not in res.output
    res = CliRunner().invoke(app, ["allan", str(p), "--header-bytes", "x"], env={"COLUMNS": "200"})
    assert res.exit_code == 2                                           # an int option: typer's usage error


#: A reader plugged in from outside: one module and one READERS line, and the CLI has its flags.
_PLUGIN = r'''
import json, sys
import numpy as np
from fogdrift.errors import ConfigError
from fogdrift.io import registry
from fogdrift.io.readers.base import Table

class ToyTable(Table):
    format = "toy"
    row_kind = "record"

def open_table(path, *, toy_gain=1.0, toy_skip=0):
    if not isinstance(toy_gain, float) or not isinstance(toy_skip, int):
        raise ConfigError(f"toy options arrived as {type(toy_gain).__name__}, {type(toy_skip).__name__}")
    body = np.loadtxt(path, skiprows=1, delimiter=",")[toy_skip:]
    return ToyTable(path, names=["wz"], units=["deg/s"], data=body[:, 1:] * toy_gain, time_s=body[:, 0])

mod = type(sys)("fogdrift_toy.fmt")
mod.open_table = open_table
sys.modules["fogdrift_toy.fmt"] = mod
registry.READERS = registry.READERS + (registry.ReaderSpec(
    "toy", "fogdrift_toy.fmt", magic=(b"TOYF",), extensions=(".toy",), description="toy format",
    options=(registry.ReaderOption("toy_gain", float, "Toy: gain [-]."),
             registry.ReaderOption("toy_skip", int, "Toy: records skipped."), registry.TEMPERATURE)),)

import typer
from typer.testing import CliRunner
from fogdrift.cli import app
from fogdrift.cli._app import FLAGS, with_load_options

probe = typer.Typer()
got = {}

@probe.command()
@with_load_options
def read(load):
    rec = load.load()
    got.update(rates=rec.rate_dph[:, 0].tolist(), reader_options=load.reader_options())

help_text = CliRunner().invoke(app, ["allan", "--help"], env={"COLUMNS": "300"}).output
res = CliRunner().invoke(probe, [sys.argv[1], "--toy-gain", "2.5", "--toy-skip", "3"])
print(json.dumps({"help": help_text, "code": res.exit_code, "out": res.output, "got": got, "flags": FLAGS}))
'''


def test_a_plugged_in_reader_with_options_needs_no_cli_edit(tmp_path):
    p = tmp_path / "log.toy"
    rates = [0.5, -1.0, 2.0, 4.0, -3.0, 1.5, 0.25, 8.0]                 # deg/s
    p.write_text("TOYF\n" + "".join(f"{0.1 * i:.1f},{r}\n" for i, r in enumerate(rates)))
    script = tmp_path / "plugin.py"
    script.write_text(textwrap.dedent(_PLUGIN))
    proc = subprocess.run([sys.executable, str(script), str(p)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    res = json.loads(proc.stdout.strip().splitlines()[-1])
    assert "--toy-gain" in res["help"] and "Toy: gain [-]." in res["help"] and "--toy-skip" in res["help"]
    assert res["help"].count("--temperature") == 1                     # shared: still one flag
    assert res["code"] == 0, res["out"]
    assert res["got"]["reader_options"] == {"toy_gain": 2.5, "toy_skip": 3}
    # deg/s -> deg/h is x3600; gain 2.5 applied; the first 3 records skipped (an int reached the reader)
    assert res["got"]["rates"] == pytest.approx([r * 2.5 * 3600.0 for r in rates[3:]], rel=1e-12)
    assert res["flags"]["toy_gain"] == "--toy-gain"
    assert registry.READERS[-1].name == "text"                         # this process's table is untouched


def test_console_says_where_a_declared_unit_came_from(tmp_path):
    """Text: "declared in the header" (as before); HDF5: "declared by the file"; an unknown declared unit in HDF5
    is named the same way (a bag's "declared by the message definition" is checked in test_io_rosbag_accel)."""
    h5py = pytest.importorskip("h5py")
    import numpy as np

    t = np.arange(4000) * 0.01
    p = tmp_path / "log.h5"
    with h5py.File(p, "w") as f:
        g = f.create_group("imu")
        g.create_dataset("t", data=t).attrs["units"] = "s"
        g.create_dataset("gz", data=np.random.default_rng(1).normal(size=t.size)).attrs["units"] = "deg/s"
    res = CliRunner().invoke(app, ["allan", str(p), "--dataset", "/imu", "--out", str(tmp_path / "o")],
                             env={"COLUMNS": "300"})
    assert res.exit_code == 0, res.output
    assert "units: rate deg/s (declared by the file)" in res.output and "in the header" not in res.output
    q = tmp_path / "log.csv"
    w = np.random.default_rng(2).normal(size=4000)
    q.write_text("t_s,gz[deg/s]\n" + "".join(f"{0.01 * i:.2f},{w[i]:.6f}\n" for i in range(4000)))
    res = CliRunner().invoke(app, ["allan", str(q), "--out", str(tmp_path / "c")], env={"COLUMNS": "300"})
    assert res.exit_code == 0, res.output
    assert "units: rate deg/s (declared in the header)" in res.output
    with h5py.File(p, "a") as f:
        f["imu/gz"].attrs["units"] = "degC"
    res = CliRunner().invoke(app, ["allan", str(p), "--dataset", "/imu", "--out", str(tmp_path / "d")],
                             env={"COLUMNS": "300"})
    assert res.exit_code == 1 and "unknown unit 'degC' declared by the file" in res.output
