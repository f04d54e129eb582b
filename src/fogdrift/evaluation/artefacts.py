"""Filtering-artefact check: does a compensator remove *real* rate along with the drift?

On a static record every low-frequency deviation looks like drift, so a compensator that subtracts a causal
smooth of the signal (persistence of the causal drift is a 128-s high-pass) lowers the Allan deviation at long
tau whether or not it knows anything about the gyro.  This check injects known rate signals into the held-out
block and measures how much of each survives the compensator:

* a **step** of amplitude A at a quarter of the active block: surviving fraction at delays of 10, 100 and
  1000 s (step-response error = 1 - survival);
* a **ramp** rising by A over the active block: surviving fraction of its slope (least squares);
* **sinusoids** A cos(2 pi f t) at f = 1, 2, 5 x 10^k Hz from 0.001 Hz to half the modelling rate (only
  frequencies with at least two periods in the block): the gain ``|response at f| / A`` (least squares on
  cos, sin and a constant).

The response is the difference of the compensated outputs with and without the injected signal (one-step
causal compensation at the modelling rate, exactly as ``fogdrift compensate`` runs it), so the gyro's own
noise cancels for linear compensators (AR, persistence, Kalman) and nearly so for the others.  The default
amplitude A is 3 x the standard deviation of the held-out rate (stated in the result).

**Flag.** A compensator *claims an improvement* around f when its compensated ADEV, at the tau where the Allan
filter is most sensitive to f (tau = 0.371 / f), is more than 10 % below the uncompensated ADEV of the same
block.  Removing more than 10 % of an injected sinusoid (gain < 0.9) in such a band is flagged: that
"improvement" is the removal of signal, which a static record cannot tell apart from drift.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from ..allan import allan_variance
from ..errors import ConfigError, InsufficientDataError
from ..models.causal_predictor import CausalPredictor, causal_weights

__all__ = ["ArtefactRow", "ArtefactResult", "artefact_check", "default_frequencies", "ALLAN_PEAK"]

#: tau * f at the maximum of the Allan-variance transfer function |H(f)|^2 = 2 sin^4(pi f tau) / (pi f tau)^2.
ALLAN_PEAK = 0.371


def default_frequencies(dt_s: float, duration_s: float) -> list:
    """1-2-5 series from 0.001 Hz to half the sample rate, keeping frequencies with >= 2 periods in ``duration_s``.

    Examples
    --------
    >>> default_frequencies(1.0, 3600.0)
    [0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5]
    """
    nyq = 0.5 / dt_s
    out = []
    for k in range(-3, 4):
        for m in (1, 2, 5):
            f = float(f"{m * 10.0 ** k:.12g}")
            if f <= nyq * (1 + 1e-12) and f * duration_s >= 2.0:
                out.append(f)
    return out


@dataclass(frozen=True)
class ArtefactRow:
    """How much of each injected signal one compensator leaves (1 = all of it survives)."""

    model: str
    gains: dict  # frequency [Hz] -> gain
    step_survival: dict  # delay [s] -> surviving fraction of the step
    ramp_survival: float
    adev_ratio: dict  # frequency [Hz] -> compensated / original ADEV at tau = 0.371 / f (None outside the curve)
    flagged_hz: tuple  # frequencies where it claims an improvement and removes > 10 % of the signal

    def to_dict(self) -> dict:
        def clean(d):
            return {str(k): (None if v is None or not math.isfinite(v) else float(v)) for k, v in d.items()}

        return {"model": self.model, "gain_vs_frequency": clean(self.gains), "step_survival": clean(self.step_survival),
                "ramp_survival": None if not math.isfinite(self.ramp_survival) else self.ramp_survival,
                "adev_ratio_at_0.371_over_f": clean(self.adev_ratio), "flagged_hz": list(self.flagged_hz)}


@dataclass
class ArtefactResult:
    """Result of :func:`artefact_check` for one axis."""

    axis: str
    dt_s: float
    amplitude_dph: float
    frequencies_hz: list
    step_delays_s: tuple
    rows: list
    notes: list = field(default_factory=list)

    def row(self, model: str) -> ArtefactRow:
        for r in self.rows:
            if r.model == model:
                return r
        raise KeyError(model)

    def to_dict(self) -> dict:
        return {"axis": self.axis, "dt_s": self.dt_s, "amplitude_dph": self.amplitude_dph,
                "frequencies_hz": self.frequencies_hz, "step_delays_s": list(self.step_delays_s),
                "rows": [r.to_dict() for r in self.rows], "notes": self.notes}


def _one_step(z, model, g):
    """Compensated series z - p (p = causal one-step drift estimate, 0 before the model has one)."""

    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        p = CausalPredictor(model, g).push(z)
    return z - np.where(np.isfinite(p), p, 0.0), np.isfinite(p)


def _amplitude_at(d, t, f):
    cols = [np.cos(2 * np.pi * f * t), np.sin(2 * np.pi * f * t), np.ones_like(t)]
    sol, *_ = np.linalg.lstsq(np.column_stack(cols), d, rcond=None)
    return float(math.hypot(sol[0], sol[1]))


def _adev_ratio_fn(base, comp, dt):
    try:
        a = allan_variance(base, dt, taus="octave")
        b = allan_variance(comp, dt, taus="octave")
    except Exception:  # noqa: BLE001 - too short: no claim can be evaluated
        return lambda tau: None
    lt = np.log(a.tau_s)
    lr = np.log(b.adev_dph / a.adev_dph)

    def at(tau):
        if not lt[0] <= math.log(tau) <= lt[-1]:
            return None
        return float(np.exp(np.interp(math.log(tau), lt, lr)))

    return at


def artefact_check(rate_dph, dt_s, models, *, causal_window: int, wavelet="db2", level=4, mode="symmetric",
                   amplitude_dph=None, frequencies_hz=None, step_delays_s=(10.0, 100.0, 1000.0),
                   claim_ratio=0.9, removal=0.1, axis="") -> ArtefactResult:
    """Inject known signals into ``rate_dph`` and measure what each compensator leaves (module docstring).

    Parameters
    ----------
    rate_dph : array_like, shape (n,)
        Held-out rate [deg/h] at the modelling interval (bias-removed as in training).
    dt_s : float
    models : dict
        Label -> fitted DriftModel.
    causal_window : int
        Causal-drift window [samples] of the drift models.
    wavelet, level, mode
        Separation settings of the models.
    amplitude_dph : float, optional
        Amplitude A of every injected signal [deg/h]; default 3 x std(rate_dph).
    frequencies_hz : sequence of float, optional
        Default :func:`default_frequencies` of the active block.
    step_delays_s : sequence of float
        Delays after the step at which its survival is read.
    claim_ratio, removal : float
        A band "claims an improvement" where compensated/original ADEV < ``claim_ratio``; it is flagged
        when the gain there is below ``1 - removal``.
    axis : str

    Returns
    -------
    ArtefactResult
        Rows for every model plus ``"constant bias"`` (gain 1 by construction).

    Raises
    ------
    ConfigError
        ``rate_dph`` is not a finite 1-D block of at least 4 causal windows.
    InsufficientDataError
        A compensator predicts nothing before the last 4 samples of the block.

    Examples
    --------
    Persistence of the causal drift is a high-pass: a slow sinusoid barely survives, a fast one does.

    >>> from fogdrift.models import Persistence
    >>> z = np.random.default_rng(0).normal(0.0, 5.0, 4000)
    >>> res = artefact_check(z, 1.0, {"persistence": Persistence().fit(z[:5])}, causal_window=128,
    ...                      frequencies_hz=[0.002, 0.2])
    >>> g = res.row("persistence").gains
    >>> g[0.002] < 0.3, g[0.2] > 0.9
    (True, True)
    """

    z = np.asarray(rate_dph, dtype=np.float64)
    if z.ndim != 1 or z.size < 4 * int(causal_window) or not np.all(np.isfinite(z)):
        raise ConfigError(f"the artefact check needs a finite 1-D block of at least 4 causal windows "
                          f"({4 * int(causal_window)} samples); got {z.shape}")
    dt = float(dt_s)
    g = causal_weights(int(causal_window), wavelet, level, mode)
    A = float(amplitude_dph) if amplitude_dph is not None else 3.0 * float(np.std(z))
    n = z.size
    t = np.arange(n) * dt
    notes = [f"amplitude {A:.6g} deg/h for every injected signal"]
    bases = {label: _one_step(z, model, g) for label, model in models.items()}
    k0 = max([int(np.argmax(ok)) if ok.any() else n for _, ok in bases.values()] + [int(causal_window)])
    if n - k0 < 4:  # (was a ZeroDivisionError / numpy TypeError further down)
        late = [label for label, (_, ok) in bases.items() if not ok[:n - 3].any()]
        raise InsufficientDataError(f"the artefact check needs compensated samples to read: no prediction from "
                                    f"{', '.join(late)} before sample {k0} of the {n}-sample block", needed=4,
                                    got=n - k0)
    active = slice(k0, n)
    freqs = list(frequencies_hz) if frequencies_hz is not None else default_frequencies(dt, (n - k0) * dt)
    dropped = [f for f in freqs if f * (n - k0) * dt < 2.0 or f > 0.5 / dt * (1 + 1e-12)]
    freqs = [f for f in freqs if f not in dropped]
    if dropped:
        notes.append(f"frequencies {dropped} Hz dropped (fewer than 2 periods in the block, or above Nyquist)")
    k_step = k0 + (n - k0) // 4
    delays = [d for d in step_delays_s if k_step + int(round(d / dt)) < n]
    signals = {("sin", f): A * np.cos(2 * np.pi * f * t) for f in freqs}
    signals[("step", 0)] = np.where(np.arange(n) >= k_step, A, 0.0)
    ramp_slope = A / ((n - k0) * dt)
    signals[("ramp", 0)] = np.where(np.arange(n) >= k0, ramp_slope * (t - k0 * dt), 0.0)

    rows = [ArtefactRow(model="constant bias", gains={f: 1.0 for f in freqs},
                        step_survival={d: 1.0 for d in delays}, ramp_survival=1.0,
                        adev_ratio={f: 1.0 for f in freqs}, flagged_hz=())]
    for label, model in models.items():
        comp0, _ = bases[label]
        ratio_at = _adev_ratio_fn(z[active], comp0[active], dt)
        gains, steps, ramp = {}, {}, math.nan
        for key, s in signals.items():
            comp, _ = _one_step(z + s, model, g)
            d = (comp - comp0)[active]
            ta = t[active]
            if key[0] == "sin":
                gains[key[1]] = _amplitude_at(d, ta, key[1]) / A
            elif key[0] == "step":
                full = comp - comp0
                for delay in delays:
                    k = k_step + int(round(delay / dt))
                    w = max(1, int(round(0.05 * delay / dt)))
                    steps[delay] = float(np.mean(full[max(k_step, k - w):k + w + 1])) / A
            else:
                half = slice((n - k0) // 2, None)  # after the transient of the ramp's start
                slope = np.polyfit(ta[half], d[half], 1)[0]
                ramp = float(slope / ramp_slope)
        claims = {f: ratio_at(ALLAN_PEAK / f) for f in freqs}
        flagged = tuple(f for f in freqs if claims[f] is not None and claims[f] < claim_ratio
                        and gains[f] < 1.0 - removal)
        rows.append(ArtefactRow(model=label, gains=gains, step_survival=steps, ramp_survival=ramp,
                                adev_ratio=claims, flagged_hz=flagged))
    return ArtefactResult(axis=axis, dt_s=dt, amplitude_dph=A, frequencies_hz=freqs, step_delays_s=tuple(delays),
                          rows=rows, notes=notes)
