"""The noise model of each channel, taken from a saved fogdrift result (``allan`` or ``noise`` JSON).

A :class:`ChannelModel` holds one axis of one quantity (``"gyro"``: angular rate, ``"accel"``: specific force) with
its coefficients **in SI** (:mod:`fogdrift.export.conversions`), each a :class:`TermValue` that keeps what the
record said: the fogdrift term, the estimate in the result's unit, its 95 % interval, its status and reason.
The quantity comes from the units the result file states for its terms, never from a channel's name.

:func:`resolve` turns a term into the number an export writes, under the ``--missing`` policy:

* the estimate, when the selected model has the term (``resolved``, or ``unresolved``: its interval reaches 0, said
  in the note);
* otherwise (the term is not in the selected model, not estimable, or no model fits the record) the term is
  *missing*: ``bound`` writes its 95 % upper bound (the default: a filter given an upper bound of a noise it
  cannot see is conservative, while zero makes it over-confident; the bound is printed as a bound), ``refuse``
  stops with the reason, ``zero`` writes 0 and warns.
"""

from __future__ import annotations

import functools
import json
import math
import numbers
from dataclasses import dataclass, field
from pathlib import Path

from .. import documents
from ..errors import ConfigError, DataFormatError
from ..noise.terms import TERMS
from ..signal import record_sampling
from ..units import name_keys
from .conversions import quantity_of_unit, single_gm_from_flicker, to_si

__all__ = ["TermValue", "GaussMarkov", "ChannelModel", "MISSING_POLICIES", "Resolved", "load_result",
           "channels_from_result", "resolve", "bias_gm"]

#: Values of ``--missing`` (see the module docstring).
MISSING_POLICIES = ("bound", "refuse", "zero")


@dataclass(frozen=True)
class TermValue:
    """One coefficient as the record gives it, with its SI value.

    Attributes
    ----------
    name : str
        ``"N"``, ``"K"``, ``"B"``, ``"Q"`` or ``"R"``.
    value, lo95, hi95 : float or None
        In ``unit`` (the result's).  ``hi95`` alone: an upper bound.
    unit : str
    status : str
        ``"resolved"``, ``"unresolved"``, ``"absent"``, ``"not_estimable"`` or ``"no_fit"`` (no model fits the
        record: the coefficient is no result, its interval's upper end a bound).
    reason : str
    si : float or None
        ``value`` in SI; ``si_lo95``, ``si_hi95`` likewise.
    si_unit, conversion : str
    source : str
        Where it was read (``"allan fit: N (selected model N+B+K)"``, ``"gmwm WN+RW: N"``).
    """

    name: str
    value: float | None
    lo95: float | None
    hi95: float | None
    unit: str
    status: str
    reason: str
    si: float | None
    si_lo95: float | None
    si_hi95: float | None
    si_unit: str
    conversion: str
    source: str

    @property
    def has_estimate(self) -> bool:
        return self.status in ("resolved", "unresolved") and self.value is not None

    def to_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass(frozen=True)
class GaussMarkov:
    """A first-order Gauss-Markov term: 1-sigma [SI rate unit] and correlation time [s] with 95 % intervals."""

    sigma_si: float
    tc_s: float
    sigma_lo95_si: float | None = None
    sigma_hi95_si: float | None = None
    tc_lo95_s: float | None = None
    tc_hi95_s: float | None = None
    source: str = ""

    def to_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class ChannelModel:
    """Noise model of one channel (see the module docstring).

    Attributes
    ----------
    name : str
        Axis name in the result (``"gx"``).
    quantity : str
        ``"gyro"`` or ``"accel"``.
    method : str
        ``"allan"`` or ``"gmwm"``.
    terms : dict[str, TermValue]
        N, K, B, Q, R.
    gms : list of GaussMarkov
        Gauss-Markov terms of the model (GMWM GMs, the Allan fit's M).
    b_tau_s : float or None
        Averaging time [s] of the B reading (the ADEV minimum, or the end of the fitted range when B is a bound).
    b_is_flicker : bool
        True when ``terms["B"]`` is the model's flicker term (not a reading of the whole curve's minimum).
    tau_range_s : (float, float)
        Fitted tau range [s].
    rate_hz : float
        Sample rate of the record [Hz].
    fit : str
        The selected model and its fit quality in words.
    no_fit : bool
        True when no model fits the record (every coefficient is then missing).
    source_file, sha256 : str
    """

    name: str
    quantity: str
    method: str
    terms: dict
    gms: list = field(default_factory=list)
    b_tau_s: float | None = None
    b_is_flicker: bool = False
    tau_range_s: tuple = (math.nan, math.nan)
    rate_hz: float = math.nan
    fit: str = ""
    no_fit: bool = False
    source_file: str = ""
    sha256: str = ""

    @property
    def label(self) -> str:
        return f"{self.quantity} {self.name}"

    def to_dict(self) -> dict:
        return {"name": self.name, "quantity": self.quantity, "method": self.method, "fit": self.fit,
                "no_fit": self.no_fit, "source_file": self.source_file, "sha256": self.sha256,
                "rate_hz": self.rate_hz, "tau_range_s": list(self.tau_range_s), "b_tau_s": self.b_tau_s,
                "terms": {k: v.to_dict() for k, v in self.terms.items()},
                "gauss_markov": [g.to_dict() for g in self.gms]}


