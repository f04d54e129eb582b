"""In-memory and out-of-core Allan results are built by one function and agree field by field.

Both :func:`fogdrift.allan.allan_variance` and :func:`fogdrift.allan.chunked.allan_variance_chunked` end in
:func:`fogdrift.allan.core.result_from_sums`.  The out-of-core path used to carry its own copy of that tail,
without the later EDF rule for phase-noise slopes at long tau (fewer than ``AUTO_MIN_INTERVALS`` intervals):
on differenced white noise (2^16 samples, octave taus, default ``noise_alpha``) its EDF at the two longest
taus was 28 088 and 21 846 against 5.5 and 2.0 in memory, with the variances identical.

Oracle: the in-memory engine on the whole array (itself checked against allantools in ``test_allan.py``).
Every field of :class:`~fogdrift.allan.AllanResult` is compared (a field added later is compared too):
integer arrays and scalars exactly, variances/deviations/taus to 1e-12 relative, EDF and the chi-squared
bounds that follow from it to 1e-9 relative.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from fogdrift.allan import AllanResult, allan_variance
from fogdrift.allan.core import AUTO_MIN_INTERVALS, result_from_sums
from fogdrift.allan.chunked import BLOCK, allan_variance_chunked
from fogdrift.io.chunked import open_source
from fogdrift.simulate import simulate

RATE_HZ = 100.0
#: Longer than four chunks of BLOCK start indices, and octave m up to 65536 > BLOCK / 2 (the large-m path).
N = 4 * BLOCK + 1234
#: EDF and the chi-squared bounds it sets: a relative tolerance for a different order of operations.
EDF_FIELDS = {"edf", "dev_lo68", "dev_hi68", "dev_lo95", "dev_hi95"}


def _noise(kind, n, seed):
    rng = np.random.default_rng(seed)
    if kind == "white":
        return 3.0 + rng.standard_normal(n)
    if kind == "quantization":                       # differenced white noise: white PM, ADEV ~ 1/tau
        return np.diff(rng.standard_normal(n + 1))
    if kind == "random walk":
        return np.cumsum(rng.standard_normal(n)) * 1e-2
    if kind == "flicker":
        return simulate(n, 1.0 / RATE_HZ, bias_instability_dph=0.5, seed=seed)
    raise AssertionError(kind)


def _chunked(tmp_path, y, **kw):
    np.save(tmp_path / "y.npy", y)
    return allan_variance_chunked(open_source(tmp_path / "y.npy", rate_hz=RATE_HZ, unit="deg/h"),
                                  chunk_samples=BLOCK, **kw)


def _assert_same_result(got: AllanResult, want: AllanResult):
    names = [f.name for f in dataclasses.fields(AllanResult)]
    assert len(names) == 16, "AllanResult gained a field: check that this comparison still covers it"
    for name in names:
        a, b = getattr(got, name), getattr(want, name)
        if isinstance(b, np.ndarray):
            assert a.dtype.kind == b.dtype.kind and a.shape == b.shape, name
            if b.dtype.kind in "iu":
                assert_array_equal(a, b, err_msg=name)
            else:
                assert_allclose(a, b, rtol=1e-9 if name in EDF_FIELDS else 1e-12, atol=0, err_msg=name)
        else:
            assert type(a) is type(b) and a == b, (name, a, b)


@pytest.mark.parametrize("estimator", ["overlapping", "non-overlapping"])
@pytest.mark.parametrize("kind", ["white", "quantization", "random walk", "flicker"])
def test_out_of_core_equals_in_memory_field_by_field(tmp_path, kind, estimator):
    y = _noise(kind, N, seed=11)
    want = allan_variance(y, 1.0 / RATE_HZ, estimator=estimator)
    assert want.m.max() > BLOCK // 2               # the chunked path reads separate windows for large m
    _assert_same_result(_chunked(tmp_path, y, estimator=estimator), want)


@pytest.mark.parametrize("noise_alpha", ["conservative", 0, -2])
def test_other_noise_types_field_by_field(tmp_path, noise_alpha):
    y = _noise("quantization", N, seed=12)
    _assert_same_result(_chunked(tmp_path, y, noise_alpha=noise_alpha),
                        allan_variance(y, 1.0 / RATE_HZ, noise_alpha=noise_alpha))


def test_quantization_long_tau_edf_is_not_the_white_pm_value(tmp_path):
    # the reported case: where fewer than AUTO_MIN_INTERVALS intervals fit, a tau^-1 slope does not earn the
    # white-PM EDF (~N/2); both paths take the smallest IEEE-952 EDF, here below the number of intervals N/m
    n = 1 << 16
    y = _noise("quantization", n, seed=0)
    want = allan_variance(y, 1.0 / RATE_HZ)
    got = _chunked(tmp_path, y)
    _assert_same_result(got, want)
    few = n < AUTO_MIN_INTERVALS * got.m
    assert few[-2:].all()
    assert np.all(got.edf[few] < n / got.m[few]), got.edf[few]


def test_result_from_sums_hand_values():
    # y = [1, 3, 2, 5, 4, 4, 6, 3], m = 1: the second differences of the mean-removed angle are the first
    # differences of y: 2, -1, 3, -1, 0, 2, -3; sum of squares 28, 7 terms -> AVAR = 28 / (2 * 7) = 2.0
    r = result_from_sums(np.array([28.0]), 8, np.array([1]), np.array([1]), 0.5, statistic="adev",
                         estimator="overlapping", noise_alpha=0)
    assert r.n_terms.tolist() == [7] and r.tau_s.tolist() == [0.5] and r.n_samples == 8 and r.dt_s == 0.5
    assert_allclose(r.var, [2.0], rtol=1e-15)
    assert 1.0 <= r.edf[0] <= 7 and r.dev_lo95[0] < np.sqrt(2.0) < r.dev_hi95[0]
    _assert_same_result(r, allan_variance([1, 3, 2, 5, 4, 4, 6, 3], 0.5, taus=[0.5], noise_alpha=0))


def test_to_dict_and_allan_csv_rows_write_each_value_as_its_python_number():
    """``AllanResult.to_dict`` and the rows of ``allan.csv`` convert whole columns at once: every value is the
    Python float (int) of its element, as one ``float(v)`` (``int(v)``) per element gives it, float32 and NaN
    included, the columns in the header's order."""
    from types import SimpleNamespace

    from fogdrift.report.files import allan_csv_rows

    res = allan_variance(simulate(5000, 0.01, arw_dprh=0.1, seed=4), 0.01, taus="all")
    hi95 = res.dev_hi95.copy()
    hi95[3] = np.nan
    res = dataclasses.replace(res, edf=res.edf.astype(np.float32), dev_hi95=hi95)
    d = res.to_dict()
    for name, key in zip(("tau_s", "m", "n_terms", "edf", "dev_hi95"),
                         ("tau_s", "m", "n_terms", "edf", "adev_hi95_dph")):
        arr = getattr(res, name)
        want = [int(v) for v in arr] if arr.dtype.kind in "iu" else [float(v) for v in arr]
        assert [type(v) for v in d[key]] == [type(v) for v in want], name
        assert np.array_equal(np.array(d[key]), np.array(want), equal_nan=True), name
    rows = allan_csv_rows([SimpleNamespace(name="gx", allan=res)])
    want = [["gx", repr(float(res.tau_s[i])), int(res.m[i]), repr(float(res.dev[i])),
             repr(float(res.var[i])), int(res.n_terms[i]), repr(float(res.edf[i])),
             repr(float(res.dev_lo68[i])), repr(float(res.dev_hi68[i])), repr(float(res.dev_lo95[i])),
             repr(float(res.dev_hi95[i]))] for i in range(res.tau_s.size)]
    assert [[str(c) for c in row] for row in rows] == [[str(c) for c in row] for row in want]


