"""Datasheet comparison (``--spec FILE``): pass / fail / cannot tell per channel, judged with the interval.

A spec file is a small YAML or JSON mapping of datasheet limits, each a string with its unit::

    sensor: ADIS16405 (datasheet, typical)
    gyro:
      arw: "2 deg/sqrt(h)"
      bias_instability: "0.007 deg/s"
    accel:
      vrw: "0.2 m/s/sqrt(h)"
      bias_instability: "0.2 mg"

Items (:data:`ITEMS`): ``gyro.arw`` (angle random walk N), ``gyro.bias_instability`` (B), ``accel.vrw``
(velocity random walk), ``accel.bias_instability``.  Every limit is an upper limit ("the sensor's figure is at
most this").  A number without a unit, or a unit this module does not know for that item, is refused with one
line (:class:`~fogdrift.errors.ConfigError`): units are never guessed.

Judgement (:func:`judge`), with the estimate's 95 % interval [lo, hi] and the limit L:

* **pass**: hi <= L (the whole interval is within the limit);
* **fail**: lo > L (the whole interval is beyond it);
* **cannot tell**: L lies inside the interval (the record cannot decide; a longer record can);
* an **upper bound only** (e.g. B_min when the ADEV still falls at the longest tau, or any term when no
  model fits): it can tell a pass (bound <= L), never a fail; a **lower bound only** can tell a fail, never
  a pass; no estimate: cannot tell.

Which B is compared: the IEEE-952 reading **B_min = min ADEV / 0.664** (:attr:`fogdrift.noise.NoiseFit.b_min`,
for GMWM :attr:`fogdrift.gmwm.ieee.IEEEResult.b_min`): the figure datasheets quote as "(in-run) bias
stability", read at the minimum of the fitted Allan deviation.  Not the flicker coefficient of the fit, not
the Gauss-Markov hump.

Conversions (each item's canonical unit first): 1 deg/s = 3600 deg/h; 1 deg/h/sqrt(Hz) = 1/60 deg/sqrt(h);
1 deg/sqrt(s) = 1 deg/s/sqrt(Hz) = 60 deg/sqrt(h); 1 g = 9.80665 m/s^2 (standard gravity, CGPM 1901);
1 m/s^2/sqrt(Hz) = 1 m/s/sqrt(s) = 60 m/s/sqrt(h).
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

from . import documents
from ._util import fmt_number
from .errors import ConfigError
from .units import DEG_PER_RAD, S_PER_H, STANDARD_GRAVITY_MPS2

__all__ = ["analysis_judgements", "ITEMS", "G0", "SpecLimit", "Reading", "Judgement", "parse_quantity", "convert", "read_spec",
           "parse_spec", "judge", "readings_from_noise_fit", "readings_from_gmwm", "compare", "B_COMPARED",
           "channel_kind", "judgement_line", "spec_columns", "judge_noise_fit", "norm_unit"]

#: Standard gravity [m/s^2] (CGPM 1901; ISO 80000-3).
G0 = STANDARD_GRAVITY_MPS2

#: What B is compared, in words (printed under every comparison).
B_COMPARED = ("B compared: the IEEE-952 reading B_min = min of the fitted Allan deviation / 0.664 (what datasheets "
              "quote as bias stability), not the flicker coefficient or the Gauss-Markov hump")

# unit tables: normalised unit text -> factor to the item's canonical unit
_ARW = {"deg/sqrt(h)": 1.0, "deg/h/sqrt(hz)": 1.0 / 60.0, "deg/sqrt(s)": 60.0, "deg/s/sqrt(hz)": 60.0,
        "rad/sqrt(s)": 60.0 * DEG_PER_RAD, "rad/s/sqrt(hz)": 60.0 * DEG_PER_RAD,
        "rad/sqrt(h)": DEG_PER_RAD, "mrad/sqrt(h)": 1e-3 * DEG_PER_RAD}
_GYRO_B = {"deg/h": 1.0, "deg/s": S_PER_H, "rad/s": S_PER_H * DEG_PER_RAD, "rad/h": DEG_PER_RAD,
           "mdeg/s": S_PER_H / 1000.0, "arcsec/s": 1.0}
_VRW = {"m/s/sqrt(h)": 1.0, "m/s/sqrt(s)": 60.0, "m/s^2/sqrt(hz)": 60.0, "g/sqrt(hz)": 60.0 * G0,
        "mg/sqrt(hz)": 60e-3 * G0, "ug/sqrt(hz)": 60e-6 * G0, "ft/s/sqrt(h)": 0.3048}
_ACC_B = {"m/s^2": 1.0, "g": G0, "mg": 1e-3 * G0, "ug": 1e-6 * G0, "mm/s^2": 1e-3}

#: (channel kind, item) -> (canonical unit, unit table, what it is, aliases of the item name).
ITEMS: dict[tuple[str, str], tuple[str, dict, str, tuple]] = {
    ("gyro", "arw"): ("deg/sqrt(h)", _ARW, "angle random walk N", ("arw", "angle_random_walk", "n")),
    ("gyro", "bias_instability"): ("deg/h", _GYRO_B, "bias instability B (B_min)",
                                   ("bias_instability", "bias_stability", "in_run_bias_stability", "b")),
    ("accel", "vrw"): ("m/s/sqrt(h)", _VRW, "velocity random walk", ("vrw", "velocity_random_walk", "n")),
    ("accel", "bias_instability"): ("m/s^2", _ACC_B, "bias instability B (B_min)",
                                    ("bias_instability", "bias_stability", "in_run_bias_stability", "b")),
}
_KINDS = {"gyro": "gyro", "gyroscope": "gyro", "accel": "accel", "accelerometer": "accel"}
_NUMBER = re.compile(r"^\s*([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)\s*(.*?)\s*$")


def norm_unit(text: str) -> str:
    """Lower case, no spaces, one spelling: ° -> deg, µ -> u, hr -> h, sec -> s, √x / rt(x) -> sqrt(x), ² -> ^2."""
    u = str(text).strip().lower().replace(" ", "")
    u = u.replace("°", "deg").replace("µ", "u").replace("μ", "u").replace("²", "^2").replace("**", "^")
    u = re.sub(r"degrees?", "deg", u)
    u = u.replace("(m/s)", "m/s").replace("(deg/h)", "deg/h").replace("(deg/s)", "deg/s").replace("(rad/s)", "rad/s")
    u = re.sub(r"(?<![a-z])(hr|hour|hours)(?![a-z])", "h", u)
    u = re.sub(r"(?<![a-z])(sec|second|seconds)(?![a-z])", "s", u)
    u = re.sub(r"(√|sqrt|rt-?)\(?(hz|h|s)\)?(?![a-z])", r"sqrt(\2)", u)
    u = re.sub(r"/s2(?![0-9])", "/s^2", u)
    return u


def parse_quantity(text, kind: str, item: str) -> tuple[float, str]:
    """``"0.007 deg/s"`` -> (value in the item's canonical unit, the unit as written).

    Raises
    ------
    ConfigError
        No unit (a bare number), an unknown unit for the item, a negative or non-finite value.

    Examples
    --------
    >>> parse_quantity("0.007 deg/s", "gyro", "bias_instability")
    (25.2, 'deg/s')
    >>> round(parse_quantity("0.2 mg", "accel", "bias_instability")[0], 9)
    0.00196133
    """
    canonical, table, what, _ = ITEMS[(kind, item)]
    where = f"{kind}.{item}"
    if isinstance(text, bool) or isinstance(text, (int, float)):
        raise ConfigError(f"spec {where}: {text!r} has no unit; write it with one, e.g. \"{text} {canonical}\"")
    if not isinstance(text, str):
        raise ConfigError(f"spec {where}: expected a value with its unit such as \"2 {canonical}\"; got {text!r}")
    m = _NUMBER.match(text)
    if not m:
        raise ConfigError(f"spec {where}: {text!r} is not a number followed by a unit (e.g. \"2 {canonical}\")")
    value, unit = float(m.group(1)), m.group(2)
    if not unit:
        raise ConfigError(f"spec {where}: {text!r} has no unit; write it with one, e.g. \"{text.strip()} "
                          f"{canonical}\"")
    key = norm_unit(unit)
    if key not in table:
        raise ConfigError(f"spec {where}: unknown unit {unit!r} for the {what}; expected one of "
                          f"{', '.join(table)}")
    if not (math.isfinite(value) and value >= 0):
        raise ConfigError(f"spec {where}: the limit must be a finite number >= 0; got {text!r}")
    return value * table[key], unit


def convert(value: float, unit: str, kind: str, item: str) -> float:
    """``value`` in ``unit`` -> the item's canonical unit (ConfigError on an unknown unit).

    Examples
    --------
    >>> convert(0.15, "deg/sqrt(h)", "gyro", "arw") == 0.15
    True
    >>> round(convert(1.0, "m/s^2/sqrt(Hz)", "accel", "vrw"), 9)
    60.0
    """
    table = ITEMS[(kind, item)][1]
    key = norm_unit(unit)
    if key not in table:
        raise ConfigError(f"unit {unit!r} is not one of the {kind} {item} units ({', '.join(table)})")
    return float(value) * table[key]


@dataclass(frozen=True)
class SpecLimit:
    """One datasheet limit: ``kind`` (gyro/accel), ``item``, ``value`` in the canonical unit, as written."""

    kind: str
    item: str
    value: float
    text: str

    @property
    def unit(self) -> str:
        return ITEMS[(self.kind, self.item)][0]


def parse_spec(data, *, source: str = "spec") -> dict:
    """Spec mapping -> ``{"sensor": str or None, "limits": [SpecLimit, ...]}`` (module docstring for the form)."""
    if not isinstance(data, dict):
        raise ConfigError(f"{source}: expected a mapping such as {{gyro: {{arw: \"2 deg/sqrt(h)\"}}}}; got "
                          f"{type(data).__name__}")
    sensor = data.get("sensor")
    limits = []
    for key, block in data.items():
        if key in ("sensor", "note", "notes", "source"):
            continue
        kind = _KINDS.get(str(key).lower())
        if kind is None:
            raise ConfigError(f"{source}: unknown section {key!r}; expected gyro or accel (and sensor, note)")
        if not isinstance(block, dict):
            raise ConfigError(f"{source}: section {key!r} must map items to limits, e.g. arw: \"2 deg/sqrt(h)\"")
        for name, text in block.items():
            item = next((it for (k, it), spec in ITEMS.items() if k == kind and str(name).lower() in spec[3]), None)
            if item is None:
                known = ", ".join(it for (k, it) in ITEMS if k == kind)
                raise ConfigError(f"{source}: unknown {kind} item {name!r}; expected one of {known}")
            value, _ = parse_quantity(text, kind, item)
            limits.append(SpecLimit(kind=kind, item=item, value=value, text=str(text).strip()))
    if not limits:
        raise ConfigError(f"{source}: no limits (expected gyro: and/or accel: sections)")
    return {"sensor": None if sensor is None else str(sensor), "limits": limits}


def read_spec(path) -> dict:
    """Read a YAML (``.yaml``/``.yml``) or JSON spec file; see :func:`parse_spec`.  One-line errors."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"spec file: no such file {p}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"spec file: cannot read {p} ({exc})") from None
    if p.suffix.lower() in (".yaml", ".yml"):
        try:
            import yaml
        except ImportError:  # pragma: no cover - PyYAML is installed with the test and fleet extras
            raise ConfigError(f"{p}: reading YAML needs PyYAML (pip install pyyaml); or write the spec as JSON") \
                from None
        try:
            data = documents.loads(text, p, yaml=True)
        except documents.DocumentError as exc:
            raise ConfigError(str(exc)) from None
        except yaml.YAMLError as exc:
            mark = getattr(exc, "problem_mark", None)
            where = f":{mark.line + 1}" if mark is not None else ""
            raise ConfigError(f"{p}{where}: not valid YAML ({getattr(exc, 'problem', None) or exc})") from None
    else:
        try:
            data = documents.loads(text, p)
        except documents.DocumentError as exc:
            raise ConfigError(str(exc)) from None
        except json.JSONDecodeError as exc:
            raise ConfigError(f"{p}:{exc.lineno}: not valid JSON ({exc.msg}); a .yaml/.yml name reads YAML") \
                from None
    return parse_spec(data, source=str(p))


