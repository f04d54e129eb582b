"""Allan family engine: reference values (method notes section 7: R8, R9, R11, R17),
agreement with allantools (``oadev``/``adev``/``ohdev``/``hdev``/``mdev``, ``data_type='freq'``)
to 1e-9 relative, the published NBS14 values of the Allan, Hadamard and modified Allan
deviations, the compiled operators against a plain evaluation of the statistics table,
numerical robustness against a large offset, EDF/bounds, the fast estimator and validation.
(EDF formulas in detail: ``test_allan_ci.py``.)

NBS14 reference values (Riley's test suite for frequency-stability software; the numbers were
taken from the NBS14 tables of NIST SP 1065 (pp. 107-108) and of W. J. Riley, "The Calculation
of Time Domain Frequency Stability" (Tables II and III), as quoted in the test suites of
allantools and allantoolkit -- the documents themselves were not available to this project):

* 10-point frequency set (R17): ADEV and overlapping ADEV (method notes R17); MDEV 91.22945,
  74.78849 and overlapping HDEV 70.80607, 85.61487 at tau = 1, 2 (SP 1065); non-overlapping
  HDEV 70.80608, 116.7980 (Riley, Table II).
* 1000-point set (generator n_{i+1} = 16807 n_i mod 2147483647, n_0 = 1234567890, value
  n_i / 2147483647): at tau = 1, 10, 100 ADEV 2.922319e-01, 9.965736e-02, 3.897804e-02;
  overlapping ADEV ..., 9.159953e-02, 3.241343e-02; MDEV ..., 6.172376e-02, 2.170921e-02;
  overlapping HDEV 2.943883e-01, 9.581083e-02, 3.237638e-02 (SP 1065); non-overlapping HDEV
  ..., 1.052754e-01, 3.910860e-02 (Riley, Table III).  All published to 7 significant
  digits, so compared at 1e-6 relative.
"""

from __future__ import annotations

import json

import allantools
import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.allan import FAST_M0, STATISTICS, AllanResult, allan_variance, edf_simple, tau_grid
from fogdrift.allan._kernels import OPERATORS, operator_sums, phase_dph_samples
from fogdrift.errors import ConfigError, DataFormatError, InsufficientDataError

R8 = [1.0, 3.0, 2.0, 5.0, 4.0, 4.0, 6.0, 3.0]
NBS14_FREQ = [892.0, 809.0, 823.0, 798.0, 671.0, 644.0, 883.0, 903.0, 677.0]


# --- reference values -------------------------------------------------------------------
def test_r8_overlapping_and_non_overlapping():
    r = allan_variance(R8, 1.0, taus=[1, 2, 3])
    assert_allclose(r.avar_dph2, [2.0, 0.7, 1.2777777778], rtol=1e-10, atol=1e-12)
    assert_array_equal(r.n_terms, [7, 5, 3])
    r2 = allan_variance(R8, 1.0, taus=[2.0], estimator="non-overlapping")
    assert_allclose(r2.avar_dph2, [0.4583333333], atol=1e-10)
    # tau0 = 0.5 s: m = 2 is tau = 1 s and the value (rate units) is still 0.7
    r3 = allan_variance(R8, 0.5, taus=[1.0])
    assert_array_equal(r3.m, [2])
    assert_allclose(r3.avar_dph2, [0.7], rtol=1e-12)


@pytest.mark.parametrize("estimator", ["overlapping", "non-overlapping"])
def test_r9_ramp_gives_r2_tau2_over_2(estimator):
    y = 0.5 * np.arange(200.0)
    r = allan_variance(y, 1.0, taus=[1.0, 4.0, 16.0], estimator=estimator)
    assert_allclose(r.avar_dph2, [0.125, 2.0, 32.0], rtol=1e-12)


def test_alternating_series():
    y = np.tile([1.0, -1.0], 50)
    r = allan_variance(y, 1.0, taus=[1, 2])
    assert_allclose(r.avar_dph2, [2.0, 0.0], atol=1e-13)