# ------------------------------------------------------------------------------------------------------------------
# reading
# ------------------------------------------------------------------------------------------------------------------
def load_result(path) -> dict:
    """Read a fogdrift result JSON (``allan.json``, ``noise.json``, or what ``--json`` printed).

    Raises
    ------
    DataFormatError
        Missing file, not JSON, or not a fogdrift allan / noise result (one line, with the path).
    """
    p = Path(path)
    if not p.is_file():
        raise DataFormatError("no such result file; expected the allan.json or noise.json of a fogdrift run "
                              "(or what 'fogdrift allan --json' printed)", path=p)
    try:
        data = documents.read(p, yaml=False)
    except documents.DocumentError as exc:
        raise DataFormatError(exc.reason, path=p, line=exc.line) from None
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DataFormatError(f"not a JSON file ({exc.__class__.__name__}: {exc})".split("\n")[0], path=p) from None
    if not isinstance(data, dict) or not isinstance(data.get("axes"), list) or not data["axes"]:
        raise DataFormatError("not a fogdrift allan or noise result: no 'axes' list; expected the allan.json or "
                              "noise.json of a fogdrift run", path=p)
    return data


def _f(x):
    return None if x is None else float(x)


def _coefficient(x, what: str, where: str, *, positive: bool = False):
    """``x`` as a float, or None; anything else than a finite number >= 0 (> 0 with ``positive``) is refused: a
    noise coefficient, interval end, correlation time or rate written by hand or by another tool must not reach a
    filter's configuration as a negative or infinite number."""
    if x is None:
        return None
    ok = isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x) and (x > 0 if positive
                                                                                           else x >= 0)
    if not ok:
        raise DataFormatError(f"{where}: {what} = {x!r} is not a finite number {'> 0' if positive else '>= 0'}; a "
                              "result file holds only such values (re-run the fit that wrote it)")
    return float(x)


def _term(name, value, lo, hi, unit, status, reason, source, *, where: str = "the result") -> TermValue:
    value, lo, hi = (_coefficient(x, f"{name} {k}", where) for x, k in ((value, "value"), (lo, "lo95"), (hi, "hi95")))
    si, si_unit, how = to_si(value, name, unit)
    return TermValue(name=name, value=_f(value), lo95=_f(lo), hi95=_f(hi), unit=str(unit), status=status,
                     reason=reason, si=si, si_lo95=to_si(lo, name, unit)[0], si_hi95=to_si(hi, name, unit)[0],
                     si_unit=si_unit, conversion=how, source=source)


def _quantity(terms: dict, where: str) -> str:
    qs = {_q(t) for t in terms.values() if t.value is not None or t.hi95 is not None}
    qs.discard(None)
    if len(qs) != 1:
        raise DataFormatError(f"{where}: the terms' units do not say one quantity (gyro or accelerometer): "
                              f"{', '.join(f'{t.name} [{t.unit}]' for t in terms.values())}")
    return qs.pop()


def _q(t: TermValue):
    return quantity_of_unit(t.name, t.unit)


