"""GMWM noise analysis of one axis, as the CLI (``fogdrift noise``) and the pipeline use it.

:func:`analyse_gmwm` takes a rate series (deg/h), :func:`analyse_wvar` an already computed or
published wavelet variance (:func:`read_curve` reads the SMAC table format); both return a
:class:`GmwmAxis` (the WV, the selection with every candidate's WIC and reasons, the IEEE-952
reading).  :func:`ieee_rows` lays the IEEE quantities out as table rows.

Units: rates in deg/h, WVs in (deg/h)^2, scales and times in s.

Examples
--------
>>> from fogdrift.gmwm import simulate_latent
>>> x = simulate_latent("WN+RW", [1.0, 1e-5], 2**15, seed=2)          # deg/h, dt = 0.01 s
>>> ax = analyse_gmwm("x", x, 0.01, model="WN+RW")
>>> ax.selection.selected, [r[0] for r in ieee_rows(ax)][:2]
('WN+RW', ['N', 'K'])
"""

from __future__ import annotations

import csv
import gzip
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ConfigError, DataFormatError
from .processes import parse_model
from .selection import SelectionResult, select_model
from .wvar import WvarResult, from_curve, haar_wvar

__all__ = ["J_CAVEAT", "GmwmAxis", "GmwmTerm", "analyse_gmwm", "analyse_wvar", "candidates_for", "read_curve", "ieee_rows"]

#: What the J statistic may and may not be read as (shown next to it in every output).
J_CAVEAT = ("the J test over-rejects (V is evaluated at the step-1 estimate and the asymptotics are "
            "large-scale approximations: about 15 % of correct models fall below p = 0.05); read a small "
            "p-value as 'look at the residuals', not as a verdict")

#: IEEE quantities in table order: (key in IEEEResult.terms, symbol shown).
_IEEE_ORDER = (("N_dprh", "N"), ("K_dphrh", "K"), ("R_dph2", "R"), ("Q_urad", "Q"), ("Q_arcsec", "Q"),
               ("B_dph", "B (flicker)"))


@dataclass(frozen=True)
class GmwmTerm:
    """One IEEE-952 term as a GMWM model implies it (the fields a report cell and a summary row need)."""

    value: float | None
    lo95: float | None
    hi95: float | None
    status: str


@dataclass
class GmwmAxis:
    """GMWM analysis of one axis: the wavelet variance and the model selection on it."""

    name: str
    wvar: WvarResult
    selection: SelectionResult

    def ieee_terms(self) -> dict:
        """The five IEEE-952 terms the selected model implies, as :class:`GmwmTerm` keyed Q, N, B, K, R.

        Units as :data:`fogdrift.noise.TERM_UNITS` (Q urad, N deg/sqrt(h), B deg/h, K deg/h^1.5, R deg/h^2).
        B is the flicker term when the model has one, else the Gauss-Markov reading (rule a of
        :mod:`fogdrift.gmwm.ieee`) when it has a GM; ``status`` is ``resolved`` when the 95 % interval
        excludes zero, ``unresolved`` when it does not, ``absent`` when the model has no such term.
        """
        from ..noise.terms import TERM_TABLE

        ie = self.selection.ieee
        out = {}
        for name, spec in TERM_TABLE.items():
            term = ie.terms.get(name + spec.suffix)
            if term is None and name == "B" and ie.b_gm is not None:
                value, lo, hi = ie.b_gm.value_dph, ie.b_gm.lo95_dph, ie.b_gm.hi95_dph
            elif term is None:
                value = lo = hi = None
            else:
                value, lo, hi = term.value, term.lo95, term.hi95
            status = "absent" if value is None else "resolved" if lo is not None and lo > 0 else "unresolved"
            out[name] = GmwmTerm(value, lo, hi, status)
        return out

    def to_dict(self) -> dict:
        sel = self.selection
        return {"name": self.name, "method": "gmwm", "selected": sel.selected,
                "passed_checks": bool(sel.passed_checks),
                "j_statistic": {"q": float(sel.fit.q), "df": int(sel.fit.df), "p_value": float(sel.fit.j_pvalue),
                                "caveat": J_CAVEAT},
                "wvar": self.wvar.to_dict(), "selection": sel.to_dict()}


def candidates_for(model) -> list | None:
    """``"auto"`` -> None (the default candidate set); a model string -> ``[canonical name]``.

    Raises
    ------
    ConfigError
        The string does not parse; the message names ``{opt:model}``.

    Examples
    --------
    >>> candidates_for("auto"), candidates_for("wn+rrw+gm")
    (None, ['WN+RW+GM'])
    """
    if model is None or str(model).strip().lower() == "auto":
        return None
    try:
        return [parse_model(str(model)).name]
    except ConfigError as exc:
        text = exc.args[0]
        if "{opt:model}" not in text:
            text += "; pass {opt:model} as 'auto' or terms such as 'WN+RW+GM'"
        raise ConfigError(text) from None


def analyse_wvar(name, wvar: WvarResult, *, model="auto") -> GmwmAxis:
    """Select (``model="auto"``) or fit one model (with the same short-scale exclusion and checks) on a WV."""
    return GmwmAxis(str(name), wvar, select_model(wvar, candidates_for(model)))