def test_r17_nbs14_published_values():
    oadev = allan_variance(NBS14_FREQ, 1.0, taus=[1, 2]).adev_dph
    adev = allan_variance(NBS14_FREQ, 1.0, taus=[1, 2], estimator="non-overlapping").adev_dph
    assert_allclose(adev, [91.22945, 115.8082], rtol=1e-6)
    assert_allclose(oadev, [91.22945, 85.95287], rtol=1e-6)


def _nbs14_1000() -> np.ndarray:
    n, out = 1234567890, []
    for _ in range(1000):
        out.append(n / 2147483647)
        n = (16807 * n) % 2147483647
    return np.array(out)


@pytest.mark.parametrize(
    "statistic, estimator, expected",
    [
        ("mdev", "overlapping", [91.22945, 74.78849]),
        ("hdev", "overlapping", [70.80607, 85.61487]),
        ("hdev", "non-overlapping", [70.80608, 116.7980]),
    ],
)
def test_nbs14_10_point_hadamard_and_modified(statistic, estimator, expected):
    r = allan_variance(NBS14_FREQ, 1.0, taus=[1, 2], statistic=statistic, estimator=estimator)
    assert r.statistic == statistic
    assert_allclose(r.dev, expected, rtol=1e-6)


@pytest.mark.parametrize(
    "statistic, estimator, expected",
    [
        ("adev", "non-overlapping", [2.922319e-01, 9.965736e-02, 3.897804e-02]),
        ("adev", "overlapping", [2.922319e-01, 9.159953e-02, 3.241343e-02]),
        ("mdev", "overlapping", [2.922319e-01, 6.172376e-02, 2.170921e-02]),
        ("hdev", "overlapping", [2.943883e-01, 9.581083e-02, 3.237638e-02]),
        ("hdev", "non-overlapping", [2.943883e-01, 1.052754e-01, 3.910860e-02]),
    ],
)
def test_nbs14_1000_point_published_values(statistic, estimator, expected):
    r = allan_variance(_nbs14_1000(), 1.0, taus=[1, 10, 100], statistic=statistic, estimator=estimator)
    assert_allclose(r.dev, expected, rtol=1e-6)


def test_r8_hadamard_and_modified_by_hand():
    """R8 by hand: HVAR(1) = (9 + 16 + 16 + 1 + 4 + 25) / (6 * 6) = 71/36 (the squared second
    differences of y); MVAR(1) = AVAR(1) = 2; MVAR(2) from SP 1065 eq. 14 with explicit loops."""
    y = np.array(R8)
    h = allan_variance(R8, 1.0, taus=[1], statistic="hdev")
    assert_allclose(h.var, [71.0 / 36.0], rtol=1e-13)
    assert_array_equal(h.n_terms, [6])
    x = np.concatenate(([0.0], np.cumsum(y)))  # phase, 9 points
    m, n_terms, acc = 2, len(x) - 3 * 2 + 1, 0.0
    for j in range(n_terms):
        acc += sum(x[i + 2 * m] - 2 * x[i + m] + x[i] for i in range(j, j + m)) ** 2
    mod = allan_variance(R8, 1.0, taus=[1, 2], statistic="mdev")
    assert_allclose(mod.var, [2.0, acc / (2 * m**2 * m**2 * n_terms)], rtol=1e-13)
    assert_array_equal(mod.n_terms, [7, n_terms])  # N + 2 - 3m


@pytest.mark.parametrize("key", list(OPERATORS))
def test_compiled_operators_match_the_table(key):
    """Each compiled kernel evaluates exactly the operator of its table entry (plain numpy here)."""
    coefs, window = key
    assert any(tuple(s.coefficients) == coefs and s.windowed == window for s in STATISTICS.values())
    rng = np.random.default_rng(4)
    y = rng.normal(size=5003) + 0.01 * np.cumsum(rng.normal(size=5003))
    p = phase_dph_samples(y)
    ms = np.array([1, 2, 3, 7, 64, 500, 1500])
    for stride_kind in (("one", "m") if not window else ("one",)):
        strides = np.ones_like(ms) if stride_kind == "one" else ms.copy()
        got = operator_sums(p, ms, strides, coefs, window)
        for m, s, g in zip(ms, strides, got):
            q = np.convolve(p, np.ones(m), mode="valid") if window else p  # window sums W_k
            span = (len(coefs) - 1) * m
            k = np.arange(0, q.size - span, s)
            d = sum(c * q[k + l * m] for l, c in enumerate(coefs))
            assert g == pytest.approx(np.sum(d * d), rel=1e-10)


