"""Kalman compensator built from a GMWM noise model (``Kalman(noise_method="gmwm")``, issue 22 item 3).

Independent references: a seeded simulation of exactly a white + random-walk + Gauss-Markov state-space model at
1 Hz (truth known: components and the drift realisation), the Kalman filter run with the *true* components (the
best any identification can do), the Allan-identified Kalman beside it, and the Allan-law identity that folds a
ramp into a random walk (:func:`fogdrift.models.statespace.components_from_allan`).
"""

from __future__ import annotations

import json
import math
import warnings
from types import SimpleNamespace

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.errors import ConfigError, InsufficientDataError
from fogdrift.models import kalman as kalman_module
from fogdrift.models import load_model, save_model
from fogdrift.models.components import components_from_gmwm
from fogdrift.models.kalman import GMWM_MIN_SAMPLES, Kalman
from fogdrift.models.statespace import components_from_allan

# white 6 (deg/h) sqrt(s) = 0.1 deg/sqrt(h); RW 20 deg/h^1.5 = 1/3 (deg/h)/sqrt(s); GM 30 s, 8 deg/h.  At 1 Hz the
# GM hump (ADEV^2 peak 0.38 * 64 at 57 s) and the random walk (K^2 tau / 3, above the GM's decay beyond ~200 s)
# are both inside a 20 000-s training block.
N_DPRH, K_DPHRH, TC_S, SIGMA_DPH = 0.1, 20.0, 30.0, 8.0
TRUE = [{"kind": "white", "arw_dprh": N_DPRH}, {"kind": "random_walk", "rrw_dphrh": K_DPHRH},
        {"kind": "gauss_markov", "tc_s": TC_S, "sigma_dph": SIGMA_DPH}]
N_TRAIN, N_TEST, H = 20_000, 4_000, 60


def _simulate(n, seed):
    """Rate and drift [deg/h] at 1 Hz of exactly the state-space model (discrete RW + AR(1) + white)."""
    rng = np.random.default_rng(seed)
    white = rng.normal(0.0, 60 * N_DPRH, n)
    rw = np.cumsum(rng.normal(0.0, K_DPHRH / 60, n))
    phi = math.exp(-1.0 / TC_S)
    e = rng.normal(0.0, SIGMA_DPH * math.sqrt(1 - phi**2), n)
    g = np.empty(n)
    g[0] = rng.normal(0.0, SIGMA_DPH)
    for k in range(1, n):
        g[k] = phi * g[k - 1] + e[k]
    return rw + g + white, rw + g


def _scores(model, y, d):
    """(one-step drift RMSE [deg/h] over the test block, RMS 60-s free-run angle error [deg] from origins every 60 s)."""
    pred = model.predict(y[N_TRAIN:], history=y[:N_TRAIN])
    rmse = float(np.sqrt(np.mean((pred - d[N_TRAIN:]) ** 2)))
    state, errs = (model.x_end_, model.P_end_), []
    for o in range(N_TRAIN, N_TRAIN + N_TEST - H + 1, H):
        mean = model.forecast_with_uncertainty(H, state=state)[0]
        errs.append(np.sum(d[o:o + H] - mean) / 3600.0)
        state = model.filter(y[o:o + H], state=state)[2]
    return rmse, float(np.sqrt(np.mean(np.square(errs))))


def _by_kind(comps):
    out = {}
    for c in comps:
        out.setdefault(c["kind"], []).append(c)
    return out


@pytest.fixture(scope="module")
def fitted():
    """Four seeded records: (y, drift, Kalman with the true components, Allan-identified, GMWM-identified)."""
    out = []
    for seed in range(4):
        y, d = _simulate(N_TRAIN + N_TEST, seed)
        m = y[:N_TRAIN].mean()  # bias removed with the training mean, as the pipeline does
        y, d = y - m, d - m
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the Allan route may warn about its fit; not under test here
            models = [Kalman(**kw).fit(y[:N_TRAIN], y[N_TRAIN:])
                      for kw in ({"components": TRUE}, {}, {"noise_method": "gmwm"})]
        out.append((y, d, *models))
    return out


