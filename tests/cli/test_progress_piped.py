"""Progress when stderr is not a terminal (a pipe, a log file, CI): plain lines instead of a bar (issue 20).

Each stage gets one line as it starts; a stage with a known total (taus, epochs, samples, files) gets a count line
each time it passes another PROGRESS_STEP_PCT %, so at most 100 / PROGRESS_STEP_PCT + 1 per stage; a long silence
gets a "still running" line.  ``--json`` keeps stdout for the JSON alone.

Independent checks: the lines captured from stderr (typer's CliRunner: not a terminal), counted against the
bounds the rule allows and against the stages the pipeline announces (fogdrift.interrupt.checkpoint); the
percentages recomputed from the counts printed beside them.
"""

from __future__ import annotations

import json
import re
import threading
import time

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift import interrupt
from fogdrift.cli import _app as cli_app
from fogdrift.cli import app

runner = CliRunner()
COUNT = re.compile(r"^(?P<label>.+): (?P<pct>\d+) % \((?P<done>\d+) of (?P<total>\d+) (?P<unit>[a-z]+)\)(?P<note>.*)$")
MAX_PER_STAGE = 100 // cli_app.PROGRESS_STEP_PCT + 1


@pytest.fixture(autouse=True)
def _no_quiet_start(request, monkeypatch):
    """The rules below are about the lines a run prints; a run here ends within the quiet start (QUIET_S) that
    keeps short runs silent, so it is switched off, except for the tests of that rule itself."""
    if "quiet_start" not in request.node.name:
        monkeypatch.setattr(cli_app, "QUIET_S", 0.0)


def lines(text: str) -> list[str]:
    return [ln for ln in text.splitlines() if ln.strip()]


def counts(err: str) -> list[re.Match]:
    return [m for m in map(COUNT.match, lines(err)) if m]