def _allan_channel(ax: dict, record: dict, path: str) -> ChannelModel:
    noise = ax.get("noise")
    if not isinstance(noise, dict) or not isinstance(noise.get("terms"), dict):
        raise DataFormatError(f"axis {ax.get('name')!r} has no noise fit ('noise.terms'); expected an allan result "
                              "with the IEEE-952 fit", path=path)
    sel = "+".join(noise.get("selected") or []) or "none"
    fit = noise.get("fit") or {}
    no_fit = noise.get("no_fit") is not None
    where = f"{path}: axis {ax.get('name')!r}"
    term = functools.partial(_term, where=where)
    terms = {}
    for name in TERMS:
        t = noise["terms"].get(name)
        if t is None:
            continue
        status = "no_fit" if no_fit and t.get("status") in ("resolved", "unresolved") else t.get("status", "absent")
        reason = t.get("reason", "")
        if no_fit:
            reason = (f"no model fits the record (best candidate {sel}, chi2_red {fit.get('chi2_red', math.nan):.3g}): "
                      "the coefficient is no result" + (f"; {reason}" if reason else ""))
        terms[name] = term(name, t.get("value"), t.get("lo95"), t.get("hi95"), t.get("unit", ""), status, reason,
                            f"allan fit: {name} (selected model {sel}, fit {fit.get('quality', '?')})")
    b_min = noise.get("b_min") or {}
    b_tau = _f(b_min.get("tau_s"))
    b_flicker = "B" in terms and terms["B"].has_estimate
    if "B" in terms and not terms["B"].has_estimate and b_min.get("value") is not None and not no_fit:
        # no flicker term in the model: the IEEE reading at the ADEV minimum is the bias instability
        bound = bool(b_min.get("bound_only"))
        terms["B"] = term("B", None if bound else b_min["value"], b_min.get("lo95"), b_min.get("hi95"),
                           b_min.get("unit", terms["B"].unit), "absent" if bound else "resolved",
                           b_min.get("rule", "") if bound else "",
                           "allan fit: B_min, " + str(b_min.get("rule", "min of the fitted ADEV / 0.664")))
    gms = []
    m = (noise.get("shaped") or {}).get("M")
    mt = noise["terms"].get("M")
    if (m and mt and "M" in (noise.get("selected") or []) and mt.get("status") == "resolved" and not no_fit
            and m.get("tc_lo95_s") is not None and m.get("tc_hi95_s") is not None):
        # sigma = q_c sqrt(T_c/2) is in the rate unit of q_c (IEEE-952 C.6)
        q_unit = str(m.get("q_unit", mt.get("unit", "")))
        factor = to_si(1.0, "q_c", q_unit)[0]
        sigma_key, = name_keys({"sigma_dph": None}, str(noise.get("quantity", "angular_rate")))  # in its unit
        gms.append(GaussMarkov(sigma_si=_coefficient(m[sigma_key], "M sigma", where) * factor,
                               tc_s=_coefficient(m["tc_s"], "M tc_s", where, positive=True),
                               tc_lo95_s=_f(m.get("tc_lo95_s")), tc_hi95_s=_f(m.get("tc_hi95_s")),
                               source="allan fit: M (exponentially correlated, IEEE-952 C.6)"))
    quality = f"chi2_red {fit.get('chi2_red', math.nan):.3g}, {fit.get('quality', '?')}"
    return ChannelModel(name=str(ax.get("name")), quantity=_quantity(terms, f"{path}: axis {ax.get('name')}"),
                        method="allan", terms=terms, gms=gms, b_tau_s=b_tau, b_is_flicker=b_flicker,
                        tau_range_s=(_f(fit.get("tau_min_s")), _f(fit.get("tau_max_s"))),
                        rate_hz=_rate_hz(record, noise, path),
                        fit=("no model fits; best candidate " if no_fit else "model ") + f"{sel} ({quality})",
                        no_fit=no_fit, source_file=str(path), sha256=str(record.get("sha256", "")))


_GMWM_KEYS = {"N": "N_dprh", "K": "K_dphrh", "R": "R_dph2", "Q": "Q_urad", "B": "B_dph"}


