"""The declared settings (fogdrift.models.settings, fogdrift.allan.settings, fogdrift.outliers.OUTLIERS_SETTING):
one declaration per setting gives the AnalysisConfig default, the rule validate() applies, and the CLI option (flag,
type, default, help).  The rules themselves: tests/test_constraints.py.

Independent checks: the defaults against the dataclass fields; a value beside each rule's bound through validate();
the CLI's help and values through typer's own runner; a toy row reaching a toy command.
"""

from __future__ import annotations

import dataclasses
import math

import pytest
import typer
from typer.testing import CliRunner

from fogdrift import constraints as C
from fogdrift.errors import ConfigError
from fogdrift.pipeline import AnalysisConfig
from fogdrift.models.settings import STAGE_SETTINGS

ROWS = STAGE_SETTINGS


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r.name)
def test_a_row_is_the_config_field_its_default_and_its_flag(row):
    fields = {f.name: f for f in dataclasses.fields(AnalysisConfig)}
    assert row.name in fields
    assert fields[row.name].default == row.default and row.rule.holds(row.default)
    if row.parse is None:  # the option's value is the setting's
        assert isinstance(row.default, row.rule.type) and row.text is None
    else:  # the option is text: its default parses to the setting's default
        assert row.parse(row.text) == row.default
    assert row.flag.startswith("--") and row.help.endswith(".")


def _bad(rule):
    from fogdrift.allan.settings import TauGrid, TauRange

    if isinstance(rule, TauGrid):
        return 0
    if isinstance(rule, TauRange):
        return (3.0, 2.0)
    if isinstance(rule, C.Integer):
        return rule.low - 1
    if isinstance(rule, C.Number):
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
        block = block.replace("- ", "-")  # a help line wrapped at a hyphen ("log- spaced")
        assert f"{row.flag} <{'str' if row.parse else row.rule.type.__name__}>" in block and row.help in block
        assert f"[default: {row.default if row.parse is None else row.text}]" in block
        assert FLAGS[row.name] == row.flag
    model_help = CliRunner().invoke(app, ["model", "--help"], env={"COLUMNS": "300"}).output
    assert "--hidden" in model_help and "--gm-window" not in model_help  # a command names the rows it offers
    allan_help = " ".join(CliRunner().invoke(app, ["allan", "--help"], env={"COLUMNS": "300"}).output.split())
    for name in ("estimator", "statistic", "outliers"):  # the Allan stage's rows in allan (and batch) too
        row = next(r for r in ROWS if r.name == name)
        assert f"{row.flag} <str> {row.help} [default: {row.default}]" in allan_help
    for name in ("taus", "fit_tau_s"):  # parsed options: their text default
        row = next(r for r in ROWS if r.name == name)
        assert f"{row.flag} <str> {row.help} [default: {row.text}]" in allan_help
    assert "--hidden" not in allan_help


@pytest.mark.parametrize("name", ["estimator", "statistic", "outliers"])
def test_the_allan_stages_choices_are_read_from_their_tables(name):
    """A statistic, estimator or outlier treatment added to its table is a value of its option: the rule's choices
    are the tables' own (not a copy)."""
    from fogdrift.allan.statistics import ESTIMATORS, STATISTICS
    from fogdrift.outliers import OUTLIER_ACTIONS

    row = next(r for r in ROWS if r.name == name)
    assert tuple(row.rule.values) == {"estimator": ESTIMATORS, "statistic": tuple(STATISTICS),
                                      "outliers": OUTLIER_ACTIONS}[name]


def test_a_new_row_is_an_option_of_the_commands_that_name_it(monkeypatch):
    from fogdrift.models.settings import SETTINGS as CLI_ROWS
    from fogdrift.cli._settings import with_settings

    toy = C.Setting("toy_gain", 2, C.Integer(1), "--toy-gain", "A toy setting [samples].")
    monkeypatch.setitem(CLI_ROWS, "toy_gain", toy)

    got = {}
    probe = typer.Typer(rich_markup_mode=None)  # as the fogdrift app: "[samples]" is a unit, not markup

    @probe.command()
    @with_settings("toy_gain", "seed", "fit_tau_s")
    def run(name: str = "x", settings: dict = None, last: int = 0):
        got.update(settings, name=name, last=last)

    res = CliRunner().invoke(probe, ["--toy-gain", "5", "--last", "3", "--fit-taus", "0.5:300"])
    assert res.exit_code == 0, res.output
    assert got == {"toy_gain": 5, "seed": 0, "fit_tau_s": (0.5, 300.0), "name": "x", "last": 3}
    got.clear()
    assert CliRunner().invoke(probe, []).exit_code == 0 and got["fit_tau_s"] == (None, None)  # the text default
    helped = CliRunner().invoke(probe, ["--help"], env={"COLUMNS": "300"}).output
    assert "--toy-gain" in helped and "A toy setting [samples]." in helped and "[default: 2]" in helped
    with pytest.raises(TypeError, match="settings"):
        with_settings("seed")(lambda name="x": None)


def test_a_parsed_option_refuses_bad_text_in_one_line(tmp_path):
    from fogdrift.cli import app

    res = CliRunner().invoke(app, ["allan", str(tmp_path / "none.csv"), "--fit-taus", "300", "--out",
                                   str(tmp_path / "o")], env={"COLUMNS": "300"})
    out = " ".join(res.output.split())
    assert res.exit_code == 1 and "--fit-taus must look like MIN:MAX" in out and "got '300'" in out
    res = CliRunner().invoke(app, ["allan", str(tmp_path / "none.csv"), "--taus", "0", "--out", str(tmp_path / "p")],
                             env={"COLUMNS": "300"})
    out = " ".join(res.output.split())
    assert res.exit_code == 1 and "--taus must be 'octave', 'decade', 'all' or a number of taus" in out
