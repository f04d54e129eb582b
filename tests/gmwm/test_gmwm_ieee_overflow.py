"""A huge but finite standard error gives an unbounded 95 % interval, never an OverflowError traceback.

Found by mutation round 3 (issue 24): a fallback GM with se_log ~ 5e3 made ``math.exp(1.96 se)`` overflow in
``gmwm.ieee`` (``_value``, the GM-hump / min-ADEV B and its one-sided bound).
"""

import math
import warnings

import numpy as np

from fogdrift.gmwm import ieee
from fogdrift.gmwm.selection import select_model
from fogdrift.gmwm.simulate import simulate_latent
from fogdrift.gmwm.wvar import haar_wvar


def test_exp_is_inf_beyond_the_float_range_and_exact_inside():
    assert ieee._exp(1000.0) == math.inf
    assert ieee._exp(-1000.0) == 0.0
    assert ieee._exp(1.0) == math.e


def test_fallback_gm_with_a_huge_standard_error_reads_an_unbounded_interval():
    x = np.convolve(simulate_latent("WN+RW", [1.0, 1e-5], 2**12, seed=3), [0.5, 0.5], "valid")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = select_model(haar_wvar(x, 0.01), ["WN+GM", "WN+2GM"])
    gm = res.ieee.gm[0]
    tc = gm["tc_s"]
    assert tc.se_log > 362.0  # exp(1.96 se) would overflow a float
    assert math.isfinite(tc.value) and tc.lo95 == 0.0 and tc.hi95 == math.inf
    n = res.ieee.terms["N_dprh"]  # a well-determined term keeps its finite interval
    assert n.lo95 < n.value < n.hi95 < math.inf