@dataclass(frozen=True)
class Reading:
    """An estimate to judge, in the unit ``unit`` (converted to the item's canonical unit by :func:`judge`).

    Attributes
    ----------
    value : float or None
        The estimate; for ``bound="upper"`` / ``"lower"`` the bound itself.
    lo95, hi95 : float or None
        Its 95 % interval (None where not known).
    unit : str
    bound : str or None
        None (a value), ``"upper"`` (only "at most value" is known) or ``"lower"``.
    label : str
        Which reading it is, in words (e.g. "B_min at τ = 120 s").
    """

    value: float | None
    lo95: float | None
    hi95: float | None
    unit: str
    bound: str | None = None
    label: str = ""


@dataclass(frozen=True)
class Judgement:
    """Verdict of one limit on one channel: ``verdict`` in pass / fail / cannot tell, and why."""

    channel: str
    limit: SpecLimit
    reading: Reading | None
    verdict: str
    reason: str
    estimate: str

    def to_dict(self) -> dict:
        return {"channel": self.channel, "kind": self.limit.kind, "item": self.limit.item,
                "limit": self.limit.text, "limit_canonical": self.limit.value, "unit": self.limit.unit,
                "estimate": self.estimate, "verdict": self.verdict, "reason": self.reason,
                "reading": None if self.reading is None else self.reading.label}