@pytest.mark.parametrize("statistic", ["hdev", "mdev"])
def test_family_ramp_and_constant(statistic):
    """A rate ramp: HVAR = 0 (the third difference of a quadratic angle vanishes), MVAR = r^2 tau^2 / 2."""
    y = 0.5 * np.arange(300.0) + 7.0
    r = allan_variance(y, 1.0, taus=[1.0, 4.0, 16.0], statistic=statistic)
    expected = [0.0, 0.0, 0.0] if statistic == "hdev" else [0.125, 2.0, 32.0]
    assert_allclose(r.var, expected, rtol=1e-12, atol=1e-11)


# --- allantools agreement ---------------------------------------------------------------
@pytest.mark.parametrize("n", [9, 100, 1001, 12345, 100_003])
@pytest.mark.parametrize("grid", ["octave", "decade", 40])
def test_matches_allantools(n, grid):
    rng = np.random.default_rng(n)
    y = 3.0 * rng.normal(size=n) + 0.01 * np.cumsum(rng.normal(size=n)) + 50.0
    for est, func in (("overlapping", allantools.oadev), ("non-overlapping", allantools.adev)):
        r = allan_variance(y, 0.01, taus=grid, estimator=est)
        taus, dev, _, ns = func(y, rate=100.0, data_type="freq", taus=r.tau_s)
        assert_allclose(taus, r.tau_s, rtol=1e-12)
        assert_allclose(r.adev_dph, dev, rtol=1e-9)
        assert_array_equal(r.n_terms, ns)


def test_all_grid_matches_allantools():
    y = np.random.default_rng(7).normal(size=300)
    r = allan_variance(y, 1.0, taus="all", max_fraction=0.5)
    assert_array_equal(r.m, np.arange(1, 151))
    taus, dev, _, _ = allantools.oadev(y, rate=1.0, data_type="freq", taus=r.tau_s)
    assert_array_equal(taus, r.tau_s[:-1])  # allantools stops at m < N/2
    assert_allclose(r.adev_dph[:-1], dev, rtol=1e-9)


@pytest.mark.parametrize("n", [10, 101, 1000, 12345, 100_003])
@pytest.mark.parametrize("grid", ["octave", "decade", 40])
def test_hadamard_and_modified_match_allantools(n, grid):
    rng = np.random.default_rng(n + 1)
    y = 3.0 * rng.normal(size=n) + 0.01 * np.cumsum(rng.normal(size=n)) + 50.0
    for statistic, est, func in (("hdev", "overlapping", allantools.ohdev),
                                 ("hdev", "non-overlapping", allantools.hdev),
                                 ("mdev", "overlapping", allantools.mdev)):
        r = allan_variance(y, 0.01, taus=grid, estimator=est, statistic=statistic)
        taus, dev, _, ns = func(y, rate=100.0, data_type="freq", taus=r.tau_s)
        keep = np.isin(np.rint(r.tau_s * 100), np.rint(np.asarray(taus) * 100))  # allantools drops m >= N/2 etc.
        assert keep.sum() >= min(len(r), 3)
        assert_allclose(taus, r.tau_s[keep], rtol=1e-12)
        assert_allclose(r.dev[keep], dev, rtol=1e-9)
        assert_array_equal(r.n_terms[keep], ns)


@pytest.mark.parametrize("statistic", ["hdev", "mdev"])
def test_family_large_offset_does_not_cancel(statistic):
    rng = np.random.default_rng(12)
    noise = rng.normal(size=1_000_000)
    a = allan_variance(noise, 0.01, taus=40, statistic=statistic)
    b = allan_variance(noise + 1.0e4, 0.01, taus=40, statistic=statistic)
    assert_allclose(b.var, a.var, rtol=1e-9)
    # white rate noise: HVAR = 1/m; MVAR = (1 + 1/m^2)/(2m) (noise_terms laws)
    m = a.m[:5].astype(float)
    law = 1.0 / m if statistic == "hdev" else (1.0 + 1.0 / m**2) / (2.0 * m)
    assert_allclose(a.var[:5] / law, 1.0, rtol=0.03)


