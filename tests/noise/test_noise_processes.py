"""The noise-process table (:mod:`fogdrift.noise.processes`): each row agrees with itself across its forms, the
consumers read the rows, and a process added from outside the package reaches GMWM, the simulators, the Allan-law
views and the exports (issue 31, deliver 1).

Independent references: quadrature of each row's PSD through the Allan transfer function (IEEE Std 952-1997
eq. C.2, sigma^2(tau) = 4 int_0^inf S(f) sin^4(pi f tau) / (pi f tau)^2 df); hand values of the SI factors
(1 deg = pi/180 rad, 1 h = 3600 s); Allan variances of seeded simulations (allantools) at a tolerance set by the EDF.
"""

from __future__ import annotations

import math

import allantools
import numpy as np
import pytest
from scipy.integrate import quad

from fogdrift.allan import allan_variance
from fogdrift.errors import ConfigError
from fogdrift.export.conversions import UNIT_TABLE, si_unit, to_si
from fogdrift.gmwm import gmwm_fit, haar_wvar, parse_model
from fogdrift.gmwm.processes import PROCESSES, haar_gain2
from fogdrift.gmwm.simulate import simulate_latent
from fogdrift.models.statespace import COMPONENT_KINDS, component_densities, components_from_allan
from fogdrift.noise import fit_noise
from fogdrift.noise.processes import (LatentSpec, NoiseProcess, TermLaw, TermSpec, power_law_names, process,
                                      processes, registered)
from fogdrift.noise.terms import TERM_TABLE, VARIANCE_LAWS
from fogdrift.simulate import simulate


def _allan_of_psd(psd, tau):
    """IEEE-952 eq. C.2 by quadrature over whole periods of sin^4 (u = pi f tau)."""
    def g(u):
        return psd(u / (math.pi * tau)) * math.sin(u) ** 4 / u**2 / (math.pi * tau)
    total = sum(quad(g, k * math.pi, (k + 1) * math.pi, limit=200)[0] for k in range(4000))
    return 4.0 * total


@pytest.mark.parametrize("name,x", [("N", 3.0), ("B", 0.7), ("K", 0.05)])
def test_each_rows_psd_gives_its_allan_law(name, x):
    p = process(name)
    law = p.laws["adev"]
    for tau in (1.0, 10.0):
        got = _allan_of_psd(lambda f: float(p.psd(x, f)), tau)
        want = law.series[0] * x * x * tau ** law.power
        assert got == pytest.approx(want, rel=2e-3), (name, tau)


def test_quantization_psd_gives_its_allan_law_below_nyquist():
    p = process("Q")
    dt, x, tau = 0.01, 2.0, 0.5  # the band-limited PSD: the Allan integral to 1/(2 dt) only
    def g(f):
        return float(p.psd(x, f, dt)) * math.sin(math.pi * f * tau) ** 4 / (math.pi * f * tau) ** 2
    edges = np.arange(0.0, 0.5 / dt + 1e-9, 1.0 / tau)
    got = 4.0 * sum(quad(g, a, b, limit=200)[0] for a, b in zip(edges[:-1], edges[1:]))
    assert got == pytest.approx(3.0 * x * x / tau**2, rel=0.02)


@pytest.mark.parametrize("name", ["Q", "N", "K", "R", "B"])
def test_latent_wv_is_half_the_allan_law_of_its_ieee_reading(name):
    """The GMWM form and the Allan form of one row describe the same process: AVAR(m) = 2 WV(2m) with the row's IEEE
    reading of the latent parameters put into the row's Allan law (exact for Q, N, R; large m for K and B)."""
    p = process(name)
    dt, theta = 0.02, np.array([0.3])
    reading = p.latent.ieee(theta, dt)
    value = next(v for k, v in reading.items() if k.startswith(name) and k.endswith(p.term.suffix.split("_", 1)[1][:2])
                 or k == f"{name}{p.term.suffix}")
    A = p.term.to_A(value)
    m = np.array([2.0**12, 2.0**14])
    wv2 = 2.0 * p.latent.wv(theta, 2.0 * m)
    law = A * p.laws["adev"].shape(m * dt, dt)
    assert np.allclose(wv2, law, rtol=1e-3), (name, wv2, law)


