"""``fogdrift analyze``'s console: the summary first, short, fitting 80 columns, with a judged verdict when the
held-out block holds enough origins (the ``make demo`` protocol), and every table behind ``--details``."""

from __future__ import annotations

import json
import re

import pytest
from typer.testing import CliRunner

from fogdrift.cli import app

runner = CliRunner()

#: The ``make demo`` protocol (Makefile DEMO_ARGS): first half fitted, second half judged, 150-s calibrations
#: every 30 s, 30- and 60-s horizons.
DEMO = ["--train-fraction", "0.4", "--val-fraction", "0.1", "--calibration", "150", "--origin-step", "30",
        "--horizons", "30,60"]


@pytest.fixture(scope="module")
def demo_run(bundled_path, tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    res = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--models",
                              "ar,persistence", *DEMO, "--out", str(out)], env={"COLUMNS": "80"})
    assert res.exit_code == 0, res.output
    return res.stdout, out


def test_the_summary_is_short_and_its_tables_fit_80_columns(demo_run):
    out, _ = demo_run
    lines = out.splitlines()
    table = [ln for ln in lines if ln[:1] in "┏┃┡│└"]
    assert table and max(len(ln) for ln in table) <= 80
    assert len(lines) <= 40
    assert "Table 2 (test block" not in out and "one-step metrics on the test block" not in out  # in the files
    assert "--details" in out
    # the summary comes before the file list
    assert out.index("Noise of the original output") < out.index("compensation verdict") < out.index("report:")


def test_the_demo_protocol_gives_a_judged_verdict(demo_run):
    out, folder = demo_run
    verdict = [ln for ln in out.splitlines() if ln.startswith("  [")]
    assert len(verdict) == 1 and verdict[0].startswith("  [") and "gz:" in verdict[0]
    assert "CANNOT JUDGE" not in verdict[0]
    doc = json.loads((folder / "analysis.json").read_text())
    ev = doc["axes"][0]["evaluation"]
    assert ev["settings"]["calibration_window_s"] == 150.0 and ev["settings"]["origin_step_s"] == 30.0
    assert ev["settings"]["horizons_s"] == [30.0, 60.0]
    assert ev["headline"]["data"]["outcome"] in ("reduces", "mixed", "none")
    # the held-out block is the second half: 923 samples at 1 Hz; at 60 s with 30-s steps the non-overlapping
    # origins are 1 + floor((n - 1) * 30 / 60), n = (923 - 150 - 60) // 30 + 1
    n = (923 - 150 - 60) // 30 + 1
    assert 60.0 in ev["headline"]["data"]["judged_horizons_s"] and 1 + (n - 1) * 30 // 60 >= 10


def test_details_prints_every_table(bundled_path, tmp_path):
    res = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--models",
                              "persistence", "--no-heading", "--details", "--out", str(tmp_path)],
                        env={"COLUMNS": "250"})
    assert res.exit_code == 0, res.output
    assert "Table 2" in res.stdout and "one-step metrics on the test block (paper's measure)" in res.stdout
    assert "heading error not evaluated (--no-heading)" in res.stdout
    assert "gz: paper's measure (one step ahead" in res.stdout and "beat persistence one step" not in res.stdout


def test_details_flag_practical_table2_rows_the_artefact_check_flags(bundled_path, tmp_path):
    # persistence on the bundled gz: the artefact check flags it at 0.001-0.02 Hz (report and console alike)
    res = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--models",
                              "persistence", *DEMO, "--details", "--out", str(tmp_path)], env={"COLUMNS": "250"})
    assert res.exit_code == 0, res.output
    flagged = [ln for ln in res.stdout.splitlines() if "FLAGGED: improvement partly removes real rate" in ln]
    assert flagged and all("(practical)" in ln for ln in flagged)


