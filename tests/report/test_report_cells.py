"""The periodic / Markov cell prints T_c and sigma only where the data bound them."""

from __future__ import annotations

from types import SimpleNamespace as NS

from fogdrift.report.tables import shaped_cell


def _fit(lo95, tc_lo, tc_hi, no_fit=None):
    m = {"tc_s": 48.0, "tc_lo95_s": tc_lo, "tc_hi95_s": tc_hi, "sigma_dph": 3.1}
    return NS(selected=("N", "M"), shaped={"M": m}, no_fit=no_fit,
              terms={"S": NS(value=None), "M": NS(value=0.6, lo95=lo95, hi95=0.9)})


def test_a_bounded_markov_term_prints_sigma_and_tc_with_its_interval():
    assert shaped_cell(_fit(0.3, 35.0, 70.0)) == "M σ 3.1 deg/h, T_c 48 [35, 70] s"


def test_an_unbounded_tc_or_unresolved_qc_prints_no_number():
    for fit in (_fit(0.3, None, 70.0), _fit(0.3, 35.0, None), _fit(0.0, 35.0, 70.0)):
        cell = shaped_cell(fit)
        assert cell == "M in the model, not resolved (T_c not bounded by the data)"
        assert "48" not in cell and "?" not in cell


def test_no_model_fits_prints_nothing():
    assert shaped_cell(_fit(0.3, 35.0, 70.0, no_fit={"why": "x"})) == "–"
