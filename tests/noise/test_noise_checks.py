"""Rules of the noise-identification checks, the periodic content and the spectral-line null, pinned by hand
(mutation round 3, issue 24 item 2).

Every expected value is computed here from a closed form, independently of the module under test:

* ``noise/checks.py``: the ~4-sigma point limit and the 95 % interval of a chi-squared point (chi2 with 2 degrees
  of freedom has ``ppf(p) = -2 ln(1 - p)``); the refusal of a flat B floor above the measured minimum and its
  classical bound ``B <= min ADEV / 0.664`` (IEEE Std 952-1997 C.2, 0.664 = sqrt(2 ln 2 / pi)); the minimum of a
  fitted N + K curve, ``sigma^2 = a / tau + b tau`` -> ``2 sqrt(a b)`` at ``tau = sqrt(a / b)``; the quantization
  versus tone rule (Q is not told apart from lines unless its variance stands Q_OVER_ENVELOPE times above their
  envelope ``Omega^2 / (m sin(pi f dt))^2``, the IEEE ``Omega^2 / (pi f tau)^2`` of sampled data); the
  sub-covariance rebuilt from a known correlation and EDF.
* ``noise/periodic.py``: a tone's ADEV ``A^2 sin^4(pi f tau) / (pi f tau)^2`` (IEEE Std 952-1997 C.7) vanishes at
  the taus :func:`null_taus` returns; the relative powers ``(a / a_ref)^2`` and the periods of
  :func:`periodic_content`.
* ``noise/_spectral_null.py``: for a half-window of one bin and EDF 2 the statistic is ``P / max(X1, X2)`` with
  three independent Exp(1) variates, whose survival function is ``2 / ((1 + r) (2 + r))``; for a very wide window
  the median is ln 2 and the survival tends to ``2^-r``.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from fogdrift.noise import checks, context
from fogdrift.noise._spectral_null import _MedianNull, _null_and_critical
from fogdrift.noise.periodic import NULL_TOLERANCE, PeriodicContent, null_taus, periodic_content
from fogdrift.noise.result import NoiseTerm
from fogdrift.noise.terms import ALL_TERMS, laws_of

IB, IN, IK, IQ, IS = (ALL_TERMS.index(t) for t in "BNKQS")
B664 = math.sqrt(2.0 * math.log(2.0) / math.pi)  # 0.6643: min ADEV of a flat floor / B


def _chi2_2_ppf(p):
    """chi2 with 2 degrees of freedom: CDF 1 - exp(-x / 2)."""
    return -2.0 * math.log1p(-p)


# ---------------------------------------------------------------------------------------------------------------
# checks: point limits and intervals


def test_point_limit_is_the_4_sigma_lower_chi2_quantile():
    y = np.array([1.0, 4.0])
    got = context.point_limits(y, np.array([2.0, 2.0]))
    np.testing.assert_allclose(got, y * 2.0 / _chi2_2_ppf(3.17e-5), rtol=1e-9)
    assert got[0] == pytest.approx(1.0 / 3.17e-5, rel=1e-4)  # ~31500 y: one point bounds little
    # an EDF far below 1 (quantile 0) bounds nothing: inf, and no RuntimeWarning, even for y = 0 (0 / 0)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = context.point_limits(np.array([0.0, 1.0]), np.array([1e-9, 1e-9]))
    assert np.isinf(got[1])


def test_points_outside_their_own_95_interval():
    """nu = 2: the interval of y is [y / 3.689, y / 0.02532] = [0.2711 y, 39.50 y]."""
    lo, hi = 2.0 / _chi2_2_ppf(0.975), 2.0 / _chi2_2_ppf(0.025)
    assert lo == pytest.approx(0.27108, rel=1e-4) and hi == pytest.approx(39.4983, rel=1e-4)
    y = np.ones(6)
    mu = np.array([0.99 * lo, 1.01 * lo, 1.0, 0.99 * hi, 1.01 * hi, 0.5])
    out = checks._points_outside(y, mu, np.full(6, 2.0))
    assert out.tolist() == [0, 4]
    # an EDF of 0 is floored at 1e-6: the upper limit is then infinite, the lower one tiny, nothing is outside


# ---------------------------------------------------------------------------------------------------------------
# checks: the refused flat floor and the classical bias-instability reading


def _ctx(tau, y, y_hi, statistic="adev", lines=(), tc_s=None):
    return SimpleNamespace(tau=np.asarray(tau, float), y=np.asarray(y, float), y_hi=np.asarray(y_hi, float),
                           dt=0.01, statistic=statistic, laws=laws_of(statistic), lines=tuple(lines), tc_s=tc_s)


def _floor_ctx():
    # measured ADEV^2 [(deg/h)^2]: minimum 0.04 at tau = 10 s (ADEV 0.2 deg/h), its 95 % upper bound 0.09
    tau = [1.0, 10.0, 100.0]
    return _ctx(tau, [1.0, 0.04, 0.25], [2.0, 0.09, 0.5])


def test_flat_floor_above_the_measured_minimum_is_refused_with_the_classical_bound():
    c = _floor_ctx()
    A = np.zeros(len(ALL_TERMS))
    scale = 2.0 * math.log(2.0) / math.pi
    A[IB] = 0.0901  # just above y_hi at the minimum
    terms = {}
    checks._check_floor(terms, c, A)
    t = terms["B"]
    assert isinstance(t, NoiseTerm) and t.status == "not_estimable" and t.value is None and t.lo95 is None
    assert t.unit == "deg/h" and t.hi95 == pytest.approx(0.2 / B664, rel=1e-9)  # 0.301 deg/h
    msg = t.reason
    assert f"{math.sqrt(0.0901 / scale):.3g} deg/h" in msg  # the refused floor, B = sqrt(A / 0.4413)
    assert "falls to 0.2 deg/h at tau = 10 s" in msg
    assert "B <= min ADEV / 0.6643 = 0.301 deg/h" in msg
    # at (or below) the upper bound the floor stands
    A[IB] = 0.09
    terms = {}
    checks._check_floor(terms, c, A)
    assert terms == {}


@pytest.mark.parametrize("statistic, name", [("hdev", "HDEV"), ("mdev", "MDEV")])
def test_refused_floor_names_the_statistic(statistic, name):
    c = _floor_ctx()
    c.statistic, c.laws = statistic, laws_of(statistic)
    A = np.zeros(len(ALL_TERMS))
    A[IB] = 1.0
    terms = {}
    checks._check_floor(terms, c, A)
    scale = laws_of(statistic)["B"].scale(0.01)
    assert f"B <= min {name} / {math.sqrt(scale):.4g} = {math.sqrt(0.04 / scale):.3g} deg/h" in terms["B"].reason


def test_classical_b_of_a_refused_floor_is_the_measured_minimum_over_0_664():
    c = _floor_ctx()
    got = checks._classical_b(c, np.zeros(len(ALL_TERMS)), floor_refused=True)
    assert got["value"] == pytest.approx(0.2 / B664, rel=1e-12)
    assert got["tau_s"] == 10.0 and got["bound_only"] is True and got["lo95"] is None and got["unit"] == "deg/h"
    assert got["hi95"] == pytest.approx(0.3 / B664, rel=1e-12)
    assert "upper bound" in got["rule"] and "measured" in got["rule"]


def _nk_ctx(a, b, taus):
    """Measured points on the N + K model itself, sigma^2 = a / tau + b tau, with +-20 % (in deviation) bounds."""
    tau = np.asarray(taus, float)
    y = a / tau + b * tau
    A = np.zeros(len(ALL_TERMS))
    A[IN], A[IK] = a, b  # the fit's coefficients of the design columns tau^-1 and tau^1
    return _ctx(tau, y, y * 1.44), A


def test_classical_b_is_the_minimum_of_the_fitted_curve():
    """a / tau + b tau has its minimum 2 sqrt(a b) at tau = sqrt(a / b) = 10 s (inside 0.1 .. 1000 s)."""
    a, b = 1.0, 0.01
    c, A = _nk_ctx(a, b, np.logspace(-1, 3, 9))
    got = checks._classical_b(c, A)
    assert got["value"] == pytest.approx(math.sqrt(2.0 * math.sqrt(a * b)) / B664, rel=1e-4)
    assert got["tau_s"] == pytest.approx(10.0, rel=0.03)  # the 400-point grid's step is 2.3 %
    assert got["bound_only"] is False and got["unit"] == "deg/h"
    j = 4  # the measured tau nearest 10 s is 10 s itself
    assert got["hi95"] == pytest.approx(math.sqrt(c.y_hi[j]) / B664, rel=1e-12)
    assert got["lo95"] == pytest.approx(math.sqrt(c.y[j] / 1.44) / B664, rel=1e-12)
    assert "fitted" in got["rule"]


def test_classical_b_at_the_longest_tau_is_a_bound_the_tighter_of_two():
    """Pure white noise: the fitted curve still falls at the longest tau (an upper bound); the measured minimum is
    lower when the last measured point dips below the curve, and then it is the reading."""
    tau = np.array([1.0, 10.0, 100.0])
    A = np.zeros(len(ALL_TERMS))
    A[IN] = 1.0
    y = 1.0 / tau
    c = _ctx(tau, y, 1.44 * y)
    got = checks._classical_b(c, A)
    assert got["bound_only"] is True and got["lo95"] is None
    assert got["value"] == pytest.approx(0.1 / B664, rel=1e-9) and got["tau_s"] == pytest.approx(100.0)
    c = _ctx(tau, [1.0, 0.1, 0.0144], [1.44, 0.144, 0.0144 * 1.44])  # measured minimum 0.12 above the fit's end
    got = checks._classical_b(c, A)
    assert got["value"] == pytest.approx(0.1 / B664, rel=1e-9) and got["hi95"] == pytest.approx(0.144 / B664)
    c = _ctx(tau, [1.0, 0.1, 0.0064], [1.44, 0.144, 0.0064 * 1.44])  # last point ADEV 0.08 < 0.1
    got = checks._classical_b(c, A)
    assert got["value"] == pytest.approx(0.08 / B664, rel=1e-12) and got["tau_s"] == 100.0
    assert got["hi95"] == pytest.approx(0.096 / B664, rel=1e-9) and got["bound_only"] is True


def test_classical_b_at_the_second_last_grid_point_is_still_the_edge():
    """The minimum on the 400-point grid at index 398 (just inside the longest tau) counts as the edge."""
    a, b = 1.0, 0.01
    tau_end = 10.0 * 1.006  # sqrt(a / b) = 10 s: the minimum sits a hair before the last grid point
    c, A = _nk_ctx(a, b, [0.1, 1.0, tau_end])
    got = checks._classical_b(c, A)
    assert got["bound_only"] is True and got["lo95"] is None


def test_classical_b_reads_the_measured_curve_when_the_fit_misses_its_minimum():
    """A fitted curve far above the measured points at its minimum (a poor fit): the measured minimum is read."""
    a, b = 1.0, 0.01
    c, A = _nk_ctx(a, b, np.logspace(-1, 3, 9))
    c.y = c.y / 100.0  # measured 10x lower in deviation
    c.y_hi = c.y * 1.44
    got = checks._classical_b(c, A)
    jm = int(np.argmin(c.y))
    assert got["value"] == pytest.approx(math.sqrt(c.y[jm]) / B664, rel=1e-12)
    assert got["tau_s"] == pytest.approx(c.tau[jm]) and got["bound_only"] is False
    assert got["lo95"] == pytest.approx(math.sqrt(c.y[jm] / 1.44) / B664, rel=1e-12)
    assert got["hi95"] == pytest.approx(math.sqrt(c.y_hi[jm]) / B664, rel=1e-12)
    assert "misses the measured points" in got["rule"]
    # a curve 10x too LOW is also a miss
    c, A = _nk_ctx(a, b, np.logspace(-1, 3, 9))
    c.y, c.y_hi = c.y * 100.0, c.y * 144.0
    assert "misses" in checks._classical_b(c, A)["rule"]


def test_classical_b_includes_the_shaped_terms_of_the_printed_model():
    """A Gauss-Markov M term or a periodic S term in the model lifts the fitted curve, hence its minimum."""
    from fogdrift.noise.terms import markov_shape, periodic_shape

    a, b = 1.0, 0.01
    tau = np.logspace(-1, 3, 9)
    c, A = _nk_ctx(a, b, tau)
    base = checks._classical_b(c, A)["value"]
    grid = np.logspace(-1, 3, 400)
    for col, kw, shape in ((ALL_TERMS.index("M"), {"tc_s": 10.0}, markov_shape(grid, 10.0, "adev", 0.01)),
                           (IS, {"lines": ((0.03, 1.0),)}, periodic_shape(grid, ((0.03, 1.0),), 0.01, "adev"))):
        A2 = A.copy()
        A2[col] = 0.9
        c2 = _ctx(tau, c.y, c.y_hi * 100.0, **kw)
        var = a / grid + b * grid + 0.9 * shape
        got = checks._classical_b(c2, A2)["value"]
        assert got == pytest.approx(math.sqrt(var.min()) / B664, rel=1e-9) and got > base * 1.01
        # without the shaped context (no tc / no lines) the term is not added
        c3 = _ctx(tau, c.y, c.y_hi * 100.0)
        assert checks._classical_b(c3, A2)["value"] == pytest.approx(base, rel=1e-12)
    # HDEV: the shaped terms in that statistic's form (the Gauss-Markov one needs the sample interval)
    lines = ((0.03, 1.0),)
    for col, kw, shape in ((ALL_TERMS.index("M"), {"tc_s": 10.0}, markov_shape(grid, 10.0, "hdev", 0.01)),
                           (IS, {"lines": lines}, periodic_shape(grid, lines, 0.01, "hdev"))):
        A2 = np.zeros(len(ALL_TERMS))
        A2[IN], A2[IK], A2[col] = a, b, 0.9
        c2 = _ctx(tau, c.y, c.y_hi * 100.0, statistic="hdev", **kw)
        law = laws_of("hdev")
        var = a * law["N"].shape(grid, 0.01) + b * law["K"].shape(grid, 0.01) + 0.9 * shape
        k = int(np.argmin(var))
        assert checks._classical_b(c2, A2)["value"] == pytest.approx(math.sqrt(var[k]) / B664, rel=1e-9)


# ---------------------------------------------------------------------------------------------------------------
# checks: quantization versus a tone


def _q_terms():
    return {"Q": NoiseTerm("Q", 1.0, "urad", 0.5, 2.0, "estimated", "")}


def test_q_below_the_lines_envelope_is_not_claimed():
    """Lines (20 Hz, power 1) and (40 Hz, power 0.25), A_S = 2: the envelope is A_S sum r / (m sin(pi f dt))^2 (each
    line's law with sin^4 replaced by 1, noise.periodic.periodic_variance); Q's variance A_Q / tau^2 must stand
    Q_OVER_ENVELOPE (10) times above it at some fitted tau (the rule the GMWM applies to QN too)."""
    from fogdrift.noise.periodic import Q_OVER_ENVELOPE
    from fogdrift.noise.terms import periodic_shape

    lines = ((20.0, 1.0), (40.0, 0.25))
    tau = np.array([0.01, 0.1])
    c = _ctx(tau, [1.0, 1.0], [2.0, 2.0], lines=lines)
    periodic = SimpleNamespace(periods_s=(0.05, 0.3))
    unit_ratio = float(np.max(tau**-2.0 / (2.0 * periodic_shape(tau, lines, 0.01, "adev", envelope=True))))
    # with dt -> 0 the envelope tends to the IEEE tau^-2 coefficient sum r / (pi f)^2; at 100 Hz it is a little more
    env1 = 1.0 / (math.pi * 20.0) ** 2 + 0.25 / (math.pi * 40.0) ** 2
    assert 1.0 / unit_ratio > 2.0 * env1
    A = np.zeros(len(ALL_TERMS))
    A[IS] = 2.0
    A[IQ] = Q_OVER_ENVELOPE * 0.999 / unit_ratio
    out = _q_terms()
    checks._q_at_whole_periods(c, None, (IQ, IS), A, 1.0, periodic, out)
    t = out["Q"]
    assert t.status == "absent" and t.lo95 == 0.0 and t.value is None and t.hi95 == 2.0 and t.unit == "urad"
    assert f"at most {Q_OVER_ENVELOPE * 0.999:.3g}x the lines' own envelope" in t.reason
    assert f"not the {Q_OVER_ENVELOPE:g}x it must stand above it" in t.reason
    # just above the threshold the envelope rule lets Q through (to the whole-period test, here short of taus)
    A[IQ] = Q_OVER_ENVELOPE * 1.001 / unit_ratio
    out = _q_terms()
    checks._q_at_whole_periods(c, SimpleNamespace(), (IQ, IS), A, 1.0, periodic, out)
    assert "envelope" not in out["Q"].reason and "whole periods" in out["Q"].reason
    # no periodic content: nothing to tell apart, Q untouched
    out = _q_terms()
    checks._q_at_whole_periods(c, None, (IQ, IS), A, 1.0, None, out)
    checks._q_at_whole_periods(c, None, (IQ, IS), A, 1.0, SimpleNamespace(periods_s=()), out)
    assert out["Q"].status == "estimated"


def test_q_above_the_envelope_without_enough_taus_past_the_period_is_unresolved():
    """Q above the envelope, but fewer than (number of terms + 1) taus from the shortest period on: lower bound 0,
    the whole-period reason (the shortest period, 0.05 s, is the one named)."""
    c = _ctx([0.01, 0.02, 0.05, 0.1], [1.0] * 4, [2.0] * 4, lines=((20.0, 1.0),))
    A = np.zeros(len(ALL_TERMS))
    A[IS], A[IQ] = 1.0, 1.0
    prob = SimpleNamespace()
    out = _q_terms()
    checks._q_at_whole_periods(c, prob, (IQ, IS), A, 1.0, SimpleNamespace(periods_s=(0.3, 0.05)), out)
    t = out["Q"]
    assert t.status == "unresolved" and t.lo95 == 0.0 and "tau >= 0.05 s" in t.reason


def test_sub_covariance_is_the_correlation_scaled_by_the_edf():
    """W = inv(chol(R)): the rebuilt covariance is R_ij sqrt(2 / nu_i) sqrt(2 / nu_j), from row/column k0 on."""
    R = np.array([[1.0, 0.5, 0.2], [0.5, 1.0, 0.4], [0.2, 0.4, 1.0]])
    nu = np.array([2.0, 8.0, 50.0])
    prob = SimpleNamespace(W=np.linalg.inv(np.linalg.cholesky(R)), nu=nu)
    want = R * np.outer(np.sqrt(2 / nu), np.sqrt(2 / nu))
    np.testing.assert_allclose(checks._sub_cov(prob, 0), want, rtol=1e-12)
    np.testing.assert_allclose(checks._sub_cov(prob, 1), want[1:, 1:], rtol=1e-12)
    assert checks._sub_cov(prob, 1)[0, 1] == pytest.approx(0.4 * 0.5 * 0.2, rel=1e-12)


# ---------------------------------------------------------------------------------------------------------------
# periodic: the tone's nulls and the content of a spectrum


def _tone_avar(f, tau):
    """ADEV^2 of a unit-amplitude sinusoid (IEEE Std 952-1997 C.7)."""
    x = math.pi * f * np.asarray(tau, float)
    return np.sin(x) ** 4 / x**2


def test_null_taus_are_whole_cycles_of_each_of_the_first_two_periods():
    dt = 0.001
    got = null_taus([0.05, 0.13, 0.7], dt, dt, 10.0)
    # 0.05 s: 1, 2, 4, 8, 16 periods; 0.13 s: 1, 2, 4, 8, 16 periods (k <= 16); 0.7 s is the third: left out
    want = sorted({0.05 * k for k in (1, 2, 4, 8, 16)} | {0.13 * k for k in (1, 2, 4, 8, 16)})
    np.testing.assert_allclose(got, want, rtol=1e-12)
    for f in (1 / 0.05, 1 / 0.13):
        on = np.isclose((got * f) % 1.0, 0.0, atol=1e-6) | np.isclose((got * f) % 1.0, 1.0, atol=1e-6)
        assert np.all(_tone_avar(f, got[on]) < 1e-20)
    # with the third period too: 0.7, 1.4, 2.8, 5.6 s (16 periods would be 11.2 s > 10 s)
    assert null_taus([0.05, 0.13, 0.7], dt, dt, 10.0, max_components=3).size == 14
    assert null_taus([0.05], dt, dt, 10.0, max_periods=4).tolist() == pytest.approx([0.05, 0.1, 0.2])


def test_null_taus_respect_the_tau_range_and_skip_bad_periods():
    np.testing.assert_allclose(null_taus([0.05], 0.01, 0.1, 0.4), [0.1, 0.2, 0.4])  # 0.05 below tau_min
    np.testing.assert_allclose(null_taus([0.05], 0.01, 0.05, 0.4), [0.05, 0.1, 0.2, 0.4])  # both ends inclusive
    assert null_taus([0.05], 0.01, 0.01, 0.39).tolist() == pytest.approx([0.05, 0.1, 0.2])
    for bad in ([0.0], [-0.05], [math.inf], [math.nan]):
        assert null_taus(bad, 0.01, 0.01, 1.0).size == 0
    np.testing.assert_allclose(null_taus([0.0, 0.05], 0.01, 0.01, 0.1), [0.05, 0.1])


def test_null_taus_take_the_nearest_sample_multiple_within_the_tolerance():
    """Period 0.035 s at dt = 0.01 s: 1 period is 3.5 samples (half a cycle off) and 2 periods 7 samples exactly;
    the search for k = 1 tries 1 period only, so the first null is at 2 periods (0.07 s); the tone's ADEV at every
    returned tau is below sin^4(pi 0.05) ~ 6e-3 of its 1/(pi f tau)^2 envelope."""
    got = null_taus([0.035], 0.01, 0.01, 1.0)
    assert got[0] == pytest.approx(0.07)
    # at most max_periods periods: with 1, the 2-period null is not searched for
    assert null_taus([0.035], 0.01, 0.01, 1.0, max_periods=1).size == 0
    cyc = got / 0.035
    assert np.all(np.abs(cyc - np.round(cyc)) <= NULL_TOLERANCE)
    x = math.pi / 0.035 * got
    assert np.all(_tone_avar(1 / 0.035, got) <= np.sin(math.pi * NULL_TOLERANCE) ** 4 / x**2 * (1 + 1e-9))
    # the nearest sample multiple of one period (10 samples, 0.1 s) is 1.049 cycles: kept; 1.051 cycles: not
    assert null_taus([0.1 / 1.049], 0.01, 0.01, 0.15).tolist() == pytest.approx([0.1])
    assert null_taus([0.1 / 1.051], 0.01, 0.01, 0.15).size == 0


def _line(f, a):
    return {"freq_hz": f, "amplitude_dph": a, "harmonic_of": None}


def test_periodic_content_of_lines_and_components():
    spec = {
        "lines": [_line(20.0, 8.0), _line(3.0, 2.0), _line(0.0, 5.0), _line(7.0, 0.0)],
        "components": [
            {"fundamental_hz": 4.0, "period_s": 0.25, "power_dph2": 1.0,
             "lines": [_line(4.0, 4.0), _line(8.0, 2.0), _line(12.0, 1.0)]},
            {"fundamental_hz": 20.0, "period_s": 0.05, "power_dph2": 32.0, "lines": [_line(20.0, 8.0)]},
        ],
        "rolloff_hz": 30,
    }
    pc = periodic_content(spec)
    assert isinstance(pc, PeriodicContent)
    # the lines: 20, 3 (from the line list; 0 Hz and 0 deg/h dropped), then 4, 8, 12 added from the component
    assert [f for f, _ in pc.lines] == [20.0, 3.0, 4.0, 8.0, 12.0]
    np.testing.assert_allclose([p for _, p in pc.lines], [1.0, (2 / 8) ** 2, (4 / 8) ** 2, (2 / 8) ** 2, (1 / 8) ** 2])
    assert pc.ref_freq_hz == 20.0 and pc.ref_amplitude_dph == 8.0
    # components by power, strongest first, then the line outside every component (3 Hz: 1/3 s)
    assert pc.periods_s == pytest.approx((0.05, 0.25, 1 / 3.0))
    assert pc.descriptions == ("spectral line at 20 Hz, 8 deg/h", "periodic error, period 0.25 s (4 Hz and 2 "
                               "harmonic(s))", "spectral line at 3 Hz, 2 deg/h")
    assert pc.text() == "; ".join(pc.descriptions)
    assert pc.rolloff_hz == 30.0 and isinstance(pc.rolloff_hz, float)


def test_periodic_content_attributes_and_defaults():
    """Duck-typed objects work as dicts do; a component without a period takes 1 / f0; no roll-off is None."""
    ln = SimpleNamespace(freq_hz=5.0, amplitude_dph=3.0)
    comp = SimpleNamespace(fundamental_hz=5.0, lines=[ln])
    pc = periodic_content(SimpleNamespace(lines=[], components=[comp]))
    assert pc.lines == ((5.0, 1.0),) and pc.periods_s == pytest.approx((0.2,)) and pc.rolloff_hz is None
    assert pc.descriptions == ("spectral line at 5 Hz, 3 deg/h",)
    assert periodic_content(None) is None
    assert periodic_content({"lines": [_line(0.0, 1.0)], "components": []}) is None
    assert periodic_content({"lines": None, "components": None}) is None
    # a component with one line listed only in the component: its period is printed once
    pc = periodic_content({"lines": [_line(5.0, 3.0)], "components": [{"fundamental_hz": 5.0, "lines": [
        _line(5.0, 3.0)]}]})
    assert pc.periods_s == pytest.approx((0.2,)) and len(pc.lines) == 1
    # components by power, strongest first; one without a power counts as power 0 (last)
    pc = periodic_content({"lines": [_line(5.0, 3.0)], "components": [
        {"fundamental_hz": 2.0, "lines": [_line(2.0, 1.0)]},
        {"fundamental_hz": 4.0, "power_dph2": 0.5, "lines": [_line(4.0, 1.0)]}]})
    assert pc.periods_s == pytest.approx((0.25, 0.5, 0.2))
    # a component with a period but no fundamental frequency: its period as given
    pc = periodic_content({"lines": [_line(5.0, 3.0)], "components": [{"fundamental_hz": 0.0, "period_s": 0.5}]})
    assert pc.periods_s == pytest.approx((0.5, 0.2))
    # a component with no line: its amplitude is unknown
    pc = periodic_content({"lines": [_line(5.0, 3.0)], "components": [{"fundamental_hz": 2.0, "period_s": 0.5}]})
    assert pc.descriptions[0] == "spectral line at 2 Hz, nan deg/h" and pc.periods_s == pytest.approx((0.5, 0.2))


# ---------------------------------------------------------------------------------------------------------------
# _spectral_null: the survival function of P / max(median_left, median_right)


def test_median_null_of_single_bins_is_the_closed_form():
    """w = 1, EDF 2: P, X1, X2 independent Exp(1): P(P >= r max(X1, X2)) = E[exp(-r M)] = 2 / ((1 + r)(2 + r))."""
    null = _MedianNull(2.0, 1, 1.0)
    r = np.array([0.5, 1.0, 3.0, 10.0, 30.0])
    np.testing.assert_allclose(null.sf(r), 2.0 / ((1 + r) * (2 + r)), rtol=2e-3)
    assert null.critical(0.1) == pytest.approx(3.0, rel=2e-3)  # 2 / (4 * 5) = 0.1
    # the bin correlation shrinks the effective window: w = 3 at correlation 3 is w = 1
    np.testing.assert_allclose(_MedianNull(2.0, 3, 3.0).sf(r), null.sf(r), rtol=1e-12)
    # and never below one variate
    np.testing.assert_allclose(_MedianNull(2.0, 1, 5.0).sf(r), null.sf(r), rtol=1e-12)


def test_median_null_of_a_wide_window_tends_to_the_chi2_survival():
    """A median over many bins is the distribution's median, ln 2 for Exp(1): sf(r) -> exp(-r ln 2) = 2^-r."""
    null = _MedianNull(2.0, 20001, 1.0)
    r = np.array([1.0, 3.0, 6.0])
    np.testing.assert_allclose(null.sf(r), 2.0 ** -r, rtol=0.03)
    assert null.sf(2.0).shape == (1,)


def test_median_null_sf_in_blocks_of_256():
    null = _MedianNull(4.0, 5, 1.3)
    r = np.linspace(0.5, 20.0, 600)
    whole = null.sf(r)
    np.testing.assert_allclose(whole[300:], null.sf(r[300:]), rtol=1e-12)
    assert np.all(np.diff(whole) < 0) and whole[0] < 1.0


def test_cached_null_and_critical_agree():
    null, crit = _null_and_critical(8.0, 7, 1.5, 1e-3)
    assert float(null.sf(crit)[0]) == pytest.approx(1e-3, rel=1e-3)
    assert _null_and_critical(8.0, 7, 1.5, 1e-3)[0] is null
    assert null.nu == 8.0


# ---------------------------------------------------------------------------------------------------------------
# checks: the re-selection without a term at its data bound or a refused floor

IM = ALL_TERMS.index("M")
TAU3 = np.array([1.0, 10.0, 100.0])


def _prob(upper):
    """Three points y = 1 of EDF 2: each point's 4-sigma limit is 1 / 3.17e-5; the K column (tau) is largest, so the
    limit over it is smallest, at tau = 100 s; the N column (1 / tau) at tau = 1 s."""
    X = np.zeros((3, len(ALL_TERMS)))
    X[:, IN], X[:, IK], X[:, IS], X[:, IM] = 1.0 / TAU3, TAU3, [0.0, 1.0, 10.0], TAU3 / 100.0  # S: a null at 1 s
    return SimpleNamespace(upper=np.asarray(upper, float), y=np.ones(3), nu=np.full(3, 2.0), X=X)


def _a(**kw):
    a = np.zeros(len(ALL_TERMS))
    for k, v in kw.items():
        a[ALL_TERMS.index(k)] = v
    return a


def _res(ic_n=12.0, a_k=4.0):
    return {(IN, IK): {"ic": 10.0, "a": _a(N=1.0, K=a_k)}, (IN,): {"ic": ic_n, "a": _a(N=1.2)},
            (IK,): {"ic": 40.0, "a": _a(K=1.0)}}


def _upper(k=4.0, s=0.0, m=0.0):
    u = np.zeros(len(ALL_TERMS))
    u[IN], u[IK], u[IS], u[IM] = 100.0, k, s, m
    return u


def test_term_at_its_bound_is_dropped_when_a_model_without_it_is_plausible():
    c = _ctx(TAU3, [1.0, 1.0, 1.0], [2.0, 2.0, 2.0])
    best, dropped = checks._drop_rejected(c, _prob(_upper()), _res(), (IN, IK))
    assert best == (IN,) and list(dropped) == [IK]
    t = dropped[IK]
    bound = 60.0 / math.sqrt(1.0 / 3.0) * 2.0  # to_unit / sqrt(law scale) x sqrt(upper) = 207.8 deg/h^1.5
    assert t.name == "K" and t.value is None and t.lo95 is None and t.status == "not_estimable"
    assert t.unit == "deg/h^1.5" and t.hi95 == pytest.approx(bound, rel=1e-12)
    assert t.reason == (f"left out of the model: its fit ran into its data bound ({bound:.4g} deg/h^1.5, set by the "
                        "point at tau = 100 s alone), so the data bound it but do not measure it; the model was "
                        "re-selected without it")


def test_term_at_its_bound_stays_when_every_model_without_it_is_far_worse():
    c = _ctx(TAU3, [1.0, 1.0, 1.0], [2.0, 2.0, 2.0])
    assert checks._drop_rejected(c, _prob(_upper()), _res(ic_n=16.5), (IN, IK)) == ((IN, IK), {})
    # exactly plausible_delta worse still counts as plausible; the threshold is the argument
    assert checks._drop_rejected(c, _prob(_upper()), _res(ic_n=16.0), (IN, IK))[0] == (IN,)
    assert checks._drop_rejected(c, _prob(_upper()), _res(ic_n=16.5), (IN, IK), plausible_delta=7.0)[0] == (IN,)


def test_at_bound_means_within_1e_3_of_the_bound_and_needs_another_term():
    c = _ctx(TAU3, [1.0, 1.0, 1.0], [2.0, 2.0, 2.0])
    assert checks._drop_rejected(c, _prob(_upper()), _res(a_k=4.0 * (1 - 0.999e-3)), (IN, IK))[0] == (IN,)
    assert checks._drop_rejected(c, _prob(_upper()), _res(a_k=4.0 * (1 - 1.001e-3)), (IN, IK)) == ((IN, IK), {})
    assert checks._drop_rejected(c, _prob(_upper(k=0.0)), _res(), (IN, IK)) == ((IN, IK), {})  # no bound
    res = {(IK,): {"ic": 10.0, "a": _a(K=4.0)}, (IN,): {"ic": 11.0, "a": _a(N=1.0)}}
    assert checks._drop_rejected(c, _prob(_upper()), res, (IK,)) == ((IK,), {})  # a lone term stays


def test_shaped_terms_at_their_bound_are_named_in_deg_h():
    """S: bound sqrt(u) deg/h; M: sqrt(u) / tc deg/h/sqrt(s) (the point: the largest column, tau = 100 s; a point
    where the column is 0, the S null at 1 s, bounds nothing and is not divided by)."""
    import warnings

    c = _ctx(TAU3, [1.0, 1.0, 1.0], [2.0, 2.0, 2.0], tc_s=4.0)
    res = {(IN, IS): {"ic": 10.0, "a": _a(N=1.0, S=9.0)}, (IN,): {"ic": 11.0, "a": _a(N=1.0)}}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        best, dropped = checks._drop_rejected(c, _prob(_upper(s=9.0)), res, (IN, IS))
    t = dropped[IS]
    assert best == (IN,) and t.name == "S" and t.unit == "deg/h" and t.hi95 == pytest.approx(3.0)
    assert "(3 deg/h, set by the point at tau = 100 s alone)" in t.reason
    res = {(IN, IM): {"ic": 10.0, "a": _a(N=1.0, M=16.0)}, (IN,): {"ic": 11.0, "a": _a(N=1.0)}}
    t = checks._drop_rejected(c, _prob(_upper(m=16.0)), res, (IN, IM))[1][IM]
    assert t.unit == "deg/h/√s" and t.hi95 == pytest.approx(1.0) and "(1 deg/h/√s, set by" in t.reason
    c.tc_s = None  # no correlation time: divided by 1
    assert checks._drop_rejected(c, _prob(_upper(m=16.0)), res, (IN, IM))[1][IM].hi95 == pytest.approx(4.0)


def test_re_selection_takes_the_best_model_without_the_term_and_its_non_zero_part():
    """Without K the best is (N, Q) at IC 11, whose Q came out 0: the model is then (N,) itself."""
    c = _ctx(TAU3, [1.0, 1.0, 1.0], [2.0, 2.0, 2.0])
    res = _res()
    res[(IQ, IN)] = {"ic": 11.0, "a": _a(N=1.0, Q=0.0)}
    res[(IQ, IN, IK)] = {"ic": 9.0, "a": _a(N=1.0, Q=0.0, K=1.0)}  # holds K: never the alternative
    assert checks._drop_rejected(c, _prob(_upper()), res, (IN, IK))[0] == (IN,)
    del res[(IN,)]
    assert checks._drop_rejected(c, _prob(_upper()), res, (IN, IK))[0] == (IQ, IN)  # (N,) was not fitted


def test_refused_floor_is_dropped_however_much_worse_the_model_without_it():
    c = _floor_ctx()
    res = {(IN, IB): {"ic": 10.0, "a": _a(N=0.01, B=1.0)}, (IN,): {"ic": 100.0, "a": _a(N=0.01)}}
    best, dropped = checks._drop_rejected(c, _prob(_upper()), res, (IN, IB))
    assert best == (IN,) and dropped[IB].status == "not_estimable"
    assert dropped[IB].hi95 == pytest.approx(0.2 / B664, rel=1e-9) and "contradicted" in dropped[IB].reason
    # a floor below the curve's upper bound stays; no alternative at all: nothing is dropped
    res[(IN, IB)]["a"] = _a(N=0.01, B=0.05)
    assert checks._drop_rejected(c, _prob(_upper()), res, (IN, IB)) == ((IN, IB), {})
    res = {(IN, IB): {"ic": 10.0, "a": _a(N=0.01, B=1.0)}}
    assert checks._drop_rejected(c, _prob(_upper()), res, (IN, IB)) == ((IN, IB), {})


def _qs_problem(a_q, a_n, nu=1e4):
    """Exact Q + N + S curve (a 20-Hz line) at octave taus 0.01 .. 1.28 s, EDF ``nu`` at every point."""
    from fogdrift.noise.engine import ScoreProblem
    from fogdrift.noise.terms import periodic_shape

    dt, lines = 0.01, ((20.0, 1.0),)
    tau = dt * 2.0 ** np.arange(8)
    X = np.zeros((tau.size, len(ALL_TERMS)))
    X[:, IQ], X[:, IN], X[:, IS] = tau**-2.0, 1.0 / tau, periodic_shape(tau, lines, dt, "adev")
    y = X @ _a(Q=a_q, N=a_n, S=1.0)
    prob = ScoreProblem(X, y, np.diag(np.full(tau.size, 2.0 / nu)), np.full(len(ALL_TERMS), 1e6))
    c = _ctx(tau, y, 2.0 * y, lines=lines)
    c.dt = dt
    return c, prob


def test_q_above_the_envelope_is_kept_only_if_resolved_at_whole_periods():
    """Envelope 1 / (m sin(pi 20 dt))^2 tau^2 ~ 2.9e-4 / tau^2: Q = 1e-2 is 35x above it.  With N = 1e-3 the taus from
    0.05 s on (0.08 .. 1.28 s) still see Q (1e-2 / tau^2 against 1e-3 / tau): resolved, Q kept; with N = 1e3 (a
    hundred thousand times Q's share at 0.08 s) Q is not resolved from zero there: unresolved, lower bound 0."""
    best = (IQ, IN, IS)
    for a_n, resolved in ((1e-3, True), (1e3, False)):
        c, prob = _qs_problem(1e-2, a_n)
        out = _q_terms()
        checks._q_at_whole_periods(c, prob, best, _a(Q=1e-2, N=a_n, S=1.0), 3.84, SimpleNamespace(periods_s=(0.05,)),
                                   out)
        assert (out["Q"].status == "estimated") == resolved
        if not resolved:
            assert out["Q"].lo95 == 0.0 and "whole periods of the periodic error (tau >= 0.05 s)" in out["Q"].reason


# ---------------------------------------------------------------------------------------------------------------
# notes: the words of the fit, on hand-built curves

from fogdrift.noise import notes  # noqa: E402


def test_tau_span_and_slope():
    assert notes._tau_span(0.64, 0.64) == "0.64" and notes._tau_span(0.64, 5.12) == "0.64-5.12"
    assert notes._tau_span(1.0001, 1.0002) == "1"  # equal to 3 digits
    tau = np.array([1.0, 10.0, 100.0])
    assert notes._slope(tau, 4.0 / tau) == pytest.approx(-0.5)  # white noise: ADEV ~ tau^-1/2
    assert notes._slope(tau, 4.0 * tau**2) == pytest.approx(1.0)  # a ramp
    assert math.isnan(notes._slope(np.array([1.0]), np.array([1.0])))


def test_worst_region_is_the_run_of_largest_square_sum():
    z = np.array([0.0, 3.0, 3.0, 0.0, -5.0, 1.0, 2.5])
    assert notes._worst_region(None, z) == (4, 4)  # 25 > 18 > 6.25
    assert notes._worst_region(None, np.array([3.0, 3.0, 0.0, -4.0])) == (0, 1)  # 18 > 16
    assert notes._worst_region(None, np.array([0.0, 2.5, 3.0])) == (1, 2)  # a run at the end
    assert notes._worst_region(None, np.array([0.5, -1.9, 1.0])) == (1, 1)  # none beyond 2: the largest |z|
    assert notes._worst_region(None, np.array([])) is None


def test_misfit_note_names_the_side_and_size():
    tau = np.array([1.0, 2.0, 4.0, 8.0])
    y = np.array([1.0, 1.0, 1.21, 1.44])
    mu = np.ones(4)
    z = np.array([0.0, 0.0, 3.0, 4.0])
    (note,) = notes._misfit_note(tau, y, mu, z, "poor", 3.456, 0.0123)
    assert note.startswith("fit poor: chi2_red = 3.46 (p = 0.012); the model misses the curve most at tau = 4-8 s, "
                           "where the measured deviation is above the model by up to 20 %; local ADEV slope there")
    assert notes._slope(tau[2:], y[2:]) == pytest.approx(math.log(1.2 / 1.1) / math.log(2.0))
    (note,) = notes._misfit_note(tau, 1.0 / y, mu, z, "poor", 3.0, 0.01)
    assert "below the model by up to 17 %; the curve falls faster than the fitted terms allow" in note


def test_no_fit_names_the_points_outside_their_intervals():
    tau = np.array([1.0, 10.0, 100.0])
    y = np.ones(3)
    mu = np.array([1.0, 0.2, 50.0])  # nu = 2: [0.271, 39.5]: the last two outside
    no_fit, note = notes._no_fit(tau, y, mu, np.full(3, 2.0), (IN, IK), 7.0)
    assert no_fit == {"tau_min_s": 1.0, "tau_max_s": 100.0, "miss_tau_s": [10.0, 100.0], "best_candidate": "N+K"}
    assert note == ("no model fits tau 1-100 s: the best candidate (N+K, chi2_red 7) misses the measured curve outside "
                    "its 95 % intervals at tau = 10, 100 s; the coefficients are not a result (the table shows their "
                    "upper bounds only)")
    assert notes._no_fit(tau, y, np.ones(3), np.full(3, 2.0), (IN,), 1.0) == (None, None)


def test_largest_gap_note_at_twice_either_way():
    tau = np.array([1.0, 10.0, 100.0])
    y = np.ones(3)
    assert notes._largest_gap_note(tau, y, np.array([1.0, 1.0, 3.99]), np.full(3, 2.0)) == []  # 1.997x
    (note,) = notes._largest_gap_note(tau, y, np.array([1.0, 1.0, 4.0]), np.full(3, 2.0))
    # nu = 2: measured/true in [0.0253, 3.689]; 1 / 2^2 = 0.25 inside
    assert note.startswith("largest gap: at tau = 100 s the model's deviation is 2.00x the measured one (above it; "
                           "~2 degrees of freedom), inside that point's own 95 % interval")
    (note,) = notes._largest_gap_note(tau, y, np.array([1.0, 0.25, 1.0]), np.full(3, 1000.0))
    assert "at tau = 10 s the model's deviation is 0.50x the measured one (below it; ~1e+03 degrees" in note
    assert note.endswith("outside that point's own 95 % interval: the model's shape is wrong there")
    assert notes._largest_gap_note(tau, y, np.array([1.0, 1.0, 4.0]), np.array([2.0, 2.0, 0.0])) == []
    assert notes._largest_gap_note(tau, y, np.array([1.0, 1.0, 4.0]), np.array([2.0, 2.0, np.inf])) == []


def test_at_bound_note_and_reasons():
    prob = _prob(_upper())
    out = {"K": NoiseTerm("K", 207.8, "deg/h^1.5", None, None, "estimated", ""),
           "N": NoiseTerm("N", 1.0, "deg/sqrt(h)", None, None, "estimated", "")}
    (note,) = notes._at_bound_notes(prob, _a(N=1.0, K=4.0), (IN, IK), TAU3, out)
    assert note == ("K = 207.8 deg/h^1.5 sits at its data bound: a larger K alone would exceed the measured curve's "
                    "~4-sigma upper limit at tau = 100 s, so that one point sets the value, not the fit as a whole; "
                    "read it as the largest K the data allow")
    assert notes._at_bound_notes(prob, _a(N=1.0, K=3.99), (IN, IK), TAU3, out) == []
    out["K"] = NoiseTerm("K", None, "deg/h^1.5", None, 207.8, "not_estimable", "")
    assert notes._at_bound_notes(prob, _a(N=1.0, K=4.0), (IN, IK), TAU3, out) == []
    res = {(IN,): {"ic": 11.3}}
    assert notes._unresolved_reason("K", [(IN,)], None, res, 10.0) == ("not resolved from zero: the model N without K "
                                                                     "describes the curve about as well (IC +1.3)")
    assert notes._unresolved_reason("K", [], None, res, 10.0) == "not resolved from zero: its 95 % interval reaches 0"


def test_absent_reason_says_where_the_term_would_dominate():
    """N = 1 (A / tau) measured on 1..100 s: a K at A_K tau dominates beyond tau = sqrt(1 / A_K); a Q at A_Q / tau^2
    below tau = A_Q."""
    c = _ctx([1.0, 10.0, 100.0], [1.0, 0.1, 0.01], [2.0, 0.2, 0.02])
    A = _a(N=1.0)
    assert notes._absent_reason(c, "K", A, 1e-6) == (
        "not in the model: at its upper bound it would dominate only beyond tau = 1e+03 s (longest fitted tau 100 s); "
        "a longer record can resolve it")
    assert notes._absent_reason(c, "Q", A, 1e-3) == ("not in the model: at its upper bound it would dominate only "
                                                     "below the fitted range (tau < 1 s)")
    assert notes._absent_reason(c, "K", A, 1.0) == "not in the model: the curve shows no sign of it in the fitted range"
    # a Q dominating up to 3 s (3 / tau^2 >= 1 / tau) reaches into the fitted range
    assert notes._absent_reason(c, "Q", A, 3.0) == "not in the model: the curve shows no sign of it in the fitted range"
    assert "beyond the record" in notes._absent_reason(c, "B", _a(N=1e9), 1e-9)


def _excl(y_short):
    """Fit from tau = 0.16 s on with N alone (ADEV^2 = 0.01 / tau); the left-out taus 0.01 .. 0.08 s hold
    ``y_short``."""
    tau = np.array([0.01, 0.02, 0.04, 0.08, 0.16])
    X = np.zeros((5, len(ALL_TERMS)))
    X[:, IN] = 1.0 / tau
    model = 0.01 / tau
    y = np.r_[np.asarray(y_short, float), model[4]]
    ctx = SimpleNamespace(tau=tau, y=y, y_hi=1.1 * y, X=X)
    return ctx, {"best": (IN,), "res": {(IN,): {"a": _a(N=0.01)}}}, model


def test_describe_excluded_below_the_model_and_flat():
    tau = np.array([0.01, 0.02, 0.04, 0.08])
    ctx, sel, _ = _excl(0.05 * (tau / 0.01) ** 0.2)  # ADEV slope +0.1, below the model at every left-out tau
    head = "ADEV below the model with a slope of +0.10 (flatter than white noise's -0.5): "
    assert notes._describe_excluded(ctx, 4, sel) == (
        head + "correlated samples (no spectrum of the series was given to say more), not a noise term")
    assert notes._describe_excluded(ctx, 4, sel, spectrum_given=True) == (
        head + "correlated samples (the spectrum shows no roll-off), not a noise term")
    assert notes._describe_excluded(ctx, 4, sel, spectrum_given=True, rolloff_hz=30.0) == (
        head + "an output low-pass / anti-alias filter (the spectrum rolls off above 30 Hz), not a noise term")


def test_describe_excluded_steeper_than_quantization_and_other_shapes():
    tau = np.array([0.01, 0.02, 0.04, 0.08])
    ctx, sel, model = _excl((tau / 0.01) ** -3.0)  # ADEV ~ tau^-1.5
    assert notes._describe_excluded(ctx, 4, sel) == "a slope of -1.50, steeper than quantization's -1: not an " \
                                                    "IEEE-952 term"
    ctx, sel, model = _excl(1.44 * 0.01 / tau)  # 20 % above the model, same slope
    assert notes._describe_excluded(ctx, 4, sel) == ("a shape no IEEE-952 term describes: the ADEV is above the "
                                                     "model by up to 20 %, many times its statistical error there")
    y = 0.01 / tau
    y[0] *= 0.64  # 20 % below at the first point only
    ctx, sel, model = _excl(y)
    assert "the ADEV is below the model by up to 20 %" in notes._describe_excluded(ctx, 4, sel)
    # one left-out tau (start = 1): its own deviation (10 % above) is reported, not the first fitted point's (40 %)
    X2 = np.zeros((2, len(ALL_TERMS)))
    X2[:, IN] = [100.0, 50.0]
    y2 = np.array([1.21, 0.98])
    ctx2 = SimpleNamespace(tau=np.array([0.01, 0.02]), y=y2, y_hi=1.1 * y2, X=X2)
    assert notes._describe_excluded(ctx2, 1, sel).endswith("the ADEV is above the model by up to 10 %, many times "
                                                           "its statistical error there")
    # a line whose share of the one left-out point is below 0.1 is not named (its share of the first fitted one, 0.15,
    # does not count): 0.30 x 0.5^2 / 1.21 = 0.062
    y3 = np.array([1.21, 0.5])
    ctx3 = SimpleNamespace(tau=np.array([0.01, 0.02]), y=y3, y_hi=1.1 * y3, X=X2)
    pc = SimpleNamespace(lines=((20.0, 1.0),), ref_amplitude_dph=0.5)
    assert "spectral line" not in notes._describe_excluded(ctx3, 1, sel, periodic=pc)
    # the largest deviation (20 % below, at 0.04 s), not the first one (10 % below)
    y = 0.01 / tau * np.array([0.81, 1.01, 0.64, 1.01])
    ctx, sel, model = _excl(y)
    assert "the ADEV is below the model by up to 20 %" in notes._describe_excluded(ctx, 4, sel)
    # below the model except just above it (2 %) at the last left-out tau: not "below the model", another shape
    ctx, sel, model = _excl([0.05, 0.05, 0.05, 0.13])
    assert notes._describe_excluded(ctx, 4, sel).startswith("a shape no IEEE-952 term describes: the ADEV is below")


def test_describe_excluded_names_a_bump_or_the_line_that_shapes_the_curve():
    tau = np.array([0.01, 0.02, 0.04, 0.08])
    y = 0.01 / tau
    y[2] *= 4.0  # ADEV sqrt(tau) twice the flat level at 0.04 s
    ctx, sel, _ = _excl(y)
    assert notes._describe_excluded(ctx, 4, sel) == ("a bump in the curve near tau = 0.04 s (an oscillation or "
                                                     "vibration; its frequency needs the spectrum of the series, not "
                                                     "the tau of the bump)")
    assert notes._describe_excluded(ctx, 4, sel, spectrum_given=True) == (
        "a bump in the curve near tau = 0.04 s (an oscillation, but the spectrum shows no line: not a noise term)")
    # two bumps: the larger one (ADEV sqrt(tau) x 1.5 at 0.08 s, the other x 1.2 at 0.02 s) is named
    y2 = 0.01 / tau * np.array([1.0, 1.44, 1.0, 2.25])
    ctx2, sel2, _ = _excl(y2)
    assert notes._describe_excluded(ctx2, 4, sel2).startswith("a bump in the curve near tau = 0.08 s")
    # a bump must clear the fit's start by 2 sd of the ADEV (y_hi = 1.1 y: sd = ln 1.1 / (2 x 1.96) = 0.024): x 1.04
    # is not a bump, x 1.06 is
    for factor, bump in ((1.04, False), (1.06, True)):
        ctx2, sel2, _ = _excl(0.01 / tau * np.array([1.0, 1.0, factor**2, 1.0]))
        assert notes._describe_excluded(ctx2, 4, sel2).startswith("a bump") == bump
    # a 20-Hz line of 1 deg/h: its ADEV^2 at 0.01 s is sin^4(0.2 pi) / (0.2 pi)^2 = 0.30 of y there (>= 0.1)
    pc = SimpleNamespace(lines=((20.0, 1.0),), ref_amplitude_dph=1.0)
    assert notes._describe_excluded(ctx, 4, sel, periodic=pc) == (
        "spectral line at 20 Hz, 1 deg/h (periodic content the fitted terms do not describe there), not a noise term")
    # 0.1 deg/h: its largest share is 0.52 x 0.01 / 0.5 = 0.010 (at 0.02 s): not named
    assert notes._lines_that_matter(SimpleNamespace(lines=((20.0, 1.0),), ref_amplitude_dph=0.1), tau, y) == []
    assert notes._lines_that_matter(SimpleNamespace(lines=((20.0, 1.0), (40.0, 0.0025)), ref_amplitude_dph=2.0), tau,
                                    y) == ["spectral line at 20 Hz, 2 deg/h"]
    assert notes._lines_that_matter(None, tau, y) == [] and notes._lines_that_matter(pc, [], []) == []


def test_median_null_critical_inverts_sf_below_e_too():
    """``critical`` searches r in [1, 1e4] (log r from 0): a lenient p whose critical ratio is below e is found."""
    null = _MedianNull(2.0, 3, 1.0)
    for p in (0.3, 0.1, 1e-3):
        r = null.critical(p)
        assert 1.0 <= r < 1e4
        assert float(null.sf(r)[0]) == pytest.approx(p, rel=1e-3)
    assert null.critical(0.3) < math.e  # the case a bracket starting at log r = 1 cannot reach


def test_periodic_content_lists_a_component_once_with_frequencies_that_need_all_nine_digits():
    """A sawtooth-like component at f0 = 1/3 Hz (0.333333333333...: ten and more digits) with its first harmonic,
    the same two lines also in the spectrum's line list, no ``period_s`` (1 / f0 then): one component, described
    once as a periodic error, and a separate line at 0.25 Hz (below 1 Hz, kept)."""
    f0 = 1.0 / 3.0
    fund = {"freq_hz": f0, "amplitude_dph": 2.0}
    harm = {"freq_hz": 2.0 * f0, "amplitude_dph": 0.5}
    lone = {"freq_hz": 0.25, "amplitude_dph": 1.0}
    comp = {"fundamental_hz": f0, "lines": [fund, harm], "power_dph2": 4.25}
    pc = periodic_content({"lines": [fund, harm, lone], "components": [comp]})
    assert pc.descriptions == ("periodic error, period 3 s (0.3333 Hz and 1 harmonic(s))",
                               "spectral line at 0.25 Hz, 1 deg/h")
    assert pc.periods_s == pytest.approx((3.0, 4.0), rel=1e-12, abs=0)
    assert [f for f, _ in pc.lines] == pytest.approx([f0, 2.0 * f0, 0.25], rel=1e-12, abs=0)
    assert [r for _, r in pc.lines] == pytest.approx([1.0, 0.0625, 0.25], rel=1e-12, abs=0)  # (a / 2)^2
