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
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ConfigError, DataFormatError
from ..noise.periodic import PeriodicContent, periodic_content
from ..noise.quantity import restate_text
from ..noise.result import NoiseTerm
from ..noise.terms import TERM_TABLE
from ..noise.spectral import analyse_spectrum
from ..units import URAD_PER_ARCSEC, rate_scale_to_dph
from .processes import parse_model
from .quantity import GMWM_ACCEL_UNITS
from .selection import SelectionResult, select_model
from .wvar import WvarResult, from_curve, haar_wvar

__all__ = ["J_CAVEAT", "CurveTable", "GmwmAxis", "GmwmTerm", "analyse_gmwm", "analyse_wvar", "b_detail_lines",
           "candidates_for", "read_curve", "read_curve_table", "ieee_rows"]

#: What the J statistic may and may not be read as (shown next to it in every output).
J_CAVEAT = ("the J test over-rejects (V is evaluated at the step-1 estimate and the asymptotics are "
            "large-scale approximations: about 15 % of correct models fall below p = 0.05); read a small "
            "p-value as 'look at the residuals', not as a verdict")

#: IEEE quantities in table order: (key in IEEEResult.terms, symbol shown).
_IEEE_ORDER = (("N_dprh", "N"), ("K_dphrh", "K"), ("R_dph2", "R"), ("Q_urad", "Q"), ("Q_arcsec", "Q"),
               ("B_dph", "B"))


#: Why the terms of a GMWM selection in which no candidate passed its checks are no result.
NO_PASS_REASON = ("no GMWM candidate passed its checks: the fallback model's values are no result; the bound is the "
                  "measured WV's own (each process alone stays below it at every used scale)")

#: One IEEE-952 term as a GMWM model implies it: the one IEEE-term value type, :class:`fogdrift.noise.NoiseTerm`
#: (the name is kept for code that imported it).
GmwmTerm = NoiseTerm


