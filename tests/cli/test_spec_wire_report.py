"""``fogdrift analyze --spec FILE``: the datasheet verdicts on the report's first screen, in analysis.json, spec.json
and the console; without ``--spec`` the report is as before.

The bundled laser-gyro record's gz axis (the ``make demo`` protocol, two light models): no Allan model fits it, so
every term is a 95 % upper bound (N < ~0.08 deg/sqrt(h), B_min < ~0.10 deg/h).  Limits by hand:

* arw 1 deg/sqrt(h): pass (even the upper bound is below it);
* bias_instability 0.01 deg/h: cannot tell (a bound above the limit can never show a fail).
"""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from fogdrift.cli import app

runner = CliRunner()

DEMO = ["--columns", "gz", "--models", "ar,persistence", "--train-fraction", "0.4", "--val-fraction", "0.1",
        "--calibration", "150", "--origin-step", "30", "--horizons", "30,60"]
SPEC = {"sensor": "bundled RLG (test limits)", "gyro": {"arw": "1 deg/sqrt(h)", "bias_instability": "0.01 deg/h"},
        "accel": {"vrw": "0.2 m/s/sqrt(h)"}}


@pytest.fixture(scope="module")
def runs(bundled_path, tmp_path_factory):
    d = tmp_path_factory.mktemp("specreport")
    spec = d / "rlg.json"
    spec.write_text(json.dumps(SPEC))
    out = {}
    for name, extra in (("with", ["--spec", str(spec)]), ("without", [])):
        res = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", *DEMO, *extra,
                                  "--out", str(d / name)], env={"COLUMNS": "80"})
        assert res.exit_code == 0, res.output
        out[name] = (res.output, d / name)
    return out


def test_first_screen_holds_one_verdict_line_per_item(runs):
    text, out = runs["with"]
    page = (out / "report.html").read_text(encoding="utf-8")
    first = page[page.index('id="summary"'):page.index("</section>", page.index('id="summary"'))]
    assert "Does it meet the datasheet? bundled RLG (test limits) (rlg.json)" in first
    assert ('<span class="badge">PASS</span>gz arw: pass: &lt; ' in first
            and "against 1 deg/sqrt(h) (even its upper bound is within the limit 1 deg/sqrt(h))" in first)
    assert ('<span class="badge">CANNOT TELL</span>gz bias_instability: cannot tell: &lt; ' in first
            and "a bound can show a pass, never a fail" in first)
    assert "B compared: the IEEE-952 reading B_min" in first
    assert "vrw" not in first                     # a gyro log is judged against the gyro section only
    # the same judgements as data, in analysis.json and spec.json, and on the console
    doc = json.loads((out / "analysis.json").read_text())["report_summary"]["spec"]
    assert [(i["channel"], i["item"], i["verdict"]) for i in doc["items"]] == [("gz", "arw", "pass"),
                                                                            ("gz", "bias_instability", "cannot tell")]
    bound = float(doc["items"][1]["estimate"].split()[1])            # "< 0.104 deg/h"
    assert bound > 0.01                                              # why it cannot tell
    assert doc["items"][0]["limit_canonical"] == 1.0 and doc["items"][1]["limit_canonical"] == 0.01
    spec_json = json.loads((out / "spec.json").read_text())
    assert [j["verdict"] for j in spec_json["judgements"]] == ["pass", "cannot tell"]
    flat = " ".join(text.split())
    assert "[PASS] gz arw: pass:" in flat and "[CANNOT TELL] gz bias_instability: cannot tell:" in flat


def test_without_spec_the_report_is_unchanged(runs):
    _, out = runs["without"]
    page = (out / "report.html").read_text(encoding="utf-8")
    assert "datasheet" not in page and "B compared" not in page and 'class="verdicts spec"' not in page
    assert "spec" not in json.loads((out / "analysis.json").read_text())["report_summary"]
    assert not (out / "spec.json").exists()
    # the rest of the first screen is the same with and without --spec (only the comparison block is added)
    with_page = (runs["with"][1] / "report.html").read_text(encoding="utf-8")

    def summary(p):
        s = p[p.index('id="summary"'):p.index("</section>", p.index('id="summary"'))]
        a = s.find("<h3>Does it meet the datasheet?")
        return s if a < 0 else s[:a] + s[s.index("<h3>Did drift compensation help?"):]

    assert summary(with_page) == summary(page)


def test_analyze_bad_spec_is_one_line_before_any_work(bundled_path, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"gyro": {"arw": "2 furlongs"}}))
    res = runner.invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", *DEMO, "--spec", str(bad),
                              "--out", str(tmp_path / "o")], env={"COLUMNS": "80"})
    assert res.exit_code == 1
    lines = [ln for ln in res.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and "unknown unit 'furlongs'" in lines[0] and "Traceback" not in res.output
    assert not (tmp_path / "o" / "analysis.json").exists()


def test_allan_help_imports_no_other_command_module():
    """``allan --help`` takes --spec from the light cli._spec, not from cli.noise (no other command module)."""
    import subprocess
    import sys

    code = ("import json, sys; sys.argv = ['fogdrift', 'allan', '--help']\n"
            "from fogdrift.cli import main\n"
            "try:\n    main()\nexcept SystemExit:\n    pass\n"
            "print('MODS', json.dumps(sorted(m for m in sys.modules if m.startswith('fogdrift.cli.'))))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                          env={"COLUMNS": "200", "PATH": "/usr/bin:/bin"})
    assert proc.returncode == 0, proc.stderr[-2000:]
    mods = json.loads(proc.stdout.split("MODS", 1)[1])
    assert "fogdrift.cli.allan" in mods and "fogdrift.cli._spec" in mods
    assert not {"fogdrift.cli.noise", "fogdrift.cli.batch", "fogdrift.cli.analyze"} & set(mods), mods


def test_batch_analyze_rows_and_report_carry_the_verdicts(bundled_path, tmp_path):
    """``batch --command analyze --spec``: each row's spec columns and the file's report first screen agree."""
    from fogdrift.fleet import run_batch

    settings = {"load": {"unit": "deg/h", "columns": "gz"},
                "analysis": {"models": ["ar", "persistence"], "train_fraction": 0.4, "val_fraction": 0.1},
                "spec": {"source": "rlg.json", **SPEC}}
    res = run_batch([bundled_path], tmp_path / "b", command="analyze", settings=settings, scheduler="serial")
    assert res.n_ok == 1, [r.get("error") for r in res.rows]
    (row,) = res.rows
    assert (row["axis"], row["spec_arw"], row["spec_bias_instability"], row["spec_vrw"]) == \
        ("gz", "pass", "cannot tell", None)
    page = next((tmp_path / "b").glob("*/report.html")).read_text(encoding="utf-8")
    assert "Does it meet the datasheet? bundled RLG (test limits) (rlg.json)" in page
    assert '<span class="badge">CANNOT TELL</span>gz bias_instability: cannot tell' in page
