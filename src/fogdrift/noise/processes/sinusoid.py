"""Sinusoidal (periodic) error: the S term of IEEE Std 952 Annex C.7, and the spectral lines of a periodic error.

Allan variance of a sinusoid of amplitude ``Omega0`` at ``f0``: ``Omega0^2 (sin^2(pi f0 tau) / (pi f0 tau))^2``,
here exact for sampled data (:func:`sinusoid_shape`); a periodic error is a sum of lines whose power ratios come from
the spectrum (:func:`periodic_shape`, one fitted scale).  IEEE-952 rate PSD ``Omega0^2 / 2 delta(f - f0)``.  A
line is never read as quantization: both estimators take the record's lines from one spectral analysis
(:mod:`fogdrift.noise.periodic`) and claim Q only where it stands above the lines' envelope.  Not a Kalman state:
it integrates to a bounded angle ``Omega0 / (2 pi f0)``, left out of the filter with a note.  SI amplitude [rad/s].
"""

from __future__ import annotations

import numpy as np

from ...errors import ConfigError
from ...units import RAD_PER_DEG, S_PER_H
from .base import NoiseProcess

__all__ = ["PROCESS", "sinusoid_shape", "periodic_shape"]

SHAPED = {"long_name": "sinusoidal (periodic) error", "unit": "deg/h", "freq_unit": "Hz",
          "source": "IEEE Std 952-1997 Annex C.7 (sinusoidal noise): sigma^2 = Omega0^2 (sin^2(pi f0 tau) / "
                    "(pi f0 tau))^2; here exact for sampled data: pi f0 tau -> m sin(pi f0 dt)"}


def sinusoid_shape(tau_s, freq_hz, dt_s, statistic="adev", *, envelope=False) -> np.ndarray:
    """Variance of a unit-amplitude sinusoid of ``freq_hz`` [Hz] at ``tau_s`` [s] (``A = Omega0^2`` multiplies it).

    Derived for sampled data: the ``m``-sample mean of ``sin(2 pi f t_k + phi)`` is a sinusoid of amplitude
    ``D_m = sin(pi f tau) / (m sin(pi f dt))``; a first difference at lag ``tau`` multiplies the amplitude by
    ``2 sin(pi f tau)``, a second difference by ``4 sin^2(pi f tau)``, and a squared sinusoid averages to 1/2::

        adev: D_m^2 sin^2(pi f tau)          = sin^4(pi f tau) / (m sin(pi f dt))^2
        hdev: (4/3) D_m^2 sin^4(pi f tau)    = (4/3) sin^6(pi f tau) / (m sin(pi f dt))^2
        mdev: D_m^4 sin^2(pi f tau)          = sin^6(pi f tau) / (m sin(pi f dt))^4

    As ``dt -> 0`` (``m sin(pi f dt) -> pi f tau``) the Allan law is IEEE-952 Annex C's
    ``(sin^2(pi f tau) / (pi f tau))^2``.  Zero at every multiple of the period.  Checked against exact
    discrete computations on noiseless sinusoids in ``tests/noise/test_noise_periodic.py``.

    ``envelope=True``: the same law with ``sin(pi f tau)`` replaced by 1 (``1 / (m sin(pi f dt))^2`` for ``adev``),
    the upper envelope of the oscillating law: a real line's amplitude and frequency wander, which fills the nulls,
    and its variance can reach the envelope at any ``tau``.

    Examples
    --------
    >>> float(sinusoid_shape(0.05, 20.0, 0.01)[()]) < 1e-30     # a whole period: the sinusoid cancels
    True
    >>> round(float(sinusoid_shape(0.05, 20.0, 0.01, envelope=True)[()]), 4)   # 1 / (5 sin(0.2 pi))^2
    0.1158
    """
    t = np.asarray(tau_s, dtype=np.float64)
    f, dt = float(freq_hz), float(dt_s)
    m = np.rint(t / dt)
    s_tau = np.ones(t.shape) if envelope else np.sin(np.pi * f * m * dt)
    den = m * np.sin(np.pi * f * dt)
    with np.errstate(divide="ignore", invalid="ignore"):
        if statistic == "adev":
            out = s_tau**4 / den**2
        elif statistic == "hdev":
            out = (4.0 / 3.0) * s_tau**6 / den**2
        elif statistic == "mdev":
            out = s_tau**6 / den**4
        else:
            raise ConfigError(f"no sinusoid law for statistic {statistic!r}; expected one of adev, hdev, mdev")
    return np.where(np.isfinite(out), out, 0.0)


def periodic_shape(tau_s, lines, dt_s, statistic="adev", *, envelope=False) -> np.ndarray:
    """Variance shape of a periodic error made of spectral lines ``[(freq_hz, relative_power), ...]``.

    The lines' powers relative to the first (the fundamental, ``relative_power`` 1) are fixed from the spectrum and
    one scale ``A = Omega0^2`` (the fundamental's squared amplitude [(deg/h)^2]) is fitted: the lines of one periodic
    error share its amplitude drift, the spectrum measures their ratios far better than the tau curve could, and one
    parameter per component keeps the model selection from trading harmonics against Q.  ``envelope``: each line's
    envelope instead of its law (:func:`sinusoid_shape`).
    """
    t = np.asarray(tau_s, dtype=np.float64)
    out = np.zeros(t.shape)
    for f, r in lines:
        out = out + float(r) * sinusoid_shape(t, f, dt_s, statistic, envelope=envelope)
    return out


PROCESS = NoiseProcess(
    "S", "sinusoid", shaped=SHAPED, shape=periodic_shape,
    si={"gyro": ("rad/s", RAD_PER_DEG / S_PER_H), "accel": ("m/s^2", 1.0)},
    source=SHAPED["source"],
)
