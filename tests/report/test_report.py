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
    pdf = ["--pdf"] if _chromium() else []  # report.pdf needs headless Chromium (checked in its own test)
    result = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--apply-to", str(other),
                                 "--out", str(tmp / "out"), *FAST, *pdf])
    assert result.exit_code == 0, result.output + repr(result.exception)
    return tmp / "out", result.output


def test_analyze_prints_tables_and_writes_report(report_dir):
    out, text = report_dir
    # stdout's summary (the noise table, the verdict) and the report line; progress lines ("... · Table 2") are
    # timing-dependent (held back during the first seconds of a run) and not asserted here
    assert "report:" in text and "Noise of the original output" in text and "compensation verdict" in text
    doc = json.loads((out / "analysis.json").read_text())
    assert doc["sha256"] == "039800de6c285c4359a60090d7d4fa0d09aaea42949eee4b5adcf37a3e484734"
    assert doc["versions"]["numpy"] and doc["config"]["model_rate_hz"] == 1.0
    ax = doc["axes"][0]
    kinds = {row["kind"] for row in ax["table2"]}
    assert kinds == {"reference", "paper", "practical"}
    assert doc["apply_to"] is not None and doc["apply_to"]["applied_models_from_other_recording"]
    # Applied models are unchanged: same parameters in both sections.
    assert doc["apply_to"]["axes"][0]["models"]["model_params"] == ax["models"]["model_params"]
    # The heading-error + artefact evaluation runs by default and is stored per axis, with its one-sentence verdict.
    ev = ax["evaluation"]
    assert ev["heading"]["rows"]
    # The bundled test block (370 samples at 1 Hz) is too short for the artefact check: skipped, and said so.
    assert ev["artefacts"] is None and any("artefact check skipped" in n for n in ev["notes"])
    assert {r["model"] for r in ev["heading"]["rows"]} >= {"constant bias", "AR(p)", "Kalman", "persistence"}
    outcome = ev["headline"]["data"]["outcome"]
    assert outcome in {"reduces", "mixed", "none", "undetermined"}
    summary = doc["report_summary"]
    assert summary["verdicts"] == [{"axis": "gz", "outcome": outcome, "sentence": ev["headline"]["lines"][0]}]
    assert summary["recording"]["file"] == "psins_lasergyro_rlg.csv.gz"
    assert doc["apply_to"]["axes"][0]["evaluation"] is not None


def test_report_is_self_contained_and_escaped(report_dir):
    out, _ = report_dir
    page = (out / "report.html").read_text()
    assert "http://" not in page and "https://" not in page and "<script" not in page
    assert "other <b>&" not in page and "other &lt;b&gt;&amp;" in page
    assert page.count("data:image/png;base64,") >= 12  # figs 1, 2 + 5 per axis section + 5 applied
    for needle in ("Table 2", "Paper&#x27;s measure", "persistence", "Heading error after a", "Filtering-artefact check",
                   "What this record cannot support", "Glossary"):
        assert needle in page


