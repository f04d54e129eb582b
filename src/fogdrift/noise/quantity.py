"""A noise fit in the units of its channel's quantity: the gyro's IEEE-952 terms or the accelerometer's twins.

The fit (:func:`fogdrift.noise.fit_noise`) is made on the internal unit of the channel (deg/h for a gyro,
m/s^2 for an accelerometer): the Allan laws are the same, only the names and the units of the coefficients
differ (:data:`fogdrift.noise.terms.TERM_TABLES`).  The fit reports in the gyro table; :func:`express` re-states
a fit made on an accelerometer channel in the accelerometer table, every number re-scaled by the ratio of the
two tables' conversion factors (``to_unit``), so nothing in the fit is computed twice:

=====  =============================  ====================================  ======================================
term   gyro (IEEE 952)                accelerometer (IEEE 1293 / 528)       factor from the law unit
=====  =============================  ====================================  ======================================
Q      angle quantization [µrad]      velocity quantization [m/s]           1 ((m/s^2) s = m/s)
N      angle random walk [deg/√h]     velocity random walk [m/s/√h]         60 (sqrt(h) = 60 sqrt(s))
B      bias instability [deg/h]       bias instability [µg] (and m/s^2)     1 / 9.80665e-6
K      rate random walk [deg/h^1.5]   acceleration random walk [m/s²/√h]    60
R      rate ramp [deg/h²]             acceleration ramp [m/s²/h]            3600
S, M   rate unit deg/h, deg/h/√s      m/s^2, m/s^2/√s                       1
=====  =============================  ====================================  ======================================

The notes and reasons the fit wrote in gyro units are re-stated the same way (a number followed by a gyro unit is
re-scaled and re-labelled; a bare rate level in deg/h is the internal unit, m/s^2, with the same number).
"""

from __future__ import annotations

import dataclasses
import re

from .readouts import Readout
from .result import NoiseFit, NoiseTerm
from .terms import SHAPED_UNITS, TERM_TABLE, term_table

__all__ = ["express", "unit_factor", "restate_text"]


def unit_factor(name: str, quantity: str) -> float:
    """Factor from the gyro table's reported unit of term ``name`` to ``quantity``'s (1 for S, M, a rate level).

    Examples
    --------
    >>> unit_factor("N", "specific_force")     # (m/s/sqrt(h)) / (deg/sqrt(h)) per law unit: 60 / (1/60)
    3600.0
    """
    if name not in TERM_TABLE or quantity == "angular_rate":
        return 1.0
    return term_table(quantity)[name].to_unit / TERM_TABLE[name].to_unit


_NUM = r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)"
# gyro unit spellings -> term (longest first, so deg/h^1.5 is not read as deg/h)
_SPELLINGS = (
    ("deg/h/sqrt(s)", None), ("deg/h/√s", None), ("deg/h^1.5", "K"), ("deg/h/√h", "K"), ("deg/h²", "R"),
    ("deg/h^2", "R"), ("deg/sqrt(h)", "N"), ("deg/√h", "N"), ("µrad", "Q"), ("urad", "Q"), ("deg/h", ""),
)


def restate_text(text: str, quantity: str) -> str:
    """``text`` with every "number gyro-unit" re-stated in ``quantity``'s unit (see the module docstring)."""
    if quantity == "angular_rate" or not text:
        return text
    disp = {k: v.header.split("[", 1)[1].rstrip("]") for k, v in term_table(quantity).items()}
    rate_unit, q_unit = SHAPED_UNITS[quantity]
    alts = "|".join(re.escape(s) for s, _ in _SPELLINGS)

    def sub(m):
        spelled = m.group(4)
        term = dict(_SPELLINGS)[spelled]
        if term is None:
            return f"{m.group(0)[:m.start(4) - m.start(0)]}{q_unit}"
        if term == "":
            return f"{m.group(0)[:m.start(4) - m.start(0)]}{rate_unit}"
        f = unit_factor(term, quantity)
        value = f"{float(m.group(1)) * f:.4g}"
        iv = "" if m.group(2) is None else f" [{float(m.group(2)) * f:.3g}, {float(m.group(3)) * f:.3g}]"
        return f"{value}{iv} {disp[term]}"

    # "x unit" and "x [lo, hi] unit": every number re-scaled
    out = re.sub(_NUM + r"(?: \[" + _NUM + r", " + _NUM + r"\])? ?(" + alts + r")(?![\w^²/])", sub, text)
    for spelled, term in _SPELLINGS:  # units without a number in front ("[0.1, 0.2] deg/√h" is rare; label only)
        if term:
            out = out.replace(spelled, disp[term])
    return out.replace("deg/h", rate_unit)