def analyse_gmwm(name, rate_dph, dt_s, *, model="auto", levels=None, robust=False) -> GmwmAxis:
    """Haar WV of one rate series (deg/h at ``dt_s`` s) and the GMWM model selection on it.

    ``levels`` is the number of scales J (default ``floor(log2 N) - 1``); ``robust`` uses the Huber WV.
    """
    cands = candidates_for(model)  # a bad model string is refused before the WV is computed
    wv = haar_wvar(np.asarray(rate_dph, dtype=np.float64), dt_s, levels=levels, robust=robust,
                   axis_names=(str(name),))
    return GmwmAxis(str(name), wv, select_model(wv, cands))


def _open_text(path: Path):
    with open(path, "rb") as fh:
        gz = fh.read(2) == b"\x1f\x8b"
    return gzip.open(path, "rt", newline="") if gz else open(path, newline="")


def read_curve(path, *, sensor=None, unit=None, axes=None) -> list[WvarResult]:
    """Read a published Haar WV table (the SMAC format, optionally gzipped): one :class:`WvarResult` per axis.

    Columns: ``scale_s``, ``wvar``, ``n_samples``, ``sample_rate_hz``; optional ``wvar_ci_low``/``wvar_ci_high``
    (published 95 % interval), ``axis``, ``sensor_key`` and ``unit_inferred`` or ``unit`` (the rate unit of the
    curve; ``unit`` overrides it).  A table with several sensors needs ``sensor``.

    Raises
    ------
    DataFormatError
        Missing columns, unparsable numbers (with the line).
    ConfigError
        Several sensors and no ``{opt:sensor}``, unknown sensor or axis, no unit.
    """
    path = Path(path)
    if not path.is_file():
        raise DataFormatError("no such curve file; pass {opt:curve} a CSV table", path=str(path))
    with _open_text(path) as fh:
        rows = list(csv.DictReader(fh))
    need = {"scale_s", "wvar", "n_samples", "sample_rate_hz"}
    if not rows or need - set(rows[0]):
        raise DataFormatError(f"a curve table needs the columns {sorted(need)}; "
                              f"found {sorted(rows[0]) if rows else 'no rows'}", path=str(path))
    sensors = list(dict.fromkeys(r.get("sensor_key", "") for r in rows))
    if sensor is None and len(sensors) > 1:
        raise ConfigError(f"{path.name} holds {len(sensors)} sensors {sensors}; choose one with {{opt:sensor}}")
    if sensor is not None:
        if sensor not in sensors:
            raise ConfigError(f"sensor {sensor!r} is not in {path.name}; it holds {sensors} ({{opt:sensor}})")
        rows = [r for r in rows if r.get("sensor_key", "") == sensor]
    names = list(dict.fromkeys(r.get("axis", "x") for r in rows))
    if axes:
        bad = [a for a in axes if a not in names]
        if bad:
            raise ConfigError(f"axis {bad[0]!r} is not in the curve table; it has {names} ({{opt:columns}})")
        names = [a for a in names if a in axes]
    out = []
    for name in names:
        rs = [(i + 2, r) for i, r in enumerate(rows) if r.get("axis", "x") == name]
        try:
            col = {k: [float(r[k]) for _, r in rs] for k in ("scale_s", "wvar", "n_samples", "sample_rate_hz")}
            ci = None
            if all(r.get("wvar_ci_low") and r.get("wvar_ci_high") for _, r in rs):
                ci = ([float(r["wvar_ci_low"]) for _, r in rs], [float(r["wvar_ci_high"]) for _, r in rs])
        except ValueError as exc:
            raise DataFormatError(f"axis {name!r}: {exc}", path=str(path)) from None
        u = unit or rs[0][1].get("unit") or rs[0][1].get("unit_inferred")
        if not u:
            raise ConfigError(f"{path.name} declares no rate unit (column 'unit' or 'unit_inferred'); pass {{opt:unit}}")
        out.append(from_curve(col["scale_s"], col["wvar"], n_samples=int(col["n_samples"][0]),
                              dt_s=1.0 / col["sample_rate_hz"][0], ci_low=None if ci is None else ci[0],
                              ci_high=None if ci is None else ci[1], unit=u, axis_name=name))
    return out


def _b_row(label, b):
    flag = " (extrapolated)" if b.flagged else ""
    return [label, b.value_dph, b.lo95_dph, b.hi95_dph, "deg/h", f"{b.rule} at tau {b.tau_s:.4g} s{flag}"]


def ieee_rows(axis: GmwmAxis) -> list[list]:
    """The IEEE-952 reading as rows ``[quantity, value, lo95, hi95, unit, where from]`` (numbers as floats)."""
    ie = axis.selection.ieee
    rows = []
    for key, sym in _IEEE_ORDER:
        if key in ie.terms:
            v = ie.terms[key]
            rows.append([sym, v.value, v.lo95, v.hi95, v.unit, v.component])
    for g in ie.gm:
        for key, sym in (("tc_s", "T_c"), ("sigma_gm_dph", "sigma_GM")):
            v = g[key]
            rows.append([f"{sym} ({g['component']})", v.value, v.lo95, v.hi95, v.unit, g["component"]])
    if ie.b_gm is not None:
        rows.append(_b_row("B", ie.b_gm))
    rows.append(_b_row("B (min AVAR)", ie.b_min))
    return rows