def _chromium():
    """The headless browser on PATH, or None."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


def _browser_or_skip():
    browser = _chromium()
    if browser is None:
        if os.environ.get("FOGDRIFT_REQUIRE_BROWSER"):
            pytest.fail("FOGDRIFT_REQUIRE_BROWSER is set but no chromium is installed")
        pytest.skip("headless Chromium not installed (CI installs Debian's chromium)")
    return browser


def test_report_renders_in_headless_chromium(report_dir, tmp_path):
    browser = _browser_or_skip()
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


#: Written into the DOM by a probe copy of the report (the report itself has no script): page width, every
#: image's decoded size, declared size and pixel variance (canvas), and where the summary and first figure are.
_LAYOUT_PROBE = """<script>window.addEventListener('load',()=>{
const im=[...document.images].map(i=>{let v=-1;try{const c=document.createElement('canvas');
c.width=i.naturalWidth;c.height=i.naturalHeight;const g=c.getContext('2d');g.drawImage(i,0,0);
const p=g.getImageData(0,0,c.width,c.height).data;let n=0,s=0,q=0;
for(let k=0;k<p.length;k+=4*7){const y=p[k]+p[k+1]+p[k+2];n++;s+=y;q+=y*y;}v=q/n-(s/n)*(s/n);}catch(e){v=-2;}
const r=i.getBoundingClientRect();
return {ok:i.complete,nw:i.naturalWidth,nh:i.naturalHeight,w:+i.getAttribute('width'),h:+i.getAttribute('height'),
var:v,shown:r.width,top:r.top+scrollY,insum:!!i.closest('#summary')};});
const sm=document.getElementById('summary').getBoundingClientRect();
document.body.setAttribute('data-probe',JSON.stringify({sw:document.documentElement.scrollWidth,iw:innerWidth,
images:im,summary_bottom:sm.bottom+scrollY,tables:document.querySelectorAll('table').length}));});</script>"""


def test_report_layout_at_1280_px(report_dir, tmp_path):
    """At 1280 px: no horizontal scroll, every figure decoded at its own size (1200 px wide), not blank and not
    wider than the window, and the summary (recording, noise, screen, verdicts, limits) above the first figure
    outside it (the summary holds one: the dynamic ADEV of the disturbed axis)."""
    from fogdrift.report.figures import DPI, FIG_WIDTH_IN

    browser = _browser_or_skip()
    out, _ = report_dir
    probe = tmp_path / "layout.html"
    probe.write_text((out / "report.html").read_text().replace("</body>", _LAYOUT_PROBE + "</body>"))
    proc = subprocess.run(
        [browser, "--headless", "--no-sandbox", "--disable-gpu", "--window-size=1280,900", f"--user-data-dir={tmp_path / 'p'}",
         "--virtual-time-budget=10000", "--dump-dom", probe.as_uri()],
        capture_output=True, text=True, timeout=180,
    )
    match = re.search(r"data-probe=\"([^\"]+)\"", proc.stdout)
    assert match, proc.stderr[-2000:]
    info = json.loads(match.group(1).replace("&quot;", '"'))
    assert info["iw"] == 1280 and info["sw"] <= info["iw"], info
    images = info["images"]
    assert len(images) >= 12 and info["tables"] >= 8
    for i, img in enumerate(images):
        assert img["ok"] and img["nw"] > 0, (i, img)
        assert (img["nw"], img["nh"]) == (img["w"], img["h"]), (i, img)  # decoded at the size the PNG declares
        assert img["nw"] == round(FIG_WIDTH_IN * DPI), (i, img)  # full width of the report column
        assert img["var"] > 0, (i, img)  # not blank (a canvas read that failed gives -2)
        assert 0 < img["shown"] <= info["iw"], (i, img)
    # the summary comes before every figure but its own: the dynamic ADEV of a disturbed axis (the bundled gz is
    # disturbed throughout), which belongs to the first screen
    assert sum(img["insum"] for img in images) == 1, info
    assert info["summary_bottom"] <= min(img["top"] for img in images if not img["insum"]), info


def test_pdf_is_written_with_the_report(report_dir):
    _browser_or_skip()
    out, _ = report_dir
    pdf = out / "report.pdf"
    assert pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 50_000
    manifest = json.loads((out / ".fogdrift-manifest.json").read_text())
    assert "report.pdf" in manifest["files"]
    assert not [p for p in out.iterdir() if p.name.startswith(".fogdrift-tmp-")]  # no temporary left behind
    # the pages themselves (PDFium, the renderer of Chromium's own PDF viewer): the first screen's text on
    # page 1, and pages with figures carry coloured pixels (a blank or text-only print has none)
    pdfium = pytest.importorskip("pypdfium2")
    import numpy as np

    doc = pdfium.PdfDocument(str(pdf))
    try:
        assert len(doc) >= 3
        first = doc[0].get_textpage().get_text_range()
        assert "Summary" in first and "How noisy is this gyro?" in first and "deg/√h" in first
        coloured = 0
        for i in range(len(doc)):
            px = np.asarray(doc[i].render(scale=0.5).to_pil().convert("RGB"), dtype=np.int16)
            assert px.std() > 0, i  # not a blank page
            coloured += int((np.ptp(px, axis=2) > 60).mean() > 0.002)  # saturated plot lines, not grey text
        assert coloured >= 3, coloured
    finally:
        doc.close()


def test_pdf_without_chromium_is_one_line_naming_how_to_install(bundled_path, tmp_path, monkeypatch):
    empty = tmp_path / "bin"
    empty.mkdir()
    monkeypatch.setenv("PATH", str(empty))
    monkeypatch.delenv("FOGDRIFT_CHROMIUM", raising=False)
    result = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--pdf",
                                 "--out", str(tmp_path / "out"), *FAST])
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert result.exit_code == 1 and len(lines) == 1, result.output
    assert "--pdf needs headless Chromium" in lines[0] and "apt install chromium" in lines[0]
    assert not (tmp_path / "out" / "report.html").exists()


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
    """Figure names carry the figure number and the axis; the applied section's start "apply_to_" (no _0/_2); the
    first screen's dynamic ADEV (the bundled gz is disturbed) is fig_dynamic_adev."""
    out, _ = report_dir
    figs = sorted(p.name for p in (out / "figures").iterdir())
    assert figs == sorted(["fig_dynamic_adev.png", "fig1_signal.png", "fig2_spectrum.png", "fig3_allan_gz.png", "fig5_drift_noise_gz.png",
                           "fig6_allan_gz.png", "fig8_models_gz.png", "fig9_residual_gz.png",
                           "apply_to_fig3_allan_gz.png", "apply_to_fig5_drift_noise_gz.png",
                           "apply_to_fig6_allan_gz.png", "apply_to_fig10_models_gz.png",
                           "apply_to_fig11_residual_gz.png"])
    manifest = json.loads((out / ".fogdrift-manifest.json").read_text())
    assert manifest["complete"] and "report.html" in manifest["files"]
