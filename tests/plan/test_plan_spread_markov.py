"""The Allan fit's Gauss-Markov stage in the planner's linearised records (``plan.spread._record_width``).

The fit (``noise.identify``) tries every model plus a first-order Gauss-Markov term M at a grid of correlation
times and keeps the M models only when the best of them beats the best model without M by ``MARKOV_IC_GAIN``
(its IC counting ``q_c`` and ``T_c``).  On 600 simulated MEMS records at the planned B length the fit brought M
into 39 and lost B to it in 12 (docs/plan.md, "The Gauss-Markov candidate"); the records must do the same.

The records here are the MEMS class's expected whitened curve plus a Gauss-Markov hump at one of the fit's
correlation times, scaled so that the M model's IC gain over the best model without M (computed here from the
definition) is a chosen number: below the fit's gain the record's width must be that of the fit without the
Markov stage, above it the M models must enter (a changed width), and a curve whose hump stands in for B must
leave B unresolved.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from scipy.optimize import brentq, nnls

from fogdrift.noise.identify import MARKOV_IC_GAIN
from fogdrift.noise.terms import all_terms
from fogdrift.plan import parse_model
from fogdrift.plan.analytic import IC_PENALTY, whitened
from fogdrift.plan.model import PLANNED_TERMS
from fogdrift.plan.spread import _fit_m, _markov_columns, _record_width

N_SAMPLES = 90_578  # the MEMS B's planned length (docs/plan.md)


def _setup():
    model = parse_model("N=0.3 deg/sqrt(h), B=5 deg/h, K=20 deg/h^1.5", 0.1)
    dt = model.dt_s
    m = _fit_m(model, N_SAMPLES)
    tau = m * dt
    ctx, L, Xall, yw0 = whitened(model.terms, model.law_coefficients(), tau, m, N_SAMPLES, dt)
    cols = [all_terms().index(u) for u in PLANNED_TERMS if u in ctx.laws]
    subsets = [s for r in range(1, len(cols) + 1) for s in itertools.combinations(cols, r)]
    return Xall, yw0, subsets, m.size, _markov_columns(L, tau, dt)


def _gain(Xall, yw, subsets, col):
    """IC of the best model without M less that of the best model plus M at this one ``T_c`` (IC ``Q + 2 k``,
    ``k`` counting ``q_c`` and ``T_c``)."""
    ic0 = min(nnls(Xall[:, list(s)], yw)[1] ** 2 + IC_PENALTY * len(s) for s in subsets)
    icm = min(nnls(np.column_stack([Xall[:, list(s)], col]), yw)[1] ** 2 + IC_PENALTY * (len(s) + 2)
              for s in [()] + subsets)
    return ic0 - icm


def _scaled(Xall, yw0, subsets, col, gain):
    """``yw0 + c col`` with ``c`` such that the M model's IC gain is ``gain``."""
    c = brentq(lambda c: _gain(Xall, yw0 + c * col, subsets, col) - gain, 1e-6, 1e6, xtol=1e-9)
    return yw0 + c * col


def test_markov_enters_the_records_only_beyond_the_fits_ic_gain():
    Xall, yw0, subsets, n_taus, mcols = _setup()
    assert len(mcols) == 12
    iB = all_terms().index("B")
    col = mcols[6]
    w_expected = _record_width(Xall, yw0, subsets, iB, n_taus, mcols)
    # the expected curve: no M model can beat the true one (Q = 0), so the Markov stage changes nothing
    assert w_expected == _record_width(Xall, yw0, subsets, iB, n_taus)
    assert math.isfinite(w_expected)
    # a hump worth 1 in IC (below the fit's 2, T_c counted): the stage must leave the record alone
    y1 = _scaled(Xall, yw0, subsets, col, MARKOV_IC_GAIN - 1.0)
    assert _record_width(Xall, y1, subsets, iB, n_taus, mcols) == _record_width(Xall, y1, subsets, iB, n_taus)
    # worth 6: the M models enter, B shares the hump with M and its interval changes
    y6 = _scaled(Xall, yw0, subsets, col, MARKOV_IC_GAIN + 4.0)
    w6 = _record_width(Xall, y6, subsets, iB, n_taus, mcols)
    assert w6 != _record_width(Xall, y6, subsets, iB, n_taus)


def test_a_hump_standing_in_for_b_leaves_b_unresolved():
    Xall, yw0, subsets, n_taus, mcols = _setup()
    iB = all_terms().index("B")
    A_true = nnls(Xall[:, [all_terms().index(t) for t in ("N", "B", "K")]], yw0)[0]
    no_b = Xall[:, all_terms().index("N")] * A_true[0] + Xall[:, all_terms().index("K")] * A_true[2]
    y = _scaled(Xall, no_b, subsets, mcols[6], MARKOV_IC_GAIN + 8.0)
    assert math.isinf(_record_width(Xall, y, subsets, iB, n_taus, mcols))


def test_share_ratio_runs_the_markov_stage(monkeypatch):
    """``share_ratio``'s records use the stage: without the Markov columns the same 300 records (fixed seed) give
    another ratio at the MEMS B's planned length (about 3 % of them take M there)."""
    from fogdrift.plan import spread

    model = parse_model("N=0.3 deg/sqrt(h), B=5 deg/h, K=20 deg/h^1.5", 0.1)
    with_m = spread.share_ratio(model, N_SAMPLES, "B", 0.8, draws=300)
    monkeypatch.setattr(spread, "_markov_columns", lambda *a: [])
    without = spread.share_ratio(model, N_SAMPLES, "B", 0.8, draws=300)
    assert math.isfinite(with_m) and math.isfinite(without)
    assert with_m != without


def test_an_m_model_counts_q_c_and_t_c():
    """An accepted M model's IC counts two parameters more than its power-law terms, and its ``dof`` both."""
    from fogdrift.plan.spread import _M, _record_fit

    Xall, yw0, subsets, n_taus, mcols = _setup()
    iB = all_terms().index("B")
    y6 = _scaled(Xall, yw0, subsets, mcols[6], MARKOV_IC_GAIN + 4.0)
    r = _record_fit(Xall, y6, subsets, all_terms().index("N"), n_taus, mcols)  # N: resolved in every model
    assert _M in r["best"] and iB in r["best"]
    for model, (_, q, ic) in r["fits"].items():
        assert ic == q + IC_PENALTY * (len(model) + (1 if _M in model else 0))
    assert r["dof"] == n_taus - (len(r["best"]) - 1) - 2
