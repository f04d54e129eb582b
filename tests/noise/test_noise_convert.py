"""Law coefficient A -> IEEE-952 value for the Hadamard and modified statistics, term by term.

``tests/noise/test_noise.py`` checks the Allan conversions; these are the other two statistics, with the
constants written out as numbers (the hdev/mdev laws of ``noise/terms.py``, derived there and checked by
quadrature in ``test_noise.py``): a wrong or dropped statistic-specific constant, a zero coefficient
refused, or ``Q_arcsec`` attached to the wrong term fails here. Units: rate deg/h, tau and dt in s.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fogdrift.errors import ConfigError
from fogdrift.noise.convert import coefficients_from_A
from fogdrift.noise.terms import TERM_TABLE, VARIANCE_LAWS, default_terms, laws_of, term_spec

URAD_PER_ARCSEC = 4.84813681109536  # pi / 180 / 3600 * 1e6, written out
# A / X^2 of each term, X in its Allan-law unit ((deg/h) s, (deg/h) sqrt(s), deg/h, (deg/h)/sqrt(s), (deg/h)/s)
HDEV_C = {"Q": 10.0 / 3.0, "N": 1.0, "B": 0.3579936717615167, "K": 1.0 / 6.0}
DT_S = 0.01
MDEV_C = {"Q": 3.0 * DT_S, "N": 0.5, "B": 0.29769223929984556, "K": 11.0 / 40.0, "R": 0.5}
# X in the law unit -> reported value (urad, deg/sqrt(h), deg/h, deg/h^1.5, deg/h^2)
TO_REPORTED = {"Q": URAD_PER_ARCSEC, "N": 1.0 / 60.0, "B": 1.0, "K": 60.0, "R": 3600.0}
X_LAW = {"Q": 0.7, "N": 0.3, "B": 0.05, "K": 0.002, "R": 3e-5}
ORDER = ("Q", "N", "B", "K", "R")


def _A(consts, only):
    return [consts[t] * X_LAW[t] ** 2 if t == only else 0.0 for t in ORDER]


@pytest.mark.parametrize(
    ("statistic", "consts", "dt_s", "term"),
    [("hdev", HDEV_C, None, t) for t in HDEV_C] + [("mdev", MDEV_C, DT_S, t) for t in MDEV_C],
)
def test_single_term_conversion(statistic, consts, dt_s, term):
    out = coefficients_from_A(_A(consts, term), statistic=statistic, dt_s=dt_s)
    expected_keys = [t for t in ORDER if t in consts]
    assert list(out) == expected_keys[:1] + ["Q_arcsec"] + expected_keys[1:]
    for t in expected_keys:  # every other term is exactly zero: A = 0 is accepted and maps to 0
        want = X_LAW[t] * TO_REPORTED[t] if t == term else 0.0
        assert out[t] == pytest.approx(want, rel=1e-12, abs=0.0), t
    want_arcsec = X_LAW["Q"] if term == "Q" else 0.0
    assert out["Q_arcsec"] == pytest.approx(want_arcsec, rel=1e-12, abs=0.0)


def test_default_terms_of_each_statistic():
    assert default_terms() == default_terms("adev") == ORDER == default_terms("mdev")


def test_hadamard_has_no_rate_ramp():
    out = coefficients_from_A([1.0, 1.0, 1.0, 1.0, 1.0], statistic="hdev")
    assert "R" not in out and default_terms("hdev") == ("Q", "N", "B", "K")


def test_modified_needs_the_sample_interval():
    with pytest.raises(ConfigError, match="needs the sample interval dt_s"):
        coefficients_from_A([1.0, 0, 0, 0, 0], statistic="mdev")
    # the white-PM constant is 3 dt: halving dt doubles A for the same Q, so Q grows by sqrt(2)
    q1 = coefficients_from_A([1.0, 0, 0, 0, 0], statistic="mdev", dt_s=0.02)["Q"]
    q2 = coefficients_from_A([1.0, 0, 0, 0, 0], statistic="mdev", dt_s=0.01)["Q"]
    assert q2 / q1 == pytest.approx(math.sqrt(2.0), rel=1e-12)


@pytest.mark.parametrize(
    "A",
    [[0, 0, 0, 0, -1e-12], [None, 0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0, 0, 0], [0, 0, float("nan"), 0, 0], [0, float("inf"), 0, 0, 0]],
)
def test_bad_A_is_refused(A):
    with pytest.raises(ConfigError, match=r"A must be 5 finite non-negative numbers A_-2..A_2"):
        coefficients_from_A(A)


def test_all_zero_A_gives_all_zero_values():
    out = coefficients_from_A(np.zeros(5))
    assert out == {"Q": 0.0, "Q_arcsec": 0.0, "N": 0.0, "B": 0.0, "K": 0.0, "R": 0.0}


def test_unknown_statistic_and_term():
    with pytest.raises(ConfigError, match=r"no IEEE-952 variance laws for statistic 'tdev'; expected one of"):
        laws_of("tdev")
    with pytest.raises(ConfigError, match=r"no IEEE-952 variance laws"):
        coefficients_from_A(np.ones(5), statistic=["adev"])
    with pytest.raises(ConfigError, match=r"term must be one of \('Q', 'N', 'B', 'K', 'R'\), got 'X'"):
        term_spec("X")


@pytest.mark.parametrize("term", ORDER)
def test_to_A_inverts_from_A_under_every_law(term):
    spec = TERM_TABLE[term]
    value = X_LAW[term] * TO_REPORTED[term]
    for statistic, laws in VARIANCE_LAWS.items():
        if term in laws:
            c = laws[term].scale(DT_S)
            A = spec.to_A(value, c)
            assert A == pytest.approx(c * X_LAW[term] ** 2, rel=1e-12), statistic
            assert spec.from_A(A, c) == pytest.approx(value, rel=1e-12), statistic


def test_law_shapes_leading_power_and_small_m_series():
    tau = np.array([0.02, 0.1, 1.0])
    k_mdev = VARIANCE_LAWS["mdev"]["K"]
    # K^2 tau (11/40 + (dt/tau)^2/24 + (dt/tau)^4/60), normalised by 11/40
    r2 = (DT_S / tau) ** 2
    want = tau * (1.0 + (1.0 / 24.0) / (11.0 / 40.0) * r2 + (1.0 / 60.0) / (11.0 / 40.0) * r2**2)
    np.testing.assert_allclose(k_mdev.shape(tau, DT_S), want, rtol=1e-14)
    np.testing.assert_array_equal(k_mdev.shape(tau, leading_only=True), tau)
    with pytest.raises(ConfigError, match=r"needs the sample interval dt_s"):
        k_mdev.shape(tau)
    with pytest.raises(ConfigError, match=r"needs the sample interval dt_s"):
        VARIANCE_LAWS["mdev"]["Q"].scale(None)
    np.testing.assert_array_equal(VARIANCE_LAWS["hdev"]["Q"].shape(tau), tau**-2.0)
    # integer taus (a list of whole seconds) with a negative power: computed in floating point
    np.testing.assert_array_equal(VARIANCE_LAWS["hdev"]["Q"].shape([1, 2, 4]), [1.0, 0.25, 0.0625])
