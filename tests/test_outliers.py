"""The outlier detector (fogdrift.outliers): compiled block medians, exact median of |deviation| in bounded
memory, and the two treatments.

Independent reference: the plain NumPy algorithm the module's docstring states (NaN-padded blocks,
``np.nanmedian`` per block, ``np.median`` of the absolute deviations, ``np.std`` fallback), written out
here.  Hand values: a record with two spikes.
"""

from __future__ import annotations

import numpy as np
import pytest

from fogdrift import outliers as O
from fogdrift.errors import ConfigError, DataFormatError

MAD = 1.482602218505602


def _reference(x, thr=6.0, block=100):
    x = np.asarray(x, dtype=np.float64)
    block = min(block, x.size)
    n = x.size
    nb = -(-n // block)
    xp = np.concatenate([x, np.full(nb * block - n, np.nan)])
    med = np.nanmedian(xp.reshape(nb, block), axis=1)
    dev = x - np.repeat(med, block)[:n]
    sigma = MAD * float(np.median(np.abs(dev)))
    if sigma == 0.0:
        sigma = float(np.std(dev))
    mask = np.abs(dev) > thr * sigma if sigma > 0 else np.zeros(n, bool)
    return mask, sigma, float(np.max(np.abs(dev))), med


@pytest.mark.parametrize("n", [7, 100, 101, 1000, 12_345])
@pytest.mark.parametrize("block", [5, 6, 100])
def test_block_medians_equal_numpy_nanmedian(n, block):
    x = np.random.default_rng(n + block).standard_normal(n)
    assert np.array_equal(O.block_medians(x, min(block, n)), _reference(x, block=block)[3])


@pytest.mark.parametrize("quantised", [False, True])
@pytest.mark.parametrize("n", [11, 1000, 4097, 100_001])
def test_radix_selection_gives_the_exact_order_statistics(n, quantised):
    x = np.random.default_rng(n).standard_normal(n)
    if quantised:  # many equal deviations, exact zeros among them
        x = np.round(2 * x) / 2
    med = O.block_medians(x, 100)
    dev = np.sort(np.abs(x - np.repeat(med, 100)[:n]))
    ranks = [0, (n - 1) // 2, n // 2, n - 1]
    assert O._select_abs_dev(x, med, 100, ranks) == [float(dev[r]) for r in ranks]


@pytest.mark.parametrize("select_above", [O.SELECT_ABOVE, 0])  # np.median path and radix path
@pytest.mark.parametrize("kind", ["gauss", "quantised", "float32", "odd"])
def test_find_outliers_equals_the_numpy_reference(kind, select_above, monkeypatch):
    monkeypatch.setattr(O, "SELECT_ABOVE", select_above)
    rng = np.random.default_rng(5)
    n = 20_001 if kind == "odd" else 20_000
    x = rng.standard_normal(n) + 0.01 * np.arange(n) / n
    x[rng.integers(0, n, 40)] += 30.0
    if kind == "quantised":
        x = np.round(x)
    if kind == "float32":
        x = x.astype(np.float32)
    mask, rep = O.find_outliers(x)
    ref_mask, sigma, top, _ = _reference(x)
    assert np.array_equal(mask, ref_mask)
    assert rep.robust_sigma_dph == sigma and rep.max_abs_deviation_dph == top
    assert rep.count == int(ref_mask.sum()) > 0
    assert rep.first_index == tuple(int(i) for i in np.flatnonzero(ref_mask)[:10])


def test_constant_record_falls_back_to_the_standard_deviation():
    x = np.zeros(1000)
    x[::10] = 1.0  # median |deviation| is 0; the std of the deviations is not
    _, rep = O.find_outliers(x)
    _, sigma, _, _ = _reference(x)
    assert rep.robust_sigma_dph == pytest.approx(sigma, rel=1e-12) and sigma > 0
    _, flat = O.find_outliers(np.full(50, 3.0))
    assert flat.count == 0 and flat.robust_sigma_dph == 0.0


def test_two_spikes_hand_values_and_treatments():
    x = np.random.default_rng(0).standard_normal(10_000)
    x[[10, 5000]] = 50.0
    mask, rep = O.find_outliers(x)
    assert np.flatnonzero(mask).tolist() == [10, 5000] and rep.per_tenth[0] == 1 and rep.per_tenth[5] == 1
    med = O.block_medians(x, 100)
    y, rep_r = O.treat_outliers(x, "replace")
    assert y[10] == med[0] and y[5000] == med[50] and rep_r.action == "replace"
    z, rep_c = O.treat_outliers(x, "clip")
    lim = 6.0 * rep.robust_sigma_dph
    assert z[5000] == pytest.approx(med[50] + lim, rel=1e-12)       # clipped to +6 sigma, not -6 sigma
    assert np.array_equal(np.delete(z, [10, 5000]), np.delete(x, [10, 5000]))
    w, rep_w = O.treat_outliers(x, "warn")
    assert w is x and rep_w.action == "none"                          # reported only: the input, no copy


def test_float32_input_is_not_copied_to_float64_when_only_warned():
    x = np.random.default_rng(1).standard_normal(5000).astype(np.float32)
    y, _ = O.treat_outliers(x, "warn")
    assert y is x


def test_bad_input_is_one_clear_error():
    with pytest.raises(DataFormatError, match=r"y\[3\] is nan"):
        O.find_outliers(np.array([1.0, 2.0, 3.0, np.nan, 5.0]))
    with pytest.raises(ConfigError, match="threshold"):
        O.find_outliers(np.ones(10), threshold=-1)
    with pytest.raises(ConfigError, match="block"):
        O.find_outliers(np.ones(10), block=2)