def test_si_factors_are_the_hand_values_and_agree_with_the_unit_table():
    deg = math.pi / 180.0
    hand = {("N", "gyro"): deg / 60.0, ("K", "gyro"): deg / 3600.0 / 60.0, ("B", "gyro"): deg / 3600.0,
            ("Q", "gyro"): 1e-6, ("R", "gyro"): deg / 3600.0**2, ("N", "accel"): 1.0 / 60.0,
            ("K", "accel"): 1.0 / 60.0, ("B", "accel"): 9.80665e-6, ("Q", "accel"): 1.0, ("R", "accel"): 1.0 / 3600.0}
    for (name, q), factor in hand.items():
        p = process(name)
        assert p.si[q][1] == pytest.approx(factor, rel=1e-12)
        unit = (p.term if q == "gyro" else p.accel_term).unit
        assert UNIT_TABLE[(name, unit)][1] == pytest.approx(factor, rel=1e-12)  # the two homes agree
        assert si_unit(q, name) == p.si[q][0]


def test_components_and_densities_come_from_the_rows():
    assert list(COMPONENT_KINDS) == ["white", "quantization", "random_walk", "ramp", "gauss_markov"]
    comps = components_from_allan([3.0, 36.0, 0.0, 1e-4, 2e-8], tau_range_s=(1, 100), ramp="state")
    assert [c["kind"] for c in comps] == ["white", "quantization", "random_walk", "ramp"]
    d = component_densities(comps)
    # densities in Allan-law units: N^2 = A_N, Q^2 = A_Q / 3, K^2 = 3 A_K, ramp slope sqrt(2 A_R)
    assert d["white2"] == pytest.approx(36.0) and d["quant2"] == pytest.approx(1.0)
    assert d["rw2"] == pytest.approx(3e-4) and d["ramps"][0] == pytest.approx(math.sqrt(4e-8))


def test_lookup_by_any_spelling_and_refusals():
    assert process("ARW") is process("white") is process("WN") is process("N")
    assert process("ar(1)").name == "M" and process("bi").name == "B"
    with pytest.raises(ConfigError, match="no noise process"):
        process("XYZ")
    assert power_law_names() == ("Q", "N", "B", "K", "R")
    assert [p.name for p in processes() if p.slope_rule] == ["K", "R"]


# ---------------------------------------------------------------------------------------------------------------
# A toy process added from this file: fractional f^(-1/2) rate noise
# ---------------------------------------------------------------------------------------------------------------
_GL_X, _GL_W = np.polynomial.legendre.leggauss(24)
_CACHE: dict = {}


def _frac_sdf(f):
    """Two-sided SDF per unit g2 (cycles/sample): |2 sin(pi f)|^(-1/2)."""
    return np.abs(2.0 * np.sin(np.pi * np.asarray(f, dtype=np.float64))) ** -0.5


def _frac_wv_factor(tau):
    """Haar WV per unit g2: 2 int_0^(1/2) |H(f)|^2 S(f) df (Gauss-Legendre on panels of one period of sin^4)."""
    out = []
    for t in np.ravel(np.asarray(tau, dtype=np.float64)):
        m = t / 2.0
        if m not in _CACHE:
            edges = np.unique(np.concatenate([np.arange(0.0, 0.5, 1.0 / m), [0.5]]))
            a, b = edges[:-1, None], edges[1:, None]
            x = (a + b) / 2 + (b - a) / 2 * _GL_X
            w = (b - a) / 2 * _GL_W
            _CACHE[m] = 2.0 * float(np.sum(w * haar_gain2(x, m) * _frac_sdf(x)))
        out.append(_CACHE[m])
    return np.reshape(out, np.shape(tau))


def _frac_simulate(theta, n, rng):
    length = 4 * n
    nf = length // 2 + 1
    f = np.arange(nf) / length
    scale = np.zeros(nf)
    scale[1:] = np.sqrt(length * theta[0] * _frac_sdf(f[1:]) / 2.0)
    spec = (rng.standard_normal(nf) + 1j * rng.standard_normal(nf)) * scale
    spec[-1] = spec[-1].real * math.sqrt(2.0)
    return np.fft.irfft(spec, n=length)[:n]


