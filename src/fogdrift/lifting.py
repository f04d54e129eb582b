"""Second-generation (lifting) wavelet transform and drift/noise separation.

A wavelet is a :class:`LiftingScheme`: a table of predict/update steps plus two
normalisation factors and the index alignment that makes the periodized transform
coefficient-identical to PyWavelets.  One generic step applier runs any table under both
boundary modes, so adding a wavelet is data, not code (method notes §1.1–1.6).

Boundary modes
--------------
``"periodization"``
    Channel indices wrap around.  Every level works on an even length: an odd length is
    made even by repeating its last sample, exactly like :func:`pywt.dwt`; the inverse
    trims back to the stored length.  Coefficients equal
    ``pywt.wavedec(x, name, mode="periodization", level=J)`` band by band (notes §1.4).
``"symmetric"``
    A step that needs a neighbour outside the other channel reflects the index
    (whole-sample symmetric, ``i -> -i``, ``i -> 2(m-1) - i``).  Nothing is padded, there are
    exactly N coefficients and there is no wrap-around from the end of the record to its
    start (notes §1.6).  Not equal to PyWavelets' ``mode="symmetric"`` (an expansive
    convolution).  The periodization alignment (input shift, detail shift) is not applied.

Drift and noise (notes §1.7): ``drift = W^-1(cA_J, 0, ..., 0)`` and
``noise = W^-1(0, cD_J, ..., cD_1)``.  Because ``W^-1`` (with its padding and trimming) is
linear, :func:`separate` computes the noise as ``x - drift``; the test suite checks that
this equals the separate reconstruction and PyWavelets' ``waverec`` on zeroed bands.

Units: the transform is unit-agnostic (coefficients carry the unit of ``x``); the
diagnostics of :func:`level_scan` assume a rate in deg/h sampled every ``dt_s`` seconds.

The kernels run in numba (compiled on first use, cached on disk); a NumPy implementation of
the same step applier is kept as the reference and is selected with
``fogdrift.lifting._set_backend("numpy")`` (used by the tests and the benchmark).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import asdict, dataclass

import numpy as np

from .errors import ConfigError, DataFormatError, InsufficientDataError

__all__ = [
    "LiftingStep",
    "LiftingScheme",
    "WAVELETS",
    "MODES",
    "get_wavelet",
    "max_level",
    "lift",
    "unlift",
    "wavedec",
    "waverec",
    "separate",
    "causal_drift",
    "LevelDiagnostic",
    "level_scan",
    "choose_level",
]

MODES = ("periodization", "symmetric")

# --------------------------------------------------------------------------------------
# Wavelet tables
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LiftingStep:
    """One lifting step: ``channel[l] += sum(c * other[l + offset] for offset, c in taps)``.

    Parameters
    ----------
    kind : {"predict", "update"}
        ``"predict"`` modifies the odd (detail) channel from the even one;
        ``"update"`` modifies the even (approximation) channel from the odd one.
    taps : tuple of (int, float)
        ``(offset, coefficient)`` pairs; the offset indexes the *other* channel.
    """

    kind: str
    taps: tuple[tuple[int, float], ...]

    def __post_init__(self):
        if self.kind not in ("predict", "update"):
            raise ConfigError(f"LiftingStep.kind must be 'predict' or 'update', got {self.kind!r}")
        if len(self.taps) == 0:
            raise ConfigError("LiftingStep.taps must hold at least one (offset, coefficient) pair")
        taps = tuple((int(o), float(c)) for o, c in self.taps)
        object.__setattr__(self, "taps", taps)

    def to_dict(self) -> dict:
        return {"kind": self.kind, "taps": [[o, c] for o, c in self.taps]}


@dataclass(frozen=True)
class LiftingScheme:
    """A wavelet as a table of lifting steps (Daubechies & Sweldens 1998).

    Forward transform of one level (periodization shown; symmetric skips the shifts):

    1. ``x' = np.roll(x, input_shift)`` (after padding an odd length with its last sample),
       ``E = x'[0::2]``, ``O = x'[1::2]``;
    2. apply ``steps`` in order (predict: ``O += taps * E``, update: ``E += taps * O``);
    3. ``cA = scale_approx * E``;
       ``cD = detail_sign * scale_detail * np.roll(O, -detail_shift)``.

    The inverse undoes these in reverse order with the step signs flipped.

    Parameters
    ----------
    name : str
        Registry name.
    steps : tuple of LiftingStep
        The lifting steps, applied in order by the forward transform.
    scale_approx, scale_detail : float
        Normalisation factors of the approximation and detail channels (non-zero).
    input_shift : int
        Periodization only: delay of the input before the split (db2: 1, notes §1.4).
    detail_shift : int
        Periodization only: ``cD_l = detail_sign * scale_detail * d_{l + detail_shift}``.
    detail_sign : float
        ``+1`` or ``-1``; PyWavelets' detail sign convention (haar, db2: ``-1``).
    filter_length : int
        Length of the equivalent FIR filter (``pywt.Wavelet(name).dec_len``); sets the
        maximum level, see :func:`max_level`.
    pywt_name : str or None
        Name of the PyWavelets wavelet the periodized transform reproduces.
    """

    name: str
    steps: tuple[LiftingStep, ...]
    scale_approx: float
    scale_detail: float
    input_shift: int = 0
    detail_shift: int = 0
    detail_sign: float = 1.0
    filter_length: int = 2
    pywt_name: str | None = None

    def __post_init__(self):
        if len(self.steps) == 0:
            raise ConfigError(f"LiftingScheme {self.name!r} needs at least one step")
        if not (self.scale_approx != 0 and self.scale_detail != 0):
            raise ConfigError(f"LiftingScheme {self.name!r}: scale factors must be non-zero")
        if self.detail_sign not in (1.0, -1.0):
            raise ConfigError(f"LiftingScheme {self.name!r}: detail_sign must be +1 or -1")
        if int(self.filter_length) < 2:
            raise ConfigError(f"LiftingScheme {self.name!r}: filter_length must be >= 2")
        object.__setattr__(self, "steps", tuple(self.steps))

    def to_dict(self) -> dict:
        d = asdict(self)
        d["steps"] = [s.to_dict() for s in self.steps]
        return d


_S3 = math.sqrt(3.0)
_S2 = math.sqrt(2.0)

WAVELETS: dict[str, LiftingScheme] = {
    # Notes §1.5: predict d = O - E, update s = E + d/2, normalise sqrt2, 1/sqrt2; pywt cD = -d.
    "haar": LiftingScheme(
        name="haar",
        steps=(
            LiftingStep("predict", ((0, -1.0),)),
            LiftingStep("update", ((0, 0.5),)),
        ),
        scale_approx=_S2,
        scale_detail=1.0 / _S2,
        input_shift=0,
        detail_shift=0,
        detail_sign=-1.0,
        filter_length=2,
        pywt_name="haar",
    ),
    # Notes §1.3 (DS98 update-first) with Convention A of §1.4.
    "db2": LiftingScheme(
        name="db2",
        steps=(
            LiftingStep("update", ((0, _S3),)),
            LiftingStep("predict", ((0, -_S3 / 4.0), (-1, -(_S3 - 2.0) / 4.0))),
            LiftingStep("update", ((1, -1.0),)),
        ),
        scale_approx=(_S3 - 1.0) / _S2,
        scale_detail=(_S3 + 1.0) / _S2,
        input_shift=1,
        detail_shift=1,
        detail_sign=-1.0,
        filter_length=4,
        pywt_name="db2",
    ),
}


def get_wavelet(name_or_scheme) -> LiftingScheme:
    """Return the :class:`LiftingScheme` for a registry name, or the scheme itself.

    Raises
    ------
    ConfigError
        Unknown name (the message lists the valid names) or a wrong type.

    Examples
    --------
    >>> get_wavelet("db2").filter_length
    4
    """
    if isinstance(name_or_scheme, LiftingScheme):
        return name_or_scheme
    if isinstance(name_or_scheme, str):
        try:
            return WAVELETS[name_or_scheme.lower()]
        except KeyError:
            raise ConfigError(
                f"unknown wavelet {name_or_scheme!r}; expected one of {sorted(WAVELETS)}"
            ) from None
    raise ConfigError(
        f"wavelet must be a name or a LiftingScheme, got {type(name_or_scheme).__name__}"
    )


def _check_mode(mode) -> str:
    if mode not in MODES:
        raise ConfigError(f"unknown boundary mode {mode!r}; expected one of {list(MODES)}")
    return mode


def max_level(n: int, wavelet="db2", mode="periodization") -> int:
    """Largest decomposition level allowed for ``n`` samples.

    The rule is PyWavelets' ``dwt_max_level`` in both modes:
    ``J_max = floor(log2(n / (L - 1)))`` with ``L`` the filter length (haar 2, db2 4), i.e.
    level J needs ``n >= (L - 1) * 2**J`` samples (db2: ``3 * 2**J``; level 4 needs 48).
    ``0`` when ``n < L - 1``.

    Examples
    --------
    >>> max_level(47), max_level(48)
    (3, 4)
    """
    scheme = get_wavelet(wavelet)
    _check_mode(mode)
    return _max_level(int(n), scheme)


def _max_level(n: int, scheme: LiftingScheme) -> int:
    lm1 = int(scheme.filter_length) - 1
    if n < lm1 or n < 1:
        return 0
    j = int(math.floor(math.log2(n / lm1)))
    # guard against floating-point error in log2 at exact powers of two
    while (j + 1) >= 0 and lm1 * 2 ** (j + 1) <= n:
        j += 1
    while j > 0 and lm1 * 2**j > n:
        j -= 1
    return max(j, 0)


# --------------------------------------------------------------------------------------
# Kernels: NumPy reference and numba
# --------------------------------------------------------------------------------------

_BACKEND = "numba"
_NUMBA = None


def _set_backend(name: str) -> None:
    """Select the kernel backend, ``"numba"`` (default) or ``"numpy"`` (reference)."""
    global _BACKEND
    if name not in ("numba", "numpy"):
        raise ConfigError(f"backend must be 'numba' or 'numpy', got {name!r}")
    _BACKEND = name


def _bmap_scalar(j: int, m: int, periodic: bool) -> int:
    if periodic:
        return j % m
    if m == 1:
        return 0
    p = 2 * (m - 1)
    j = j % p
    return p - j if j > m - 1 else j


def _np_step(target, other, offs, coefs, periodic):
    """``target[l] += sum_t coefs[t] * other[map(l + offs[t])]`` (NumPy reference)."""
    n_t, m = target.shape[0], other.shape[0]
    for off, c in zip(offs.tolist(), coefs.tolist()):
        lo = max(0, -off)
        hi = min(n_t, m - off)
        if hi > lo:
            target[lo:hi] += c * other[lo + off : hi + off]
            edges = list(range(0, lo)) + list(range(hi, n_t))
        else:
            edges = range(n_t)
        for l in edges:
            target[l] += c * other[_bmap_scalar(l + off, m, periodic)]


def _np_split(x, n_pad, shift, e, o):
    n = x.shape[0]
    if n_pad != n:
        x = np.append(x, x[-1])
    if shift:
        x = np.roll(x, shift)
    e[:] = x[0::2]
    o[:] = x[1::2]


def _np_merge(e, o, shift, out):
    n = out.shape[0]
    h = e.shape[0]
    n_pad = 2 * h
    buf = np.empty(n_pad)
    buf[0::2] = e
    buf[1::2] = o
    if shift:
        buf = np.roll(buf, -shift)
    out[:] = buf[:n]


def _numba_kernels():
    global _NUMBA
    if _NUMBA is not None:
        return _NUMBA
    import numba
    from numba import prange

    @numba.njit(cache=True, inline="always")
    def bmap(j, m, periodic):
        if periodic:
            j = j % m
            if j < 0:
                j += m
            return j
        if m == 1:
            return 0
        p = 2 * (m - 1)
        j = j % p
        if j < 0:
            j += p
        if j > m - 1:
            j = p - j
        return j

    @numba.njit(cache=True, fastmath=False)
    def step(target, other, offs, coefs, periodic):
        n_t = target.shape[0]
        m = other.shape[0]
        nt = offs.shape[0]
        lo = min(max(0, -offs.min()), n_t)
        hi = max(min(n_t, m - offs.max()), lo)
        for l in range(lo, hi):
            acc = 0.0
            for t in range(nt):
                acc += coefs[t] * other[l + offs[t]]
            target[l] += acc
        for l in range(0, lo):
            acc = 0.0
            for t in range(nt):
                acc += coefs[t] * other[bmap(l + offs[t], m, periodic)]
            target[l] += acc
        for l in range(hi, n_t):
            acc = 0.0
            for t in range(nt):
                acc += coefs[t] * other[bmap(l + offs[t], m, periodic)]
            target[l] += acc

    @numba.njit(cache=True)
    def split(x, n_pad, shift, e, o):
        n = x.shape[0]
        h = e.shape[0]
        if shift == 0 and n_pad == n:
            for i in range(o.shape[0]):
                e[i] = x[2 * i]
                o[i] = x[2 * i + 1]
            if h > o.shape[0]:
                e[h - 1] = x[2 * (h - 1)]
            return
        for i in range(h):
            j = (2 * i - shift) % n_pad
            if j < 0:
                j += n_pad
            e[i] = x[min(j, n - 1)]
            j = (2 * i + 1 - shift) % n_pad
            if j < 0:
                j += n_pad
            o[i] = x[min(j, n - 1)]

    @numba.njit(cache=True)
    def merge(e, o, shift, out):
        n = out.shape[0]
        h = e.shape[0]
        n_pad = 2 * h
        if shift == 0:
            for i in range(o.shape[0]):
                if 2 * i < n:
                    out[2 * i] = e[i]
                if 2 * i + 1 < n:
                    out[2 * i + 1] = o[i]
            if h > o.shape[0] and 2 * (h - 1) < n:
                out[2 * (h - 1)] = e[h - 1]
            return
        for i in range(h):
            j = (2 * i - shift) % n_pad
            if j < 0:
                j += n_pad
            if j < n:
                out[j] = e[i]
            j = (2 * i + 1 - shift) % n_pad
            if j < 0:
                j += n_pad
            if j < n:
                out[j] = o[i]

    @numba.njit(cache=True, inline="always")
    def step_local(T, S, lo, hi, t0, t1, offs, coefs, sign):
        # T[l] += sign * sum_t coefs[t] * S[l + offs[t]] for l in [lo, hi); 1 and 2 taps unrolled
        nt = t1 - t0
        if nt == 1:
            c0 = sign * coefs[t0]
            o0 = offs[t0]
            for l in range(lo, hi):
                T[l] += c0 * S[l + o0]
        elif nt == 2:
            c0 = sign * coefs[t0]
            o0 = offs[t0]
            c1 = sign * coefs[t0 + 1]
            o1 = offs[t0 + 1]
            for l in range(lo, hi):
                T[l] += c0 * S[l + o0] + c1 * S[l + o1]
        else:
            for t in range(t0, t1):
                c = sign * coefs[t]
                o = offs[t]
                for l in range(lo, hi):
                    T[l] += c * S[l + o]

    @numba.njit(cache=True)
    def apply_steps_local(E, O, w, kinds, ptr, offs, coefs, reach, sign):
        # steps on cache-resident buffers; after step k values are valid on [reach[k], w - reach[k])
        for k in range(kinds.shape[0]):
            r = reach[k]
            if kinds[k] == 1:
                step_local(O, E, r, w - r, ptr[k], ptr[k + 1], offs, coefs, sign)
            else:
                step_local(E, O, r, w - r, ptr[k], ptr[k + 1], offs, coefs, sign)

    @numba.njit(cache=True, parallel=True)
    def fwd_blocks(x, n_pad, shift, kinds, ptr, offs, coefs, reach, M, scale_a, s_out, g_lo, g_hi, B):
        # fused split + lifting + scaling of the approximation, block by block (halo M);
        # blocks are independent, so they run in parallel, each with its own buffers
        n = x.shape[0]
        for ib in prange((g_hi - g_lo + B - 1) // B):
            a = g_lo + ib * B
            E = np.empty(B + 2 * M)
            O = np.empty(B + 2 * M)
            b = min(a + B, g_hi)
            w = b - a + 2 * M
            base = a - M
            j0 = 2 * base - shift
            if j0 >= 0 and j0 + 2 * w - 1 < n:
                for i in range(w):
                    E[i] = x[j0 + 2 * i]
                    O[i] = x[j0 + 2 * i + 1]
            else:
                for i in range(w):
                    j = (j0 + 2 * i) % n_pad
                    if j < 0:
                        j += n_pad
                    E[i] = x[min(j, n - 1)]
                    j = (j0 + 2 * i + 1) % n_pad
                    if j < 0:
                        j += n_pad
                    O[i] = x[min(j, n - 1)]
            apply_steps_local(E, O, w, kinds, ptr, offs, coefs, reach, 1.0)
            for i in range(b - a):
                s_out[a + i] = E[M + i] * scale_a

    @numba.njit(cache=True, parallel=True)
    def inv_blocks(s, n_out, shift, kinds, ptr, offs, coefs, reach, M, scale_a, out, x, noise,
                   g_lo, g_hi, B):
        # fused unscaling + inverse lifting (zero detail band) + merge, block by block;
        # kinds/ptr/offs/coefs/reach describe the reversed step list; writes noise = x - out
        # when noise has the length of out.
        h = s.shape[0]
        n_pad = 2 * h
        do_noise = noise.shape[0] == out.shape[0]
        inv_a = 1.0 / scale_a
        for ib in prange((g_hi - g_lo + B - 1) // B):
            a = g_lo + ib * B
            E = np.empty(B + 2 * M)
            O = np.empty(B + 2 * M)
            b = min(a + B, g_hi)
            w = b - a + 2 * M
            base = a - M
            if base >= 0 and base + w <= h:
                for i in range(w):
                    E[i] = s[base + i] * inv_a
                    O[i] = 0.0
            else:
                for i in range(w):
                    g = (base + i) % h
                    if g < 0:
                        g += h
                    E[i] = s[g] * inv_a
                    O[i] = 0.0
            apply_steps_local(E, O, w, kinds, ptr, offs, coefs, reach, -1.0)
            j0 = 2 * a - shift
            if j0 >= 0 and j0 + 2 * (b - a) <= n_out:
                for i in range(b - a):
                    out[j0 + 2 * i] = E[M + i]
                    out[j0 + 2 * i + 1] = O[M + i]
                    if do_noise:
                        noise[j0 + 2 * i] = x[j0 + 2 * i] - E[M + i]
                        noise[j0 + 2 * i + 1] = x[j0 + 2 * i + 1] - O[M + i]
            else:
                for i in range(b - a):
                    for q in range(2):
                        j = (j0 + 2 * i + q) % n_pad
                        if j < 0:
                            j += n_pad
                        if j < n_out:
                            v = E[M + i] if q == 0 else O[M + i]
                            out[j] = v
                            if do_noise:
                                noise[j] = x[j] - v

    _NUMBA = (step, split, merge, fwd_blocks, inv_blocks)
    return _NUMBA


def _step(target, other, offs, coefs, periodic):
    if _BACKEND == "numba":
        _numba_kernels()[0](target, other, offs, coefs, periodic)
    else:
        _np_step(target, other, offs, coefs, periodic)


def _split(x, n_pad, shift, e, o):
    if _BACKEND == "numba":
        _numba_kernels()[1](x, n_pad, shift, e, o)
    else:
        if n_pad == x.shape[0] and shift == 0:
            e[:] = x[0::2]
            o[:] = x[1::2]
        else:
            _np_split(x, n_pad, shift, e, o)


def _merge(e, o, shift, out):
    if _BACKEND == "numba":
        _numba_kernels()[2](e, o, shift, out)
    else:
        if shift == 0 and e.shape[0] + o.shape[0] >= out.shape[0]:
            k = out[0::2].shape[0]
            out[0::2] = e[:k]
            out[1::2] = o[: out[1::2].shape[0]]
        else:
            _np_merge(e, o, shift, out)


_STEP_ARRAYS: dict = {}


def _step_arrays(scheme: LiftingScheme):
    """Offsets/coefficients of every step as arrays (cached per scheme)."""
    key = id(scheme)
    hit = _STEP_ARRAYS.get(key)
    if hit is not None and hit[0] is scheme:
        return hit[1]
    arrs = [
        (
            s.kind == "predict",
            np.array([o for o, _ in s.taps], dtype=np.int64),
            np.array([c for _, c in s.taps], dtype=np.float64),
        )
        for s in scheme.steps
    ]
    _STEP_ARRAYS[key] = (scheme, arrs)
    return arrs


# --------------------------------------------------------------------------------------
# One level, private (inputs already validated, 1-D float64 contiguous)
# --------------------------------------------------------------------------------------


def _raw_forward(x, scheme, periodic):
    """Split and lift: returns the scaled (s, d) channels before the detail alignment.

    Periodization applies the padding and the input shift; symmetric applies neither.
    """
    n = x.shape[0]
    if periodic:
        n_pad = n + (n & 1)
        h = n_pad // 2
        e = np.empty(h)
        o = np.empty(h)
        _split(x, n_pad, scheme.input_shift % n_pad, e, o)
    else:
        e = np.empty((n + 1) // 2)
        o = np.empty(n // 2)
        _split(x, n, 0, e, o)
    for is_predict, offs, coefs in _step_arrays(scheme):
        if is_predict:
            _step(o, e, offs, coefs, periodic)
        else:
            _step(e, o, offs, coefs, periodic)
    e *= scheme.scale_approx
    o *= scheme.scale_detail
    return e, o


def _forward(x, scheme, periodic, need_detail=True):
    s, d = _raw_forward(x, scheme, periodic)
    if not need_detail:
        return s, None
    if periodic and scheme.detail_shift % d.shape[0]:
        d = np.roll(d, -scheme.detail_shift)
    if scheme.detail_sign < 0:
        np.negative(d, out=d)
    return s, d


def _inverse(ca, cd, scheme, periodic, n, out=None):
    """Inverse of one level; ``cd=None`` means an all-zero detail band; output length n."""
    e = ca / scheme.scale_approx
    h_o = ca.shape[0] if periodic else n // 2
    if cd is None:
        o = np.zeros(h_o)
    else:
        o = cd * (scheme.detail_sign / scheme.scale_detail)
        if periodic and scheme.detail_shift % h_o:
            o = np.roll(o, scheme.detail_shift)
    for is_predict, offs, coefs in reversed(_step_arrays(scheme)):
        if is_predict:
            _step(o, e, offs, -coefs, periodic)
        else:
            _step(e, o, offs, -coefs, periodic)
    if out is None:
        out = np.empty(n)
    shift = (scheme.input_shift % (2 * e.shape[0])) if periodic else 0
    _merge(e, o, shift, out)
    return out


def _band_lengths(n: int, level: int, periodic: bool) -> list[int]:
    """Signal length entering each level: [n, n_1, ..., n_{level-1}] and the final cA length."""
    lens = [n]
    for _ in range(level):
        lens.append((lens[-1] + 1) // 2)
    return lens


# --------------------------------------------------------------------------------------
# Validation helpers
# --------------------------------------------------------------------------------------


def _as_signal(x, name="x", allow_2d=False) -> np.ndarray:
    try:
        arr = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise DataFormatError(f"{name} must be numeric; got {type(x).__name__}") from exc
    if arr.ndim == 0 or arr.ndim > (2 if allow_2d else 1):
        want = "1-D (n,) or 2-D (n, n_axes)" if allow_2d else "1-D (n,)"
        raise DataFormatError(f"{name} must be {want}; got shape {arr.shape}")
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = np.unravel_index(int(np.argmax(bad)), arr.shape)
        where = idx[0] if arr.ndim == 1 else idx
        raise DataFormatError(
            f"{name}[{', '.join(str(int(i)) for i in np.atleast_1d(where))}] is "
            f"{arr[idx]!r}; expected finite values"
        )
    if arr.shape[0] < 2:
        raise InsufficientDataError(
            f"{name} has {arr.shape[0]} samples; a wavelet level needs at least 2",
            needed=2,
            got=int(arr.shape[0]),
        )
    return np.ascontiguousarray(arr)


def _check_level(level, n, scheme, mode) -> int:
    if isinstance(level, bool) or not isinstance(level, numbers.Integral):
        raise ConfigError(f"level must be a positive integer (or 'auto' where allowed), got {level!r}")
    level = int(level)
    jmax = _max_level(n, scheme)
    if level < 1:
        raise ConfigError(f"level must be >= 1, got {level}")
    if level > jmax:
        raise ConfigError(
            f"level {level} is too high for {n} samples with {scheme.name!r}; the maximum is "
            f"{jmax} (rule: level J needs n >= (L-1)*2**J = {scheme.filter_length - 1}*2**J)"
        )
    return level


# --------------------------------------------------------------------------------------
# Public transform
# --------------------------------------------------------------------------------------


def lift(x, wavelet="db2", mode="periodization") -> tuple[np.ndarray, np.ndarray]:
    """One level of the forward lifting wavelet transform.

    Parameters
    ----------
    x : array_like, shape (n,)
        Signal, n >= 2, finite.
    wavelet : str or LiftingScheme
        ``"haar"``, ``"db2"`` or a custom scheme.
    mode : {"periodization", "symmetric"}
        Boundary rule (module docstring).

    Returns
    -------
    approx, detail : ndarray
        Periodization: both of length ``ceil(n/2)``, equal to
        ``pywt.dwt(x, wavelet, mode="periodization")``.  Symmetric: lengths ``ceil(n/2)``
        and ``floor(n/2)``.

    Raises
    ------
    DataFormatError
        Not 1-D or non-finite values (the message gives the index).
    ConfigError
        Unknown wavelet or mode.

    Notes
    -----
    db2 uses the Daubechies–Sweldens (1998) update-first factorisation with PyWavelets'
    alignment (Convention A, method notes §1.3–1.4): ``x' = roll(x, 1)``, lift, then
    ``cA = s`` and ``cD = -roll(d, -1)``.

    Examples
    --------
    >>> a, d = lift([1.0, 2.0, 3.0, 4.0], "haar")
    >>> np.round(a, 10).tolist(), np.round(d, 10).tolist()
    ([2.1213203436, 4.9497474683], [-0.7071067812, -0.7071067812])
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    x = _as_signal(x)
    return _forward(x, scheme, mode == "periodization")