def _term(t: NoiseTerm, quantity: str) -> NoiseTerm:
    f = unit_factor(t.name, quantity)
    unit = term_table(quantity)[t.name].unit if t.name in TERM_TABLE else (
        SHAPED_UNITS[quantity][0] if t.name == "S" else SHAPED_UNITS[quantity][1])
    return NoiseTerm(t.name, None if t.value is None else t.value * f, unit, None if t.lo95 is None else t.lo95 * f,
                     None if t.hi95 is None else t.hi95 * f, t.status, restate_text(t.reason, quantity))


def express(fit: NoiseFit, quantity: str) -> NoiseFit:
    """The fit re-stated in the term table of ``quantity`` (the same fit, a new object; a gyro's fit unchanged).

    Examples
    --------
    >>> import numpy as np
    >>> from fogdrift.simulate import simulate
    >>> from fogdrift.allan import allan_variance
    >>> from fogdrift.noise import fit_noise
    >>> y = simulate(2**16, 0.01, arw_dprh=0.002, seed=1)       # read as m/s^2: N = 0.002 x 3600 m/s/sqrt(h)
    >>> f = express(fit_noise(allan_variance(y, 0.01)), "specific_force")
    >>> f.terms["N"].unit, round(f.terms["N"].value, 1)
    ('m/s/sqrt(h)', 7.2)
    """
    term_table(quantity)
    if quantity == "angular_rate":
        return fit
    terms = {k: _term(v, quantity) for k, v in fit.terms.items()}
    b_min = dict(fit.b_min or {})
    if b_min:
        f = unit_factor("B", quantity)
        for k in ("value", "lo95", "hi95"):
            if b_min.get(k) is not None:
                b_min[k] = b_min[k] * f
        b_min["unit"] = term_table(quantity)["B"].unit
        b_min["si"] = {"unit": "m/s^2", **{k: (None if b_min.get(k) is None else b_min[k] / f)
                                          for k in ("value", "lo95", "hi95")}}
    readouts = {}
    for k, r in (fit.readouts or {}).items():
        f = unit_factor(k, quantity)
        readouts[k] = Readout(r.term, None if r.value is None else r.value * f, term_table(quantity)[k].unit,
                              r.tau_s, r.slope, r.dominated, restate_text(r.note, quantity))
    shaped = {k: {f: (restate_text(x, quantity) if isinstance(x, str) else x) for f, x in v.items()}
              for k, v in (fit.shaped or {}).items()}  # descriptions ("spectral line at f Hz, a deg/h") re-stated
    if "M" in shaped:
        shaped["M"]["q_unit"] = SHAPED_UNITS[quantity][1]
        shaped["M"]["sigma_unit"] = SHAPED_UNITS[quantity][0]
    if "S" in shaped:
        shaped["S"]["amplitude_unit"] = SHAPED_UNITS[quantity][0]
    excluded = [{k: (restate_text(v, quantity) if isinstance(v, str) else v) for k, v in e.items()}
                if isinstance(e, dict) else e for e in fit.excluded]
    return dataclasses.replace(fit, terms=terms, b_min=b_min, readouts=readouts, shaped=shaped, excluded=excluded,
                               notes=[restate_text(n, quantity) for n in fit.notes], quantity=quantity)