def _g(x) -> str:
    """Three significant digits (``g`` rule, NaN as ``nan``): :func:`fogdrift._util.fmt_number`."""
    return fmt_number(x, 3, nonfinite=None)


def judge(limit: SpecLimit, reading: Reading | None, channel: str = "") -> Judgement:
    """Pass / fail / cannot tell of one upper limit against one reading (module docstring).

    Examples
    --------
    >>> lim = parse_spec({"gyro": {"arw": "2 deg/sqrt(h)"}})["limits"][0]
    >>> judge(lim, Reading(2.4, 2.37, 2.42, "deg/sqrt(h)")).verdict
    'fail'
    >>> judge(lim, Reading(2.1, 1.9, 2.3, "deg/sqrt(h)")).verdict
    'cannot tell'
    """
    u = limit.unit
    L = limit.value
    if reading is None or reading.value is None or not math.isfinite(reading.value):
        return Judgement(channel, limit, reading, "cannot tell", "no estimate of this term in the record", "–")
    try:
        c = convert(1.0, reading.unit, limit.kind, limit.item)
    except ConfigError:  # an estimate in a unit this table lacks (e.g. a gyro unit on an accel limit): say so
        return Judgement(channel, limit, reading, "cannot tell",
                         f"the estimate's unit {reading.unit!r} is not a {limit.kind} {limit.item} unit", "–")
    v = reading.value * c
    lo = None if reading.lo95 is None else reading.lo95 * c
    hi = None if reading.hi95 is None else reading.hi95 * c
    lim = f"limit {_g(L)} {u}"
    if reading.bound == "upper":
        est = f"< {_g(v)} {u}"
        if v <= L:
            return Judgement(channel, limit, reading, "pass", f"even its upper bound is within the {lim}", est)
        return Judgement(channel, limit, reading, "cannot tell",
                         f"only an upper bound ({_g(v)} > {_g(L)}): a bound can show a pass, never a fail", est)
    if reading.bound == "lower":
        est = f"> {_g(v)} {u}"
        if v > L:
            return Judgement(channel, limit, reading, "fail", f"even its lower bound exceeds the {lim}", est)
        return Judgement(channel, limit, reading, "cannot tell",
                         f"only a lower bound ({_g(v)} <= {_g(L)}): a lower bound can show a fail, never a pass", est)
    if lo is None or hi is None:
        return Judgement(channel, limit, reading, "cannot tell",
                         f"the estimate {_g(v)} {u} has no interval to judge with", f"{_g(v)} {u}")
    est = f"{_g(v)} [{_g(lo)}, {_g(hi)}] {u}"
    if hi <= L:
        return Judgement(channel, limit, reading, "pass", f"the whole 95 % interval is within the {lim}", est)
    if lo > L:
        return Judgement(channel, limit, reading, "fail", f"the whole 95 % interval exceeds the {lim}", est)
    return Judgement(channel, limit, reading, "cannot tell",
                     f"the {lim} lies inside the 95 % interval: this record cannot decide", est)