# Allan law of the toy for tau >> dt: AVAR(m) = 2 WV(2m) -> c g2 m^(-1/2); with X^2 = g2 dt^(1/2) [(deg/h)^2 s^1/2]
# (the coefficient in the law's units) AVAR(tau) = c X^2 tau^(-1/2).
_C = float(2.0 * _frac_wv_factor(2.0 * 4096.0) * 4096.0**0.5)
TOY = NoiseProcess(
    "X", "fractional",
    term=TermSpec("X", "fractional rate noise", -0.5, _C, "(deg/h) s^(1/4)", "deg/h*s^(1/4)", "_dphs4",
                  "X [deg/h·s^¼]", 1.0, -0.5, "toy process of tests/noise/test_noise_processes.py"),
    laws={"adev": TermLaw(-0.5, (_C,), exact=False, source="toy")},
    latent=LatentSpec("FRAC", "fractional f^(-1/2) noise", ("g2",), ("rate^2",),
                      wv=lambda th, tau: th[0] * _frac_wv_factor(tau),
                      sdf=lambda th, f: th[0] * _frac_sdf(f),
                      ieee=lambda th, dt: {"X_dphs4": math.sqrt(th[0] * dt**0.5)},
                      simulate=_frac_simulate),
    simulate=lambda x, n, dt, rng: _frac_simulate([x * x * dt**-0.5], n, rng),
    sim_kwarg="frac_dphs4", sim_stream=4,
    si={"gyro": ("rad/s*s^(1/4)", math.pi / 180.0 / 3600.0)},
)


def test_a_process_added_from_a_test_file_reaches_both_estimators_the_simulators_and_the_exports():
    assert "X" not in TERM_TABLE and "FRAC" not in PROCESSES
    with registered(TOY):
        # the Allan-law views and the lookup see it
        assert TERM_TABLE["X"].long_name == "fractional rate noise" and "X" in VARIANCE_LAWS["adev"]
        assert process("frac") is TOY and power_law_names()[-1] == "X"
        # GMWM: a model string with it, its WV and the compiled kernel's stand-in, and an estimate covering the truth
        mdl = parse_model("wn+frac")
        assert mdl.name == "WN+FRAC" and mdl.param_names == ("WN.sigma2", "FRAC.g2")
        truth = np.array([1.0, 0.05])
        x = simulate_latent(mdl, truth, 2**16, seed=11)
        wv = haar_wvar(x, 0.01)
        fit = gmwm_fit(wv, mdl)
        assert np.all(np.abs(fit.z - np.log(truth)) < 3.5 * fit.se_z), (fit.theta, fit.se_z)
        # the measured WV of the toy alone follows the row's law (the simulator and the WV agree)
        alone = haar_wvar(simulate_latent("FRAC", [2.0], 2**16, seed=3), 1.0)
        law = 2.0 * _frac_wv_factor(alone.tau_samples)
        j = alone.tau_samples <= 2**10
        assert np.all(np.abs(alone.nu2_dph2[j] / law[j] - 1.0) < 4.0 * np.sqrt(2.0 / alone.eta3[j]) + 0.02)
        # the IEEE simulator takes its keyword; its Allan variance follows the row's Allan law (allantools)
        dt, xval = 0.01, 5.0
        y = simulate(2**16, dt, frac_dphs4=xval, seed=5)
        taus = np.array([0.64, 2.56, 10.24])
        t2, ad, err, _ = allantools.oadev(y, rate=1.0 / dt, data_type="freq", taus=taus)
        want = TOY.laws["adev"].scale(dt) * xval**2 * t2**-0.5
        assert np.all(np.abs(ad**2 / want - 1.0) < 0.15), (ad**2 / want)
        # the Allan fit: its law is a column of the design, its spectrum enters the covariance; selected by default
        for seed in (0, 1):
            av = allan_variance(simulate(2**18, dt, arw_dprh=0.01, frac_dphs4=1.0, seed=seed), dt)
            fit = fit_noise(av)
            x_term = fit.terms["X"]
            assert "X" in fit.selected and x_term.status == "resolved" and x_term.unit == "deg/h*s^(1/4)"
            assert x_term.lo95 < 1.0 < x_term.hi95, x_term
            assert fit.terms["N"].lo95 < 0.01 < fit.terms["N"].hi95
        # the exports convert its reported unit to SI through its row
        v, unit, _ = to_si(2.0, "X", "deg/h*s^(1/4)")
        assert unit == "rad/s*s^(1/4)" and v == pytest.approx(2.0 * math.pi / 180.0 / 3600.0)
    assert "X" not in TERM_TABLE and "FRAC" not in PROCESSES  # gone with the block
    with pytest.raises(ConfigError, match="unknown term keyword"):
        simulate(100, 0.01, frac_dphs4=1.0, seed=1)