def test_large_offset_does_not_cancel():
    """1e6 samples of 1e4 deg/h + unit noise give the offset-free result (mean removed,
    compensated integration)."""
    rng = np.random.default_rng(11)
    noise = rng.normal(size=1_000_000)
    a = allan_variance(noise, 0.01, taus=60)
    b = allan_variance(noise + 1.0e4, 0.01, taus=60)
    assert_allclose(b.avar_dph2, a.avar_dph2, rtol=1e-9)
    # and the absolute level is right for white noise: sigma^2(m) = 1/m
    assert_allclose(a.avar_dph2[:5] * a.m[:5], 1.0, rtol=0.02)


def test_scaling_and_constant_invariance():
    y = np.random.default_rng(3).normal(size=5000)
    r = allan_variance(y, 0.1)
    assert_allclose(allan_variance(-2.5 * y + 7.0, 0.1).adev_dph, 2.5 * r.adev_dph, rtol=1e-10)


# --- EDF and confidence bounds ----------------------------------------------------------
@pytest.mark.parametrize(
    "alpha, m, expected",
    [
        (0, 1, 681.7795), (0, 16, 93.5471), (0, 128, 10.0031),
        (-1, 1, 889.6787), (-1, 16, 76.4959), (-1, 128, 7.2818),
        (-2, 16, 61.2419), (-2, 128, 5.5162), (2, 16, 504.8652),
        (2, 1, 512.499), (-2, 1, 1024.003),
    ],
)
def test_r11_edf_simple(alpha, m, expected):
    assert edf_simple(1025, m, alpha) == pytest.approx(expected, rel=1e-4)


def test_flicker_fm_m1_keeps_the_square():
    """allantools 2024.6 drops the square of (N-2) and gets ~0.87; the correct value is ~890."""
    assert edf_simple(1025, 1, -1) > 800.0


def test_r11_white_fm_confidence_multipliers():
    y = np.random.default_rng(0).normal(size=1024)  # N + 1 = 1025 phase points
    r = allan_variance(y, 1.0, taus=[16], noise_alpha=0)
    assert r.edf[0] == pytest.approx(93.5471, rel=1e-4)
    lo = (r.adev_lo68_dph[0] / r.adev_dph[0]) ** 2
    hi = (r.adev_hi68_dph[0] / r.adev_dph[0]) ** 2
    assert_allclose([lo, hi], [0.872829, 1.170539], rtol=1e-5)
    assert r.adev_lo95_dph[0] < r.adev_lo68_dph[0] < r.adev_dph[0] < r.adev_hi68_dph[0] < r.adev_hi95_dph[0]


@pytest.mark.parametrize("bad", [dict(n_phase=2, m=1, alpha=0), dict(n_phase=100, m=60, alpha=0),
                                 dict(n_phase=100, m=1, alpha=3), dict(n_phase=100, m=1, alpha=0.5)])
def test_edf_simple_rejects_bad_arguments(bad):
    with pytest.raises(ConfigError):
        edf_simple(**bad)


def test_auto_alpha_follows_slope():
    rng = np.random.default_rng(5)
    white = allan_variance(rng.normal(size=2**16), 1.0)
    assert np.mean(white.noise_alpha[:-3] == 0) >= 0.8
    rw = allan_variance(np.cumsum(rng.normal(size=2**16)), 1.0)
    assert np.mean(rw.noise_alpha[2:] == -2) >= 0.8
    cons = allan_variance(rng.normal(size=2**12), 1.0, noise_alpha="conservative")
    for a in (2, 0, -1, -2):
        fixed = allan_variance(rng.normal(size=2**12), 1.0, noise_alpha=a)
        assert np.all(cons.edf <= fixed.edf + 1e-9)
    assert "slope" in white.edf_rule and "smallest" in cons.edf_rule


