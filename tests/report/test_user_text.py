"""No Python names in user text: console lines of `allan` and `analyze`, and the visible text of report.html.

Python names carry the unit in a suffix (``arw_dprh``, ``q_urad``, ``dt_s``: :mod:`fogdrift.units`); the user
reads words and a unit instead ("N 0.0662 deg/√h").  JSON keys keep the names and are not checked here.  File
names and the user's own column names (quoted, e.g. ``'t_s'``) are the user's words and are left out.
"""

from __future__ import annotations

import re
from html.parser import HTMLParser

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.report.glossary import plain_name, plain_setting
from fogdrift.simulate import simulate

runner = CliRunner()

#: What a leaked Python name looks like: a unit suffix after an underscore, a keyword repr, a result field.
LEAK = re.compile(r"\b[A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)*_(?:dph|dprh|dps|urad|dphrh|dph2|hz|deg|arcsec|s)\b"
                  r"|\b\w+=(?:True|False|None)\b|passed_checks|\bmax_order\b|\bval_fraction\b")
#: File names and quoted names (the user's own column names) are not Python names.
USERS_OWN = re.compile(r"'[^']*'|\S+\.(?:csv|png|json|npz|gz|html|pdf)\b")


class _Visible(HTMLParser):
    """The text a reader sees: no <style>, <title> or <script>."""

    def __init__(self):
        super().__init__()
        self.skip, self.parts = 0, []

    def handle_starttag(self, tag, attrs):
        self.skip += tag in ("style", "title", "script")

    def handle_endtag(self, tag):
        self.skip -= tag in ("style", "title", "script")

    def handle_data(self, data):
        if not self.skip:
            self.parts.append(data)


def leaks(text: str) -> list:
    return sorted({m.group(0) for line in text.splitlines() for m in LEAK.finditer(USERS_OWN.sub(" ", line))})


def test_the_leak_pattern_catches_the_issue_s_names():
    # the pattern itself, on the texts the issue quotes and on their fixed wording
    assert leaks("gz: states: white (arw_dprh 0.0662); quantization (q_urad 33.9)") == ["arw_dprh", "q_urad"]
    assert leaks("dt_s 0.01 from the median step; order 4, max_order 12") == ["dt_s", "max_order"]
    assert leaks("QN.q2 passed_checks=False, robust=True") == ["passed_checks=False", "robust=True"]
    assert leaks("white noise (N 0.0662 deg/√h); sample interval 0.01 s of time column 't_s'; fig1_signal.png") == []


@pytest.mark.parametrize("name, words", [("arw_dprh", "N 0.5 deg/√h"), ("q_urad", "Q 0.5 µrad"),
                                         ("rrw_dphrh", "K 0.5 deg/h^1.5"), ("ramp_dph2", "R 0.5 deg/h²"),
                                         ("tc_s", "correlation time 0.5 s"), ("window_s", "window 0.5 s"),
                                         ("drift_dph", "drift 0.5 deg/h"), ("rate_dps", "rate 0.5 deg/s"),
                                         ("learning_rate", "learning rate 0.5")])
def test_plain_setting_writes_words_and_the_unit(name, words):
    assert plain_setting(name, 0.5) == words
    assert plain_name(name)[1] in words  # the unit comes from the suffix table of fogdrift.units


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    from fogdrift.cli import app

    tmp = tmp_path_factory.mktemp("usertext")
    n, dt_s = 30_000, 0.01
    rate_dph = simulate(n, dt_s, arw_dprh=0.05, q_urad=2.0, bias_dph=5.0, seed=3)
    log = tmp / "sim.csv"
    np.savetxt(log, np.column_stack([np.arange(n) * dt_s, rate_dph]), delimiter=",", header="t_s,gz",
               comments="", fmt="%.6f")
    allan = runner.invoke(app, ["allan", str(log), "--unit", "deg/h", "--out", str(tmp / "allan")])
    assert allan.exit_code == 0, allan.output + repr(allan.exception)
    analyze = runner.invoke(app, ["analyze", str(log), "--unit", "deg/h", "--no-heading", "--models",
                                  "ar,persistence,kalman", "--out", str(tmp / "analyze")])
    assert analyze.exit_code == 0, analyze.output + repr(analyze.exception)
    page = _Visible()
    page.feed((tmp / "analyze" / "report.html").read_text(encoding="utf-8"))
    return {"allan console": allan.output, "analyze console": analyze.output, "report.html": "\n".join(page.parts)}


@pytest.mark.parametrize("where", ["allan console", "analyze console", "report.html"])
def test_no_python_names_in_user_text(runs, where):
    assert runs[where].strip()
    assert leaks(runs[where]) == [], where


def test_the_kalman_states_read_in_words(runs):
    # the issue's example: the Kalman model's identified states in the settings table
    html = runs["report.html"]
    assert "arw_dprh" not in html and re.search(r"white noise \(N [0-9.e-]+ deg/√h", html)