def assert_counts_follow_the_rule(err: str, unit: str | None) -> dict[str, list[int]]:
    """Every count line: the percentage is floor(100 done / total) of the numbers beside it; per stage (label) the
    percentages rise, each in a new PROGRESS_STEP_PCT step, at most MAX_PER_STAGE lines.  Returns label -> pcts."""
    per_stage: dict[str, list[int]] = {}
    for m in counts(err):
        assert unit is None or m["unit"] == unit, m.group(0)
        done, total, pct = int(m["done"]), int(m["total"]), int(m["pct"])
        assert 0 <= done <= total and pct == 100 * done // total, m.group(0)
        per_stage.setdefault(m["label"], []).append(pct)
    for label, pcts in per_stage.items():
        steps = [p // cli_app.PROGRESS_STEP_PCT for p in pcts]
        assert steps == sorted(set(steps)), (label, pcts)  # one line per step, rising
        assert len(pcts) <= MAX_PER_STAGE
    return per_stage


# ------------------------------------------------------------------------------------------
# the rule, on the plain-lines display itself
# ------------------------------------------------------------------------------------------
def test_count_lines_one_per_step_whatever_the_number_of_calls(capsys):
    with cli_app._Lines("job") as display:
        display.stage("job · stage one")
        for done in range(0, 1001):  # 1001 calls
            display.count("job · stage one", done, 1000, "samples")
        display.stage("job · stage two")
        for done in (1, 2, 3):  # 3 calls: 33 %, 66 %, 100 %
            display.count("job · stage two", done, 3, "files", note="last finished: c.npy")
        display.stage("job · stage two")  # announced again: not repeated
    err = capsys.readouterr().err
    per_stage = assert_counts_follow_the_rule(err, None)
    assert per_stage["job · stage one"] == list(range(0, 101, 10))
    assert per_stage["job · stage two"] == [33, 66, 100]
    assert [ln for ln in lines(err) if not COUNT.match(ln)] == ["job · stage one", "job · stage two"]
    assert lines(err)[-1] == "job · stage two: 100 % (3 of 3 files); last finished: c.npy"


def test_a_total_that_is_not_known_prints_no_count(capsys):
    with cli_app._Lines("job") as display:
        display.count("job", 5, None, "taus")
        display.count("job", 5, 0, "taus")
    assert capsys.readouterr().err == ""  # nothing before the first stage or count, no "5 of None"


def test_a_long_silence_gets_a_still_running_line(monkeypatch, capsys):
    monkeypatch.setattr(cli_app, "HEARTBEAT_S", 0.02)
    got = []
    with cli_app._Lines("compensate") as display:
        display.stage("compensate · heading-error evaluation")
        for _ in range(6000):  # a hang guard only: ends as soon as the line is there
            got.append(capsys.readouterr().err)
            if "still running" in got[-1]:
                break
            time.sleep(0.01)
    got.append(capsys.readouterr().err)
    err = "".join(got)
    still = [ln for ln in lines(err) if "still running" in ln]
    assert still and all(re.fullmatch(r"compensate · heading-error evaluation: still running \(\d+ s since the "
                                      r"start\)", ln) for ln in still), err
    assert not any(t.name == "fogdrift-progress-heartbeat" for t in threading.enumerate())  # stopped with the block


class FakeClock:
    """The progress lines' clock (cli_app.CLOCK), read by the tests' own hand: no rule depends on the machine's load."""

    def __init__(self, now: float = 1000.0, step: float = 0.0):
        self.now, self.step = now, step

    def __call__(self) -> float:
        self.now += self.step
        return self.now


def test_the_still_running_line_comes_after_heartbeat_s_without_a_line(monkeypatch, capsys):
    clock = FakeClock()
    monkeypatch.setattr(cli_app, "CLOCK", clock)
    with cli_app._Lines("compensate") as display:
        display.stage("compensate · heading-error evaluation")       # a line at t0
        clock.now += cli_app.HEARTBEAT_S - 0.5
        display.beat()                                               # not yet
        assert lines(capsys.readouterr().err) == ["compensate · heading-error evaluation"]
        clock.now += 0.5
        display.beat()                                               # HEARTBEAT_S since the last line
        display.beat()                                               # and not again at once
        clock.now += 10.0
        display.count("compensate · heading-error evaluation", 1, 10, "samples")  # a line: the silence ends
        clock.now += cli_app.HEARTBEAT_S - 1.0
        display.beat()
    assert lines(capsys.readouterr().err) == [
        f"compensate · heading-error evaluation: still running ({cli_app.HEARTBEAT_S:.0f} s since the start)",
        "compensate · heading-error evaluation: 10 % (1 of 10 samples)"]


def test_a_terminal_gets_the_bar_and_a_pipe_the_lines(monkeypatch):
    monkeypatch.setattr(cli_app, "_bar_on_terminal", lambda: True)
    assert isinstance(cli_app._display("x"), cli_app._Bar)
    monkeypatch.setattr(cli_app, "_bar_on_terminal", lambda: False)
    assert isinstance(cli_app._display("x"), cli_app._Lines)


def test_progress_callbacks_still_stop_on_ctrl_c(capsys):
    interrupt.reset()
    try:
        with cli_app.progress("model", ["gz"]) as (allan_cb, epoch_cb):
            interrupt.request()
            with pytest.raises(interrupt.Interrupted):
                epoch_cb(1, 10, 0.5, 0.6)
        with cli_app.progress_count("batch allan", "files") as update:
            with pytest.raises(interrupt.Interrupted):
                update(1, 3)
    finally:
        interrupt.reset()


# ------------------------------------------------------------------------------------------
# the commands, with stderr captured (not a terminal)
# ------------------------------------------------------------------------------------------
def test_allan_piped_prints_each_stage_and_bounded_counts(bundled_path, tmp_path):
    seen = []
    with interrupt.stage_listener(lambda *a: seen.append(a)):
        result = runner.invoke(app, ["allan", str(bundled_path), "--unit", "deg/h", "--columns", "gx,gz",
                                     "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    err = result.stderr
    stage_lines = [ln for ln in lines(err) if ln.startswith("allan · ") and not COUNT.match(ln)]
    assert stage_lines == [f"allan · axis {a} ({k}/2) · Allan variance" for k, a in ((1, "gx"), (2, "gz"))]
    assert len(seen) == 2  # one line per stage the pipeline announced
    per_stage = assert_counts_follow_the_rule(err, "taus")
    assert sorted(per_stage) == stage_lines and all(p[-1] == 100 for p in per_stage.values())
    assert "allan · " not in result.stdout  # progress is on stderr only


def test_model_piped_names_every_model_it_fits(bundled_path, tmp_path):
    result = runner.invoke(app, ["model", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--models",
                                 "ar,persistence", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    stage_lines = [ln for ln in lines(result.stderr) if ln.startswith("model · ")]
    assert stage_lines[:3] == ["model · axis gz (1/1) · separation", "model · axis gz (1/1) · fitting ar",
                               "model · axis gz (1/1) · fitting persistence"]
    assert len(stage_lines) <= 6


def test_json_keeps_stdout_for_the_json_while_progress_goes_to_stderr(bundled_path, tmp_path):
    result = runner.invoke(app, ["allan", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--json",
                                 "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout) == json.loads((tmp_path / "allan.json").read_text())
    assert "allan · axis gz (1/1) · Allan variance: 100 % (" in result.stderr


def _npy_logs(folder, n, samples, seed):
    rng = np.random.default_rng(seed)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for k in range(n):
        p = folder / f"unit{k}.npy"
        np.save(p, rng.normal(0.0, 1.0, samples))
        paths.append(p)
    return paths


def test_batch_piped_prints_its_stages_and_a_line_per_file(tmp_path):
    pytest.importorskip("pyarrow")
    files = _npy_logs(tmp_path / "in", 3, 4000, seed=41)
    result = runner.invoke(app, ["batch", *map(str, files), "--unit", "deg/h", "--rate", "100", "--scheduler",
                                 "serial", "--out", str(tmp_path / "out")])
    assert result.exit_code == 0, result.output
    progress = [ln for ln in lines(result.stderr) if ln.startswith("batch allan")]
    assert progress == ["batch allan · 3 files, serial",
                        "batch allan: 33 % (1 of 3 files); last finished: unit0.npy",
                        "batch allan: 66 % (2 of 3 files); last finished: unit1.npy",
                        "batch allan: 100 % (3 of 3 files); last finished: unit2.npy",
                        "batch allan · writing summary.parquet and fleet.html"]  # no per-file, per-axis stages


def test_compensate_piped_counts_the_samples(tmp_path):
    from fogdrift.bundle import write_bundle
    from fogdrift.io import from_array
    from fogdrift.pipeline import AnalysisConfig, run_models
    from fogdrift.simulate import simulate

    fs = 10.0
    rec = from_array(simulate(20000, 1 / fs, arw_dprh=0.05, rrw_dphrh=2.0, bias_dph=3.0, seed=5)[:, None] / 3600.0,
                     dt_s=1 / fs, unit="deg/s", axis_names=["gz"])
    cfg = AnalysisConfig(models=("ar", "persistence"))
    write_bundle(tmp_path / "bundle", run_models(rec, cfg), cfg, rec)
    x = simulate(12345, 1 / fs, arw_dprh=0.05, rrw_dphrh=2.0, bias_dph=3.0, seed=6) / 3600.0
    np.savetxt(tmp_path / "log.csv", np.column_stack([np.arange(x.size) / fs, x]), delimiter=",",
               header="t_s,gz[deg/s]", comments="", fmt="%.17g")
    result = runner.invoke(app, ["compensate", str(tmp_path / "bundle"), str(tmp_path / "log.csv"), "--model", "ar",
                                 "--no-heading", "--no-artefacts", "--chunk", "1000", "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    per_stage = assert_counts_follow_the_rule(result.stderr, "samples")
    assert list(per_stage) == ["compensate"]
    pcts = per_stage["compensate"]
    assert pcts[-1] == 100 and 5 <= len(pcts) <= MAX_PER_STAGE  # 13 chunks of <= 1000 samples: several steps
    assert counts(result.stderr)[-1]["total"] == "12345"


def test_quiet_start_a_short_run_prints_no_progress(bundled_path, tmp_path, monkeypatch):
    # the rule, whatever the machine's load: a run that ends within QUIET_S of its start prints no progress (a
    # frozen clock: the whole run within the quiet start; the real one took ~1 s idle, more than QUIET_S loaded)
    assert cli_app.QUIET_S > 0
    monkeypatch.setattr(cli_app, "CLOCK", FakeClock())
    result = runner.invoke(app, ["allan", str(bundled_path), "--unit", "deg/h", "--columns", "gz",
                                 "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert not [ln for ln in lines(result.stderr) if ln.startswith("allan · ")]  # only the result


def test_quiet_start_a_run_past_it_prints_its_progress(bundled_path, tmp_path, monkeypatch):
    # the same run on a clock that passes QUIET_S at its second reading: the stage and its counts are printed
    monkeypatch.setattr(cli_app, "CLOCK", FakeClock(step=cli_app.QUIET_S))
    result = runner.invoke(app, ["allan", str(bundled_path), "--unit", "deg/h", "--columns", "gz",
                                 "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    per_stage = assert_counts_follow_the_rule(result.stderr, "taus")
    assert [ln for ln in lines(result.stderr) if ln.startswith("allan · ") and not COUNT.match(ln)] == [
        "allan · axis gz (1/1) · Allan variance"]
    assert per_stage["allan · axis gz (1/1) · Allan variance"][-1] == 100


def test_quiet_start_a_long_run_prints_the_line_it_is_at_then_every_line(monkeypatch, capsys):
    clock = FakeClock()
    monkeypatch.setattr(cli_app, "CLOCK", clock)
    with cli_app._Lines("job") as display:
        display.stage("job · stage 1")
        clock.now += cli_app.QUIET_S - 0.5
        display.stage("job · stage 2")          # held back: within the quiet start
        display.beat()                          # still within it
        assert capsys.readouterr().err == ""
        clock.now += 0.5
        display.beat()                          # the quiet start is over: the line it is at, once
        display.beat()
        display.stage("job · stage 3")
    err = lines(capsys.readouterr().err)
    assert err == ["job · stage 2", "job · stage 3"]  # the latest held-back line once, then each line


def test_quiet_start_the_heartbeat_thread_prints_the_held_back_line(monkeypatch, capsys):
    # the wiring: the thread beats on its own (a hang guard only: it ends as soon as the line is there)
    clock = FakeClock()
    monkeypatch.setattr(cli_app, "CLOCK", clock)
    monkeypatch.setattr(cli_app, "HEARTBEAT_S", 60.0)
    with cli_app._Lines("job") as display:
        display.stage("job · stage 1")
        clock.now += cli_app.QUIET_S
        for _ in range(6000):
            if display._pending is None:
                break
            time.sleep(0.01)
    assert lines(capsys.readouterr().err) == ["job · stage 1"]