def unlift(approx, detail, wavelet="db2", mode="periodization", length=None) -> np.ndarray:
    """Inverse of :func:`lift`.

    Parameters
    ----------
    approx, detail : array_like, shape (h,) and (h,) or (h - 1,)
        Coefficient bands.  Periodization needs equal lengths; symmetric needs
        ``len(approx) - len(detail)`` in {0, 1}.
    wavelet, mode
        As in :func:`lift`.
    length : int, optional
        Output length.  Periodization: default ``2*len(detail)``; pass ``2h - 1`` to undo
        the padding of an odd-length input.  Symmetric: must be ``len(approx) + len(detail)``.

    Returns
    -------
    ndarray, shape (length,)

    Raises
    ------
    ConfigError
        Inconsistent band lengths or ``length``.
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    a = _as_signal(approx, "approx") if np.size(approx) > 1 else np.asarray(approx, float).ravel()
    d = _as_signal(detail, "detail") if np.size(detail) > 1 else np.asarray(detail, float).ravel()
    if not (np.isfinite(a).all() and np.isfinite(d).all()):
        raise DataFormatError("approx/detail hold non-finite values")
    periodic = mode == "periodization"
    h = a.shape[0]
    if periodic:
        if d.shape[0] != h:
            raise ConfigError(
                f"periodization needs len(approx) == len(detail); got {h} and {d.shape[0]}"
            )
        n = 2 * h if length is None else int(length)
        if n not in (2 * h, 2 * h - 1):
            raise ConfigError(f"length must be {2 * h} or {2 * h - 1} for {h} coefficients, got {length}")
    else:
        if h - d.shape[0] not in (0, 1):
            raise ConfigError(
                f"symmetric needs len(approx) - len(detail) in {{0, 1}}; got {h} and {d.shape[0]}"
            )
        n = h + d.shape[0]
        if length is not None and int(length) != n:
            raise ConfigError(f"symmetric: length must be len(approx)+len(detail)={n}, got {length}")
    return _inverse(a, d, scheme, periodic, n)


def wavedec(x, wavelet="db2", level=4, mode="periodization") -> list[np.ndarray]:
    """Multilevel forward lifting transform.

    Parameters
    ----------
    x : array_like, shape (n,)
        Finite signal.
    wavelet : str or LiftingScheme
    level : int
        1 <= level <= :func:`max_level` ``(n)``.
    mode : {"periodization", "symmetric"}

    Returns
    -------
    list of ndarray
        ``[cA_J, cD_J, cD_{J-1}, ..., cD_1]`` (PyWavelets order).  Periodization: equal to
        ``pywt.wavedec(x, wavelet, mode="periodization", level=J)``; every level pads an odd
        length with its last sample, so band lengths are ``ceil(n_j / 2)``.

    Raises
    ------
    ConfigError
        Level out of range (the message names the maximum), unknown wavelet or mode.
    DataFormatError
        Non-finite input (the message gives the index).

    Examples
    --------
    >>> [len(c) for c in wavedec(np.arange(101.0), "db2", level=4)]
    [7, 7, 13, 26, 51]
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    x = _as_signal(x)
    level = _check_level(level, x.shape[0], scheme, mode)
    periodic = mode == "periodization"
    a = x
    details = []
    for _ in range(level):
        a, d = _forward(a, scheme, periodic)
        details.append(d)
    return [a] + details[::-1]


