"""AR(p) baseline against simulated truth and an independent least-squares solve; drift-model skill check.

Tolerances are derived before looking at results: for a Gaussian AR(2) the asymptotic standard error of
each LS coefficient is sqrt((1 - φ₂²)/n) (Box & Jenkins, large-sample theory), the error of the implied
mean is σ/(1 - φ₁ - φ₂)/sqrt(n), and of the residual sd σ/sqrt(2n); tests allow 4 standard errors.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from fogdrift.models.ar import AR, ar_aic, ar_fit
from fogdrift.errors import ConfigError, InsufficientDataError, NotFittedError
from fogdrift.models.grey import GM11
from fogdrift.metrics import rmse
from fogdrift.models import Persistence, load_model, save_model

PHI = (0.6, -0.3)
C_TRUE = 0.5
N_AR = 20_000


def simulate_ar2(seed: int, n: int = N_AR, burn: int = 500) -> np.ndarray:
    rng = np.random.default_rng(seed)
    e = rng.normal(0.0, 1.0, n + burn)
    y = np.zeros(n + burn)
    for t in range(2, n + burn):
        y[t] = C_TRUE + PHI[0] * y[t - 1] + PHI[1] * y[t - 2] + e[t]
    return y[burn:]


@pytest.fixture(scope="module")
def ar2_series():
    return simulate_ar2(11)


def test_ar2_coefficients_recovered(ar2_series):
    model = AR(order=2).fit(ar2_series)
    se_phi = math.sqrt((1 - PHI[1] ** 2) / N_AR)  # 0.0067
    assert_allclose(model.coef_, PHI, atol=4 * se_phi)
    mu_true = C_TRUE / (1 - sum(PHI))
    mu_hat = model.intercept_ / (1 - model.coef_.sum())
    assert mu_hat == pytest.approx(mu_true, abs=4 * 1.0 / (1 - sum(PHI)) / math.sqrt(N_AR))
    assert model.sigma_ == pytest.approx(1.0, abs=4 / math.sqrt(2 * N_AR))
    assert model.order_ == 2 and model.n_train_ == N_AR


@pytest.mark.parametrize("p", [1, 2, 5])
def test_ar_matches_lstsq_on_raw_lagged_design(ar2_series, p):
    """Independent solve on the uncentred lagged design [1, y[t-1], ..., y[t-p]] (offset added)."""
    y = ar2_series[:3000] + 7.5  # a large constant, as with Earth rate left in
    X = np.column_stack([np.ones(y.size - p)] + [y[p - 1 - i : y.size - 1 - i] for i in range(p)])
    sol, rss, *_ = np.linalg.lstsq(X, y[p:], rcond=None)
    fit = ar_fit(y, p)
    assert_allclose(fit.coef, sol[1:], rtol=1e-9, atol=1e-10)
    assert fit.intercept == pytest.approx(sol[0], rel=1e-8)
    assert fit.rss == pytest.approx(float(rss[0]), rel=1e-9)
    assert fit.sigma == pytest.approx(math.sqrt(rss[0] / (y.size - p - p - 1)), rel=1e-9)


def test_aic_values_and_selection(ar2_series):
    y = ar2_series[:4000]
    pmax = 6
    aic = ar_aic(y, pmax)
    m = y.size - pmax
    for p in range(1, pmax + 1):  # by hand on the common sample t = pmax..n-1
        X = np.column_stack([np.ones(m)] + [y[pmax - 1 - i : y.size - 1 - i] for i in range(p)])
        _, rss, *_ = np.linalg.lstsq(X, y[pmax:], rcond=None)
        assert aic[p - 1] == pytest.approx(m * math.log(rss[0] / m) + 2 * (p + 1), rel=1e-10)
    model = AR(order="aic", max_order=pmax).fit(y)
    assert model.order_ == int(np.argmin(aic)) + 1
    assert model.order_ >= 2  # AR(1) is far worse on AR(2) data:
    assert aic[0] - aic[1] > 100
    assert_allclose(model.aic_, aic)
    assert AR(order=3).fit(y).aic_.size == 0


def test_predict_and_forecast_by_hand():
    rng = np.random.default_rng(2)
    y = rng.normal(size=80)
    model = AR(order=3).fit(y[:60])
    c, phi = model.intercept_, model.coef_
    pred = model.predict(y[60:], history=y[:60])
    ref = [c + phi[0] * y[k - 1] + phi[1] * y[k - 2] + phi[2] * y[k - 3] for k in range(60, 80)]
    assert_allclose(pred, ref, rtol=1e-12)
    no_hist = model.predict(y[60:])
    assert np.isnan(no_hist[:3]).all()
    assert_allclose(no_hist[3:], ref[3:], rtol=1e-12)
    fc = model.forecast(4)
    buf = list(y[57:60])
    for i in range(4):
        nxt = c + phi[0] * buf[-1] + phi[1] * buf[-2] + phi[2] * buf[-3]
        assert fc[i] == pytest.approx(nxt, rel=1e-12)
        buf.append(nxt)
    # a stationary AR forecast converges to its mean
    mu = c / (1 - phi.sum())
    assert model.forecast(400)[-1] == pytest.approx(mu, abs=1e-6)


def test_persistence_by_definition():
    """predict(y, history) == [history[-1], y[0], ..., y[-2]] exactly; forecasts repeat the last sample."""
    rng = np.random.default_rng(11)
    train, hist, y = rng.normal(size=50), rng.normal(size=30), rng.normal(size=20)
    model = Persistence().fit(train)
    assert model.predict(y, history=hist).tolist() == [hist[-1], *y[:-1]]
    without = model.predict(y)
    assert math.isnan(without[0]) and without[1:].tolist() == y[:-1].tolist()
    assert model.predict(y[:1], history=hist).tolist() == [hist[-1]]
    assert model.forecast(4).tolist() == [train[-1]] * 4
    assert model.forecast(3, history=hist).tolist() == [hist[-1]] * 3


def test_ar_errors_and_persistence(tmp_path):
    y = np.linspace(0, 1, 30) + np.sin(np.arange(30))
    with pytest.raises(ConfigError, match="order"):
        AR(order=0).fit(y)
    with pytest.raises(ConfigError, match="order"):
        AR(order="bic").fit(y)
    with pytest.raises(InsufficientDataError) as info:
        AR(order=4).fit(y[:9])
    assert (info.value.needed, info.value.got) == (10, 9)
    with pytest.raises(NotFittedError):
        AR().predict(y)
    model = AR(order=2).fit(y[:20])
    with pytest.raises(InsufficientDataError):
        model.forecast(3, history=y[:1])
    save_model(model, tmp_path / "ar")
    back = load_model(tmp_path / "ar")
    assert_allclose(back.predict(y[20:], history=y[:20]), model.predict(y[20:], history=y[:20]), rtol=0, atol=0)


# -- drift with learnable structure -----------------------------------------------------------------
RW_SD = 0.0005  # deg/h per sample


def synthetic_drift(seed: int, n: int = 3000) -> np.ndarray:
    """Exponential warm-up (τ = 300 samples) + slow oscillation (period 400 samples) + random walk [deg/h].

    The per-sample change of the oscillation (rms ≈ 0.0022) exceeds the random-walk step (0.0005), so
    persistence (which always misses the whole change) is beatable; no predictor can beat the
    random-walk innovations, which floor the achievable RMSE at ≈ RW_SD.
    """
    rng = np.random.default_rng(seed)
    k = np.arange(n)
    return 0.5 * np.exp(-k / 300) + 0.2 * np.sin(2 * np.pi * k / 400) + np.cumsum(rng.normal(0, RW_SD, n))


@pytest.fixture(scope="module")
def drift_ratios():
    """RMSE(model)/RMSE(persistence) on the test block (last 20 %), models fitted on the first 60 %."""
    y = synthetic_drift(2024)
    a, b = 1800, 2400
    train, val, test, hist = y[:a], y[a:b], y[b:], y[:b]
    r_p = rmse(test, Persistence().fit(train).predict(test, history=hist))
    out = {"persistence_rmse": r_p}
    for name, model in (("AR4", AR(order=4)), ("GM11_rolling", GM11(mode="rolling", window=8)),
                        ("GM11_whole", GM11(mode="whole"))):
        model.fit(train, val)
        out[name] = rmse(test, model.predict(test, history=hist)) / r_p
    return out


def test_ar_beats_persistence_on_learnable_drift(drift_ratios):
    # Stated margin: AR(4) RMSE below 35 % of persistence's (measured 0.25 over seeds 0-4 and 2024),
    # and not below the random-walk floor (a lower value would mean leakage).
    assert drift_ratios["AR4"] < 0.35
    assert drift_ratios["AR4"] > 0.9 * RW_SD / drift_ratios["persistence_rmse"]


def test_gm11_versus_persistence_on_learnable_drift(drift_ratios):
    """Honest record: rolling GM(1,1) (window 8) beats persistence here but not AR(4) (measured ~0.30 vs
    ~0.25); the paper-style whole-block GM(1,1) does NOT beat persistence — its extrapolated exponential
    is ~100x worse on the test block."""
    assert drift_ratios["GM11_rolling"] < 0.5
    assert drift_ratios["GM11_rolling"] > drift_ratios["AR4"]
    assert drift_ratios["GM11_whole"] > 10.0
