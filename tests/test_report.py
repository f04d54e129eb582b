"""The whole analysis: pipeline on the bundled recording, --apply-to, and the HTML report in headless Chromium."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess

import numpy as np
import pytest
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.io import load
from fogdrift.pipeline import AnalysisConfig, run_analysis

runner = CliRunner()
FAST = ["--epochs", "60", "--hidden", "8"]


@pytest.fixture(scope="module")
def report_dir(bundled_path, tmp_path_factory):
    """Run `fogdrift analyze` once on gz, applying the models to a second recording (gx of the same file
    renamed to gz: real data the models were not fitted on)."""
    tmp = tmp_path_factory.mktemp("analyze")
    rec = load(bundled_path, unit="deg/h")
    other = tmp / "other <b>&.csv"
    gx = np.asarray(rec.axis("gx"))
    t = np.arange(gx.size) * rec.dt_s
    np.savetxt(other, np.column_stack([t, gx]), delimiter=",", header="t_s,gz", comments="", fmt="%.6f")
    result = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--apply-to", str(other),
                                 "--out", str(tmp / "out"), *FAST])
    assert result.exit_code == 0, result.output + repr(result.exception)
    return tmp / "out", result.output


def test_analyze_prints_tables_and_writes_report(report_dir):
    out, text = report_dir
    assert "report:" in text and "Table 2" in text
    doc = json.loads((out / "analysis.json").read_text())
    assert doc["sha256"] == "039800de6c285c4359a60090d7d4fa0d09aaea42949eee4b5adcf37a3e484734"
    assert doc["versions"]["numpy"] and doc["config"]["model_rate_hz"] == 1.0
    ax = doc["axes"][0]
    kinds = {row["kind"] for row in ax["table2"]}
    assert kinds == {"reference", "paper", "practical"}
    assert doc["apply_to"] is not None and doc["apply_to"]["applied_models_from_other_recording"]
    # Applied models are unchanged: same parameters in both sections.
    assert doc["apply_to"]["axes"][0]["models"]["model_params"] == ax["models"]["model_params"]


def test_report_is_self_contained_and_escaped(report_dir):
    out, _ = report_dir
    page = (out / "report.html").read_text()
    assert "http://" not in page and "https://" not in page and "<script" not in page
    assert "other <b>&" not in page and "other &lt;b&gt;&amp;" in page
    assert page.count("data:image/png;base64,") >= 12  # figs 1, 2 + 5 per axis section + 5 applied
    for needle in ("Table 2", "Metrics on the test block", "persistence"):
        assert needle in page


def _chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def test_report_renders_in_headless_chromium(report_dir, tmp_path):
    browser = _chromium()
    if browser is None:
        if os.environ.get("FOGDRIFT_REQUIRE_BROWSER"):
            pytest.fail("FOGDRIFT_REQUIRE_BROWSER is set but no chromium is installed")
        pytest.skip("headless Chromium not installed (CI installs Debian's chromium)")
    out, _ = report_dir
    # A probe copy of the report counts decoded images and tables after load; the report itself has no script.
    probe = tmp_path / "probe.html"
    probe_js = (
        "<script>window.addEventListener('load',()=>{const im=[...document.images];"
        "document.body.setAttribute('data-probe',"
        "JSON.stringify({n:im.length,ok:im.filter(i=>i.complete&&i.naturalWidth>0).length,"
        "tables:document.querySelectorAll('table').length}));});</script>"
    )
    probe.write_text((out / "report.html").read_text().replace("</body>", probe_js + "</body>"))
    proc = subprocess.run(
        [browser, "--headless", "--no-sandbox", "--disable-gpu", "--virtual-time-budget=10000", "--dump-dom",
         probe.as_uri()],
        capture_output=True, text=True, timeout=180,
    )
    match = re.search(r"data-probe=\"([^\"]+)\"", proc.stdout)
    assert match, proc.stderr[-2000:]
    info = json.loads(match.group(1).replace("&quot;", '"'))
    assert info["n"] >= 12 and info["ok"] == info["n"], info
    assert info["tables"] >= 8, info


def test_pipeline_blocks_do_not_leak(bundled_record):
    """Changing the test block changes no fitted parameter (models see only the training block)."""
    rec = bundled_record.select(["gz"])
    cfg = AnalysisConfig(models=("ar", "gm11"), epochs=10)
    a = run_analysis(rec, cfg)
    data = np.array(rec.rate_dph, copy=True)
    data[int(0.85 * data.shape[0]):] += 50.0  # alter the last part of the record (inside the test block)
    from fogdrift.io import from_array

    b = run_analysis(from_array(data, dt_s=rec.dt_s, axis_names=("gz",)), cfg)
    pa, pb = a.axes[0].models.fitted, b.axes[0].models.fitted
    for label in pa:
        sa, sb = pa[label]._get_state(), pb[label]._get_state()
        assert json.dumps(sa[0], sort_keys=True, default=str) == json.dumps(sb[0], sort_keys=True, default=str)
        for key in sa[1]:
            np.testing.assert_array_equal(sa[1][key], sb[1][key])
    assert a.axes[0].models.bias_dph == b.axes[0].models.bias_dph


def test_report_files_have_deterministic_names(report_dir):
    """Figure names carry the figure number and the axis; the applied section's start "apply_to_" (no _0/_2)."""
    out, _ = report_dir
    figs = sorted(p.name for p in (out / "figures").iterdir())
    assert figs == sorted(["fig1_signal.png", "fig2_spectrum.png", "fig3_allan_gz.png", "fig5_drift_noise_gz.png",
                           "fig6_allan_gz.png", "fig8_models_gz.png", "fig9_residual_gz.png",
                           "apply_to_fig3_allan_gz.png", "apply_to_fig5_drift_noise_gz.png",
                           "apply_to_fig6_allan_gz.png", "apply_to_fig10_models_gz.png",
                           "apply_to_fig11_residual_gz.png"])
    manifest = json.loads((out / ".fogdrift-manifest.json").read_text())
    assert manifest["complete"] and "report.html" in manifest["files"]