def channel_kind(quantity: str | None) -> str:
    """``"angular_rate"`` (or None) -> ``"gyro"``; ``"specific_force"`` -> ``"accel"``."""
    return "accel" if quantity == "specific_force" else "gyro"


def readings_from_noise_fit(noise, kind: str = "gyro") -> dict:
    """Readings of an Allan noise fit (:class:`fogdrift.noise.NoiseFit`): the white term (ARW/VRW) and B_min.

    The white term is ``terms["N"]`` with its 95 % interval; where no model fits, or the term is absent / not
    estimable, only its 95 % upper bound ``hi95`` is a reading.  B is the IEEE reading ``b_min`` (a bound when
    its ``bound_only`` says so).  Units are the fit's own (read from the terms), converted by :func:`judge`.
    """
    white_item = "arw" if kind == "gyro" else "vrw"
    out = {}
    t = noise.terms.get("N")
    if t is not None:
        if getattr(noise, "no_fit", None) or not t.estimable:
            out[white_item] = Reading(t.hi95, None, None, t.unit, "upper",
                                      "N: only its 95 % upper bound (" + ("no model fits" if getattr(
                                          noise, "no_fit", None) else t.status) + ")") if t.hi95 is not None else None
        else:
            out[white_item] = Reading(t.value, t.lo95, t.hi95, t.unit, None, "N from the Allan fit")
    b = noise.b_min or {}
    if b.get("value") is not None:
        at = f" at τ = {b['tau_s']:.4g} s" if b.get("tau_s") else ""
        if b.get("bound_only"):
            out["bias_instability"] = Reading(b["value"], None, None, b.get("unit", "deg/h"), "upper",
                                              f"B_min{at}, an upper bound")
        else:
            out["bias_instability"] = Reading(b["value"], b.get("lo95"), b.get("hi95"), b.get("unit", "deg/h"), None,
                                              f"B_min{at}")
    return _accel_in_place_of_deg_h(out) if kind == "accel" else out