def test_gmwm_identified_components_are_near_the_truth(fitted):
    """Every seed finds the white noise, the random walk and one Gauss-Markov term (a quantization term may come
    with them: 2 of 20 seeds); N within 3 %, K within 45 %, T_c within 35 %, sigma within 15 %, the means over the
    four seeds within 15 / 15 / 10 %.  (Spread over 20 seeds of a 20 000-s block: N 0.096-0.101, K 14.6-27.5,
    T_c 24.5-37.8 s, sigma 7.2-8.9 deg/h; the GMWM's own 95 % intervals are about +-30 %, +-20 %, +-8 %.)"""
    ks, tcs, sigmas = [], [], []
    for _, _, _, _, gm in fitted:
        info = gm.identification_
        assert info["method"] == "gmwm" and info["selected"] in ("WN+RW+GM", "QN+WN+RW+GM")
        assert info["passed_checks"] is True and info["n_samples"] == N_TRAIN
        comps = _by_kind(gm.components_)
        assert set(comps) - {"quantization"} == {"gauss_markov", "random_walk", "white"}
        assert comps["white"][0]["arw_dprh"] == pytest.approx(N_DPRH, rel=0.03)
        ks.append(comps["random_walk"][0]["rrw_dphrh"])
        tcs.append(comps["gauss_markov"][0]["tc_s"])
        sigmas.append(comps["gauss_markov"][0]["sigma_dph"])
    assert_allclose(ks, K_DPHRH, rtol=0.45)
    assert_allclose(tcs, TC_S, rtol=0.35)
    assert_allclose(sigmas, SIGMA_DPH, rtol=0.15)
    assert np.mean(ks) == pytest.approx(K_DPHRH, rel=0.15)
    assert np.mean(tcs) == pytest.approx(TC_S, rel=0.15)
    assert np.mean(sigmas) == pytest.approx(SIGMA_DPH, rel=0.10)


def test_gmwm_identified_kalman_forecasts_at_least_as_well_as_the_allan_one(fitted):
    """On held-out data: the one-step drift error and the 60-s free-run angle error of the GMWM-identified filter are
    no worse than the Allan-identified filter's (1 % slack per seed for the one-step error, none on the mean over
    seeds) and within 1 % / 5 % of the filter that knows the true model."""
    rows = [(_scores(true, y, d), _scores(al, y, d), _scores(gm, y, d)) for y, d, true, al, gm in fitted]
    for (t_rmse, t_ang), (a_rmse, a_ang), (g_rmse, g_ang) in rows:
        assert g_rmse <= 1.01 * a_rmse
        assert g_rmse <= 1.01 * t_rmse and g_ang <= 1.05 * t_ang
    mean = np.mean(np.asarray([[r[0] for r in row] + [r[1] for r in row] for row in rows]), axis=0)
    t_rmse, a_rmse, g_rmse, t_ang, a_ang, g_ang = mean
    assert g_rmse <= a_rmse and g_ang <= a_ang


def test_the_gmwm_fit_sees_exactly_the_training_samples(monkeypatch):
    """Spy on the GMWM: Kalman.fit(y_train, y_val) hands it y_train itself (len == n_train), never y_val."""
    calls = []
    real = kalman_module.analyse_gmwm

    def spy(name, x, dt_s, **kw):
        calls.append(np.array(x, copy=True))
        return real(name, x, dt_s, **kw)

    monkeypatch.setattr(kalman_module, "analyse_gmwm", spy)
    rng = np.random.default_rng(7)
    y_train, y_val = rng.normal(0.0, 6.0, 3000), rng.normal(50.0, 6.0, 1000)
    model = Kalman(noise_method="gmwm").fit(y_train, y_val)
    assert len(calls) == 1 and len(calls[0]) == len(y_train)
    assert_array_equal(calls[0], y_train)
    # the filter's final state is the training block's: continuing it over y_val is what predict does
    assert_array_equal(model.predict(y_val, history=y_train), model.filter(y_val, state=(model.x_end_, model.P_end_))[0])


def test_pipeline_gives_the_gmwm_only_the_training_block(monkeypatch, bundled_record):
    """With noise_method 'gmwm' the pipeline's Kalman runs the GMWM once per axis on exactly the training block."""
    from fogdrift.pipeline import AnalysisConfig, run_models

    calls = []
    real = kalman_module.analyse_gmwm
    monkeypatch.setattr(kalman_module, "analyse_gmwm",
                        lambda name, x, dt_s, **kw: calls.append(np.array(x, copy=True)) or real(name, x, dt_s, **kw))
    ma = run_models(bundled_record.select("gz"), AnalysisConfig(models=("kalman", "persistence"), noise_method="gmwm"))[0]
    a, b = ma.split["train"]
    assert len(calls) == 1 and len(calls[0]) == b - a
    assert_array_equal(calls[0], ma.rate_dph[a:b])
    assert ma.fitted["Kalman"].identification_["method"] == "gmwm"


def test_gmwm_kalman_model_file_round_trip(tmp_path):
    rng = np.random.default_rng(3)
    y = np.cumsum(rng.normal(0.0, 0.05, 2000)) + rng.normal(0.0, 6.0, 2000)
    model = Kalman(noise_method="gmwm").fit(y[:1500])
    json_path, _ = save_model(model, tmp_path / "kal")
    doc = json.loads(json_path.read_text())
    assert doc["params"]["noise_method"] == "gmwm"
    assert doc["state"]["identification_"]["method"] == "gmwm"
    back = load_model(tmp_path / "kal")
    assert isinstance(back, Kalman) and back.noise_method == "gmwm"
    assert back.identification_ == model.identification_ and back.components_ == model.components_
    assert_array_equal(back.predict(y[1500:], history=y[:1500]), model.predict(y[1500:], history=y[:1500]))
    # a file written before noise_method existed loads as the Allan route it was
    del doc["params"]["noise_method"]
    json_path.write_text(json.dumps(doc))
    assert load_model(tmp_path / "kal").noise_method == "allan"


