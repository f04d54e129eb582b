"""What ``fogdrift plan`` plans for: the noise model (stated, read from a fogdrift JSON, or identified from a pilot
log), the targets (term -> relative 95 % half-width) and record lengths, parsed with one clear line on bad input.

The model is the IEEE-952 power-law terms of a gyro in their reported units (Q [urad], N [deg/sqrt(h)], B [deg/h],
K [deg/h^1.5], R [deg/h^2]) plus the sample interval; :meth:`PlanModel.law_coefficients` gives the Allan-law
coefficients ``A`` the fit works with (``A = (value / to_unit)^2 * law.scale(dt)``, the inverse of
:meth:`fogdrift.noise.NoiseFit.coefficient`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import documents
from ..errors import ConfigError
from ..noise.terms import TERM_TABLE, all_terms, laws_of
from ..signal import record_sampling
from ..spec import norm_unit
from ..units import ARCSEC_PER_DEG, DEG_PER_RAD, S_PER_H, S_PER_MIN, URAD_PER_ARCSEC

__all__ = ["PlanModel", "parse_model", "parse_targets", "parse_length", "model_from_fit", "read_model_file",
           "DEFAULT_TARGETS", "PLANNED_TERMS", "fmt_length"]

#: Terms the planner handles (the built-in power laws; S and M are not planned).
PLANNED_TERMS = ("Q", "N", "B", "K", "R")

#: Terms whose Allan variance does not fall with tau (flat or rising): a longer record sees them at taus a pilot
#: never reached, so a pilot's bound on them is only an extrapolation (Q falls faster than white noise: the
#: pilot's short taus already bound it as well as the longer record will).
LONG_TAU_TERMS = ("B", "K", "R")

#: Default relative 95 % half-width per term (a term is planned only when the model holds it).
DEFAULT_TARGETS = {"Q": 0.25, "N": 0.05, "B": 0.10, "K": 0.25, "R": 0.25}

# normalised unit text (fogdrift.spec's spelling rules) -> factor to the term's reported unit
_UNITS = {
    "Q": {"urad": 1.0, "rad": 1e6, "mrad": 1e3, "arcsec": TERM_TABLE["Q"].to_unit,
          "deg": ARCSEC_PER_DEG * URAD_PER_ARCSEC},
    "N": {"deg/sqrt(h)": 1.0, "deg/h/sqrt(hz)": 1 / 60, "deg/sqrt(s)": 60.0, "deg/s/sqrt(hz)": 60.0,
          "rad/sqrt(s)": 60.0 * DEG_PER_RAD, "rad/s/sqrt(hz)": 60.0 * DEG_PER_RAD, "rad/sqrt(h)": DEG_PER_RAD},
    "B": {"deg/h": 1.0, "deg/s": S_PER_H, "rad/s": S_PER_H * DEG_PER_RAD, "rad/h": DEG_PER_RAD,
          "mdeg/s": S_PER_H / 1000.0},
    "K": {"deg/h^1.5": 1.0, "deg/h/sqrt(h)": 1.0, "deg/h^(3/2)": 1.0, "deg/s^1.5": S_PER_H**1.5,
          "deg/s/sqrt(s)": S_PER_H**1.5, "deg/s^2/sqrt(hz)": S_PER_H**1.5, "rad/s^1.5": S_PER_H**1.5 * DEG_PER_RAD,
          "rad/s/sqrt(s)": S_PER_H**1.5 * DEG_PER_RAD, "rad/s^2/sqrt(hz)": S_PER_H**1.5 * DEG_PER_RAD},
    "R": {"deg/h^2": 1.0, "deg/h/h": 1.0, "deg/s^2": S_PER_H**2, "rad/s^2": S_PER_H**2 * DEG_PER_RAD},
}
_TIME = {"s": 1.0, "sec": 1.0, "min": S_PER_MIN, "m": S_PER_MIN, "h": S_PER_H, "hr": S_PER_H, "hour": S_PER_H,
         "hours": S_PER_H, "d": 86400.0, "day": 86400.0, "days": 86400.0}
_NUM = r"([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"


@dataclass(frozen=True)
class PlanModel:
    """A gyro noise model to plan for: ``coefficients`` term -> value in its reported unit (> 0), ``dt_s`` [s].

    ``tau_min_s`` [s]: the shortest tau the fit will use (None: ``dt_s``).  A pilot's Allan fit leaves out the short
    taus no term describes (an output filter, correlated samples, a spectral line); the same sensor's longer
    record shows them again, so the plan fits from the pilot's first fitted tau.
    ``bounds``: term -> 95 % upper bound [reported unit] of the long-tau terms (:data:`LONG_TAU_TERMS`) the pilot
    could only bound (absent from its model); the plan adds each at
    :data:`~fogdrift.plan.analytic.BOUND_FRACTION` of its bound as a plausible alternative (:mod:`.analytic`).
    """

    coefficients: dict
    dt_s: float
    source: str = "stated"
    notes: tuple = field(default_factory=tuple)
    tau_min_s: float | None = None
    bounds: dict = field(default_factory=dict)

    @property
    def terms(self) -> tuple:
        return tuple(t for t in PLANNED_TERMS if self.coefficients.get(t, 0.0) > 0)

    def law_coefficients(self) -> np.ndarray:
        """``A`` of every fit column (:func:`fogdrift.noise.terms.all_terms` order; S and M zero) [(deg/h)^2]."""
        names = all_terms()
        laws = laws_of("adev")
        A = np.zeros(len(names))
        for t in self.terms:
            A[names.index(t)] = (self.coefficients[t] / TERM_TABLE[t].to_unit) ** 2 * laws[t].scale(self.dt_s)
        return A

    def simulate_kwargs(self) -> dict:
        """Keyword arguments of :func:`fogdrift.simulate.simulate` for this model."""
        key = {"Q": "q_urad", "N": "arw_dprh", "B": "bias_instability_dph", "K": "rrw_dphrh", "R": "ramp_dph2"}
        return {key[t]: float(self.coefficients[t]) for t in self.terms}

    def text(self) -> str:
        return ", ".join(f"{t} = {self.coefficients[t]:.4g} {TERM_TABLE[t].unit}" for t in self.terms)

    def to_dict(self) -> dict:
        return {"dt_s": self.dt_s, "sample_rate_hz": 1.0 / self.dt_s, "source": self.source,
                "terms": {t: {"value": float(self.coefficients[t]), "unit": TERM_TABLE[t].unit} for t in self.terms},
                "tau_min_s": self.tau_min_s,
                "bounds": {t: {"hi95": float(v), "unit": TERM_TABLE[t].unit} for t, v in self.bounds.items()},
                "notes": list(self.notes)}


def _check_dt(dt_s) -> float:
    try:
        dt = float(dt_s)
    except (TypeError, ValueError):
        dt = math.nan
    if not (math.isfinite(dt) and dt > 0):
        raise ConfigError(f"the sample interval must be a finite number > 0 s; got {dt_s!r} (option {{opt:rate_hz}})")
    return dt


def _make(coefs: dict, dt_s, source, notes=(), tau_min_s=None, bounds=None) -> PlanModel:
    model = PlanModel(dict(coefs), _check_dt(dt_s), source, tuple(notes), tau_min_s, dict(bounds or {}))
    if not model.terms:
        raise ConfigError("the model holds no noise term > 0 to plan for (Q, N, B, K or R)")
    return model


def parse_model(text: str, dt_s) -> PlanModel:
    """``"N=0.15 deg/sqrt(h), B=0.5 deg/h, K=0.02 deg/h^1.5"`` at sample interval ``dt_s`` [s] -> :class:`PlanModel`.

    Every value needs its unit (one of the term's units above); a term may appear once; S, M and unknown names
    are refused.

    Examples
    --------
    >>> m = parse_model("N=0.15 deg/sqrt(h), B=0.5 deg/h, K=1 deg/s/sqrt(s)", 0.01)
    >>> m.coefficients["N"], m.coefficients["B"], m.coefficients["K"]
    (0.15, 0.5, 216000.0)
    """
    if not isinstance(text, str) or not text.strip():
        raise ConfigError("{opt:model} is empty; write terms such as \"N=0.15 deg/sqrt(h), B=0.5 deg/h\"")
    coefs = {}
    for item in (p.strip() for p in text.split(",")):
        if not item:
            continue
        m = re.fullmatch(r"([A-Za-z]+)\s*[=:]\s*" + _NUM + r"\s*(.*)", item)
        if not m:
            raise ConfigError(f"{{opt:model}}: {item!r} is not TERM=VALUE UNIT (e.g. \"B=0.5 deg/h\")")
        name, value, unit = m.group(1).upper(), float(m.group(2)), m.group(3).strip()
        if name not in _UNITS:
            raise ConfigError(f"{{opt:model}}: unknown term {m.group(1)!r}; the planner takes "
                              f"{', '.join(PLANNED_TERMS)}")
        if name in coefs:
            raise ConfigError(f"{{opt:model}}: term {name} given twice")
        if not unit:
            raise ConfigError(f"{{opt:model}}: {item!r} has no unit; write it with one, e.g. "
                              f"\"{name}={m.group(2)} {TERM_TABLE[name].unit}\"")
        key = norm_unit(unit).replace("^(1.5)", "^1.5")
        if key not in _UNITS[name]:
            raise ConfigError(f"{{opt:model}}: unknown unit {unit!r} for {name}; expected one of "
                              f"{', '.join(_UNITS[name])}")
        if not (math.isfinite(value) and value >= 0):
            raise ConfigError(f"{{opt:model}}: {name} must be a finite number >= 0; got {item!r}")
        coefs[name] = value * _UNITS[name][key]
    return _make(coefs, dt_s, "stated")


def parse_targets(text, terms) -> dict:
    """``"B:10%,K:25%,N:2%"`` -> {term: relative half-width}; ``None``/empty: :data:`DEFAULT_TARGETS` of ``terms``.

    Examples
    --------
    >>> parse_targets("B:10%, N:0.02", ("N", "B"))
    {'B': 0.1, 'N': 0.02}
    >>> parse_targets(None, ("N", "K"))
    {'N': 0.05, 'K': 0.25}
    """
    if text is None or not str(text).strip():
        return {t: DEFAULT_TARGETS[t] for t in terms}
    out = {}
    for item in (p.strip() for p in str(text).split(",")):
        if not item:
            continue
        m = re.fullmatch(r"([A-Za-z]+)\s*[:=]\s*" + _NUM + r"\s*(%?)", item)
        if not m:
            raise ConfigError(f"{{opt:target}}: {item!r} is not TERM:WIDTH (e.g. \"B:10%\")")
        name = m.group(1).upper()
        w = float(m.group(2)) / (100.0 if m.group(3) else 1.0)
        if name not in PLANNED_TERMS:
            raise ConfigError(f"{{opt:target}}: unknown term {m.group(1)!r}; expected one of {', '.join(PLANNED_TERMS)}")
        if name not in terms:
            raise ConfigError(f"{{opt:target}}: the model has no {name} term to plan for (model terms: "
                              f"{', '.join(terms)})")
        if not (0 < w < 1):
            raise ConfigError(f"{{opt:target}}: the width of {name} must be between 0 and 100 % (a relative 95 % "
                              f"half-width); got {item!r}")
        if name in out:
            raise ConfigError(f"{{opt:target}}: term {name} given twice")
        out[name] = w
    if not out:
        raise ConfigError("{opt:target} names no term")
    return out


def parse_length(text) -> float:
    """``"2h"``, ``"30 min"``, ``"1.5 d"``, ``"7200"`` (seconds) -> seconds (> 0).

    Examples
    --------
    >>> parse_length("2h"), parse_length("30 min"), parse_length("90")
    (7200.0, 1800.0, 90.0)
    """
    m = re.fullmatch(r"\s*" + _NUM + r"\s*([A-Za-z]*)\s*", str(text))
    if not m:
        raise ConfigError(f"{{opt:length}}: {text!r} is not a duration such as 2h, 30min, 1.5d or 7200s")
    unit = m.group(2).lower() or "s"
    if unit not in _TIME:
        raise ConfigError(f"{{opt:length}}: unknown time unit {m.group(2)!r}; expected one of s, min, h, d")
    v = float(m.group(1)) * _TIME[unit]
    if not (math.isfinite(v) and v > 0):
        raise ConfigError(f"{{opt:length}}: the length must be > 0; got {text!r}")
    return v


def fmt_length(seconds) -> str:
    """A record length in the unit that reads best: ``"45 s"``, ``"12 min"``, ``"5.2 h"``, ``"3.1 d"``."""
    if seconds is None or not math.isfinite(seconds):
        return "–"
    s = float(seconds)
    if s < 120:
        return f"{s:.3g} s"
    if s < 7200:
        return f"{s / S_PER_MIN:.3g} min"
    if s < 3 * 86400:
        return f"{s / S_PER_H:.3g} h"
    return f"{s / 86400:.3g} d"


def model_from_fit(noise, dt_s, source="pilot") -> PlanModel:
    """The model of an Allan fit (:class:`fogdrift.noise.NoiseFit`): every term of the selected model with a value
    > 0, the fit's first fitted tau (``tau_min_s``: the short taus it left out stay out of the plan) and the
    95 % upper bound of every long-tau term (:data:`LONG_TAU_TERMS`) not in its model (``bounds``: in the plan's
    union of models, see :mod:`fogdrift.plan.analytic`); terms the pilot could not estimate are named in the notes
    (with their bound)."""
    coefs, notes, bounds = {}, [], {}
    for t in PLANNED_TERMS:
        term = noise.terms.get(t)
        if term is None:
            continue
        if t in noise.selected and term.value and term.value > 0:
            coefs[t] = float(term.value)
            if term.status != "resolved":
                notes.append(f"{t} from the pilot is {term.status} ({term.value:.3g} {term.unit}, 95 % interval "
                             f"reaches 0): planned at its estimate")
        elif term.hi95 is not None and t in LONG_TAU_TERMS:
            if math.isfinite(term.hi95) and term.hi95 > 0:
                bounds[t] = float(term.hi95)
            notes.append(f"{t} is not in the pilot's model (< {term.hi95:.3g} {term.unit}): not planned (state "
                         "it with --model to plan for it); the widths allow for it at half that bound")
    fit_tau = getattr(noise, "fit_tau_s", None)
    tau_min = float(fit_tau[0]) if fit_tau is not None and len(fit_tau) else None
    if tau_min is not None and tau_min > float(dt_s) * (1 + 1e-9):
        notes.append(f"the pilot's fit starts at tau = {tau_min:.3g} s (shorter taus left out): so does the plan")
    return _make(coefs, dt_s, source, notes, tau_min, bounds)


def _from_terms(d: dict, dt_s, source) -> PlanModel:
    coefs = {}
    for t in PLANNED_TERMS:
        e = d.get(t)
        if isinstance(e, dict):
            v, unit = e.get("value"), e.get("unit", TERM_TABLE[t].unit)
            status = e.get("status", "resolved")
            if v is None or status in ("absent", "not_estimable", "no_fit"):
                continue
            key = norm_unit(unit)
            if key not in _UNITS[t]:
                raise ConfigError(f"{source}: unit {unit!r} of {t} is not a gyro unit the planner knows "
                                  f"({', '.join(_UNITS[t])})")
            coefs[t] = float(v) * _UNITS[t][key]
        elif isinstance(e, (int, float)) and not isinstance(e, bool):
            coefs[t] = float(e)
    return _make(coefs, dt_s, source)


def read_model_file(path, dt_s=None, axis=None) -> PlanModel:
    """A model from a fogdrift JSON: ``allan.json`` / ``noise.json`` (``--method allan``: the Allan fit of one axis,
    ``axis`` or the first) or ``noise_model.json`` (``fogdrift export``).  ``dt_s`` overrides the file's rate."""
    p = Path(path)
    try:
        data = documents.read(p, yaml=False)
    except FileNotFoundError:
        raise ConfigError(f"{p}: no such file") from None
    except documents.DocumentError as e:
        raise ConfigError(str(e)) from None
    except (OSError, ValueError) as e:
        raise ConfigError(f"{p}: not a readable JSON file ({e.__class__.__name__})") from None
    if not isinstance(data, dict):
        raise ConfigError(f"{p}: expected a fogdrift allan.json, noise.json or noise_model.json")
    axes = data.get("axes") or data.get("channels") or []
    if isinstance(axes, dict):
        axes = [dict(v, name=k) for k, v in axes.items()]
    for a in axes if isinstance(axes, list) else []:
        if not isinstance(a, dict) or (axis is not None and a.get("name", a.get("axis")) != axis):
            continue
        if a.get("quantity", "angular_rate") not in ("angular_rate", "gyro"):
            continue
        noise = a.get("noise") if isinstance(a.get("noise"), dict) else a
        terms = noise.get("terms")
        dt = dt_s if dt_s is not None else noise.get("dt_s", a.get("dt_s", data.get("dt_s")))
        if dt is None:
            smp = record_sampling(data.get("record"), f"{p}: the record")
            dt = None if smp is None else smp.dt_s
        if dt is None and a.get("sample_rate_hz", data.get("sample_rate_hz")):
            dt = 1.0 / float(a.get("sample_rate_hz", data.get("sample_rate_hz")))
        if isinstance(terms, dict):
            if dt is None:
                raise ConfigError(f"{p}: no sample interval in the file; give {{opt:rate_hz}}")
            return _from_terms(terms, dt, f"{p.name}" + (f" axis {a.get('name')}" if a.get("name") else ""))
    raise ConfigError(f"{p}: no gyro axis with noise terms{'' if axis is None else ' named ' + repr(axis)} "
                      "(expected a fogdrift allan.json, noise.json or noise_model.json)")


