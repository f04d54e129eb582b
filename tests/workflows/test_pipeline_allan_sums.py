"""pipeline.analyse_allan takes the Allan operator sums once per series and rebuilds every result from them.

The reference is the sequence of calls analyse_allan made before (one ``allan_variance`` per grid and EDF alpha,
written out here): every field of the display curve and of the fit curve must be the same, bit for bit, for every
grid, estimator and statistic, with and without periodic content, and on the out-of-core path for long series.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from fogdrift import pipeline
from fogdrift.allan import sums as pipeline_sums
from fogdrift.allan import allan_variance
from fogdrift.allan.ci import periodic_alpha
from fogdrift.noise.periodic import null_taus, periodic_content
from fogdrift.noise.spectral import analyse_spectrum
from fogdrift.pipeline import AnalysisConfig, analyse_allan

DT = 0.01


def _reference_curves(rate, dt, cfg, spectrum):
    """(display curve, fit curve) as analyse_allan computed them with one allan_variance call per grid/alpha."""
    content = periodic_content(spectrum)
    kw = dict(estimator=cfg.estimator, statistic=cfg.statistic)
    res = allan_variance(rate, dt, taus=cfg.taus, **kw)
    if content is not None:
        alphas, _ = periodic_alpha(res.noise_alpha, True)
        if np.any(alphas != res.noise_alpha):
            res = allan_variance(rate, dt, taus=res.tau_s, noise_alpha=alphas, **kw)
    fit = res if cfg.taus == "octave" else allan_variance(rate, dt, taus="octave", **kw)
    if content is not None:
        extra = null_taus(content.periods_s, dt, float(fit.tau_s[0]), float(fit.tau_s[-1]))
        taus = np.union1d(fit.tau_s, extra)
        if taus.size != fit.tau_s.size or np.any(fit.noise_alpha > 0):
            near = np.abs(np.log(taus)[:, None] - np.log(fit.tau_s)[None, :]).argmin(axis=1)
            alphas, _ = periodic_alpha(np.asarray(fit.noise_alpha)[near], True)
            fit = allan_variance(rate, dt, taus=taus, noise_alpha=alphas, **kw)
    return res, fit


def _same(a, b, rtol=0.0):
    """Field by field; floats bit for bit (rtol 0) or to ``rtol``, integers and text exactly."""
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert x.dtype == np.asarray(y).dtype and x.shape == np.shape(y), f.name
            if rtol == 0.0 or x.dtype.kind in "iu":
                assert np.array_equal(x, y), f.name
            else:
                np.testing.assert_allclose(x, y, rtol=rtol, atol=0, err_msg=f.name)
        else:
            assert x == y, f.name


def _series(n, periodic: bool, seed=3):
    rng = np.random.default_rng(seed)
    y = rng.normal(0.0, 30.0, n) + np.cumsum(rng.normal(0.0, 0.05, n)) + 10.0
    if periodic:
        y += 40.0 * np.sin(2 * np.pi * np.arange(n) * DT / 0.37)
    return y


@pytest.fixture
def fit_spy(monkeypatch):
    """Capture the curve handed to the noise fit (patched where the pipeline looks it up, and on the package)."""
    import fogdrift.noise as noise_pkg
    import fogdrift.pipeline as pipeline_mod

    seen = []

    real = noise_pkg.fit_noise

    def spy(curve, **kw):
        seen.append(curve)
        return real(curve, **kw)

    monkeypatch.setattr(noise_pkg, "fit_noise", spy)
    monkeypatch.setattr(pipeline_mod, "fit_noise", spy)
    return seen


@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize("taus,estimator,statistic", [
    ("octave", "overlapping", "adev"),
    (30, "overlapping", "adev"),
    ("decade", "non-overlapping", "adev"),
    ("octave", "fast", "adev"),
    (20, "overlapping", "hdev"),
    ("octave", "overlapping", "mdev"),
])
def test_curves_equal_the_one_call_per_grid_reference(fit_spy, periodic, taus, estimator, statistic):
    rate = _series(40_000, periodic)
    cfg = AnalysisConfig(taus=taus, estimator=estimator, statistic=statistic)
    spectrum = analyse_spectrum(rate, DT)
    if periodic:
        assert periodic_content(spectrum) is not None  # the periodic branch is exercised
    ref_res, ref_fit = _reference_curves(rate, DT, cfg, spectrum)
    got = analyse_allan("x", rate, DT, cfg, spectrum=spectrum)
    _same(got.allan, ref_res)
    _same(fit_spy[-1], ref_fit)


def test_one_kernel_pass_per_series(monkeypatch):
    """The phase (angle) array is built once per analysed series, whatever the grids and alphas."""
    from fogdrift.allan import _kernels

    calls = []
    real = _kernels.phase_dph_samples
    monkeypatch.setattr(_kernels, "phase_dph_samples", lambda y: calls.append(y.size) or real(y))
    rate = _series(40_000, True)
    analyse_allan("x", rate, DT, AnalysisConfig(taus=30))
    assert calls == [40_000]


@pytest.mark.parametrize("estimator", ["overlapping", "non-overlapping"])
def test_long_series_take_the_out_of_core_sums_with_the_same_result(monkeypatch, fit_spy, estimator):
    """Above CHUNKED_MIN_SAMPLES the sums come from the out-of-core engine (no angle array).

    Its sums add the same terms in another order (measured 7e-15 relative on this series): every float field to
    1e-12 as tests/allan/test_allan_result_shared.py holds the engine to, the grids and alphas exactly."""
    from fogdrift.allan import _kernels

    rate = _series(300_000, True, seed=5)
    cfg = AnalysisConfig(taus=25, estimator=estimator)
    spectrum = analyse_spectrum(rate, DT)
    ref_res, ref_fit = _reference_curves(rate, DT, cfg, spectrum)
    monkeypatch.setattr(pipeline_sums, "CHUNKED_MIN_SAMPLES", 100_000)
    monkeypatch.setattr(pipeline_sums, "OUT_OF_CORE_CHUNK", 65536)   # several chunks: the windowed path

    def no_phase(y):
        raise AssertionError("the in-memory angle array was built")

    monkeypatch.setattr(_kernels, "phase_dph_samples", no_phase)
    got = analyse_allan("x", rate, DT, cfg, spectrum=spectrum)
    _same(got.allan, ref_res, rtol=1e-12)
    _same(fit_spy[-1], ref_fit, rtol=1e-12)


def test_errors_are_those_of_allan_variance():
    from fogdrift.errors import ConfigError, InsufficientDataError

    with pytest.raises(InsufficientDataError, match="at least 2 rate samples"):
        analyse_allan("x", np.ones(1), DT, AnalysisConfig(), spectrum=None)
    with pytest.raises(ConfigError, match="statistic='mdev'"):
        analyse_allan("x", _series(1000, False), DT, AnalysisConfig(statistic="mdev", estimator="fast"),
                      spectrum=None)


def test_plausibility_sums_are_handed_on_and_reused(monkeypatch):
    """check_record(sums=) keeps the noise floor's octave ADEV sums; run_allan reuses them: one angle array per
    axis for the check and the analysis together, and the same results as without them."""
    from fogdrift.allan import _kernels
    from fogdrift.io import from_array
    from fogdrift.plausibility import check_record
    from fogdrift.pipeline import run_allan

    rate = np.column_stack([_series(30_000, True), _series(30_000, False, seed=9)])
    record = from_array(rate, dt_s=DT, unit="deg/h")
    want = run_allan(record, AnalysisConfig())
    calls = []
    real = _kernels.operator_sums
    monkeypatch.setattr(_kernels, "operator_sums", lambda p, m, *a: calls.append(m.tolist()) or real(p, m, *a))
    sums = {}
    check_record(record, sums=sums)
    assert sorted(sums) == sorted(record.axis_names)
    octave = [2**k for k in range(13)]           # m <= 30 000 / 4
    assert calls == [octave, octave]
    got = run_allan(record, AnalysisConfig(), sums=sums)
    # the analysis adds only the null taus of the periodic axis (period 0.37 s: 37 samples and multiples), no
    # octave m again; the aperiodic axis needs no pass at all
    assert len(calls) == 3 and not set(calls[2]) & set(octave) and 37 in calls[2]
    for a, b in zip(got, want):
        _same(a.allan, b.allan)
        assert a.noise.to_dict() == b.noise.to_dict()


def test_sums_of_another_array_are_not_reused():
    from fogdrift.allan.sums import AllanSums

    x = _series(5000, False)
    s = AllanSums(x, DT)
    assert s.holds(x, DT, "adev", "overlapping")
    assert s.holds(x[:], DT, "adev", "overlapping")          # the same memory through another view
    assert not s.holds(x.copy(), DT, "adev", "overlapping")
    assert not s.holds(x[:-1], DT, "adev", "overlapping")
    assert not s.holds(x, 2 * DT, "adev", "overlapping")
    assert not s.holds(x, DT, "hdev", "overlapping")


def test_run_analysis_reuses_the_sums_for_the_native_rate_row(monkeypatch):
    """run_analysis(sums=) hands each axis' sums to its native-rate analysis only (the other rows are other
    series); the result is the same as without them."""
    from fogdrift.io import from_array
    from fogdrift.plausibility import check_record
    from fogdrift.pipeline import run_analysis

    record = from_array(_series(3000, False, seed=4), dt_s=1.0, unit="deg/h")
    cfg = AnalysisConfig(models=("ar",), level=2, causal_window_s=64.0)
    want = run_analysis(record, cfg)
    sums = {}
    check_record(record, sums=sums)
    seen = []
    real = pipeline.analyse_allan

    def spy(*a, **k):
        seen.append(k.get("sums"))
        return real(*a, **k)

    monkeypatch.setattr(pipeline, "analyse_allan", spy)
    got = run_analysis(record, cfg, sums=sums)
    assert seen[0] is sums[record.axis_names[0]] and all(s is None for s in seen[1:])
    x = np.asarray(record.axis(record.axis_names[0]), dtype=np.float64)
    assert sums[record.axis_names[0]].holds(x, 1.0, "adev", "overlapping")   # reused, not recomputed
    _same(got.axes[0].original.allan, want.axes[0].original.allan)
    assert got.axes[0].original.noise.to_dict() == want.axes[0].original.noise.to_dict()


@pytest.mark.parametrize("statistic, estimator", [("adev", "overlapping"), ("adev", "fast"), ("hdev", "overlapping")])
def test_sums_taken_in_progress_groups_equal_one_pass(statistic, estimator):
    """With a progress callback the kernel runs in groups of cluster sizes (``_progress_group``): every sum is that
    of the one-pass computation, bit for bit, and progress counts up to the number of taus."""
    rate = _series(6_000, False)
    one = pipeline_sums.AllanSums(rate, DT, statistic, estimator)
    m = one.grid("all")
    one.compute([m])
    seen = []
    grouped = pipeline_sums.AllanSums(rate, DT, statistic, estimator)
    grouped.compute([m], progress=lambda done, total: seen.append((done, total)))
    assert np.array_equal(grouped.m, one.m) and np.array_equal(grouped.sums, one.sums)
    group = pipeline_sums._progress_group(m.size, rate.size + 1)
    assert len(seen) == -(-m.size // group) > 1
    assert [d for d, _ in seen] == sorted(d for d, _ in seen) and seen[-1] == (m.size, m.size)


def test_progress_group_sizes():
    """About 1 % of the grid, at least 8, and a group that 8 taus would run on one thread stays below the
    parallel threshold."""
    from fogdrift.allan._kernels import PARALLEL_MIN

    assert pipeline_sums._progress_group(100, 1_000) == 8
    assert pipeline_sums._progress_group(25_000, 100_001) == (PARALLEL_MIN - 1) // 100_001
    assert pipeline_sums._progress_group(25_000, 1_000) == 250
    assert pipeline_sums._progress_group(10_000, 10_000_000) == 100  # 8 taus run in parallel already
