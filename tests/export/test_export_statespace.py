"""Item 3 of issue 22: the filter-ready state-space model and its exact discretisation.

Van Loan's matrix exponential is checked against closed forms derived by hand (scalar Gauss-Markov, random walk,
the integrated random walk's 2x2 covariance, a ramp) and against fogdrift.models.statespace.state_space; an
export made from a log is checked end to end against the white noise that was put into the log."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from fogdrift.cli import app
from fogdrift.errors import ConfigError
from fogdrift.export.discretize import continuous_model, van_loan
from fogdrift.models.statespace import state_space

runner = CliRunner()
D = math.pi / 180.0
ADIS = Path("/work/shared/data/adis16405_static/adis16405_imu1.csv.gz")


@pytest.mark.parametrize("tc, sigma, dt", [(2.0, 3.0, 0.01), (0.5, 1.0, 1.0), (1000.0, 0.1, 0.005)])
def test_van_loan_gauss_markov_closed_form(tc, sigma, dt):
    phi, qd = van_loan([[-1.0 / tc]], [[2.0 * sigma ** 2 / tc]], dt)
    assert phi[0, 0] == pytest.approx(math.exp(-dt / tc), rel=1e-13)
    assert qd[0, 0] == pytest.approx(sigma ** 2 * (1.0 - math.exp(-2.0 * dt / tc)), rel=1e-10)


def test_van_loan_random_walk_and_integrated_random_walk():
    k2, dt = 4e-6, 0.25
    phi, qd = van_loan([[0.0]], [[k2]], dt)
    assert phi[0, 0] == 1.0 and qd[0, 0] == pytest.approx(k2 * dt, rel=1e-13)
    # x = [angle, rate], d angle/dt = rate, d rate/dt = w: Qd = q [[dt^3/3, dt^2/2], [dt^2/2, dt]]
    phi, qd = van_loan([[0.0, 1.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, k2]], dt)
    assert phi == pytest.approx(np.array([[1.0, dt], [0.0, 1.0]]))
    want = k2 * np.array([[dt ** 3 / 3, dt ** 2 / 2], [dt ** 2 / 2, dt]])
    assert np.allclose(qd, want, rtol=1e-12, atol=0)


def test_van_loan_refuses_bad_input():
    with pytest.raises(ConfigError, match="dt_s must be a finite number > 0"):
        van_loan([[0.0]], [[1.0]], 0.0)
    with pytest.raises(ConfigError, match="square and of one size"):
        van_loan([[0.0, 1.0]], [[1.0]], 1.0)


def test_continuous_model_discretised_equals_statespace_closed_forms():
    comps = [{"kind": "white", "arw_dprh": 0.1}, {"kind": "quantization", "q_urad": 2.0},
             {"kind": "random_walk", "rrw_dphrh": 0.6}, {"kind": "gauss_markov", "tc_s": 30.0, "sigma_dph": 0.5},
             {"kind": "gauss_markov", "tc_s": 300.0, "sigma_dph": 0.2}, {"kind": "ramp", "ramp_dph2": 0.3}]
    dt = 0.1
    cm = continuous_model(comps, 1.0)          # scale 1: deg/h units, as statespace's
    phi, qd = van_loan(cm["F"], cm["Qc"], dt)
    ss = state_space(comps, dt_s=dt, bias_prior_dph=1.0)
    assert cm["names"] == list(ss.names)
    assert np.allclose(phi, ss.F, rtol=0, atol=1e-14)
    assert np.allclose(qd, ss.Q, rtol=1e-10, atol=1e-22)
    r = cm["white_density"] ** 2 / dt + 2 * cm["quantization"] ** 2 / dt ** 2
    assert r == pytest.approx(ss.r, rel=1e-12)


def test_export_from_a_log_recovers_the_white_noise(tmp_path):
    # white rate noise of N = 0.5 deg/sqrt(h) at 10 Hz: sigma = 60 N / sqrt(dt) deg/h per sample
    rng = np.random.default_rng(7)
    n_arw, dt = 0.5, 0.1
    x = rng.standard_normal(2 ** 15) * 60.0 * n_arw / math.sqrt(dt)
    log = tmp_path / "white.csv"
    np.savetxt(log, np.column_stack([np.arange(x.size) * dt, x]), delimiter=",", header="t_s,gz[deg/h]",
               comments="", fmt="%.10g")
    res = runner.invoke(app, ["export", str(log), "--target", "kalibr,json", "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    d = yaml.safe_load((tmp_path / "o" / "imu.yaml").read_text())
    assert d["gyroscope_noise_density"] == pytest.approx(n_arw * D / 60, rel=0.05)
    assert d["update_rate"] == pytest.approx(10.0)
    assert (tmp_path / "o" / "allan.json").is_file()          # the fit the export came from is kept beside it


@pytest.mark.slow
@pytest.mark.skipif(not ADIS.is_file(), reason="ADIS16405 session 1 not on this machine")
def test_adis16405_session1_all_targets(tmp_path):
    res = runner.invoke(app, ["export", str(ADIS), "--unit", "deg/s", "--out", str(tmp_path / "o")])
    assert res.exit_code == 0, res.output
    d = yaml.safe_load((tmp_path / "o" / "imu.yaml").read_text())
    # the Allan fit's N of the three axes is 2.2-2.5 deg/sqrt(h) (README of the data set: ARW about 2.4)
    assert 2.2 * D / 60 < d["gyroscope_noise_density"] < 2.7 * D / 60
    # gx has no K in its model: its bound is written and said as a bound
    assert "gx: K is its 95 % upper bound" in res.output


def test_discrete_values_simulate_back_to_the_continuous_densities():
    """The comments' discrete values, used the way Kalibr's wiki simulates (white sigma_d = N sqrt(f), bias steps
    K / sqrt(f)), give back N as the ADEV at tau = 1 s (allantools, independent of fogdrift) and K^2 T as the
    variance of the bias change over T."""
    import allantools

    from fogdrift.export.conversions import walk_discrete, white_discrete

    n_si, k_si, f = 1e-3, 2e-5, 50.0                          # rad/s/sqrt(Hz), rad/s^2/sqrt(Hz), Hz
    rng = np.random.default_rng(3)
    m = 2 ** 18
    bias = np.cumsum(rng.standard_normal(m) * walk_discrete(k_si, f))
    y = rng.standard_normal(m) * white_discrete(n_si, f) + bias
    _, adev, _, _ = allantools.oadev(y, rate=f, data_type="freq", taus=np.array([1.0]))
    assert adev[0] == pytest.approx(math.sqrt(n_si ** 2 / 1.0 + k_si ** 2 * 1.0 / 3), rel=0.03)
    t_s = 10.0                                                # 524 independent 10-s changes: about 6 % scatter
    change = np.diff(bias[:: int(t_s * f)])
    assert np.mean(change ** 2) == pytest.approx(k_si ** 2 * t_s, rel=0.2)