def waverec(coeffs, wavelet="db2", mode="periodization", length=None) -> np.ndarray:
    """Multilevel inverse of :func:`wavedec`.

    Parameters
    ----------
    coeffs : list of array_like
        ``[cA_J, cD_J, ..., cD_1]``.
    wavelet, mode
        As used by :func:`wavedec`.
    length : int, optional
        Length of the original signal.  Periodization: the output has ``2*len(cD_1)``
        samples unless ``length`` trims it (``length = n`` undoes the padding of an odd n,
        like trimming ``pywt.waverec``); symmetric lengths are implied by the bands.

    Returns
    -------
    ndarray, shape (length,)

    Raises
    ------
    ConfigError
        Fewer than two bands or band lengths that do not chain.
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    periodic = mode == "periodization"
    if not isinstance(coeffs, (list, tuple)) or len(coeffs) < 2:
        raise ConfigError("coeffs must be a list [cA_J, cD_J, ..., cD_1] with at least two bands")
    bands = [np.ascontiguousarray(np.asarray(c, dtype=np.float64)).ravel() for c in coeffs]
    for i, b in enumerate(bands):
        if not np.isfinite(b).all():
            raise DataFormatError(f"coeffs[{i}] holds non-finite values")
    a = bands[0]
    details = bands[1:]
    for k, d in enumerate(details):
        last = k == len(details) - 1
        if periodic:
            if a.shape[0] == d.shape[0] + 1:
                a = a[:-1]  # undo the padding of the odd length at this level (pywt rule)
            if a.shape[0] != d.shape[0]:
                raise ConfigError(
                    f"band {k + 1}: cA has {a.shape[0]} coefficients but cD has {d.shape[0]}"
                )
            n = 2 * d.shape[0]
            if last and length is not None:
                if int(length) not in (n, n - 1):
                    raise ConfigError(f"length must be {n} or {n - 1}, got {length}")
                n = int(length)
        else:
            if a.shape[0] - d.shape[0] not in (0, 1):
                raise ConfigError(
                    f"band {k + 1}: cA has {a.shape[0]} coefficients and cD {d.shape[0]}; "
                    "symmetric needs a difference of 0 or 1"
                )
            n = a.shape[0] + d.shape[0]
            if last and length is not None and int(length) != n:
                raise ConfigError(f"symmetric: length must be {n}, got {length}")
        a = _inverse(a, d, scheme, periodic, n)
    return a


# --------------------------------------------------------------------------------------
# Separation into drift and noise
# --------------------------------------------------------------------------------------


def _drift_1d(x, scheme, level, periodic, out=None, noise=None):
    """Drift of a clean 1-D signal: W^-1(cA_J, 0, ..., 0) with padding/trimming per level.

    Uses the fused block kernels (numba backend, long enough records) or the step-by-step
    reference path; ``noise`` (optional, same length) receives ``x - drift``.
    """
    if _BACKEND == "numba" and x.shape[0] >= _FUSED_MIN:
        return _fused_drift(x, scheme, level, periodic, out, noise)
    d = _drift_ref(x, scheme, level, periodic, out)
    if noise is not None:
        np.subtract(x, d, out=noise)
    return d


def _drift_ref(x, scheme, level, periodic, out=None):
    """Step-by-step reference implementation of :func:`_drift_1d`."""
    lens = _band_lengths(x.shape[0], level, periodic)
    a = x
    for _ in range(level):
        a, _unused = _forward(a, scheme, periodic, need_detail=False)
    for j in range(level, 0, -1):
        n = lens[j - 1]
        a = _inverse(a, None, scheme, periodic, n, out=out if j == 1 else None)
    return a


_FUSED_MIN = 2048  # records shorter than this use the step-by-step kernels
_BLOCK = 2048  # channel samples per block of the fused kernels (buffers stay in L1/L2)


def _fused_tables(scheme, reverse):
    key = (id(scheme), reverse)
    hit = _STEP_ARRAYS.get(key)
    if hit is not None and hit[0] is scheme:
        return hit[1]
    steps = list(scheme.steps)[::-1] if reverse else list(scheme.steps)
    # Only the approximation path is needed: the forward pass may drop trailing predict
    # steps (they only change the detail channel), and the inverse pass, whose detail
    # channel starts at zero, may drop leading update steps (they add 0 to the even channel).
    drop = "update" if reverse else "predict"
    if reverse:
        while len(steps) > 1 and steps[0].kind == drop:
            steps = steps[1:]
    else:
        while len(steps) > 1 and steps[-1].kind == drop:
            steps = steps[:-1]
    kinds = np.array([1 if st.kind == "predict" else 0 for st in steps], dtype=np.int64)
    ptr = np.zeros(len(steps) + 1, dtype=np.int64)
    ptr[1:] = np.cumsum([len(st.taps) for st in steps])
    offs = np.array([o for st in steps for o, _ in st.taps], dtype=np.int64)
    coefs = np.array([c for st in steps for _, c in st.taps], dtype=np.float64)
    reach = np.cumsum([max(abs(o) for o, _ in st.taps) for st in steps]).astype(np.int64)
    tables = (kinds, ptr, offs, coefs, reach, max(int(reach[-1]), 1))  # halo >= 1 keeps edge segments non-empty
    _STEP_ARRAYS[key] = (scheme, tables)
    return tables


def _fused_tables_full_reach(scheme) -> int:
    """Halo for the symmetric head/tail segments: total reach of all steps (>= 1)."""
    return max(sum(max(abs(o) for o, _ in st.taps) for st in scheme.steps), 1)


def _sym_edges_forward(x, scheme, M, hE, hO):
    """Symmetric mode: exact approximation values on the head [0, 2M) and tail [hO-2M, hE)."""
    T = 4 * M
    s_head, _ = _raw_forward_channels(x[0 : 2 * T : 2].copy(), x[1 : 2 * T : 2].copy(), scheme)
    g0 = hO - T
    s_tail, _ = _raw_forward_channels(x[2 * g0 :: 2].copy(), x[2 * g0 + 1 :: 2].copy(), scheme)
    return s_head[: 2 * M], s_tail[T - 2 * M :]


def _raw_forward_channels(e, o, scheme):
    for is_predict, offs, coefs in _step_arrays(scheme):
        if is_predict:
            _step(o, e, offs, coefs, False)
        else:
            _step(e, o, offs, coefs, False)
    return e * scheme.scale_approx, o


def _sym_edges_inverse(s, n, scheme, M, out):
    """Symmetric mode: exact inverse (zero details) on the head and tail channel ranges."""
    hE, hO = (n + 1) // 2, n // 2
    T = 4 * M
    for g0, keep_from in ((0, 0), (hO - T, T - 2 * M)):
        e = s[g0 : g0 + T if g0 == 0 else hE] / scheme.scale_approx
        o = np.zeros(T if g0 == 0 else hO - g0)
        for is_predict, offs, coefs in reversed(_step_arrays(scheme)):
            if is_predict:
                _step(o, e, offs, -coefs, False)
            else:
                _step(e, o, offs, -coefs, False)
        if g0 == 0:
            out[0 : 4 * M : 2] = e[: 2 * M]
            out[1 : 4 * M : 2] = o[: 2 * M]
        else:
            g1 = g0 + keep_from
            out[2 * g1 :: 2] = e[keep_from:]
            out[2 * g1 + 1 :: 2] = o[keep_from:]


def _fused_drift(x, scheme, level, periodic, out=None, noise=None):
    """Drift (and optionally noise) with the fused numba block kernels.

    Periodization: every block gathers its halo with periodic indexing, which is exact
    because the steps are shift-invariant on the circle.  Symmetric: interior blocks need
    no boundary rule; the head and tail (2M channel samples each, M = total step reach)
    are computed step by step on 4M-sample segments, whose truncation error reaches at
    most M samples inwards, so they are exact.
    """
    kern = _numba_kernels()
    fwd_blocks, inv_blocks = kern[3], kern[4]
    kf, pf, of, cf, rf, mf = _fused_tables(scheme, reverse=False)
    ki, pi, oi, ci, ri, mi = _fused_tables(scheme, reverse=True)
    M = max(mf, mi, _fused_tables_full_reach(scheme))
    lens = _band_lengths(x.shape[0], level, periodic)
    empty = np.empty(0)
    a = x
    for j in range(level):
        n = a.shape[0]
        if periodic:
            n_pad = n + (n & 1)
            h = n_pad // 2
            s = np.empty(h)
            fwd_blocks(a, n_pad, scheme.input_shift % n_pad, kf, pf, of, cf, rf, M,
                       scheme.scale_approx, s, 0, h, _BLOCK)
        else:
            hE, hO = (n + 1) // 2, n // 2
            if hO < 8 * M + 2:
                s, _ = _raw_forward(a, scheme, False)
            else:
                s = np.empty(hE)
                fwd_blocks(a, n, 0, kf, pf, of, cf, rf, M, scheme.scale_approx, s,
                           2 * M, hO - 2 * M, _BLOCK)
                head, tail = _sym_edges_forward(a, scheme, M, hE, hO)
                s[: 2 * M] = head
                s[hO - 2 * M :] = tail
        a = s
    for j in range(level, 0, -1):
        n = lens[j - 1]
        last = j == 1
        dst = out if (last and out is not None) else np.empty(n)
        nz = noise if (last and noise is not None) else empty
        if periodic:
            h = a.shape[0]
            inv_blocks(a, n, scheme.input_shift % (2 * h), ki, pi, oi, ci, ri, M,
                       scheme.scale_approx, dst, x, nz, 0, h, _BLOCK)
        else:
            hO = n // 2
            if hO < 8 * M + 2:
                _inverse(a, None, scheme, False, n, out=dst)
                if nz.shape[0]:
                    np.subtract(x, dst, out=nz)
            else:
                inv_blocks(a, n, 0, ki, pi, oi, ci, ri, M, scheme.scale_approx, dst, x, nz,
                           2 * M, hO - 2 * M, _BLOCK)
                _sym_edges_inverse(a, n, scheme, M, dst)
                if nz.shape[0]:
                    nz[: 4 * M] = x[: 4 * M] - dst[: 4 * M]
                    k0 = 2 * (hO - 2 * M)
                    nz[k0:] = x[k0:] - dst[k0:]
        a = dst
    return a


def separate(x, wavelet="db2", level=4, mode="periodization", *, dt_s=None):
    """Split a signal into a slow drift and a fast noise part by separate reconstruction.

    Parameters
    ----------
    x : array_like, shape (n,) or (n, n_axes)
        Signal (e.g. rate in deg/h); 2-D input is processed column by column along axis 0.
    wavelet : str or LiftingScheme
    level : int or "auto"
        Decomposition depth J (1 <= J <= :func:`max_level`).  ``"auto"`` runs
        :func:`level_scan` (needs ``dt_s``) and :func:`choose_level` on each column.
    mode : {"periodization", "symmetric"}
    dt_s : float, optional
        Sample interval in s; only needed for ``level="auto"``.

    Returns
    -------
    drift, noise : ndarray, same shape as ``x``
        ``drift = W^-1(cA_J, 0, ..., 0)``, ``noise = W^-1(0, cD_J, ..., cD_1) = x - drift``.

    Raises
    ------
    ConfigError
        Level too high (the message names the maximum), ``"auto"`` without ``dt_s``,
        unknown wavelet or mode.
    DataFormatError
        Non-finite input (the message gives the index).

    Notes
    -----
    Method notes §1.7.  ``W^-1`` and the per-level padding/trimming are linear, so the noise
    is computed as ``x - drift`` (one inverse transform instead of two); the tests check it
    against ``W^-1(0, cD_J, ..., cD_1)`` and PyWavelets' ``waverec`` on zeroed bands.
    The drift is non-causal (it depends on ~30–45 future samples at J = 4, db2); see
    :func:`causal_drift` for the real-time version.  About ``1/2**J`` of white-noise variance
    stays in the drift (notes §1.7, R16).

    Examples
    --------
    >>> drift, noise = separate(np.full(64, 2.5), "db2", level=4)
    >>> bool(np.allclose(drift, 2.5) and np.allclose(noise, 0.0))
    True
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    arr = _as_signal(x, allow_2d=True)
    periodic = mode == "periodization"
    n = arr.shape[0]
    cols = [arr] if arr.ndim == 1 else [np.ascontiguousarray(arr[:, k]) for k in range(arr.shape[1])]
    if isinstance(level, str):
        if level != "auto":
            raise ConfigError(f"level must be a positive integer or 'auto', got {level!r}")
        if dt_s is None:
            raise ConfigError("level='auto' needs dt_s (the sample interval in s)")
        levels = [choose_level(level_scan(c, dt_s, scheme, mode=mode)) for c in cols]
    else:
        levels = [_check_level(level, n, scheme, mode)] * len(cols)
    drift = np.empty(arr.shape)
    noise = np.empty(arr.shape)
    for k, (c, lv) in enumerate(zip(cols, levels)):
        if arr.ndim == 1:
            _drift_1d(c, scheme, lv, periodic, out=drift, noise=noise)
        else:
            d = _drift_1d(c, scheme, lv, periodic)
            drift[:, k] = d
            noise[:, k] = c - d
    return drift, noise


