"""Heading-error metric, artefact check and verdicts.

Independent references: a rate ramp, for which the angle errors of constant bias and persistence are written
out by hand (the causal drift taken from :func:`fogdrift.lifting.causal_drift`); the transfer function of
"rate minus the previous causal drift" computed analytically from the drift filter; a simulated record whose
noise model is known (Kalman envelope coverage ~68 %).
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from fogdrift.errors import InsufficientDataError
from fogdrift.evaluation import (artefact_check, compensation_verdicts, evaluate_axis, heading_errors, heading_table,
                                 heading_verdict)
from fogdrift.lifting import causal_drift
from fogdrift.models import Persistence
from fogdrift.models.kalman import Kalman


def test_heading_error_on_a_ramp_by_hand():
    """r_k = a k (dt = 1 s), 300-s calibration: constant bias leaves E(H) = a H (H + 300) / 7200 deg at every
    origin; persistence forecasts the last causal-drift value c of the calibrated window, E = E_bias - H c / 3600."""
    a = 0.01  # deg/h per s
    r = a * np.arange(8000.0)
    res = heading_errors(r, 1.0, {"persistence": Persistence().fit([0.0])}, causal_window=128,
                         horizons_s=(60.0, 600.0, 3600.0))
    H = np.array([60.0, 600.0, 3600.0])
    e_bias = a * H * (H + 300.0) / 7200.0
    win = r[:300] - r[:300].mean()  # every window is the same ramp once calibrated
    c_last = causal_drift(win, 128, "db2", level=4, mode="symmetric")[-1]
    e_pers = e_bias - H * c_last / 3600.0
    for j, h in enumerate(H):
        assert_allclose(res.row("constant bias", h).rms_deg, e_bias[j], rtol=1e-9)
        assert_allclose(res.row("persistence", h).rms_deg, abs(e_pers[j]), rtol=1e-9)
        assert_allclose(res.row("persistence", h).ratio_to_bias, abs(e_pers[j]) / e_bias[j], rtol=1e-9)
    assert res.row("constant bias", 60.0).n_origins == len(range(300, 8000 - 60 + 1, 300))
    assert res.row("constant bias", 3600.0).n_origins == len(range(300, 8000 - 3600 + 1, 300))
    # the errors of every origin, not only their RMS
    assert_allclose(res.errors["constant bias"][:, 0], e_bias[0], rtol=1e-9)


def test_horizons_that_do_not_fit_are_dropped_and_short_windows_refused():
    r = np.random.default_rng(0).normal(0.0, 1.0, 1000)
    res = heading_errors(r, 1.0, {}, causal_window=128, horizons_s=(60.0, 3600.0))
    assert res.horizons_s == (60.0,) and "3600 s dropped" in res.notes[0]
    with pytest.raises(InsufficientDataError, match="longer than the causal-drift window"):
        heading_errors(r, 1.0, {}, causal_window=128, calib_s=100.0)
    with pytest.raises(InsufficientDataError, match="no horizon fits"):
        heading_errors(r[:320], 1.0, {}, causal_window=128, horizons_s=(60.0,))


def test_kalman_envelope_holds_68_percent_of_origins_with_the_true_noise_model():
    """White 6 (deg/h) sqrt(s) + random walk 0.01 (deg/h)/sqrt(s) at 1 Hz; 60-s horizons every 120 s (no overlap):
    the predicted 1-sigma angle envelope holds the real error at 60-76 % of ~800 origins."""
    rng = np.random.default_rng(4)
    n = 100_000
    r = 2.0 + rng.normal(0.0, 6.0, n) + np.cumsum(rng.normal(0.0, 0.01, n))
    kal = Kalman(components=[{"kind": "white", "arw_dprh": 0.1}, {"kind": "random_walk", "rrw_dphrh": 0.6}],
                 bias_prior_dph=100.0).fit(r[:100])
    res = heading_errors(r, 1.0, {"Kalman": kal}, causal_window=128, step_s=120.0, horizons_s=(60.0,))
    row = res.row("Kalman", 60.0)
    assert row.n_origins > 800
    assert 0.60 < row.inside_sigma < 0.76
    # the envelope is the white-noise angle random walk plus the calibration's bias error, about 6 sqrt(60) arcsec
    assert 0.9 < row.predicted_sigma_deg / (6.0 * np.sqrt(60.0 + 60.0**2 / 300.0) / 3600.0) < 1.1


def test_persistence_gain_is_the_analytic_transfer_function():
    """comp[k] = z[k] - sum_i g_i z[k - W + i]: |H(f)| = |1 - sum_i g_i exp(-2 pi i f (W - i))| (dt = 1 s)."""
    z = np.random.default_rng(1).normal(0.0, 5.0, 6000)
    freqs = [0.001, 0.002, 0.005, 0.01, 0.05, 0.2, 0.5]
    res = artefact_check(z, 1.0, {"persistence": Persistence().fit([0.0])}, causal_window=128, frequencies_hz=freqs)
    g = causal_drift(np.eye(128), 128, "db2", level=4, mode="symmetric")[-1]
    lags = 128 - np.arange(128)
    for f in freqs:
        H = 1.0 - np.sum(g * np.exp(-2j * np.pi * f * lags))
        assert_allclose(res.row("persistence").gains[f], abs(H), rtol=1e-6)
    row = res.row("persistence")
    assert abs(row.step_survival[1000.0]) < 1e-9  # a step is fully absorbed once it fills the causal window
    assert abs(row.ramp_survival) < 1e-6
    assert res.row("constant bias").gains[0.001] == 1.0 and res.amplitude_dph == pytest.approx(3 * np.std(z))


def test_a_high_pass_that_claims_an_allan_improvement_is_flagged():
    """On random walk + white noise, persistence of the causal drift lowers long-tau ADEV (the claim) by removing
    slow rate: flagged at the low frequencies; a Kalman filter with a white-noise model removes nothing."""
    rng = np.random.default_rng(2)
    z = rng.normal(0.0, 5.0, 8000) + np.cumsum(rng.normal(0.0, 0.5, 8000))
    kal = Kalman(components=[{"kind": "white", "arw_dprh": 5 / 60}], bias_prior_dph=1e-6).fit(z[:10])
    res = artefact_check(z, 1.0, {"persistence": Persistence().fit([0.0]), "Kalman": kal}, causal_window=128)
    p = res.row("persistence")
    assert 0.001 in p.flagged_hz and p.adev_ratio[0.001] < 0.9 and p.gains[0.001] < 0.1
    assert res.row("Kalman").flagged_hz == ()


@pytest.fixture(scope="module")
def model_axis():
    from fogdrift.io import from_array
    from fogdrift.pipeline import AnalysisConfig, run_models
    from fogdrift.simulate import simulate

    rec = from_array(simulate(6000, 1.0, arw_dprh=0.1, rrw_dphrh=3.0, bias_dph=1.0, seed=3), dt_s=1.0,
                     axis_names=["gz"])
    cfg = AnalysisConfig(models=("ar", "kalman", "persistence"), model_rate_hz=None, train_fraction=0.4,
                         val_fraction=0.2)
    return run_models(rec, cfg)[0], cfg


def test_evaluate_axis_gives_the_verdicts_headline_first(model_axis):
    ma, cfg = model_axis
    ev = evaluate_axis(ma, cfg)
    assert [v.kind for v in ev["verdicts"]] == ["heading", "artefacts", "causal", "paper"]
    assert "paper's measure" in ev["verdicts"][-1].lines[0]
    assert ev["heading"].horizons_s == (60.0, 600.0) and "3600 s dropped" in ev["heading"].notes[0]
    headers, rows = heading_table(ev["heading"])
    assert headers[0] == "model" and [r[0] for r in rows] == ["constant bias", "AR(p)", "Kalman", "persistence"]
    text = " ".join(heading_verdict(ev["heading"]).lines)
    assert "constant bias leaves" in text and "origins" in text
    assert "7 origin(s) are too few to judge" in text and "reduces the heading error" not in text
    assert [v.kind for v in compensation_verdicts(model_axis=ma)] == ["causal", "paper"]


def test_analyze_heading_prints_the_evaluation_and_writes_a_bundle(bundled_path, tmp_path):
    from typer.testing import CliRunner

    from fogdrift.bundle import load_bundle
    from fogdrift.cli import app

    result = CliRunner().invoke(app, ["analyze", str(bundled_path), "--unit", "deg/h", "--columns", "gz", "--models", "ar,persistence",
                                      "--train-fraction", "0.4", "--val-fraction", "0.1", "--heading",
                                      "--details", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    out = result.output
    assert "heading error after a 300-s calibration" in out and "surviving fraction" in out
    assert out.index("heading error after") < out.index("paper's measure (one step ahead")
    assert load_bundle(tmp_path / "bundle").axis_names == ("gz",)
