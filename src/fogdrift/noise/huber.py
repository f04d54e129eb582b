"""The Huber constant of the noise-fit objective: one home, read by :mod:`.engine` (NumPy) and :mod:`._kernels` (numba).

A whitened Wilson-Hilferty residual beyond ``HUBER_K`` standard deviations counts linearly, not quadratically,
so one extreme innovation (typically the last, 1-3 EDF octave, whose distribution is far from normal) cannot drag
the whole fit.  Normal residuals exceed it with probability 0.27 %.  Kept apart from both users so that the
NumPy engine does not import numba and the compiled kernels do not import the engine (no import cycle).
"""

__all__ = ["HUBER_K"]

#: Huber constant in standard deviations of the whitened residual (dimensionless).
HUBER_K = 3.0
