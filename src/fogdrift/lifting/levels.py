"""Choice of the decomposition level: :func:`level_scan` describes the noise part of every
level, :func:`choose_level` picks one from those diagnostics.

This is the one implementation of the automatic level: :func:`~fogdrift.lifting.separate`
takes an integer level, and callers that want ``"auto"`` run
``choose_level(level_scan(x, dt_s, wavelet, mode=mode))`` first.  Units: ``x`` is a rate in
deg/h sampled every ``dt_s`` seconds.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from ..allan import allan_variance
from ..errors import ConfigError, InsufficientDataError
from ._drift import _drift_1d
from .schemes import get_wavelet
from ..units import check_dt_s
from .transform import _as_signal, _check_level, _check_mode, _max_level

__all__ = ["LevelDiagnostic", "level_scan", "choose_level"]


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
        As in :func:`~fogdrift.lifting.separate`.
    max_level : int, optional
        Highest level scanned; default and upper bound
        :func:`fogdrift.lifting.max_level` ``(n)``.

    Returns
    -------
    list of LevelDiagnostic
        One per level, in increasing order.

    Notes
    -----
    The ADEV slope is a least-squares fit of ``log ADEV`` on ``log tau`` over octave taus
    from ``dt_s`` to ``n*dt_s/10`` (overlapping estimator, NIST SP 1065 eq. 11).  A pure
    white-noise noise part has slope -1/2 (IEEE 952 Annex C); a noise part that is
    high-passed too hard (level too low) falls faster (towards -1 at large tau), and one
    that has swallowed part of the drift (level too high) is flatter or rising.
    """
    scheme = get_wavelet(wavelet)
    mode = _check_mode(mode)
    y = _as_signal(x)

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
    the drift (db2, J = 4, periodization: a sinusoid with a period of 4 * 2**J = 64 samples
    keeps 0.938 of its power in the drift whatever its phase; one of 2 * 2**J = 32 samples
    keeps 0.007 to 0.93 depending on its phase, 0.387 for a sine; measured in
    ``tests/lifting/test_lifting_levels.py``).

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