def _gmwm_channel(ax: dict, record: dict, path: str) -> ChannelModel:
    ie = ((ax.get("selection") or {}).get("ieee")) or {}
    model = ie.get("model") or ax.get("selected") or "?"
    if not isinstance(ie.get("terms"), dict):
        raise DataFormatError(f"axis {ax.get('name')!r} has no GMWM IEEE reading ('selection.ieee.terms')", path=path)
    n_unit = str((ie["terms"].get("N_dprh") or {}).get("unit", "deg/sqrt(h)"))
    gyro = quantity_of_unit("N", n_unit) != "accel"
    unit_default = ({"N": "deg/sqrt(h)", "K": "deg/h^1.5", "R": "deg/h^2", "Q": "urad", "B": "deg/h"} if gyro else
                    {"N": "m/s/sqrt(h)", "K": "m/s^2/sqrt(s)", "R": "m/s^3", "Q": "m/s", "B": "m/s^2"})
    where = f"{path}: axis {ax.get('name')!r}"
    term = functools.partial(_term, where=where)
    terms = {}
    for name, key in _GMWM_KEYS.items():
        t = ie["terms"].get(key)
        if name == "B" and t is None:
            bh = ie.get("b_headline") or {}
            if bh.get("value_dph") is not None:
                terms["B"] = term("B", bh["value_dph"], bh.get("lo95_dph"), bh.get("hi95_dph"), unit_default["B"],
                                   "resolved", "", f"gmwm {model}: B, {bh.get('label', '')}")
            else:
                terms["B"] = term("B", None, 0.0, bh.get("bound_dph"), unit_default["B"], "absent",
                                   bh.get("reason", "no bias-instability reading"),
                                   f"gmwm {model}: B, {bh.get('label', '')}")
            continue
        if t is None:
            bound, why = (_rw_bound_from_wv(ax.get("wvar")) if name == "K" and gyro else (None, ""))
            terms[name] = term(name, None, None if bound is None else 0.0, bound, unit_default[name], "absent",
                                f"not in the GMWM model {model}"
                                + (f"; {why}" if why else " (GMWM gives no upper bound for a term it leaves out)"),
                                f"gmwm {model}: {name}")
            continue
        lo = t.get("lo95")
        unit = "deg/h^1.5" if t.get("unit") == "deg/h/sqrt(h)" else t.get("unit", unit_default[name])
        terms[name] = term(name, t.get("value"), lo, t.get("hi95"), unit,
                            "resolved" if lo is not None and lo > 0 else "unresolved",
                            "" if lo is not None and lo > 0 else "its 95 % interval reaches 0",
                            f"gmwm {model}: {name} (component {t.get('component', '?')})")
    gms = []
    for g in ie.get("gm") or []:
        tc, sg = g["tc_s"], g["sigma_gm_dph"]
        f = to_si(1.0, "sigma", sg.get("unit", "deg/h"))[0]
        gms.append(GaussMarkov(sigma_si=_coefficient(sg["value"], "GM sigma", where) * f,
                               tc_s=_coefficient(tc["value"], "GM tc_s", where, positive=True),
                               sigma_lo95_si=None if sg.get("lo95") is None else sg["lo95"] * f,
                               sigma_hi95_si=None if sg.get("hi95") is None else sg["hi95"] * f,
                               tc_lo95_s=tc.get("lo95"), tc_hi95_s=tc.get("hi95"),
                               source=f"gmwm {model}: {g.get('component', 'GM')}"))
    bh = ie.get("b_headline") or {}
    tr = ie.get("tau_range_s") or [math.nan, math.nan]
    jp = (ax.get("j_statistic") or {}).get("p_value")
    return ChannelModel(name=str(ax.get("name")), quantity=_quantity(terms, f"{path}: axis {ax.get('name')}"),
                        method="gmwm", terms=terms, gms=gms, b_tau_s=_f(bh.get("tau_s")),
                        b_is_flicker=ie["terms"].get("B_dph") is not None,
                        tau_range_s=(_f(tr[0]), _f(tr[1])),
                        rate_hz=_rate_hz(record, ie, path),
                        fit=f"GMWM model {model} (J-test p = {jp:.2g})" if jp is not None else f"GMWM model {model}",
                        source_file=str(path), sha256=str(record.get("sha256", "")))


def _rate_hz(record: dict, fit: dict, path) -> float:
    """The sample rate [Hz] of the record a result describes: its ``signal.sampling`` rate
    (:func:`fogdrift.signal.record_sampling`), else 1 / the fit's ``dt_s``."""
    try:
        smp = record_sampling(record, "the record")
    except ConfigError as exc:
        raise DataFormatError(str(exc), path=path) from None
    if smp is not None:
        return smp.rate_hz
    dt = _coefficient(fit.get("dt_s"), "dt_s", str(path), positive=True)
    if dt is None:
        raise DataFormatError("the result says no sample rate (record 'signal.sampling' or the fit's 'dt_s'); "
                              "expected the allan.json or noise.json of a fogdrift run", path=path)
    return 1.0 / dt