#: An accelerometer fit whose terms still carry the gyro unit labels holds m/s^2 in place of deg/h (the internal unit
#: of a specific force): deg/sqrt(h) = (deg/h) sqrt(h) -> (m/s^2) sqrt(h) = 3600 m/s/sqrt(h); deg/h -> m/s^2.
_GYRO_LABEL_AS_ACCEL = {"deg/sqrt(h)": (S_PER_H, "m/s/sqrt(h)"), "deg/h": (1.0, "m/s^2")}


def _accel_in_place_of_deg_h(readings: dict) -> dict:
    """Re-read gyro-labelled readings of an accelerometer channel in m/s^2 units (a label that is already an
    accelerometer unit is kept)."""
    out = {}
    for item, r in readings.items():
        key = None if r is None else norm_unit(r.unit)
        if key not in _GYRO_LABEL_AS_ACCEL:
            out[item] = r
            continue
        f, unit = _GYRO_LABEL_AS_ACCEL[key]
        out[item] = Reading(*(None if x is None else x * f for x in (r.value, r.lo95, r.hi95)), unit, r.bound,
                            r.label + f" (fit labelled {r.unit}: m/s^2 in place of deg/h)")
    return out


def readings_from_gmwm(axis, kind: str = "gyro") -> dict:
    """Readings of a GMWM axis (:class:`fogdrift.gmwm.analysis.GmwmAxis`): N and the min-AVAR B reading."""
    ie = axis.selection.ieee
    out = {}
    n = ie.terms.get("N_dprh")
    if n is not None:
        out["arw" if kind == "gyro" else "vrw"] = Reading(n.value, n.lo95, n.hi95, n.unit, None, "N from GMWM")
    b = ie.b_min
    if b.value_dph is not None:
        at = f" at τ = {b.tau_s:.4g} s" if b.tau_s else ""
        out["bias_instability"] = Reading(b.value_dph, b.lo95_dph, b.hi95_dph, "deg/h", None, f"B_min{at} (GMWM)")
    elif b.bound_dph is not None:
        out["bias_instability"] = Reading(b.bound_dph, None, None, "deg/h", "upper",
                                          f"B_min, an upper bound ({b.reason})")
    return _accel_in_place_of_deg_h(out) if kind == "accel" else out


