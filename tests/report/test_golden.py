"""Golden regression of the bundled RLG recording's headline tables (issue 14).

The expected values in ``tests/golden/bundled_headline.json`` were produced by the two commands users run
first, through the CLI and its ``--json`` output:

- ``fogdrift allan data/psins_lasergyro_rlg/psins_lasergyro_rlg.csv.gz --unit deg/h``: per axis the Allan
  deviation at every octave tau, the selected noise terms and each term's value, 95 % interval and status;
- ``fogdrift analyze ... --unit deg/h --models ar,persistence``: per axis the split, training bias, scoring
  start and the test-block metrics of AR(p) and persistence (both deterministic: least squares and a shift;
  the neural models are left out because their training is not bit-reproducible across machines).

This is a *regression* check, not a proof of correctness: the numbers are proven elsewhere against
independent references (allantools, PyWavelets, hand values). It catches any unintended change of a headline
number. After an **intended** change, regenerate the file with one command and review the diff::

    .venv/bin/python tests/report/test_golden.py

Tolerances (relative, per value; absolute 1e-12 for values that are 0):

- Allan deviations: rtol 1e-9. Sums of float64 squares in a fixed order; only the summation order of a
  different numpy/BLAS build can move them (~1e-13 relative).
- Noise-term values, interval ends, training bias and the test metrics: rtol 1e-6. They go through linear
  solves (GLS, AR least squares) and, for the interval ends, a root search whose tolerance is far below
  1e-6; LAPACK builds differ by ~1e-12 relative, so 1e-6 leaves room for those and still flags any real
  change (every deliberate bug tried changes them by > 1e-4).
- Integers, strings, statuses and the selected terms: exact.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parents[1]  # tests/
GOLDEN = HERE / "golden" / "bundled_headline.json"
DATA = HERE.parent / "data" / "psins_lasergyro_rlg" / "psins_lasergyro_rlg.csv.gz"
RTOL_ALLAN = 1e-9
RTOL_FIT = 1e-6
ATOL = 1e-12
METRIC_KEYS = ("rmse_dph", "mae_dph", "max_abs_dph", "mase", "skill", "p0_weighted_pct", "n",
               "rmse_persistence_dph")


def _cli_json(args: list[str]) -> dict:
    from typer.testing import CliRunner

    from fogdrift.cli import app

    result = CliRunner().invoke(app, args + ["--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def allan_headline(out_dir) -> dict:
    """Headline numbers of ``fogdrift allan`` on the bundled record."""
    res = _cli_json(["allan", str(DATA), "--unit", "deg/h", "--out", str(Path(out_dir) / "allan")])
    axes = {}
    for ax in res["axes"]:
        noise = ax["noise"]
        axes[ax["name"]] = {
            "tau_s": ax["allan"]["tau_s"],
            "adev_dph": ax["allan"]["adev_dph"],
            "selected": noise["selected"],
            "terms": {name: {k: t[k] for k in ("value", "lo95", "hi95", "unit", "status")}
                      for name, t in noise["terms"].items()},
        }
    return axes


def run_analyze(out_dir) -> dict:
    """``fogdrift analyze --models ar,persistence`` on the bundled record into ``out_dir/analyze``; its JSON."""
    return _cli_json(["analyze", str(DATA), "--unit", "deg/h", "--models", "ar,persistence",
                      "--out", str(Path(out_dir) / "analyze")])


def analyze_headline(out_dir, res=None) -> dict:
    """Headline numbers of ``fogdrift analyze --models ar,persistence`` on the bundled record."""
    res = run_analyze(out_dir) if res is None else res
    axes = {}
    for ax in res["axes"]:
        m = ax["models"]
        axes[ax["name"]] = {
            "split": m["split"],
            "bias_dph": m["bias_dph"],
            "score_from_test_index": m["score_from_test_index"],
            "metrics": {label: {k: v[k] for k in METRIC_KEYS} for label, v in m["metrics_paper_target"].items()},
            "p0_as_measured_pct": m["p0_as_measured_pct"],
        }
    return axes


def _compare(got, want, rtol, path="") -> list[str]:
    """Differences between two JSON trees: floats within rtol (atol 1e-12), everything else exact."""
    if isinstance(want, dict):
        if not isinstance(got, dict) or set(got) != set(want):
            return [f"{path}: keys {sorted(got) if isinstance(got, dict) else got!r} != {sorted(want)}"]
        return [d for k in want for d in _compare(got[k], want[k], rtol, f"{path}.{k}")]
    if isinstance(want, list):
        if not isinstance(got, list) or len(got) != len(want):
            return [f"{path}: {got!r} != {want!r}"]
        return [d for i, (g, w) in enumerate(zip(got, want)) for d in _compare(g, w, rtol, f"{path}[{i}]")]
    if isinstance(want, float) and isinstance(got, (int, float)) and not isinstance(got, bool):
        if math.isclose(got, want, rel_tol=rtol, abs_tol=ATOL):
            return []
        return [f"{path}: {got!r} != {want!r} (rel {abs(got - want) / max(abs(want), 1e-300):.2e} > {rtol:g})"]
    return [] if got == want else [f"{path}: {got!r} != {want!r}"]


@pytest.fixture(scope="module")
def golden() -> dict:
    return json.loads(GOLDEN.read_text())


def test_allan_headline_matches_golden(golden, tmp_path):
    got = allan_headline(tmp_path)
    want = golden["allan"]
    diffs = []
    for axis in want:
        w, g = want[axis], got.get(axis, {})
        diffs += _compare(g.get("tau_s"), w["tau_s"], RTOL_ALLAN, f"{axis}.tau_s")
        diffs += _compare(g.get("adev_dph"), w["adev_dph"], RTOL_ALLAN, f"{axis}.adev_dph")
        diffs += _compare(g.get("selected"), w["selected"], 0.0, f"{axis}.selected")
        diffs += _compare(g.get("terms"), w["terms"], RTOL_FIT, f"{axis}.terms")
    assert set(got) == set(want)
    assert not diffs, "\n".join(diffs[:20])


@pytest.fixture(scope="module")
def analyze_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("golden")
    return run_analyze(out), out / "analyze"


@pytest.mark.slow
def test_analyze_headline_matches_golden(golden, analyze_run):
    res, out = analyze_run
    got = analyze_headline(out, res)
    diffs = _compare(got, golden["analyze"], RTOL_FIT, "analyze")
    assert not diffs, "\n".join(diffs[:20])


@pytest.mark.slow
def test_report_figures_have_content(analyze_run):
    """Every figure of the report is a real plot: a usable size, coloured data on the canvas, and no two
    per-axis figures identical (a blank or placeholder image, or one axis plotted three times, fails)."""
    import matplotlib.image as mpimg
    import numpy as np

    _, out = analyze_run
    figures = sorted((out / "figures").glob("*.png"))
    assert len(figures) >= 12, figures
    pixels = {}
    for path in figures:
        img = mpimg.imread(path)[..., :3]
        assert img.shape[0] >= 300 and img.shape[1] >= 400, (path.name, img.shape)
        # data are drawn in colour, frames, grids and text in grey: an empty axes (even with a grid) has
        # no saturated pixel, every report figure has >= 0.5 % (measured 0.5-4 % on the bundled record)
        colour = float(np.mean(img.max(axis=-1) - img.min(axis=-1) > 0.25))
        assert colour > 0.002, (path.name, colour)
        pixels[path.name] = img
    per_axis = [n for n in pixels if n.endswith("_gx.png")]
    assert per_axis
    for name in per_axis:
        twin = name.replace("_gx.png", "_gy.png")
        if twin in pixels and pixels[twin].shape == pixels[name].shape:
            assert not np.array_equal(pixels[twin], pixels[name]), name


def test_compare_flags_a_relative_change_above_the_tolerance():
    # the comparison itself can fail: a 2e-6 relative change, a changed status, a missing key
    assert _compare({"a": [1.0, 2.0]}, {"a": [1.0, 2.0 * (1 + 2e-6)]}, RTOL_FIT)
    assert not _compare({"a": [1.0, 2.0]}, {"a": [1.0, 2.0 * (1 + 2e-7)]}, RTOL_FIT)
    assert _compare({"s": "resolved"}, {"s": "absent"}, RTOL_FIT)
    assert _compare({"x": None}, {"x": 1.0}, RTOL_FIT)
    assert _compare({}, {"x": 1.0}, RTOL_FIT)


def regenerate() -> None:
    """Rewrite the golden file from the current code (after an intended change; review the diff)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        data = {
            "_about": "headline numbers of the bundled PSINS RLG record; regenerate with "
                      "`.venv/bin/python tests/report/test_golden.py` after an intended change (see its docstring)",
            "allan": allan_headline(tmp),
            "analyze": analyze_headline(tmp),
        }
    GOLDEN.parent.mkdir(exist_ok=True)
    GOLDEN.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    print(f"wrote {GOLDEN}")


if __name__ == "__main__":
    sys.exit(regenerate())