def test_95_bounds_cover_truth_for_white_noise():
    """Over 40 seeds the 95 % interval of sigma at m = 64 covers the true 1/sqrt(m) >= 34 times."""
    hits = 0
    for seed in range(40):
        r = allan_variance(np.random.default_rng(seed).normal(size=4096), 1.0, taus=[64])
        hits += r.adev_lo95_dph[0] <= 1 / 8 <= r.adev_hi95_dph[0]
    assert hits >= 34


# --- fast estimator ---------------------------------------------------------------------
def test_fast_agrees_with_exact_within_bounds():
    rng = np.random.default_rng(21)
    n = 2**20
    y = rng.normal(size=n) + 0.002 * np.cumsum(rng.normal(size=n))
    exact = allan_variance(y, 0.01, taus=80)
    fast = allan_variance(y, 0.01, taus=80, estimator="fast")
    assert_array_equal(fast.m, exact.m)
    small = exact.m < 2 * FAST_M0
    assert_allclose(fast.avar_dph2[small], exact.avar_dph2[small], rtol=1e-12)
    assert np.all(fast.adev_dph >= exact.adev_lo68_dph) and np.all(fast.adev_dph <= exact.adev_hi68_dph)
    assert np.all(fast.edf <= exact.edf + 1e-9) and np.all(fast.edf >= 0.5 * exact.edf)
    assert np.all(fast.n_terms[~small] < exact.n_terms[~small])


def test_fast_on_octaves_keeps_taus():
    y = np.random.default_rng(2).normal(size=10_000)
    assert_array_equal(allan_variance(y, 1.0, estimator="fast").m, tau_grid(10_000, 1.0))


# --- grids, result object, validation ---------------------------------------------------
def test_tau_grids():
    assert tau_grid(100, 0.1).tolist() == [1, 2, 4, 8, 16]
    assert tau_grid(1000, 1.0, "decade").tolist() == [1, 2, 5, 10, 20, 50, 100, 200]
    assert tau_grid(20, 1.0, "all").tolist() == [1, 2, 3, 4, 5]
    g = tau_grid(10**6, 0.01, 100)
    assert g[0] == 1 and g[-1] == 250_000 and 60 < g.size <= 100 and np.all(np.diff(g) > 0)
    assert tau_grid(10, 0.5, [0.5, 1.0, 1.0, 2.5]).tolist() == [1, 2, 5]


@pytest.mark.parametrize("taus", ["weekly", [0.1], [6.0], [np.nan], 0, []])
def test_tau_grid_rejects(taus):
    with pytest.raises(ConfigError):
        tau_grid(10, 1.0, taus)


def test_validation_errors():
    with pytest.raises(DataFormatError, match=r"y\[2\]"):
        allan_variance([1.0, 2.0, np.nan, 3.0], 1.0)
    with pytest.raises(DataFormatError, match="1-D"):
        allan_variance(np.zeros((4, 2)), 1.0)
    with pytest.raises(ConfigError, match="dt_s"):
        allan_variance(np.zeros(10), 0.0)
    with pytest.raises(ConfigError, match="estimator"):
        allan_variance(np.zeros(10), 1.0, estimator="modified")
    with pytest.raises(ConfigError, match="noise_alpha"):
        allan_variance(np.zeros(10), 1.0, noise_alpha="pink")
    with pytest.raises(ConfigError, match="noise_alpha"):
        allan_variance(np.zeros(10), 1.0, noise_alpha=[0, 0, 0, 0, 0])
    with pytest.raises(InsufficientDataError):
        allan_variance([1.0], 1.0)


@pytest.mark.parametrize(
    "statistic, estimator",
    [("mdev", "non-overlapping"), ("mdev", "fast"), ("hdev", "fast"), ("tdev", "overlapping")],
)
def test_unsupported_statistic_or_sampling_is_a_config_error(statistic, estimator):
    with pytest.raises(ConfigError, match="statistic|estimator") as err:
        allan_variance(np.zeros(100), 1.0, statistic=statistic, estimator=estimator)
    if statistic != "tdev":
        assert "estimator=" in str(err.value) and "--estimator" in err.value.render({"estimator": "--estimator"})


