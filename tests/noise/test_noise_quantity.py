"""Tests of ``fogdrift.noise.quantity`` (first written against the surviving mutants of a mutation round,
docs/testing-rounds.md): :func:`express` re-states every number of a fit (value, interval, B_min and its SI
copy, read-outs) by the factor of its own term, relabels the units, and leaves a gyro fit alone.

The factors themselves are pinned by hand in ``tests/test_accel.py::test_unit_factor_gyro_to_accel``
(N: 3600, B: 1/9.80665e-6); here they are written out again as numbers."""

from __future__ import annotations

import dataclasses

import pytest

from fogdrift.allan import allan_variance
from fogdrift.noise import fit_noise
from fogdrift.noise.quantity import express, unit_factor
from fogdrift.simulate import simulate

# per term: factor from the gyro table's unit to the accelerometer table's, and the accelerometer unit
ACC = {"N": (3600.0, "m/s/sqrt(h)"), "B": (1.0 / 9.80665e-6, "ug")}


@pytest.fixture(scope="module")
def fit():
    y = simulate(2**14, 0.01, arw_dprh=0.002, bias_instability_dph=0.05, seed=3)  # a model ADEV minimum inside
    f = fit_noise(allan_variance(y, 0.01))
    # a note and a reason written in gyro units, to be re-stated
    return dataclasses.replace(f, notes=["N = 0.01 deg/√h sits at its bound"])


def test_a_gyro_fit_is_returned_unchanged(fit):
    assert express(fit, "angular_rate") is fit


def test_every_term_value_and_interval_is_scaled_by_its_own_factor(fit):
    acc = express(fit, "specific_force")
    assert acc is not fit and acc.quantity == "specific_force"
    for name, t in fit.terms.items():
        a = acc.terms[name]
        f = unit_factor(name, "specific_force")
        if name in ("N", "B"):
            assert f == pytest.approx(ACC[name][0], rel=1e-12)
            assert a.unit == ACC[name][1]
        assert a.name == name and a.status == t.status
        for attr in ("value", "lo95", "hi95"):
            g = getattr(t, attr)
            assert (getattr(a, attr) is None) if g is None else getattr(a, attr) == pytest.approx(g * f, rel=1e-12)
    n = acc.terms["N"]
    assert n.value == pytest.approx(fit.terms["N"].value * 3600.0, rel=1e-12)
    assert n.lo95 < n.value < n.hi95


def test_b_min_is_in_micro_g_and_its_si_copy_in_m_per_s2(fit):
    acc = express(fit, "specific_force")
    b, b0 = acc.b_min, fit.b_min
    assert b["unit"] == "ug" and b["tau_s"] == b0["tau_s"]
    for k in ("value", "lo95", "hi95"):
        assert b[k] == pytest.approx(b0[k] / 9.80665e-6, rel=1e-12)
        assert b["si"][k] == pytest.approx(b0[k], rel=1e-12)   # the internal unit is m/s^2 already
    assert b["si"]["unit"] == "m/s^2"
    assert fit.b_min["unit"] == "deg/h"   # the input is not modified


def test_read_outs_are_scaled_and_relabelled(fit):
    acc = express(fit, "specific_force")
    r0, r = fit.readouts["N"], acc.readouts["N"]
    assert r.value == pytest.approx(r0.value * 3600.0, rel=1e-12) and r.unit == "m/s/sqrt(h)"
    assert (r.tau_s, r.slope, r.dominated) == (r0.tau_s, r0.slope, r0.dominated)
    assert acc.readouts["Q"].value is None


def test_notes_are_restated(fit):
    acc = express(fit, "specific_force")
    assert acc.notes == ["N = 36 m/s/√h sits at its bound"]


def test_restate_text_of_the_shaped_units_and_a_bare_rate_unit():
    from fogdrift.noise.quantity import restate_text

    assert restate_text("q = 0.5 deg/h/√s here", "specific_force") == "q = 0.5 m/s^2/sqrt(s) here"
    assert restate_text("in deg/h throughout", "specific_force") == "in m/s^2 throughout"
    assert restate_text("N = 0.01 deg/√h", "angular_rate") == "N = 0.01 deg/√h"


def test_unit_factor_of_shaped_terms_is_one():
    assert unit_factor("S", "specific_force") == 1.0 and unit_factor("M", "specific_force") == 1.0


def test_shaped_terms_are_relabelled_and_excluded_reasons_restated(fit):
    from fogdrift.noise.result import NoiseTerm

    f = dataclasses.replace(fit, terms={**fit.terms, "S": NoiseTerm("S", 2.0, "deg/h", 1.0, 3.0, "resolved", ""),
                                        "M": NoiseTerm("M", 0.5, "deg/h/sqrt(s)", None, None, "resolved", "")},
                            excluded=[{"tau_s": 1.0, "why": "above 0.01 deg/√h"}, "kept"])
    acc = express(f, "specific_force")
    assert (acc.terms["S"].unit, acc.terms["S"].value, acc.terms["S"].hi95) == ("m/s^2", 2.0, 3.0)
    assert (acc.terms["M"].unit, acc.terms["M"].value) == ("m/s^2/sqrt(s)", 0.5)
    assert acc.excluded == [{"tau_s": 1.0, "why": "above 36 m/s/√h"}, "kept"]


def test_restate_text_of_an_interval_scales_both_ends():
    from fogdrift.noise.quantity import restate_text

    # N 0.01 [0.005, 0.02] deg/√h -> x 3600: 36 [18, 72] m/s/√h
    assert restate_text("N = 0.01 [0.005, 0.02] deg/√h", "specific_force") == "N = 36 [18, 72] m/s/√h"


def test_shaped_markov_and_sinusoid_units_are_relabelled(fit):
    f = dataclasses.replace(fit, shaped={"M": {"q": 1.0, "q_unit": "deg/h/sqrt(s)", "sigma_unit": "deg/h"},
                                         "S": {"amplitude": 2.0, "amplitude_unit": "deg/h"}})
    acc = express(f, "specific_force")
    assert acc.shaped["M"] == {"q": 1.0, "q_unit": "m/s^2/sqrt(s)", "sigma_unit": "m/s^2"}
    assert acc.shaped["S"] == {"amplitude": 2.0, "amplitude_unit": "m/s^2"}
    assert f.shaped["M"]["sigma_unit"] == "deg/h"   # the input is not modified
