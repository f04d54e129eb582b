"""A GMWM reading in the units of its channel's quantity (the accelerometer twin of :mod:`fogdrift.gmwm.ieee`).

The GMWM fit runs on the internal unit of the channel (m/s^2 for an accelerometer); :mod:`fogdrift.gmwm.ieee`
reads the model out in the gyro's units.  :func:`express_gmwm` re-states the reading of an accelerometer channel
(the keys stay, ``N_dprh`` ..., so every reader of the JSON finds them; the ``unit`` of each value says what it
is, which is how :mod:`fogdrift.export` tells an accelerometer result from a gyro's):

==========  ======================  ==========================  ====================================
key         gyro unit               accelerometer unit          factor (accel / gyro number)
==========  ======================  ==========================  ====================================
N_dprh      deg/sqrt(h)             m/s/sqrt(h)                 3600 (60 / (1/60))
K_dphrh     deg/h/sqrt(h)           m/s^2/sqrt(h)               1 (both 60 x the law unit)
R_dph2      deg/h^2                 m/s^2/h                     1 (both 3600 x the law unit)
Q_urad      urad                    m/s                         1 / 4.848137 (urad per arcsec)
Q_arcsec    arcsec                  m/s                         1
B_dph       deg/h                   m/s^2                       1 (the law unit; printed in ug too)
sigma_gm    deg/h                   m/s^2                       1
==========  ======================  ==========================  ====================================
"""

from __future__ import annotations

import dataclasses

from ..noise.quantity import restate_text
from ..units import S_PER_H, URAD_PER_ARCSEC

__all__ = ["express_gmwm", "GMWM_ACCEL_UNITS", "UG_PER_MPS2"]

#: key -> (accelerometer unit, factor from the gyro number).
GMWM_ACCEL_UNITS = {
    "N_dprh": ("m/s/sqrt(h)", S_PER_H),
    "K_dphrh": ("m/s^2/sqrt(h)", 1.0),
    "R_dph2": ("m/s^2/h", 1.0),
    "Q_urad": ("m/s", 1.0 / URAD_PER_ARCSEC),
    "Q_arcsec": ("m/s", 1.0),
    "B_dph": ("m/s^2", 1.0),
    "sigma_gm_dph": ("m/s^2", 1.0),
}
#: Micro-g per m/s^2 (1 ug = 9.80665e-6 m/s^2).
UG_PER_MPS2 = 1.0 / 9.80665e-6


def _value(v, key):
    unit, f = GMWM_ACCEL_UNITS[key]
    return dataclasses.replace(v, value=v.value * f, lo95=v.lo95 * f, hi95=v.hi95 * f, unit=unit)


def express_gmwm(axis, quantity: str):
    """The GMWM axis with its IEEE reading in ``quantity``'s units (a gyro's axis is returned unchanged).

    Examples
    --------
    >>> GMWM_ACCEL_UNITS["N_dprh"]     # a white noise of 1e-4 deg/sqrt(h) read as m/s^2 is 0.36 m/s/sqrt(h)
    ('m/s/sqrt(h)', 3600.0)
    """
    if quantity != "specific_force":
        return axis
    ie = axis.selection.ieee
    # Q once (in m/s; Q_arcsec is the gyro's second spelling of the same number)
    terms = {k: (_value(v, k) if k in GMWM_ACCEL_UNITS else v) for k, v in ie.terms.items() if k != "Q_arcsec"}
    gm = [{**g, "sigma_gm_dph": _value(g["sigma_gm_dph"], "sigma_gm_dph")} if "sigma_gm_dph" in g else g
          for g in ie.gm]
    ie2 = dataclasses.replace(ie, terms=terms, gm=gm)
    sel = dataclasses.replace(axis.selection, ieee=ie2)
    check = axis.allan_check
    if check is not None:
        check = {**check, "lines": [restate_text(line, quantity) for line in check.get("lines", [])]}
    return dataclasses.replace(axis, selection=sel, allan_check=check, quantity=quantity)


def accel_rows(rows: list) -> list:
    """:func:`fogdrift.gmwm.analysis.ieee_rows` of an accelerometer axis for print: the B row (m/s^2, the law unit)
    shown in ug."""
    out = []
    for r in rows:
        if r[0] == "B" and r[4] == "deg/h":
            f = UG_PER_MPS2
            conv = [x * f if isinstance(x, float) else
                    (f"< {float(x[2:]) * f:.3g}" if isinstance(x, str) and x.startswith("< ") else x) for x in r[1:4]]
            out.append(["B", *conv, "µg", r[5]])
        else:
            out.append(r)
    return out