def compare(spec: dict, channels: dict) -> list[Judgement]:
    """Judge every limit of ``spec`` (:func:`parse_spec`) on every channel of its kind.

    Parameters
    ----------
    channels : dict
        Channel name -> ``(kind, {item: Reading})``.

    Returns
    -------
    list of Judgement
        In channel order, then the spec's order; a channel kind the spec has no limits for gives none.
    """
    out = []
    for name, (kind, readings) in channels.items():
        for lim in spec["limits"]:
            if lim.kind == kind:
                out.append(judge(lim, readings.get(lim.item), name))
    return out


def judgement_line(j: Judgement) -> str:
    """One line for a first screen or a log: ``gx arw: fail: 2.4 [2.37, 2.42] deg/sqrt(h) against 2 deg/sqrt(h)
    (the whole 95 % interval exceeds the limit 2 deg/sqrt(h))``."""
    return f"{j.channel} {j.limit.item}: {j.verdict}: {j.estimate} against {j.limit.text} ({j.reason})"


def spec_columns(judgements) -> dict:
    """Summary-table columns of one channel's judgements: ``spec_<item>`` -> verdict, ``spec_<item>_why`` -> reason
    (e.g. ``spec_arw = "fail"``); every item of the spec for that channel's kind."""
    out = {}
    for j in judgements:
        out[f"spec_{j.limit.item}"] = j.verdict
        out[f"spec_{j.limit.item}_why"] = j.reason
    return out


def judge_noise_fit(spec: dict, name: str, noise, kind: str = "gyro") -> list[Judgement]:
    """The judgements of one channel's Allan noise fit (:func:`readings_from_noise_fit`): the call a batch row or a
    report's first screen needs."""
    return compare(spec, {name: (kind, readings_from_noise_fit(noise, kind))})


def analysis_judgements(result, limits: dict, kind: str = "gyro") -> list:
    """The datasheet judgements (:func:`compare`) of every axis of an analysis, read from the noise model its
    headline shows: the GMWM axis when every axis has one (``--noise-method gmwm``), else the Allan fit of the whole
    record.  ``limits``: a parsed spec (:func:`read_spec`; this function reads nothing); ``kind``: the spec section
    (``analyze`` takes gyro logs).

    Returns
    -------
    list of Judgement
        Per axis, in the spec's order.
    """
    axes = list(result.axes)
    gmwm = bool(axes) and all(getattr(ax, "gmwm", None) is not None for ax in axes)
    return compare(limits, {ax.name: (kind, readings_from_gmwm(ax.gmwm, kind) if gmwm
                                      else readings_from_noise_fit(ax.original.noise, kind)) for ax in axes})