def test_gmwm_refuses_a_short_training_block_in_one_line():
    y = np.random.default_rng(0).normal(0.0, 6.0, GMWM_MIN_SAMPLES - 1)
    with pytest.raises(InsufficientDataError, match=f"needs at least {GMWM_MIN_SAMPLES}") as exc:
        Kalman(noise_method="gmwm").fit(y)
    assert "\n" not in str(exc.value) and "noise_method 'allan'" in str(exc.value)
    Kalman(noise_method="gmwm").fit(np.random.default_rng(0).normal(0.0, 6.0, GMWM_MIN_SAMPLES))


@pytest.mark.parametrize("bad", ["GMWM ", "wavelet", None, 1])
def test_noise_method_is_validated(bad):
    with pytest.raises(ConfigError, match="noise_method must be one of allan, gmwm"):
        Kalman(noise_method=bad).fit(np.zeros(200))


def test_given_components_ignore_the_noise_method():
    model = Kalman(components=TRUE, noise_method="gmwm").fit(np.zeros(10))
    assert model.identification_ == {"method": "given"} and model.components_ == TRUE


def test_gmwm_ramp_folds_into_the_random_walk_like_the_allan_route():
    """DR -> random walk with the Allan variance of the ramp at the longest tau: the same component as
    components_from_allan gives for the same N, K, R (A_-1 = N^2, A_1 = K^2/3, A_2 = R^2/2 in (deg/h)^2 and s)."""
    v = lambda x: SimpleNamespace(value=x)  # noqa: E731
    ie = SimpleNamespace(terms={"N_dprh": v(0.1), "K_dphrh": v(3.0), "R_dph2": v(50.0)}, gm=[], tau_range_s=(2.0, 900.0))
    comps, notes = components_from_gmwm(ie, ramp="random_walk")
    n_s, k_s, r_s = 0.1 * 60, 3.0 / 60, 50.0 / 3600
    ref = components_from_allan([0.0, n_s**2, 0.0, k_s**2 / 3, r_s**2 / 2], tau_range_s=(2.0, 900.0), terms="NKR")
    assert [c["kind"] for c in comps] == ["white", "random_walk"] and len(notes) == 1
    assert_allclose([list(c.values())[1] for c in comps], [list(c.values())[1] for c in ref], rtol=1e-12)
    # the default keeps the ramp as a state (the consistency check's reading)
    assert [c["kind"] for c in components_from_gmwm(ie)[0]] == ["white", "random_walk", "ramp"]
    with pytest.raises(ConfigError, match="ramp must be"):
        components_from_gmwm(ie, ramp="drop")


def test_a_fallback_gmwm_selection_is_used_with_one_warning_saying_why(monkeypatch):
    """No candidate passed the checks: the best one is used, one FogdriftWarning names it and its failed check
    (the selection's own warning is not repeated), and identification_ records it."""
    from fogdrift.errors import FogdriftWarning

    v = lambda x: SimpleNamespace(value=x)  # noqa: E731

    def fake(name, x, dt_s, **kw):
        warnings.warn("no candidate passed every sanity check; WN (smallest WIC ...)", FogdriftWarning)
        ie = SimpleNamespace(terms={"N_dprh": v(0.1)}, gm=[], tau_range_s=(1.0, 64.0))
        sel = SimpleNamespace(selected="WN", passed_checks=False, ieee=ie,
                              candidates=[SimpleNamespace(model="WN", reasons=("soft: residual z = 4.2 at scale 8 s",))])
        return SimpleNamespace(selection=sel)

    monkeypatch.setattr(kalman_module, "analyse_gmwm", fake)
    with warnings.catch_warnings(record=True) as log:
        warnings.simplefilter("always")
        model = Kalman(noise_method="gmwm").fit(np.zeros(GMWM_MIN_SAMPLES))
    msgs = [str(w.message) for w in log if issubclass(w.category, FogdriftWarning)]
    assert len(msgs) == 1 and "WN has the smallest WIC (soft: residual z = 4.2 at scale 8 s)" in msgs[0]
    assert model.identification_["passed_checks"] is False and "residual z" in model.identification_["reason"]
    assert model.components_ == [{"kind": "white", "arw_dprh": 0.1}]


def test_pipeline_keeps_the_allan_identification_by_default(bundled_record):
    """The analysis setting reaches the Kalman: the default 'allan' analysis gives an Allan-identified Kalman."""
    from fogdrift.pipeline import AnalysisConfig, run_models

    ma = run_models(bundled_record.select("gz"), AnalysisConfig(models=("kalman",)))[0]
    assert ma.fitted["Kalman"].identification_["method"] != "gmwm"
    assert ma.fitted["Kalman"].noise_method == "allan"
