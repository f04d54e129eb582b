"""Second-generation (lifting) wavelet transform and drift/noise separation.

A wavelet is a :class:`LiftingScheme`, a table of predict/update steps (Daubechies &
Sweldens 1998); one generic step applier runs any table under both boundary modes, so
adding a wavelet is one entry of :data:`WAVELETS` (:func:`wavelist` lists them).  In
``mode="periodization"`` every registered wavelet is coefficient-identical to
``pywt.wavedec(x, name, mode="periodization")``; ``mode="symmetric"`` reflects channel
indices at the record ends instead of wrapping the end onto the start.

Modules (one job each):

* :mod:`~fogdrift.lifting.schemes` -- :class:`LiftingStep`, :class:`LiftingScheme`, the
  registry :data:`WAVELETS`, :func:`get_wavelet`, :func:`wavelist`;
* :mod:`~fogdrift.lifting.transform` -- :func:`lift`, :func:`unlift`, :func:`wavedec`,
  :func:`waverec`, :func:`max_level`, the boundary modes :data:`MODES`;
* :mod:`~fogdrift.lifting.separation` -- :func:`separate` (drift ``W^-1(cA_J, 0, ..., 0)``
  and noise ``W^-1(0, cD_J, ..., cD_1)``) and the real-time :func:`causal_drift`;
* :mod:`~fogdrift.lifting.levels` -- :class:`LevelDiagnostic`, :func:`level_scan`,
  :func:`choose_level` (the automatic level);
* ``_kernels`` (NumPy reference and numba kernels, ``_set_backend``) and ``_drift`` (the
  drift operator, step by step or fused).

Units: the transform is unit-agnostic; :func:`level_scan` assumes a rate in deg/h sampled
every ``dt_s`` seconds.

References
----------
I. Daubechies, W. Sweldens, "Factoring wavelet transforms into lifting steps",
J. Fourier Anal. Appl. 4(3):247-269, 1998.  PyWavelets documentation (``pywt.wavedec``,
"Signal extension modes").

Examples
--------
>>> import numpy as np
>>> from fogdrift.lifting import choose_level, level_scan, separate
>>> x = np.random.default_rng(0).standard_normal(4096)
>>> level = choose_level(level_scan(x, 0.1, "db4", max_level=5))  # white noise: the deepest
>>> level
5
>>> drift, noise = separate(x, "db4", level=level, mode="symmetric")
>>> drift.shape == noise.shape == x.shape
True
"""

from __future__ import annotations

from ._kernels import _get_backend, _set_backend
from .levels import LevelDiagnostic, choose_level, level_scan
from .schemes import WAVELETS, LiftingScheme, LiftingStep, get_wavelet, wavelist
from .separation import causal_drift, separate
from .transform import MODES, lift, max_level, unlift, wavedec, waverec

__all__ = [
    "LiftingStep",
    "LiftingScheme",
    "WAVELETS",
    "MODES",
    "get_wavelet",
    "wavelist",
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
