"""The scheme table: registry helpers, validation, and the provenance of the db4 entry.

The db4 steps are re-derived here from PyWavelets' filters by the Euclidean algorithm for
Laurent polynomials (Daubechies & Sweldens 1998), as the table's comments describe, so a
mistyped constant or a changed alignment fails with the derivation next to it.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import pywt

from fogdrift import lifting as L
from fogdrift.errors import ConfigError


def test_wavelist_is_the_registry():
    assert L.wavelist() == list(L.WAVELETS) == ["haar", "db2", "db4"]
    assert L.wavelist("db") == ["db2", "db4"]
    assert L.wavelist("haar") == ["haar"]
    assert L.wavelist("sym") == []
    for name in L.wavelist():
        assert L.get_wavelet(name).name == name
        assert L.get_wavelet(name.upper()) is L.WAVELETS[name]


def test_get_wavelet_errors():
    with pytest.raises(ConfigError) as err:
        L.get_wavelet("db99")
    assert "['haar', 'db2', 'db4']" in str(err.value)
    assert "wavelet=" in str(err.value)  # {opt:wavelet}
    assert "--wavelet" in err.value.render({"wavelet": "--wavelet"})
    with pytest.raises(ConfigError, match="LiftingScheme"):
        L.get_wavelet(4)
    scheme = L.WAVELETS["db2"]
    assert L.get_wavelet(scheme) is scheme


def test_scheme_validation_and_json():
    for name, scheme in L.WAVELETS.items():
        d = json.loads(json.dumps(scheme.to_dict()))
        assert d["name"] == name
        assert len(d["steps"]) == len(scheme.steps)
    with pytest.raises(ConfigError):
        L.LiftingStep("split", ((0, 1.0),))
    with pytest.raises(ConfigError):
        L.LiftingStep("predict", ())
    step = L.LiftingStep("predict", ((0, 1.0),))
    with pytest.raises(ConfigError, match="non-zero"):
        L.LiftingScheme("x", (step,), 0.0, 1.0)
    with pytest.raises(ConfigError, match="detail_sign"):
        L.LiftingScheme("x", (step,), 1.0, 1.0, detail_sign=2.0)
    with pytest.raises(ConfigError, match="filter_length"):
        L.LiftingScheme("x", (step,), 1.0, 1.0, filter_length=1)


# ---------------------------------------------------------------- Euclidean factorisation
# Laurent polynomials as {power: coefficient}; z**k means "the other channel at l + k", the
# convention of LiftingStep.taps.  Analysis polyphase rows: cA_l = sum_k He[k] E_{l+k} +
# Ho[k] O_{l+k} (same for the detail row G) with E_l = x_{2l-s}, O_l = x_{2l+1-s}.


def _clean(p):
    return {k: v for k, v in p.items() if abs(v) > 1e-12}


def _mul(p, q):
    r = {}
    for a, x in p.items():
        for b, y in q.items():
            r[a + b] = r.get(a + b, 0.0) + x * y
    return _clean(r)


def _sub(p, q):
    r = dict(p)
    for k, v in q.items():
        r[k] = r.get(k, 0.0) - v
    return _clean(r)


def _divide(a, b, n_left):
    """q, r with r = a - q b, cancelling n_left coefficients at a's low end and the rest at its high end."""
    a0, a1, b0, b1 = min(a), max(a), min(b), max(b)
    n_q = (a1 - a0) - (b1 - b0) + 1
    q_pows = list(range(a0 - b0, a1 - b1 + 1))
    pos = list(range(a0, a0 + n_left)) + list(range(a1 - (n_q - n_left) + 1, a1 + 1))
    m = np.array([[b.get(p - qp, 0.0) for qp in q_pows] for p in pos])
    q = _clean(dict(zip(q_pows, np.linalg.solve(m, [a.get(p, 0.0) for p in pos]))))
    return q, _sub(a, _mul(q, b))


def _polyphase_rows(name, shift):
    n, l = 64, 16  # pywt's periodized analysis rows from impulse responses at coefficient l
    lo, hi = {}, {}
    for j in range(n):
        ca, cd = pywt.dwt(np.eye(n)[j], name, mode="periodization")
        lo[j - 2 * l], hi[j - 2 * l] = ca[l], cd[l]

    def split(f):
        even, odd = {}, {}
        for i, c in f.items():
            if abs(c) > 1e-14:
                t = i + shift
                (even if t % 2 == 0 else odd)[t // 2] = c
        return even, odd

    return split(lo), split(hi)


def _factorisations(he, ho, ge, go, steps, out):
    """Every Euclidean reduction of the row (he, ho) to (K, 0), the detail row carried along."""
    if not ho:
        if len(he) == 1 and 0 in he and len(go) == 1:
            (k_a,), ((ds, beta),) = he.values(), go.items()
            last = {k - ds: v / beta for k, v in ge.items()}  # the highpass completion
            out.append((steps + ([("predict", last)] if last else []), k_a, abs(beta), np.sign(beta), ds))
        return
    if not he:
        return
    span_e, span_o = max(he) - min(he), max(ho) - min(ho)
    if span_o >= span_e:  # an update step E += u O leaves Ho - u He
        for n_left in range(span_o - span_e + 2):
            u, ho2 = _divide(ho, he, n_left)
            _factorisations(he, ho2, ge, _sub(go, _mul(u, ge)), steps + [("update", u)], out)
    if span_e >= span_o:  # a predict step O += p E leaves He - p Ho
        for n_left in range(span_e - span_o + 2):
            p, he2 = _divide(he, ho, n_left)
            _factorisations(he2, ho, _sub(ge, _mul(p, go)), go, steps + [("predict", p)], out)


def test_db4_table_entry_is_the_smallest_euclidean_factorisation():
    scheme = L.WAVELETS["db4"]
    (he, ho), (ge, go) = _polyphase_rows("db4", scheme.input_shift)
    found = []
    _factorisations(he, ho, ge, go, [], found)
    assert len(found) > 1  # the factorisation is not unique ...
    # ... the table takes the fewest steps, then the smallest largest coefficient
    steps, k_a, k_d, sign, ds = min(
        found, key=lambda f: (len(f[0]), max(abs(c) for _, p in f[0] for c in p.values()))
    )
    assert [kind for kind, _ in steps] == [s.kind for s in scheme.steps]
    for (kind, poly), st in zip(steps, scheme.steps):
        assert sorted(poly) == sorted(o for o, _ in st.taps)
        np.testing.assert_allclose([poly[o] for o, _ in st.taps], [c for _, c in st.taps], rtol=0, atol=1e-13)
    assert k_a == pytest.approx(scheme.scale_approx, abs=1e-13)
    assert k_d == pytest.approx(scheme.scale_detail, abs=1e-13)
    assert (sign, ds) == (scheme.detail_sign, scheme.detail_shift)