def _rw_bound_from_wv(wv) -> tuple[float | None, str]:
    """95 % upper bound of K [deg/h^1.5] from a Haar wavelet variance (``noise.json``'s ``wvar``): the upper end of
    the measured WV's 95 % interval at the longest scale, all of it taken as random walk (every other process only
    adds to the WV).  The random walk's Haar WV at tau samples is gamma^2 (tau^2 + 2) / (12 tau), gamma^2 = K^2 dt
    (:mod:`fogdrift.gmwm.processes`)."""
    try:
        tau = float(wv["tau_samples"][-1])
        hi = float(wv["ci_hi95_dph2"][-1])
        dt = float(wv["dt_s"])
        scale = float(wv["scale_s"][-1])
    except (KeyError, TypeError, ValueError, IndexError):
        return None, ""
    if not (tau > 0 and hi > 0 and dt > 0 and math.isfinite(hi)):
        return None, ""
    k = 60.0 * math.sqrt(hi * 12.0 * tau / (tau * tau + 2.0) / dt)  # (deg/h)/sqrt(s) -> deg/h^1.5
    return k, (f"95 % upper bound from the wavelet variance: the upper end of its 95 % interval at the longest scale "
               f"({scale:.4g} s), all of it taken as random walk")


def channels_from_result(data, path="result", *, expect: str | None = None) -> list[ChannelModel]:
    """Every axis of a result as a :class:`ChannelModel`.

    Parameters
    ----------
    data : dict or result object
        A loaded result file (:func:`load_result`), or a result in memory whose ``to_dict()`` is that document
        (:class:`fogdrift.workflows.allan.AllanRun`), read as it is: NaN stays NaN where the file holds ``null``
        (the file is strict JSON), and numpy numbers count as numbers.
    path : str
        For messages.
    expect : {"gyro", "accel", None}
        The quantity the caller was told the file holds (``--gyro`` / ``--accel``); a mismatch is refused.

    Raises
    ------
    DataFormatError
        An axis without a noise model, units that do not say one quantity, or the wrong quantity.
    """
    if hasattr(data, "to_dict"):
        data = data.to_dict()
    record = data.get("record") or {}
    out = []
    for ax in data["axes"]:
        if not isinstance(ax, dict):
            raise DataFormatError("an entry of 'axes' is not an object", path=path)
        method = ax.get("method") or ("gmwm" if "selection" in ax else "allan")
        try:
            ch = _gmwm_channel(ax, record, str(path)) if method == "gmwm" else _allan_channel(ax, record, str(path))
        except (KeyError, TypeError, ValueError, AttributeError, ZeroDivisionError) as exc:
            if isinstance(exc, DataFormatError):
                raise
            raise DataFormatError(f"axis {ax.get('name')!r} is not a complete fogdrift {method} result "
                                  f"({exc.__class__.__name__}: {exc}); expected the allan.json or noise.json of a "
                                  "fogdrift run", path=path) from None
        if expect is not None and ch.quantity != expect:
            flag = {"gyro": "--gyro", "accel": "--accel"}[expect]
            raise DataFormatError(f"{flag} was given a {ch.quantity} result (axis {ch.name}: N in "
                                  f"{ch.terms['N'].unit}); pass it as {'--accel' if expect == 'gyro' else '--gyro'}",
                                  path=path)
        out.append(ch)
    return out


# ------------------------------------------------------------------------------------------------------------------
# the --missing policy
# ------------------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Resolved:
    """The number an export writes for one term, and how it was chosen.

    ``how``: ``"estimate"``, ``"bound"`` (95 % upper bound of a missing term) or ``"zero"``; ``note`` says it in
    words (empty for a resolved estimate)."""

    si: float
    how: str
    note: str
    term: TermValue


def _interval(t: TermValue) -> str:
    if t.value is not None:
        iv = "" if t.lo95 is None else f" [{t.lo95:.4g}, {t.hi95:.4g}]"
        return f"{t.value:.4g}{iv} {t.unit}"
    return f"< {t.hi95:.4g} {t.unit} (95 % upper bound)" if t.hi95 is not None else "no value"


def describe(t: TermValue) -> str:
    """The fogdrift term with its estimate and interval, in words (for comments)."""
    return f"{t.name} = {_interval(t)} [{t.status}]; from {t.source}"


