"""The modelling stage's settings table (fogdrift.models.settings): one declaration per setting gives the
AnalysisConfig default, the rule validate() applies, and the CLI option (flag, type, default, help).

Independent checks: the rules against hand-picked values at and beside their bounds; the defaults against the
dataclass fields; the CLI's help and values through typer's own runner; a toy row reaching a toy command.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from fogdrift.errors import ConfigError
from fogdrift.models import settings as S
from fogdrift.pipeline import AnalysisConfig

ROWS = S.MODEL_SETTINGS


def test_rules_at_and_beside_their_bounds():
    one = S.Integer(1)
    assert one.holds(1) and one.holds(np.int64(7)) and one.holds(10**12)
    assert not any(one.holds(v) for v in (0, -3, True, 1.5, "2", None, np.float64(2.0)))
    open_ = S.Number(0.0, 1.0)
    assert open_.holds(0.5) and open_.holds(np.float32(0.25)) and open_.holds(1e-12)
    assert not any(open_.holds(v) for v in (0.0, 1.0, -0.1, math.nan, math.inf, False, "0.5", None))
    left = S.Number(0.0, 1.0, "left")
    assert left.holds(0.0) and not left.holds(1.0)
    above = S.Number(0.0)
    assert above.holds(1e9) and not above.holds(0.0) and not above.holds(math.inf)
    assert S.Number(0.0, 1.0, "both").describe() == "a number in [0, 1]" and above.describe() == "a number > 0"
    choice = S.Choice(("bptt", "bp"))
    assert choice.holds("bp") and not choice.holds("BP") and not choice.holds(None)
    with pytest.raises(ConfigError) as info:
        one.check("lags", 0)
    msg = info.value.args[0]  # by its meaning: the option, the rule's bound, the value given
    assert msg.startswith("{opt:lags} ") and "integer >= 1" in msg and msg.endswith("got 0")


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r.name)
def test_a_row_is_the_config_field_its_default_and_its_flag(row):
    fields = {f.name: f for f in dataclasses.fields(AnalysisConfig)}
    assert row.name in fields
    assert fields[row.name].default == row.default and row.rule.holds(row.default)
    assert isinstance(row.default, row.rule.type)
    assert row.flag.startswith("--") and row.help.endswith(".")


def _bad(rule):
    if isinstance(rule, S.Integer):
        return rule.low - 1
    if isinstance(rule, S.Number):
        return rule.high if math.isfinite(rule.high) else rule.low
    return "no-such-choice"


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r.name)
def test_validate_applies_each_rows_rule_and_names_its_option(row):
    cfg = AnalysisConfig(**{row.name: _bad(row.rule)})
    with pytest.raises(ConfigError) as info:
        cfg.validate()
    assert f"{{opt:{row.name}}}" in info.value.args[0]  # the CLI spells it as the row's flag


def test_the_cli_options_come_from_the_rows():
    from fogdrift.cli import app
    from fogdrift.cli._app import FLAGS

    text = CliRunner().invoke(app, ["analyze", "--help"], env={"COLUMNS": "300"}).output
    lines = text.splitlines()
    for row in ROWS:  # analyze offers every setting of the stage
        at = next(i for i, ln in enumerate(lines) if ln.strip().startswith(row.flag + " "))
        block = " ".join(lines[at:at + 3])
        block = " ".join((block[:block.index("  --", 3)] if "  --" in block[3:] else block).split())
        assert f"{row.flag} <{row.rule.type.__name__}>" in block and row.help in block
        assert f"[default: {row.default}]" in block
        assert FLAGS[row.name] == row.flag
    model_help = CliRunner().invoke(app, ["model", "--help"], env={"COLUMNS": "300"}).output
    assert "--hidden" in model_help and "--gm-window" not in model_help  # a command names the rows it offers


def test_a_new_row_is_an_option_of_the_commands_that_name_it(monkeypatch):
    toy = S.Setting("toy_gain", 2, S.Integer(1), "--toy-gain", "A toy setting [samples].")
    monkeypatch.setitem(S._BY_NAME, "toy_gain", toy)
    from fogdrift.cli._settings import with_settings

    got = {}
    probe = typer.Typer(rich_markup_mode=None)  # as the fogdrift app: "[samples]" is a unit, not markup

    @probe.command()
    @with_settings("toy_gain", "seed")
    def run(name: str = "x", settings: dict = None, last: int = 0):
        got.update(settings, name=name, last=last)

    res = CliRunner().invoke(probe, ["--toy-gain", "5", "--last", "3"])
    assert res.exit_code == 0, res.output
    assert got == {"toy_gain": 5, "seed": 0, "name": "x", "last": 3}
    helped = CliRunner().invoke(probe, ["--help"], env={"COLUMNS": "300"}).output
    assert "--toy-gain" in helped and "A toy setting [samples]." in helped and "[default: 2]" in helped
    with pytest.raises(TypeError, match="settings"):
        with_settings("seed")(lambda name="x": None)