def _drift_row_last(window: int, scheme, level: int, periodic: bool, block: int = 256) -> np.ndarray:
    """Weights g with ``drift(v)[-1] == g @ v`` for every v of length ``window``.

    Column i of the drift operator is the drift of the unit vector e_i; its last entry is
    g[i].  Computed on blocks of unit vectors (memory ``window * block``).
    """
    g = np.empty(window)
    for start in range(0, window, block):
        stop = min(window, start + block)
        for i in range(start, stop):
            e = np.zeros(window)
            e[i] = 1.0
            g[i] = _drift_1d(e, scheme, level, periodic)[-1]
    return g


def causal_drift(x, window, wavelet="db2", level=4, mode="symmetric") -> np.ndarray:
    """Real-time (causal) drift: the last sample of the drift of a sliding window.

    ``drift[k]`` is the last sample of ``separate(x[k-window+1 : k+1], ...)[0]``, so it uses
    no sample later than k (method notes §5.3).  ``NaN`` for ``k < window - 1``.

    Parameters
    ----------
    x : array_like, shape (n,) or (n, n_axes)
    window : int
        Window length in samples; ``level`` must be allowed for it (see :func:`max_level`).
    wavelet, level, mode
        As in :func:`separate`; the default ``"symmetric"`` avoids wrapping the window's
        start onto its end.

    Returns
    -------
    ndarray, same shape as ``x``

    Raises
    ------
    ConfigError
        Bad window or level.
    InsufficientDataError
        ``window > n``.

    Notes
    -----
    The drift of a window is linear in the window, so its last sample is ``g @ window``
    with ``g`` the last row of the drift operator; ``g`` is computed once (``window``
    unit-vector separations) and then applied as a sliding dot product, which is exact to
    round-off and equal to the naive per-window separation.
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    arr = _as_signal(x, allow_2d=True)
    if isinstance(window, bool) or not isinstance(window, numbers.Integral) or window < 2:
        raise ConfigError(f"window must be an integer >= 2, got {window!r}")
    window = int(window)
    n = arr.shape[0]
    if window > n:
        raise InsufficientDataError(
            f"window {window} is longer than the record ({n} samples)", needed=window, got=n
        )
    level = _check_level(level, window, scheme, mode)
    g = _drift_row_last(window, scheme, level, mode == "periodization")
    out = np.full(arr.shape, np.nan)
    views = np.lib.stride_tricks.sliding_window_view(arr, window, axis=0)
    if arr.ndim == 1:
        out[window - 1 :] = views @ g
    else:
        out[window - 1 :] = views @ g
    return out


# --------------------------------------------------------------------------------------
# Level selection
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class LevelDiagnostic:
    """Diagnostics of the noise part of a level-J separation.

    Attributes
    ----------
    level : int
        Decomposition level J.
    cutoff_hz : float or None
        Nominal drift cutoff ``1 / (2**(J+1) * dt_s)`` [Hz] (upper edge of the cA_J band).
    noise_adev_slope : float
        Least-squares log-log slope of the noise part's overlapping ADEV over octave taus
        from dt_s to ~n*dt_s/10 (white rate noise: -1/2).
    noise_arw_dprh : float or None
        Angle random walk of the noise part, ``ADEV(dt_s) * sqrt(dt_s) / 60`` [deg/sqrt(h)].
    drift_rms_dph, noise_rms_dph : float
        RMS about the mean of the drift and of the noise part [deg/h].
    noise_inband_slope : float
        Log-log ADEV slope of the noise part over its pass band only, octave taus
        ``dt_s .. 2**(J-1) * dt_s`` (at least taus dt_s and 2 dt_s).  White noise: about
        -0.52..-0.57 (J >= 2); slow drift leaking into the noise part makes it flatter.
        Used by :func:`choose_level`.
    """

    level: int
    cutoff_hz: float | None
    noise_adev_slope: float
    noise_arw_dprh: float | None
    drift_rms_dph: float
    noise_rms_dph: float
    noise_inband_slope: float = float("nan")

    def to_dict(self) -> dict:
        return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in asdict(self).items()}


def _oadev_octaves(y: np.ndarray, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Overlapping ADEV of rate samples y at octave taus m = 1, 2, 4, ... <= n/10 (via :mod:`fogdrift.allan`)."""
    from .allan import allan_variance  # lazy: lifting stays importable on its own

    res = allan_variance(y, dt_s, taus="octave", max_fraction=0.1)
    return res.tau_s, res.adev_dph


