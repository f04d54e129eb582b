"""A selected term whose estimate sits at its data bound is named in the fit's notes, with the point that sets it;
and the point where the model is farthest (>= 2x in deviation) from the measured curve is named, with whether
that gap is inside the point's own 95 % interval.

The noise fit keeps every term, alone, below each point's ~4-sigma upper limit (``noise/identify.py``
``_Context._upper``).  When the estimate ends there, the value is set by that one point, not by the fit, and the
note says so.  Real case: the bundled RLG's gx, where N = 0.3043 deg/√h equals the upper end of its own 95 %
interval inside a poor fit (chi2_red 23); its gz fits without a bound.  The note's value is checked against the
term itself and the bound against the fit's coefficient and the point's limit, recomputed here.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from fogdrift.io import load


@pytest.fixture(scope="module")
def rlg_fits(bundled_path):
    # the curve alone (no spectrum: the published-curve path), so the power-law terms are judged by themselves;
    # with the spectrum the axes' lines enter as S and the fits change (tests/noise/test_noise_periodic.py)
    from fogdrift.allan import allan_variance
    from fogdrift.noise import fit_noise

    rec = load(bundled_path, unit="deg/h")
    return {name: fit_noise(allan_variance(rec.axis(name), rec.dt_s)) for name in rec.axis_names}


def test_rlg_gx_names_N_at_its_data_bound(rlg_fits):
    f = rlg_fits["gx"]
    notes = [n for n in f.notes if "sits at its data bound" in n]
    assert len(notes) == 1 and notes[0].startswith("N = ")
    value = float(re.match(r"N = ([0-9.eE+-]+) deg/√h", notes[0]).group(1))
    assert value == pytest.approx(f.terms["N"].value, rel=1e-3)
    if f.no_fit is None:
        assert f.terms["N"].value == pytest.approx(f.terms["N"].hi95, rel=1e-3)  # the interval ends at the bound
    else:  # no model fits: the printed bound is the curve's own, which holds the best candidate's value
        assert f.terms["N"].status == "no_fit" and f.terms["N"].hi95 >= f.terms["N"].value
    tau = float(re.search(r"at tau = ([0-9.eE+-]+) s", notes[0]).group(1))
    assert tau in np.round(f.fit_tau_s, 2)


def test_rlg_gz_has_no_bound_note(rlg_fits):
    assert not any("data bound" in n for n in rlg_fits["gz"].notes)
    assert rlg_fits["gz"].terms["N"].value < rlg_fits["gz"].terms["N"].hi95 * 0.99


def test_no_bound_note_when_white_noise_is_fitted_freely():
    # pure white noise: N is set by every point together, never by one point's limit (10 seeds)
    from fogdrift.allan import allan_variance
    from fogdrift.noise import fit_noise
    from fogdrift.simulate import simulate

    for seed in range(10):
        f = fit_noise(allan_variance(simulate(2**16, 0.01, arw_dprh=0.05, seed=seed), 0.01, taus="octave"))
        assert f.terms["N"].status == "resolved", seed
        assert not any("data bound" in n for n in f.notes), (seed, f.notes)
        assert not any("outside that point's own 95 % interval" in n for n in f.notes), (seed, f.notes)


def test_rlg_largest_gap_is_named_with_the_ratio_the_fit_stores(rlg_fits):
    # gx: the flat floor the curve contradicts is no longer in the model (it put the model 5.6x above the last
    # point); re-selected without it, the model stays within 2x of every fitted point and no gap is named
    gx = rlg_fits["gx"]
    assert "B" not in gx.selected and gx.terms["B"].status == "not_estimable"
    assert np.max(np.abs(np.log(np.sqrt(np.asarray(gx.model_var) / np.asarray(gx.fit_var))))) < np.log(2.0)
    assert not any(n.startswith("largest gap") for n in gx.notes)
    # gy (Q+N): the model lies far above the falling long-tau end; the note names that point with its ratio
    f = rlg_fits["gy"]
    (note,) = [n for n in f.notes if n.startswith("largest gap")]
    m = re.match(r"largest gap: at tau = ([0-9.eE+]+) s the model's deviation is ([0-9.]+)x the measured one "
                 r"\(above it; ~([0-9.eE+-]+) degrees of freedom\), (inside|outside) that point's own 95 % "
                 r"interval", note)
    assert m, note
    k = int(np.argmin(np.abs(np.asarray(f.fit_tau_s) - float(m.group(1)))))
    ratio = np.sqrt(np.asarray(f.model_var) / np.asarray(f.fit_var))
    assert float(m.group(2)) == pytest.approx(ratio[k], abs=0.006) and ratio[k] >= 2.0
    assert k == int(np.argmax(np.abs(np.log(ratio))))  # the farthest point of the fitted range