def test_statistics_table_states_samplings_and_sources():
    assert set(STATISTICS) == {"adev", "hdev", "mdev"}
    assert STATISTICS["adev"].samplings == ("overlapping", "non-overlapping", "fast")
    assert STATISTICS["hdev"].samplings == ("overlapping", "non-overlapping")
    assert STATISTICS["mdev"].samplings == ("overlapping",)
    assert [STATISTICS[k].norm for k in ("adev", "hdev", "mdev")] == [2.0, 6.0, 2.0]
    for s in STATISTICS.values():
        assert "SP 1065" in s.equation and "p." in s.equation and s.edf_source


def test_tau_grid_per_statistic():
    assert tau_grid(10, 1.0, "all", max_fraction=0.5).tolist() == [1, 2, 3, 4, 5]
    assert tau_grid(10, 1.0, "all", max_fraction=0.5, statistic="hdev").tolist() == [1, 2, 3]
    assert tau_grid(11, 1.0, "all", max_fraction=0.5, statistic="mdev").tolist() == [1, 2, 3, 4]
    assert tau_grid(10, 1.0, [3.0], statistic="hdev").tolist() == [3]
    with pytest.raises(ConfigError, match="Hadamard"):
        tau_grid(10, 1.0, [4.0], statistic="hdev")
    with pytest.raises(InsufficientDataError):
        tau_grid(2, 1.0, statistic="hdev")


def test_result_names_per_statistic(tmp_path):
    y = np.random.default_rng(8).normal(size=2000)
    a = allan_variance(y, 0.5, taus=[0.5, 1.0])
    assert a.statistic == "adev"
    assert a.avar_dph2 is a.var and a.adev_dph is a.dev and a.adev_hi95_dph is a.dev_hi95
    h = allan_variance(y, 0.5, taus=[0.5, 1.0], statistic="hdev")
    with pytest.raises(AttributeError, match="Hadamard"):
        _ = h.adev_dph
    d = json.loads(json.dumps(h.to_dict()))
    assert d["statistic"] == "hdev" and "hdev_dph" in d and "hvar_dph2" in d and "adev_dph" not in d
    assert_allclose(d["hdev_lo95_dph"], h.dev_lo95, rtol=1e-15)
    path = tmp_path / "hdev.csv"
    h.to_csv(path)
    text = path.read_text().splitlines()
    assert "statistic=hdev" in text[0]
    assert text[2] == ",".join(h.column_names()) and text[2].startswith("tau_s,m,hvar_dph2,hdev_dph,hdev_lo68_dph")
    assert allan_variance(y, 0.5, taus=[1.0], statistic="mdev").column_names()[2:4] == ("mvar_dph2", "mdev_dph")
    h.to_csv(path, quantity="specific_force")  # an accelerometer's curve: m/s^2 in the names and the units line
    acc = path.read_text().splitlines()
    assert "hvar_m2ps4 [(m/s^2)^2]; hdev_* [m/s^2]" in acc[1] and "deg/h" not in acc[1]
    assert acc[2].startswith("tau_s,m,hvar_m2ps4,hdev_mps2,hdev_lo68_mps2") and acc[3:] == text[3:]


def test_result_serialisation_and_progress(tmp_path):
    calls = []
    r = allan_variance(np.random.default_rng(1).normal(size=1000), 0.5, taus=30,
                       progress=lambda d, t: calls.append((d, t)))
    assert isinstance(r, AllanResult)
    assert calls[-1] == (len(r), len(r)) and all(d <= t for d, t in calls)
    d = json.loads(json.dumps(r.to_dict()))
    assert d["estimator"] == "overlapping" and len(d["adev_dph"]) == len(r)
    path = tmp_path / "allan.csv"
    r.to_csv(path)
    text = path.read_text().splitlines()
    assert text[0].startswith("#") and text[2].startswith("tau_s,m,avar_dph2,adev_dph")
    back = np.loadtxt(path, delimiter=",", comments="#", skiprows=3)
    assert_allclose(back[:, 0], r.tau_s, rtol=1e-15)
    assert_allclose(back[:, 3], r.adev_dph, rtol=1e-15)
