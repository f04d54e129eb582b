"""The record screen on the report's first screen (issue 32): per axis what disturbs it (interval, peak against the
quiet level, character), what the noise fit used and what the whole record gave, and the dynamic ADEV figure.

Seeded records with known truth: white (N = 0.02 deg/sqrt(h)) + flicker noise at 10 Hz, one with a burst of white
noise 7x the quiet deviation over 600-750 s."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.pipeline import AnalysisConfig, analyse_allan
from fogdrift.simulate import simulate

N_SAMPLES, DT, N_TRUE = 2**14, 0.1, 0.02
BURST = (6000, 7500)  # samples: 600-750 s


def _record(burst: bool) -> np.ndarray:
    y = simulate(N_SAMPLES, DT, arw_dprh=N_TRUE, bias_instability_dph=0.3, seed=3)
    if burst:
        q = np.std(np.diff(y)) / np.sqrt(2)
        a, b = BURST
        y[a:b] += np.random.default_rng(3).normal(scale=np.sqrt(48.0) * q, size=b - a)  # 7x the quiet deviation
    return y


def _analyze(tmp, y):
    path = tmp / "rec.csv"
    np.savetxt(path, np.c_[np.arange(y.size) * DT, y], delimiter=",", header="t_s,gz", comments="", fmt="%.9g")
    r = CliRunner().invoke(app, ["analyze", str(path), "--unit", "deg/h", "--models", "ar", "--no-heading",
                                 "--out", str(tmp / "out")])
    assert r.exit_code == 0, r.output + repr(r.exception)
    out = tmp / "out"
    return json.loads((out / "analysis.json").read_text()), (out / "report.html").read_text(), out


@pytest.fixture(scope="module")
def disturbed(tmp_path_factory):
    y = _record(True)
    return (y,) + _analyze(tmp_path_factory.mktemp("disturbed"), y)


def _summary_html(page: str) -> str:
    m = re.search(r'<section class="summary" id="summary">(.*?)</section>', page, re.S)
    assert m, "no summary section"
    return m.group(1)


def test_first_screen_names_the_burst_with_its_edges_peak_and_quiet_level(disturbed):
    y, doc, page, _ = disturbed
    scr = doc["report_summary"]["screen"]
    assert scr["disturbed"] == ["gz"]
    (row,) = scr["intervals"]["rows"]
    axis, kind, start, end, peak, peak_level, quiet = row
    assert axis == "gz" and kind == "transient"
    # edges within 5 % of the record (82 s) of the truth
    assert abs(float(start) - BURST[0] * DT) <= 0.05 * N_SAMPLES * DT
    assert abs(float(end) - BURST[1] * DT) <= 0.05 * N_SAMPLES * DT
    # the peak is the burst's deviation against the quiet one (7x by construction; one window's scatter)
    ratio = float(peak.rstrip("×"))
    assert 5.5 <= ratio <= 9.0
    # quiet level: the RMS of a quiet 128-sample window after a line, measured here on the part before the burst
    w = y[:5888].reshape(-1, 128)
    t = np.arange(128) - 63.5
    res = w - w.mean(1, keepdims=True) - np.outer((w - w.mean(1, keepdims=True)) @ t / (t @ t), t)
    q_true = np.sqrt(np.mean(np.sum(res**2, 1) / 126))
    assert float(quiet) == pytest.approx(q_true, rel=0.1)
    assert float(peak_level) == pytest.approx(ratio * float(quiet), rel=0.05)
    for header in scr["intervals"]["headers"][2:4]:
        assert header.endswith("[s]")
    assert scr["intervals"]["headers"][-1] == "quiet level [deg/h]"


def test_first_screen_says_what_the_fit_used_and_what_the_whole_record_gave(disturbed):
    y, doc, page, _ = disturbed
    (row,) = doc["report_summary"]["screen"]["axes"]["rows"]
    used_cell, n_used, n_whole = row[4], row[5], row[6]
    assert used_cell.startswith("quiet segments 0–") and "pooled without bridging a gap" in used_cell
    cut = doc["axes"][0]["original"]["screen"]["segments_used"]
    assert len(cut) == 2 and cut[0][1] <= BURST[0] and cut[1][0] >= BURST[1]

    def value_and_interval(cell):
        v, lo, hi = map(float, re.match(r"([\d.e+-]+) \[([\d.e+-]+), ([\d.e+-]+)\]", cell).groups())
        return v, lo, hi

    v_used, lo_used, hi_used = value_and_interval(n_used)
    v_whole, lo_whole, hi_whole = value_and_interval(n_whole)
    assert lo_used <= N_TRUE <= hi_used  # the quiet part gives the sensor's N
    assert lo_whole > N_TRUE  # the whole record reads the burst as white noise
    # the whole-record cell is what the whole record's own analysis gives (computed here independently)
    whole = analyse_allan("gz", y, DT, AnalysisConfig().validate()).noise.terms["N"]
    assert v_whole == pytest.approx(whole.value, rel=1e-3)


def test_dynamic_adev_figure_is_on_the_first_screen(disturbed):
    _, doc, page, out = disturbed
    summary = _summary_html(page)
    assert "Is the record stationary?" in summary and "Disturbed intervals" in summary
    assert summary.count("data:image/png;base64,") == 1 and 'alt="fig_dynamic_adev"' in summary
    assert (out / "figures" / "fig_dynamic_adev.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # before the settings and the recording's figures
    assert page.index('alt="fig_dynamic_adev"') < page.index('id="settings"') < page.index('alt="fig1_signal"')


def test_stationary_record_says_so_in_one_line_and_draws_no_dynamic_adev(tmp_path):
    _, doc, page, out = (None,) + _analyze(tmp_path, _record(False))
    scr = doc["report_summary"]["screen"]
    assert scr["disturbed"] == [] and scr["intervals"]["rows"] == []
    (row,) = scr["axes"]["rows"]
    assert row[1].startswith("stationary") and row[4].startswith("the whole record, 1638.4 s (stationary)")
    assert row[6] == row[8] == "the same (whole record fitted)"
    summary = _summary_html(page)
    assert "No disturbed interval on any axis" in summary and "data:image/png" not in summary
    assert not (out / "figures" / "fig_dynamic_adev.png").exists()