@dataclass
class GmwmAxis:
    """GMWM analysis of one axis: the wavelet variance and the model selection on it."""

    name: str
    wvar: WvarResult
    selection: SelectionResult
    #: The comparison with the Allan fit of the same record (:func:`fogdrift.evaluation.gmwm_vs_allan.compare_with_allan`),
    #: when one was made: ``{"agree": bool, "lines": [str, ...], ...}``.
    allan_check: dict | None = None
    #: The spectral lines of the rate (:class:`fogdrift.noise.periodic.PeriodicContent`) the selection took into
    #: account; None for a curve given as a table or a rate whose spectrum shows no line.
    periodic: PeriodicContent | None = None
    #: The channel's quantity (``"angular_rate"`` or ``"specific_force"``, :func:`fogdrift.gmwm.quantity.express_gmwm`):
    #: the texts of :meth:`to_dict` are in its unit.
    quantity: str = "angular_rate"

    def data_bounds(self) -> dict:
        """The bound the measured WV alone sets on N, Q and K (units of :data:`fogdrift.noise.TERM_UNITS`).

        Latent processes add and none is negative, so each alone stays below the measured WV at every used scale
        (per sample, ``tau`` the scale in samples; [GMWM]_ §2 and §4 of :mod:`.processes`): WN
        ``sigma2 / tau`` (N = sqrt(sigma2 dt) / 60), QN ``6 q2 / tau^2`` (Q = sqrt(q2) dt arcsec), RW
        ``gamma2 (tau^2 + 2) / (12 tau)`` (K = 60 sqrt(gamma2 / dt)).  Each point's 95 % upper limit is stretched
        to ~4 sigma, so the minimum over all the used scales still holds.  Needs no model: a true bound where no
        candidate passes its checks.
        """
        wv, used = self.wvar, np.isin(self.wvar.level, self.selection.levels_used)
        nu = np.asarray(wv.nu2_dph2, dtype=np.float64)[used]
        hi = np.asarray(wv.ci_hi95_dph2, dtype=np.float64)[used]
        tau = np.asarray(wv.tau_samples, dtype=np.float64)[used]
        ok = (nu > 0) & np.isfinite(hi) & (hi >= nu)
        if not np.any(ok):
            return {}
        top = nu[ok] * (hi[ok] / nu[ok]) ** (4.0 / 1.96)
        t, dt = tau[ok], float(wv.dt_s)
        return {"N": math.sqrt(float(np.min(top * t)) * dt) / 60.0,
                "Q": math.sqrt(float(np.min(top * t**2 / 6.0))) * dt * URAD_PER_ARCSEC,
                "K": 60.0 * math.sqrt(float(np.min(top * 12.0 * t / (t**2 + 2.0))) / dt)}

    def ieee_terms(self) -> dict:
        """The five IEEE-952 terms the selected model implies, as :class:`~fogdrift.noise.NoiseTerm` keyed Q, N, B, K, R.

        Units as :data:`fogdrift.noise.TERM_UNITS` (Q urad, N deg/sqrt(h), B deg/h, K deg/h^1.5, R deg/h^2).
        B is the flicker term when the model has one and ``absent`` otherwise: the bias-instability readings of
        a model without one (the minimum of its ADEV, a GM hump) are readings, not terms, and live in
        :attr:`fogdrift.gmwm.ieee.IEEEResult.b_headline` / ``b_details``.  ``status`` is ``resolved`` when the
        95 % interval excludes zero, ``unresolved`` when it does not, ``absent`` when the model has no such term;
        ``reason`` says why a term is not resolved.  The same type as the Allan fit's terms, so a report cell or a
        fleet column reads both alike.
        """
        ie = self.selection.ieee
        out = {}
        for name, spec in TERM_TABLE.items():
            term = ie.terms.get(name + spec.suffix)
            if term is None:
                value = lo = hi = None
            else:
                value, lo, hi = term.value, term.lo95, term.hi95
            status = "absent" if value is None else "resolved" if lo is not None and lo > 0 else "unresolved"
            reason = {"absent": f"not in the selected GMWM model ({self.selection.selected})",
                      "unresolved": "its 95 % interval reaches 0", "resolved": ""}[status]
            out[name] = NoiseTerm(name, value, spec.unit, lo, hi, status, reason)
        if self.selection.no_result:  # no candidate passed its checks: nothing is a result
            bounds = self.data_bounds()
            for name, t in out.items():
                if t.status in ("resolved", "unresolved") or name in bounds:
                    out[name] = NoiseTerm(name, t.value, t.unit, None, bounds.get(name), "no_fit", NO_PASS_REASON)
        return out

    def to_dict(self) -> dict:
        sel = self.selection
        return {"name": self.name, "method": "gmwm", "selected": sel.selected,
                "passed_checks": bool(sel.passed_checks), "no_result": bool(sel.no_result),
                "b_headline_text": restate_text(sel.ieee.b_headline.text(), self.quantity),
                **({} if self.allan_check is None else {"allan_check": self.allan_check}),
                "spectral_lines": [] if self.periodic is None else [restate_text(t, self.quantity)
                                                                    for t in self.periodic.descriptions],
                **({} if self.quantity == "angular_rate" else {"quantity": self.quantity}),
                "j_statistic": {"q": float(sel.fit.j_stat), "df": int(sel.fit.df), "p_value": float(sel.fit.j_pvalue),
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


def analyse_gmwm(name, y, dt_s, *, model="auto", levels=None, robust=False, spectrum="auto") -> GmwmAxis:
    """Haar WV of one series (its channel's internal unit, deg/h or m/s^2, at ``dt_s`` s) and the GMWM model
    selection on it.

    ``levels`` is the number of scales J (default ``floor(log2 N) - 1``); ``robust`` uses the Huber WV.

    ``spectrum``: the :class:`~fogdrift.noise.spectral.SpectrumSummary` of this rate, ``"auto"`` (default: computed
    here by :func:`~fogdrift.noise.spectral.analyse_spectrum`, the function the Allan fit uses) or None (no
    spectrum).  Its lines (:func:`~fogdrift.noise.periodic.periodic_content`) go to
    :func:`~fogdrift.gmwm.selection.select_model` as ``periodic``: the scales they dominate are excluded and QN is
    claimed only above their envelope.
    """
    cands = candidates_for(model)  # a bad model string is refused before the WV is computed
    rate = np.asarray(y, dtype=np.float64)
    if isinstance(spectrum, str) and spectrum == "auto":

        spectrum = analyse_spectrum(rate, dt_s)
    content = periodic_content(spectrum)
    wv = haar_wvar(rate, dt_s, levels=levels, robust=robust, axis_names=(str(name),))
    return GmwmAxis(str(name), wv, select_model(wv, cands, periodic=content), periodic=content)


def _open_text(path: Path):
    with open(path, "rb") as fh:
        gz = fh.read(2) == b"\x1f\x8b"
    return gzip.open(path, "rt", newline="") if gz else open(path, newline="")


@dataclass(frozen=True)
class CurveTable:
    """A published curve table read by :func:`read_curve_table`.

    Attributes
    ----------
    wvars : list of WvarResult
        One per axis, in (deg/h)^2.
    unit : str
        Rate unit of the table's numbers.
    unit_source : str
        Where the unit came from, in words (``"from the table's unit column"``, ``"from --unit"``).
    kind : str
        ``"wavelet variance"`` or ``"Allan variance"`` (converted: WV(2 tau) = AVAR(tau) / 2).
    """

    wvars: list
    unit: str
    unit_source: str
    kind: str


#: Columns of the two table kinds :func:`read_curve_table` reads (besides the optional ones).
WV_COLUMNS = ("scale_s", "wvar", "n_samples", "sample_rate_hz")
AVAR_COLUMNS = ("tau_s", "avar", "n_samples", "sample_rate_hz")


def _table_unit(name, first_row, unit) -> tuple[str, str]:
    """(unit, where it came from) of a curve table: ``--unit`` or the ``unit`` column, never ``unit_inferred``."""
    declared = (first_row.get("unit") or "").strip()
    inferred = (first_row.get("unit_inferred") or "").strip()
    if unit:
        if declared and declared != unit:
            raise ConfigError(f"{name} declares the rate unit {declared!r} in its 'unit' column but {{opt:unit}} "
                              f"says {unit!r}; drop {{opt:unit}} or correct the table")
        rate_scale_to_dph(unit)
        how = "from --unit" + (f" (the table's unit_inferred column, not a declaration, says {inferred})"
                               if inferred and inferred != unit else "")
        return unit, how
    if declared:
        rate_scale_to_dph(declared)
        return declared, "from the table's unit column"
    if inferred:
        raise ConfigError(f"{name} does not declare its rate unit: its 'unit_inferred' column ({inferred!r}) is an "
                          "inference, not a declaration; pass {opt:unit}")
    raise ConfigError(f"{name} declares no rate unit (no 'unit' column); pass {{opt:unit}}")


def read_curve_table(path, *, sensor=None, unit=None, axes=None) -> CurveTable:
    """Read a published wavelet-variance or Allan-variance table (the SMAC formats, optionally gzipped).

    Wavelet variance: columns ``scale_s`` (Haar scale 2^j dt, s), ``wvar`` (unit^2), ``n_samples``,
    ``sample_rate_hz``; optional ``wvar_ci_low``/``wvar_ci_high`` (published 95 % interval).  Allan variance:
    ``tau_s`` (s, 2^k dt), ``avar`` (unit^2; or ``adev``, unit), ``n_samples``, ``sample_rate_hz``; optional
    ``adev_ci_low``/``adev_ci_high``; it is converted with the exact identity of the maximal-overlap estimators,
    WV(scale 2 tau) = AVAR(tau) / 2.  Both: optional ``axis``, ``sensor_key`` and ``unit`` (the declared rate
    unit).  ``unit_inferred`` is never used as the unit: a table without ``unit`` needs ``unit`` (``--unit``),
    and ``unit`` conflicting with a declared one is an error naming both.  A table with several sensors needs
    ``sensor``.

    Raises
    ------
    DataFormatError
        Missing columns, unparsable numbers (with the axis).
    ConfigError
        Several sensors and no ``{opt:sensor}``, unknown sensor or axis, no declared unit and no ``{opt:unit}``,
        or the two in conflict.
    """
    path = Path(path)
    if not path.is_file():
        raise DataFormatError("no such curve file; pass {opt:curve} a CSV table", path=str(path))
    with _open_text(path) as fh:
        rows = list(csv.DictReader(fh))
    cols = set(rows[0]) if rows else set()
    is_wv = not set(WV_COLUMNS) - cols
    is_av = not set(AVAR_COLUMNS) - cols or (not {"tau_s", "adev", "n_samples", "sample_rate_hz"} - cols)
    if not rows or not (is_wv or is_av):
        raise DataFormatError(f"a curve table needs the columns {list(WV_COLUMNS)} (wavelet variance) or "
                              f"{list(AVAR_COLUMNS)} (Allan variance; or adev for avar); "
                              f"found {sorted(cols) if rows else 'no rows'}", path=str(path))
    sensors = list(dict.fromkeys(r.get("sensor_key", "") for r in rows))
    if sensor is None and len(sensors) > 1:
        raise ConfigError(f"{path.name} holds {len(sensors)} sensors {sensors}; choose one with {{opt:sensor}}")
    if sensor is not None:
        if sensor not in sensors:
            raise ConfigError(f"sensor {sensor!r} is not in {path.name}; it holds {sensors} ({{opt:sensor}})")
        rows = [r for r in rows if r.get("sensor_key", "") == sensor]
    u, how = _table_unit(path.name, rows[0], unit)
    names = list(dict.fromkeys(r.get("axis", "x") for r in rows))
    if axes:
        bad = [a for a in axes if a not in names]
        if bad:
            raise ConfigError(f"axis {bad[0]!r} is not in the curve table; it has {names} ({{opt:columns}})")
        names = [a for a in names if a in axes]
    out = []
    for name in names:
        rs = [r for r in rows if r.get("axis", "x") == name]
        try:
            n_samples, fs = float(rs[0]["n_samples"]), float(rs[0]["sample_rate_hz"])
            ci = None
            if is_wv:
                scale = [float(r["scale_s"]) for r in rs]
                wv = [float(r["wvar"]) for r in rs]
                if all(r.get("wvar_ci_low") and r.get("wvar_ci_high") for r in rs):
                    ci = ([float(r["wvar_ci_low"]) for r in rs], [float(r["wvar_ci_high"]) for r in rs])
            else:
                scale = [2.0 * float(r["tau_s"]) for r in rs]
                wv = [(float(r["avar"]) if r.get("avar") else float(r["adev"]) ** 2) / 2.0 for r in rs]
                if all(r.get("adev_ci_low") and r.get("adev_ci_high") for r in rs):
                    ci = ([float(r["adev_ci_low"]) ** 2 / 2.0 for r in rs],
                          [float(r["adev_ci_high"]) ** 2 / 2.0 for r in rs])
        except (ValueError, KeyError) as exc:
            raise DataFormatError(f"axis {name!r}: {exc}", path=str(path)) from None
        out.append(from_curve(scale, wv, n_samples=int(n_samples), dt_s=1.0 / fs,
                              ci_low=None if ci is None else ci[0], ci_high=None if ci is None else ci[1],
                              unit=u, axis_name=name))
    return CurveTable(out, u, how, "wavelet variance" if is_wv else "Allan variance")


def read_curve(path, *, sensor=None, unit=None, axes=None) -> list[WvarResult]:
    """The :class:`WvarResult` of every axis of a curve table (:func:`read_curve_table`, which also says the
    unit and where it came from)."""
    return read_curve_table(path, sensor=sensor, unit=unit, axes=axes).wvars


def _b_cells(b) -> tuple:
    """(value, lo95, hi95, from) of a B reading: a bound or nothing is a text value with no interval."""
    if b.value_dph is not None:
        where = b.label + ("" if b.tau_s is None else f", at τ = {b.tau_s:.4g} s")
        return b.value_dph, b.lo95_dph, b.hi95_dph, where
    if b.bound_dph is not None:
        return f"< {b.bound_dph:.3g}", None, None, f"{b.label} (a bound, below)"
    return "not reached", None, None, f"{b.label} (below)"


def ieee_rows(axis: GmwmAxis) -> list[list]:
    """The IEEE-952 reading as rows ``[quantity, value, lo95, hi95, unit, where from]``.

    Values are floats, except a B reading that lies beyond the scales the fit used: its value is the text of
    its bound (``"< 7.06"``) or ``"not reached"``, with no interval.  Exactly one B row (the headline reading,
    :attr:`fogdrift.gmwm.ieee.IEEEResult.b_headline`); the other readings are in :func:`b_detail_lines`.
    """
    ie = axis.selection.ieee
    rows = []
    if axis.selection.no_result:  # the values of a model that failed its checks are no result
        bounds = axis.data_bounds()
        n = ie.terms.get("N_dprh")
        accel = n is not None and n.unit == GMWM_ACCEL_UNITS["N_dprh"][0]  # re-stated by express_gmwm
        for key, sym in _IEEE_ORDER:
            if key in ("N_dprh", "Q_urad", "K_dphrh") and (key in ie.terms or sym in bounds):
                b, unit = bounds.get(sym), TERM_TABLE[sym].unit
                if accel and b is not None:
                    unit, f = GMWM_ACCEL_UNITS[key]
                    b *= f
                rows.append([sym, "no result" if b is None else f"< {b:.4g}", None, None, unit,
                             "the measured WV's own bound (no candidate passed its checks)"])
        rows.append(["B", "no result", None, None, "deg/h", "no candidate passed its checks"])
        return rows
    for key, sym in _IEEE_ORDER:
        if key in ie.terms and key != "B_dph":
            v = ie.terms[key]
            rows.append([sym, v.value, v.lo95, v.hi95, v.unit, v.component])
    for g in ie.gm:
        for key, sym in (("tc_s", "T_c, correlation time"), ("sigma_gm_dph", "σ, standard deviation")):
            v = g[key]
            rows.append([f"{g['component']} {sym}", v.value, v.lo95, v.hi95, v.unit, f"Gauss-Markov {g['component']}"])
    value, lo, hi, where = _b_cells(ie.b_headline)
    rows.append(["B", value, lo, hi, "deg/h", where])
    return rows


def b_detail_lines(axis: GmwmAxis) -> list[str]:
    """Lines under the IEEE table: why the headline B is a bound or nothing (when it is), then the B readings that
    are not the headline B (the GM hump's, the min-AVAR reading beside a flicker term), each labelled by its rule."""
    ie = axis.selection.ieee
    if axis.selection.no_result:
        return ["no result: no candidate passed its checks, so neither its terms nor its B readings are numbers to "
                "sign; the table gives the bounds the measured WV itself sets (--details says why each failed)"]
    head = ie.b_headline
    out = [] if head.value_dph is not None else [f"B ({head.label}): {head.text()}"]
    for b in ie.b_details:
        label = b.label if b.rule == "gm-max" else f"B_min, {b.label}"
        out.append(f"detail, not the headline B: {label}: {b.text()}")
    return out