def _loglog_slope(taus, adev) -> float:
    if len(taus) < 2 or not np.all(adev > 0):
        return float("nan")
    return float(np.polyfit(np.log(taus), np.log(adev), 1)[0])


def level_scan(x, dt_s, wavelet="db2", max_level=None, mode="periodization") -> list[LevelDiagnostic]:
    """Separate at every level 1..max_level and describe the noise part of each.

    Parameters
    ----------
    x : array_like, shape (n,)
        Rate in deg/h, n >= 20.
    dt_s : float
        Sample interval in s (> 0).
    wavelet, mode
        As in :func:`separate`.
    max_level : int, optional
        Highest level scanned; default and upper bound :func:`max_level` ``(n)``.

    Returns
    -------
    list of LevelDiagnostic
        One per level, in increasing order.

    Notes
    -----
    The ADEV slope is a least-squares fit of ``log ADEV`` on ``log tau`` over octave taus
    from ``dt_s`` to ``n*dt_s/10`` (overlapping estimator, NIST SP 1065 eq. 14).  A pure
    white-noise noise part has slope -1/2 (IEEE 952 Annex C); a noise part that is
    high-passed too hard (level too low) falls faster (towards -1 at large tau), and one
    that has swallowed part of the drift (level too high) is flatter or rising.
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    y = _as_signal(x)
    from .units import check_dt_s

    dt_s = check_dt_s(dt_s)
    n = y.shape[0]
    if n < 20:
        raise InsufficientDataError(f"level_scan needs at least 20 samples, got {n}", needed=20, got=n)
    if max_level is None:
        top = _max_level(n, scheme)
    else:
        top = _check_level(max_level, n, scheme, mode)
    if top < 1:
        raise ConfigError(f"{n} samples are too few for one {scheme.name!r} level")
    periodic = mode == "periodization"
    out = []
    for j in range(1, top + 1):
        drift = _drift_1d(y, scheme, j, periodic)
        noise = y - drift
        taus, adev = _oadev_octaves(noise, dt_s)
        slope = _loglog_slope(taus, adev)
        inband = _loglog_slope(taus[: max(2, j)], adev[: max(2, j)])
        arw = float(adev[0] * math.sqrt(dt_s) / 60.0)
        out.append(
            LevelDiagnostic(
                level=j,
                cutoff_hz=1.0 / (2.0 ** (j + 1) * dt_s),
                noise_adev_slope=slope,
                noise_arw_dprh=arw,
                drift_rms_dph=float(np.std(drift)),
                noise_rms_dph=float(np.std(noise)),
                noise_inband_slope=inband,
            )
        )
    return out


def choose_level(diagnostics, *, tol: float = 0.1) -> int:
    """Pick a decomposition level from :func:`level_scan` output.

    Rule: the largest level J such that every level 2..J has a pass-band noise slope
    (``noise_inband_slope``, ADEV slope over taus dt..2**(J-1) dt) ``<= -1/2 + tol``
    (default tol 0.1, threshold -0.4); level 1 is always acceptable.  The scan stops at
    the first level whose noise part is redder than white noise, i.e. where slow drift
    starts to leak into the noise part.  Returns 1 if level 2 already fails.

    Notes
    -----
    The overall slope ``noise_adev_slope`` (taus up to n*dt/10) is *not* used: the noise
    part is high-passed at ~fs/2**(J+1), so at taus beyond 2**J dt its ADEV falls like
    tau**-1 and the overall slope drifts from about -1 (J = 1) towards -1/2 only at
    levels deep enough to have swallowed the drift (measured on white noise plus a
    256-sample sinusoid, N = 2**16: overall slopes -1.01 ... -0.17 over J = 1..14, crossing
    -0.5 only at J = 10 where the sinusoid is entirely in the noise part).  On the same
    signal the pass-band rule picks J = 5..6, keeping >= 94 % of the sinusoid's power in
    the drift (method notes §1.7: a period of 4 * 2**J samples keeps 0.938 of its power).

    Parameters
    ----------
    diagnostics : sequence of LevelDiagnostic
    tol : float
        Allowed excess of the pass-band slope over -1/2.

    Returns
    -------
    int

    Raises
    ------
    ConfigError
        Empty input.
    """
    diags = sorted(diagnostics, key=lambda d: d.level)
    if not diags:
        raise ConfigError("choose_level needs at least one LevelDiagnostic")
    best = diags[0].level
    for d in diags:
        if d.level >= 2 and not (d.noise_inband_slope <= -0.5 + tol):
            break
        best = d.level
    return int(best)
