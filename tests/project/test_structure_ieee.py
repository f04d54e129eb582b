"""One IEEE-term shape for the Allan fit and GMWM (issue 21): fleet's one column mapper, GMWM's B_min in the Allan
fit's ``b_min`` shape, the term list and the report's model order read from their tables."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from fogdrift.fleet.commands import TERMS, ieee_columns
from fogdrift.gmwm.ieee import BiasInstability
from fogdrift.models.registry import MODELS
from fogdrift.noise.terms import TERM_TABLE
from fogdrift.report.html import MODEL_ORDER, _order
from fogdrift.report.tables import NOISE_HEADERS


def _b(value=None, lo=None, hi=None, tau=None, bound=None):
    return BiasInstability("min-avar", value, lo, hi, tau, bound, "" if value else "still falling",
                           "min of the model's ADEV / 0.664")


def test_gmwm_b_min_in_the_allan_shape():
    got = _b(2.0, 1.5, 2.5, 117.0).as_b_min()
    assert got == {"value": 2.0, "unit": "deg/h", "tau_s": 117.0, "bound_only": False, "lo95": 1.5, "hi95": 2.5,
                   "rule": "min of the model's ADEV / 0.664"}
    bound = _b(tau=900.0, bound=7.06).as_b_min()     # beyond the scales used: the 95 % bound, flagged
    assert bound["value"] == 7.06 and bound["bound_only"] is True and bound["lo95"] is None
    assert bound["hi95"] == 7.06 and bound["tau_s"] == 900.0
    assert _b().as_b_min() == {}
    # the Allan fit's b_min has these keys (noise/checks.py _classical_b)
    assert set(got) == {"value", "unit", "tau_s", "bound_only", "lo95", "hi95", "rule"}


def test_one_column_mapper_for_both_methods():
    t = SimpleNamespace
    terms = {n: t(value=None, lo95=None, hi95=0.5, status="absent") for n in TERM_TABLE}
    terms["N"] = t(value=0.01, lo95=0.009, hi95=0.011, status="resolved")
    allan = ieee_columns(terms, {"value": 2.0, "tau_s": 117.0, "bound_only": False})
    gmwm = ieee_columns(terms, _b(2.0, 1.5, 2.5, 117.0).as_b_min())
    assert allan == gmwm
    assert allan["N_dprh"] == 0.01 and allan["N_lo95_dprh"] == 0.009 and allan["N_hi95_dprh"] == 0.011
    assert allan["Q_urad"] is None and allan["Q_hi95_urad"] == 0.5 and allan["Q_status"] == "absent"
    assert allan["b_min_dph"] == 2.0 and allan["b_min_tau_s"] == 117.0 and allan["b_min_bound_only"] is False
    bound = ieee_columns(terms, _b(tau=900.0, bound=7.06).as_b_min())
    assert bound["b_min_dph"] == 7.06 and bound["b_min_bound_only"] is True
    none = ieee_columns(terms, _b().as_b_min())
    assert none["b_min_dph"] is None and none["b_min_tau_s"] is None and none["b_min_bound_only"] is None


def test_term_lists_come_from_the_term_table():
    assert TERMS == (("Q", "urad"), ("N", "dprh"), ("B", "dph"), ("K", "dphrh"), ("R", "dph2"))
    assert [n for n, _ in TERMS] == list(TERM_TABLE)
    assert NOISE_HEADERS == ("Q [µrad]", "N [deg/√h]", "B [deg/h]", "K [deg/h^1.5]", "R [deg/h²]")


def test_report_model_order_is_the_registry_order():
    labels = [s.label for s in MODELS]
    assert MODEL_ORDER == ("constant bias", *labels[:-1]) and labels[-1] == "persistence"
    got = _order(["persistence", "AR(4)", "Kalman", "constant bias", "GM(1,1)", "Elman", "grey-Elman", "other"])
    assert got == ["constant bias", "grey-Elman", "Elman", "GM(1,1)", "AR(4)", "Kalman", "other", "persistence"]


@pytest.mark.parametrize("label", ["ARX", "AR"])
def test_ar_template_matches_only_ar_with_an_order(label):
    assert _order([label, "AR(2)"])[0] == "AR(2)"


def test_one_strict_json_writer(tmp_path):
    import json

    import numpy as np

    from fogdrift import _util, report
    from fogdrift.report import files

    assert report.write_json is files.write_json
    doc = {"edf": np.array([1.5, np.nan]), "tau_s": np.float32(2.0), "hi": float("inf"), "n": np.int64(3),
           "nested": [{"x": float("-inf")}]}
    p = files.write_json(doc, tmp_path / "a.json")
    text = p.read_text()
    assert "NaN" not in text and "Infinity" not in text
    assert json.loads(text) == {"edf": [1.5, None], "tau_s": 2.0, "hi": None, "n": 3, "nested": [{"x": None}]}
    assert [f.name for f in tmp_path.iterdir()] == ["a.json"]        # no temporary left beside it
    assert _util.strict_json({"b": 1, "a": 2}, indent=None, sort_keys=True) == '{"a": 2, "b": 1}'


def test_flicker_constant_has_one_home():
    import math

    from fogdrift.gmwm.ieee import B_ADEV_FACTOR
    from fogdrift.units import B_FACTOR

    assert B_ADEV_FACTOR is B_FACTOR and math.isclose(B_FACTOR, 0.664282, rel_tol=1e-6)


def _old_table(x, digits=4):  # report/tables._fmt before the one formatter (oracle)
    import math
    if x is None:
        return "–"
    x = float(x)
    if not math.isfinite(x):
        return "NaN"
    if x == 0:
        return "0"
    if abs(x) >= 1e4 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def _old_gmwm(x, digits=4):  # report/gmwm.fmt before
    import math
    if isinstance(x, str):
        return x
    if x is None or not math.isfinite(float(x)):
        return "–"
    return f"{float(x):.{digits}g}"


def _old_page(x):  # fleet/page._fmt before
    if x is None:
        return "–"
    if isinstance(x, float):
        return f"{x:.0f}" if 1e4 <= abs(x) < 1e9 and x == round(x) else f"{x:.4g}"
    return str(x)


VALUES = [None, 0.0, -0.0, 1.0, -2.5, 2.41234e-4, 9.99949e-4, 1e-3, 0.012345678, 123.456, 9999.4, 9999.96, 1e4,
          12345.0, -12345.678, 3.6e5, 1e9, 2.5e12, float("nan"), float("inf"), float("-inf"), 7, 0]


@pytest.mark.parametrize("x", VALUES)
def test_one_formatter_prints_what_each_old_one_printed(x):
    from fogdrift.fleet.page import _fmt as page
    from fogdrift.evaluation.gmwm_vs_allan import _g
    from fogdrift.report.gmwm import fmt as gmwm
    from fogdrift.report.tables import _fmt as table

    for d in (2, 3, 4):
        assert table(x, d) == _old_table(x, d)
        assert gmwm(x, d) == _old_gmwm(x, d)
        if x is not None:
            assert _g(x, d) == f"{x:.{d}g}"
    assert page(x) == _old_page(x)
    assert gmwm("< 7.06") == "< 7.06"


def test_no_copies_in_the_report_and_fleet_packages():
    # a ratchet on the places this issue cleaned: the term list, JSON serialisation, the flicker constant
    import re
    from pathlib import Path

    src = Path(__file__).resolve().parents[2] / "src" / "fogdrift"
    files = [*sorted((src / "report").glob("*.py")), src / "fleet" / "commands.py", src / "fleet" / "page.py",
             src / "fleet" / "summary.py", src / "gmwm" / "ieee.py", src / "evaluation" / "gmwm_vs_allan.py"]
    for f in files:
        text = f.read_text(encoding="utf-8")
        assert '"Q", "N", "B", "K", "R"' not in text, f"{f.name}: read the term list from noise.terms.TERMS"
        assert not re.search(r"json\.dumps?\(", text), f"{f.name}: JSON through _util.strict_json / report write_json"
        assert not re.search(r"log\(2(\.0)?\) / (math|np)\.pi", text), f"{f.name}: the flicker constant is units.B_FACTOR"
