"""Wavelets as tables of lifting steps: :class:`LiftingStep`, :class:`LiftingScheme`, the registry.

A wavelet is data: a list of predict/update steps, two normalisation factors and the index
alignment that makes the periodized transform coefficient-identical to PyWavelets.  One
generic step applier (:mod:`fogdrift.lifting._kernels`) runs any table, so adding a wavelet
is one entry in :data:`WAVELETS`; the test suite checks every entry of :func:`wavelist`
against ``pywt.wavedec(..., mode="periodization")``.

How the table entries were obtained
-----------------------------------
A lifting factorisation writes the analysis polyphase matrix of a two-channel filter bank
as a product of triangular steps (Daubechies & Sweldens 1998): with
``E_l = x'_{2l}``, ``O_l = x'_{2l+1}``, a *predict* step ``O_l += sum_k p_k E_{l+k}`` and an
*update* step ``E_l += sum_k u_k O_{l+k}``, followed by ``cA = K_a E``, ``cD = ±K_d O``.

* ``haar``: predict ``d = O - E``, update ``s = E + d/2``, normalise by sqrt(2) and 1/sqrt(2);
  PyWavelets' detail is ``-d``.
* ``db2``: the update-first factorisation of D4 given by Daubechies & Sweldens (1998),
  ``s = E + sqrt(3) O``, ``d = O - sqrt(3)/4 s_l - (sqrt(3)-2)/4 s_{l-1}``,
  ``s -= d_{l+1}``, with the input delayed by one sample and ``cD_l = -d_{l+1}`` to match
  PyWavelets' periodization.
* ``db4`` (8 taps): derived for this table by the Euclidean algorithm for Laurent
  polynomials (Daubechies & Sweldens 1998) applied to the polyphase components of
  ``pywt.Wavelet("db4").dec_lo`` and ``dec_hi`` in PyWavelets' periodization alignment,
  with the input delayed by two samples (so that the reduced lowpass row is a constant).
  Each division step may cancel coefficients at either end of the Laurent polynomial;
  the search finds three distinct five-step factorisations and the table uses the one
  whose largest coefficient is smallest (0.735), which keeps the round-off of the steps
  at the level of db2's.  The last predict step is the highpass completion
  ``G_e / G_o`` of the reduced matrix.  Verified numerically: all bands equal
  ``pywt.wavedec(x, "db4", mode="periodization")`` to 4e-15 * max|x| for odd and even n
  (``tests/lifting/test_lifting_pywt.py``); ``tests/lifting/test_lifting_schemes.py`` re-derives the table
  entry from PyWavelets' filters.

References
----------
I. Daubechies, W. Sweldens, "Factoring wavelet transforms into lifting steps",
J. Fourier Anal. Appl. 4(3):247-269, 1998.  PyWavelets documentation, "Signal extension
modes" (``periodization``) and ``pywt.dwt``/``pywt.wavedec``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from ..errors import ConfigError

__all__ = ["LiftingStep", "LiftingScheme", "WAVELETS", "get_wavelet", "wavelist"]


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

    Examples
    --------
    >>> LiftingStep("predict", ((0, -1.0),)).to_dict()
    {'kind': 'predict', 'taps': [[0, -1.0]]}
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
        Periodization only: delay of the input before the split (db2: 1, db4: 2).
    detail_shift : int
        Periodization only: ``cD_l = detail_sign * scale_detail * d_{l + detail_shift}``.
    detail_sign : float
        ``+1`` or ``-1``; PyWavelets' detail sign convention (haar, db2: ``-1``; db4: ``+1``).
    filter_length : int
        Length of the equivalent FIR filter (``pywt.Wavelet(name).dec_len``); sets the
        maximum level, see :func:`fogdrift.lifting.max_level`.
    pywt_name : str or None
        Name of the PyWavelets wavelet the periodized transform reproduces.

    Examples
    --------
    >>> s = get_wavelet("db4")
    >>> len(s.steps), s.filter_length, s.pywt_name
    (5, 8, 'db4')
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

#: The registry: name -> scheme.  Adding a wavelet is adding an entry here; the tests
#: parametrised over :func:`wavelist` then check it against PyWavelets.
WAVELETS: dict[str, LiftingScheme] = {
    # predict d = O - E, update s = E + d/2, normalise sqrt2, 1/sqrt2; pywt cD = -d.
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
    # Daubechies & Sweldens (1998), update-first D4; input delayed by 1, cD_l = -d_{l+1}.
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
    # Euclidean factorisation of pywt's db4 polyphase matrix (module docstring); input
    # delayed by 2, cD_l = +K_d d_{l+2}.  scale_approx * scale_detail = 1 - 4e-16.
    "db4": LiftingScheme(
        name="db4",
        steps=(
            LiftingStep("predict", ((1, -0.3222758880002811),)),
            LiftingStep("update", ((-1, 0.29195312600347534), (0, 0.7346312579208225))),
            LiftingStep("predict", ((-1, 0.17267310081004741), (0, -0.540028283419714))),
            LiftingStep("update", ((1, -0.36483834388117875), (2, 0.06472423932208018))),
            LiftingStep("predict", ((-2, -0.03262364945797306),)),
        ),
        scale_approx=0.8421450430697311,
        scale_detail=1.1874439067584677,
        input_shift=2,
        detail_shift=2,
        detail_sign=1.0,
        filter_length=8,
        pywt_name="db4",
    ),
}


def wavelist(family: str | None = None) -> list[str]:
    """Names of the registered lifting wavelets, like :func:`pywt.wavelist`.

    Parameters
    ----------
    family : str, optional
        Keep only the names of this family: the name without its trailing digits
        (``"db"`` gives ``db2`` and ``db4``).

    Returns
    -------
    list of str
        In registry order.

    Examples
    --------
    >>> wavelist()
    ['haar', 'db2', 'db4']
    >>> wavelist("db")
    ['db2', 'db4']
    """
    if family is None:
        return list(WAVELETS)
    return [name for name in WAVELETS if name.rstrip("0123456789") == family]


def get_wavelet(name_or_scheme) -> LiftingScheme:
    """Return the :class:`LiftingScheme` for a registry name, or the scheme itself.

    Raises
    ------
    ConfigError
        Unknown name (the message lists :func:`wavelist`) or a wrong type.

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
                f"unknown wavelet {name_or_scheme!r}; pass {{opt:wavelet}} as one of {wavelist()}"
            ) from None
    raise ConfigError(
        f"wavelet must be a name or a LiftingScheme, got {type(name_or_scheme).__name__}"
    )