@pytest.mark.parametrize("args, message", [
    (["--horizons", "60,x"], "--horizons must be numbers of seconds"),
    (["--horizons", "0"], "--horizons must be positive"),
    (["--calibration", "0"], "--calibration must be a positive number of seconds"),
    (["--origin-step", "nan"], "--origin-step must be a positive number of seconds"),
])
def test_heading_options_are_checked_before_the_work(bundled_path, tmp_path, args, message):
    res = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", *args, "--out", str(tmp_path / "o")])
    assert res.exit_code != 0
    assert message in res.output and "Traceback" not in res.output
    assert "samples x" not in res.output  # refused before the log was read
    assert not (tmp_path / "o").exists()


def test_stacked_cells_keep_the_whole_text():
    from fogdrift.cli.analyze import _short_label, _stacked

    for cell in ("0.3043 [0.237, 0.304]", "n/e (< 1.14)", "39.2 at τ = 117 s", "Q+N", "–"):
        assert re.sub(r"\s+", " ", _stacked(cell)) == cell
    assert _stacked("0.3043 [0.237, 0.304]") == "0.3043\n[0.237, 0.304]"
    assert _short_label("N angle random walk [deg/√h]") == "N [deg/√h]"
    assert _short_label("selected noise model") == "model"
    from fogdrift.cli.analyze import _terse

    assert _terse("40.6 (no model fits, p = 1e-135)") == "40.6 (no model fits)"
    assert _terse("no model fits (best candidate Q+N+S)") == "no model fits (best Q+N+S)"


def test_the_three_axis_summary_fits_80_columns(bundled_path, tmp_path):
    res = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--models", "persistence",
                              "--no-heading", "--out", str(tmp_path)], env={"COLUMNS": "80"})
    assert res.exit_code == 0, res.output
    table = [ln for ln in res.stdout.splitlines() if ln[:1] in "┏┃┡│└"]
    assert max(len(ln) for ln in table) <= 80 and "(continued" not in res.stdout  # one table, three axes


def test_the_headline_holds_no_value_where_no_model_fits(demo_run):
    _, folder = demo_run
    doc = json.loads((folder / "analysis.json").read_text())
    fit = doc["axes"][0]["original"]["noise"]
    rows = {r[0]: r[1] for r in doc["report_summary"]["noise"]["rows"]}
    terms = [label for label in rows if label[:2] in ("N ", "B ", "K ", "R ", "Q ")]
    assert len(terms) == 5
    assert fit["no_fit"]  # the bundled gz at 100 Hz: broad 2.7/5.6 Hz vibration peaks no IEEE term describes
    # a bound, or a labelled slope read-out with its bound: never the best candidate's value
    assert all(rows[t].startswith(("–", "n/e")) or (rows[t].startswith("≈") and "read-out" in rows[t])
               for t in terms), rows
    assert rows["selected noise model"].startswith("no model fits (best candidate ")


def test_the_demo_console_fits_40_rows_of_80_columns(bundled_path, tmp_path):
    """``make demo``'s console (three axes, the demo protocol) in at most 40 rows of an 80-column terminal, long
    lines counted as the rows they wrap to; progress lines are transient on a terminal and go to stderr."""
    res = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--models", "ar,persistence", *DEMO,
                              "--out", str(tmp_path / "demo")], env={"COLUMNS": "80"})
    assert res.exit_code == 0, res.output
    lines = [ln.rstrip() for ln in res.stdout.splitlines()]
    rows = sum(max(1, -(-len(ln) // 80)) for ln in lines)
    assert rows <= 40, "\n".join(lines)
    verdicts = [ln for ln in lines if ln.startswith("  [")]
    assert [v.split("] ")[1][:3] for v in verdicts] == ["gx:", "gy:", "gz:"]
    assert all(len(v) <= 160 for v in verdicts)  # two rows each at most
    screen = [ln for ln in lines if ln.startswith(("  gx: ", "  gy: ", "  gz: "))]
    assert len(screen) == 3 and all(len(ln) <= 80 for ln in screen)