def resolve(ch: ChannelModel, name: str, policy: str) -> Resolved:
    """The value of term ``name`` of ``ch`` an export writes under ``policy`` (module docstring).

    Raises
    ------
    ConfigError
        ``policy`` is ``refuse`` and the term is missing, or ``bound`` and the record gives no bound.
    """
    if policy not in MISSING_POLICIES:
        raise ConfigError(f"{{opt:missing}} must be one of {', '.join(MISSING_POLICIES)}; got {policy!r}")
    t = ch.terms.get(name)
    if t is None:
        raise ConfigError(f"{ch.label}: the result has no term {name}")
    if t.has_estimate:
        note = "" if t.status == "resolved" else (f"{name} = {t.value:.4g} {t.unit} is the estimate, "
                                                  f"{t.reason or 'not resolved from zero: its 95 % interval reaches 0'}")
        return Resolved(t.si, "estimate", note, t)
    why = t.reason or "not in the selected model"
    if policy == "zero":
        return Resolved(0.0, "zero", f"{name} written as 0 (--missing zero): {why}", t)
    if policy == "bound" and t.si_hi95 is not None and t.si_hi95 > 0:
        return Resolved(t.si_hi95, "bound", f"{name} is its 95 % upper bound {t.hi95:.4g} {t.unit}, not an "
                                            f"estimate (--missing bound): {why}", t)
    more = ("; the record gives no upper bound either" if policy == "bound" else
            f"; its 95 % upper bound is {t.hi95:.4g} {t.unit}" if t.hi95 is not None else "")
    raise ConfigError(f"{ch.label}: {name} is not resolved by the record: {why}{more}; pass {{opt:missing}} "
                      f"{'zero' if policy == 'bound' else 'bound or zero'} to write "
                      f"{'0 with a warning' if policy == 'bound' else 'its bound or 0'}, "
                      "or export from a record that resolves it")


def bias_gm(ch: ChannelModel, policy: str) -> tuple[GaussMarkov, str]:
    """The one Gauss-Markov bias process of a channel (what KF-GINS and gnss-ins-sim take), and how it was chosen.

    The slowest of the model's Gauss-Markov terms (GMWM GMs, the Allan fit's M: short correlation times are coloured
    measurement noise, the slowest is the bias wander) and, when the model has a flicker term B, the single GM whose
    Allan peak equals its floor at tau_B (:func:`~fogdrift.export.conversions.single_gm_from_flicker`).  With neither,
    that GM is made from the B reading (the ADEV minimum), B resolved under ``policy``.  A flicker term whose 95 %
    interval reaches 0 (status ``unresolved``: the model without it describes the curve about as well) does not
    displace a fitted Gauss-Markov term: a small flicker beside a Markov hump would otherwise become the filter's
    bias, with the hump's variance lost (seen in the gnss-ins-sim round trip, tests/export/test_export_roundtrip.py).
    """
    cands = [(g, f"the model's slowest Gauss-Markov term ({g.source}): sigma and T_c as fitted") for g in ch.gms]
    b = ch.terms["B"]
    if ch.b_is_flicker and b.has_estimate and not (cands and b.status == "unresolved"):
        cands.append(_gm_from_b(ch, resolve(ch, "B", policy)))
    if cands:
        return max(cands, key=lambda c: c[0].tc_s)
    return _gm_from_b(ch, resolve(ch, "B", policy))


def _gm_from_b(ch: ChannelModel, b: Resolved) -> tuple[GaussMarkov, str]:
    tau = ch.b_tau_s if ch.b_tau_s is not None else ch.tau_range_s[1]
    sigma, tc = single_gm_from_flicker(b.si, tau)
    lo = None if b.term.si_lo95 is None or b.how != "estimate" else single_gm_from_flicker(b.term.si_lo95, tau)[0]
    hi = None if b.term.si_hi95 is None or b.how != "estimate" else single_gm_from_flicker(b.term.si_hi95, tau)[0]
    g = GaussMarkov(sigma_si=sigma, tc_s=tc, sigma_lo95_si=lo, sigma_hi95_si=hi,
                    source=f"from B at tau = {tau:.4g} s")
    how = (f"one GM matched to B ({b.how}{': ' + b.note if b.note else ''}): sigma = 1.0760 B, T_c = tau_B/1.8926 "
           f"with tau_B = {tau:.4g} s (its Allan peak equals the flicker floor 0.664 B there)")
    return g, how