@pytest.mark.parametrize("quantity", ["angular_rate", "specific_force"])
def test_allan_json_with_encoded_float_columns_is_the_documents_strict_json(tmp_path, monkeypatch, quantity):
    """``write_allan_outputs`` hands allan.json's float columns to the JSON writer as the texts it made for
    allan.csv: the file is byte for byte ``strict_json`` of the document (an infinity written as null, a column
    with a NaN left to the writer), for either quantity's keys."""
    from types import SimpleNamespace

    import fogdrift.report.files as files
    from fogdrift._util import strict_json

    res = allan_variance(simulate(4000, 0.01, arw_dprh=0.1, seed=5), 0.01, taus="all")
    hi95, edf = res.dev_hi95.copy(), res.edf.copy()
    hi95[-1], edf[2] = np.inf, np.nan
    res = dataclasses.replace(res, dev_hi95=hi95, edf=edf)

    class Axis(SimpleNamespace):
        def to_dict(self):
            return {"name": self.name, "allan": self.allan.to_dict(quantity)}

    axes = [Axis(name="gx", allan=res, noise=SimpleNamespace(quantity=quantity)),
            Axis(name="gy", allan=dataclasses.replace(res, dev=res.dev * 2), noise=SimpleNamespace(
                quantity=quantity))]
    record = SimpleNamespace(source="mem", metadata=lambda: {"n": 1}, quantities=(quantity, quantity),
                             axis_names=["gx", "gy"])
    monkeypatch.setattr(files, "plot_allan", lambda *a: None)
    monkeypatch.setattr(files, "plot_dynamic_adev", lambda *a: None)
    written = []
    real_write = files.write_json
    monkeypatch.setattr(files, "write_json", lambda doc, path: written.append(doc) or real_write(doc, path))
    files.write_allan_outputs(axes, record, tmp_path)
    assert (tmp_path / "allan.json").read_text() == strict_json(files.allan_document(axes, record))
    # every float column went as text but the one with a NaN (edf): 7 of 8 per axis
    assert [sum(type(v) is files.RawJson for v in a["allan"].values()) for a in written[0]["axes"]] == [7, 7]
