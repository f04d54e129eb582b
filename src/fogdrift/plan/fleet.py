"""``fogdrift plan --fleet``: how many units of a type to record to know the type's spread (and mean) of each
noise term to a stated precision, with the fleet table of ``fogdrift batch`` as the pilot.

The pilot is the batch's ``summary.parquet`` (or a CSV with its columns): one row per file x axis, each IEEE-952
term ``{T}_{unit}`` with its 95 % interval ``{T}_lo95_{unit}``, ``{T}_hi95_{unit}`` and ``{T}_status``.  A unit
is one row; only the rows where the term is ``resolved`` enter that term.

Statistics, per term (values in the table's unit; widths relative 95 % half-widths, ``(hi - lo) / (2 value)``):

* each unit's own measurement error ``sd_i = (hi95_i - lo95_i) / (2 z)``, ``z = 1.96`` (the interval taken as
  normal); the within-unit variance ``w2 = mean(sd_i^2)``;
* the SD of the measured values over the units, ``s``, estimates the **total** SD ``sigma_t = sqrt(sigma_b^2 +
  w2)``; the **between-unit** SD (the type's spread) is ``sigma_b = sqrt(max(s^2 - w2, 0))`` (0: the units' own
  intervals explain the scatter, the spread is not resolved from the pilot);
* with ``M`` units, ``(M - 1) s^2 / sigma_t^2`` is chi-square with ``M - 1`` degrees of freedom (normal units,
  equal own errors), so ``sigma_t`` lies in ``[s sqrt((M-1)/chi2_0.975), s sqrt((M-1)/chi2_0.025)]`` and, with
  ``w2`` taken as known, ``sigma_b`` in ``[sqrt(max((M-1) s^2/chi2_0.975 - w2, 0)), sqrt(max((M-1) s^2/chi2_0.025
  - w2, 0))]`` (the rule: subtract the units' own variance from both ends of the total variance's interval);
* the type's mean: ``mean +- t_0.975,M-1 s / sqrt(M)`` (``s`` holds both the spread and the units' own errors);
* planned widths are those at the expected ``s = sigma_t`` of the pilot, for units recorded as the pilot's were
  (same length and rate, so the same own errors).  The units needed: the smallest ``M >= 2`` (up to
  :data:`MAX_UNITS`) from which every larger fleet meets the target.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ConfigError, DataFormatError
from ..io.readers.base import require
from ..noise.terms import ACCEL_TERM_TABLE, TERM_TABLE
from .model import PLANNED_TERMS, parse_targets

__all__ = ["FleetPilot", "FleetPlan", "read_fleet_table", "rows_of_estimator", "ESTIMATOR_OF_COMMAND", "fleet_pilot", "term_spread", "sd_interval",
           "spread_width", "mean_width", "units_needed", "make_fleet_plan", "parse_fleet_targets",
           "DEFAULT_SPREAD_TARGET", "DEFAULT_MEAN_TARGET", "MAX_UNITS", "MIN_UNITS", "SUMMARY_NAME", "Z95"]

#: The fleet table ``fogdrift batch`` writes in its output folder.
SUMMARY_NAME = "summary.parquet"
#: Largest fleet searched.
MAX_UNITS = 10_000
#: Fewest units with a resolved term for the term to be planned.
MIN_UNITS = 3
#: Default relative 95 % half-width of the between-unit SD (each planned term).
DEFAULT_SPREAD_TARGET = 0.25
#: Default relative 95 % half-width of the type's mean (each planned term).
DEFAULT_MEAN_TARGET = 0.10
#: Normal 97.5 % quantile: a 95 % interval is +-Z95 sd.
Z95 = 1.959963984540054
#: Fleet sizes at which a plan keeps each term's width curve (about 16 per decade from 2 to :data:`MAX_UNITS`).
CURVE_UNITS = np.unique(np.round(np.logspace(math.log10(2), math.log10(MAX_UNITS), 60)).astype(np.int64))


#: The estimator behind a fleet-table row, by the ``fogdrift batch`` command that made it.
ESTIMATOR_OF_COMMAND = {"allan": "allan", "analyze": "allan", "noise": "gmwm"}
#: The estimators' names on the first screen.
ESTIMATOR_NAMES = {"allan": "Allan fit", "gmwm": "GMWM"}


# -- the fleet table ----------------------------------------------------------------------------------------
def rows_of_estimator(rows, estimators=("allan", "gmwm"), source="fleet table") -> tuple[list[dict], str | None]:
    """The rows of one estimator (:data:`ESTIMATOR_OF_COMMAND` of each row's ``command``) and its name; the units
    of a type are planned from one estimator's intervals, never two pooled (a unit would count twice).

    ``estimators``: the ones asked for (``{opt:estimator}``; both: whichever the table holds, if it holds one).  A
    table without a ``command`` column is taken as it is when both are asked for (the name is then None).

    Raises
    ------
    ConfigError
        Rows of both estimators with both asked for, or no row of the estimator asked for.

    Examples
    --------
    >>> rows_of_estimator([{"command": "noise", "axis": "gx"}], ("gmwm",))
    ([{'command': 'noise', 'axis': 'gx'}], 'gmwm')
    """
    kinds = {ESTIMATOR_OF_COMMAND.get(str(r.get("command", ""))) for r in rows}
    if None in kinds:
        if set(estimators) >= {"allan", "gmwm"}:
            return list(rows), None
        raise ConfigError(f"{{opt:fleet}} {source}: the table does not say which estimator made its rows (no batch "
                          f"'command' column for some); drop {{opt:estimator}} to plan from the table as it is")
    found = kinds & set(estimators)
    held = " and ".join(ESTIMATOR_NAMES[k] for k in sorted(kinds))
    if not found:
        raise ConfigError(f"{{opt:fleet}} {source} holds {held} rows only; {{opt:estimator}} "
                          f"{' or '.join(estimators)} finds none")
    if len(found) > 1:
        raise ConfigError(f"{{opt:fleet}} {source} holds rows of the Allan fit (batch allan/analyze) and of the GMWM "
                          "(batch noise): plan from one, with {opt:estimator} allan or gmwm")
    name = found.pop()
    return [r for r in rows if ESTIMATOR_OF_COMMAND[str(r.get("command"))] == name], name


def read_fleet_table(path) -> tuple[list[dict], Path]:
    """Rows of a fleet table: a ``fogdrift batch`` output folder (its :data:`SUMMARY_NAME`), the Parquet file, or a
    CSV with the same column names (e.g. ``duckdb -c "COPY (SELECT * FROM 'summary.parquet') TO 'fleet.csv'"``).

    Returns
    -------
    (rows, path)
        The rows as dicts (CSV: empty cells None, numbers as float) and the file read.

    Raises
    ------
    DataFormatError
        Missing or unreadable table (message names the file and ``{opt:fleet}``).
    """
    p = Path(path).expanduser()
    if p.is_dir():
        if not (p / SUMMARY_NAME).is_file():
            raise DataFormatError(f"{{opt:fleet}} {p}: no {SUMMARY_NAME} in this folder (give a fogdrift batch "
                                  "output folder or its fleet table)")
        p = p / SUMMARY_NAME
    if not p.is_file():
        raise DataFormatError(f"{{opt:fleet}} {p}: no such file (give a fogdrift batch output folder or its "
                              f"{SUMMARY_NAME})")
    suffix = p.suffix.lower()
    try:
        if suffix == ".csv":
            with open(p, newline="", encoding="utf-8") as fh:
                rows = [{k: _cell(v) for k, v in r.items()} for r in csv.DictReader(fh)]
        else:
            pq = require("pyarrow.parquet", "fleet", "reading the batch fleet table (Parquet)")
            rows = pq.read_table(p).to_pylist()
    except (OSError, ValueError, UnicodeDecodeError) as exc:
        raise DataFormatError(f"{{opt:fleet}} {p}: not a readable fleet table ({type(exc).__name__}: {exc})"
                              ) from exc
    except Exception as exc:  # pyarrow's own errors (ArrowInvalid is a ValueError; others are not)
        if type(exc).__module__.startswith("pyarrow"):
            raise DataFormatError(f"{{opt:fleet}} {p}: not a readable Parquet fleet table ({exc})") from exc
        raise
    return rows, p


def _cell(v):
    if v is None or v == "":
        return None
    try:
        return float(v)
    except ValueError:
        return v


def _columns(quantity: str) -> dict:
    """Term -> (value, lo95, hi95, status) column names of a quantity's rows."""
    table = ACCEL_TERM_TABLE if quantity == "specific_force" else TERM_TABLE
    out = {}
    for name, spec in table.items():
        u = spec.suffix.lstrip("_")
        out[name] = (f"{name}_{u}", f"{name}_lo95_{u}", f"{name}_hi95_{u}", f"{name}_status")
    return out


def _unit_text(name: str, quantity: str) -> str:
    return (ACCEL_TERM_TABLE if quantity == "specific_force" else TERM_TABLE)[name].unit


@dataclass
class FleetPilot:
    """The pilot fleet: per term the resolved units' values and 95 % bounds (the table's unit, :attr:`units`).

    ``terms``: term -> ``{"labels", "value", "lo95", "hi95"}`` (lists over the units that resolve it);
    ``n_rows``: units (rows) read; ``axes``: the axis names pooled; ``notes``: what was left out and why.
    """

    source: str
    quantity: str
    n_rows: int
    axes: list
    terms: dict
    units: dict
    notes: list = field(default_factory=list)


def fleet_pilot(rows, source="fleet table", axis=None) -> FleetPilot:
    """The pilot from fleet-table rows: error rows dropped, one quantity (the gyro's unless only accelerometer
    rows, or ``axis`` names an accelerometer axis), ``axis`` (if given) alone; per term the rows whose
    ``{T}_status`` is ``resolved`` with finite value and bounds ``lo95 <= value <= hi95``.

    Raises
    ------
    DataFormatError
        No term columns, or no usable row (message names ``source`` and ``{opt:fleet}``).
    ConfigError
        ``axis`` is not in the table.
    """
    rows = [r for r in rows if r.get("status") != "error"]
    if not rows:
        raise DataFormatError(f"{{opt:fleet}} {source}: no unit without an error in the fleet table")
    if axis is not None:
        names = sorted({str(r.get("axis")) for r in rows})
        rows = [r for r in rows if str(r.get("axis")) == axis]
        if not rows:
            raise ConfigError(f"{{opt:axis}} {axis!r} is not an axis of the fleet table {source} "
                              f"({', '.join(names)})")
    quantities = {r.get("quantity") or "angular_rate" for r in rows}
    quantity = "angular_rate" if "angular_rate" in quantities or len(quantities) != 1 else quantities.pop()
    notes = []
    kept = [r for r in rows if (r.get("quantity") or "angular_rate") == quantity]
    if len(kept) < len(rows):
        notes.append(f"{len(rows) - len(kept)} accelerometer row(s) left out (the gyro rows are planned; "
                     "--axis NAME plans an accelerometer axis)")
    rows = kept
    cols = _columns(quantity)
    if not any(c[0] in r for r in rows for c in cols.values()):
        raise DataFormatError(f"{{opt:fleet}} {source}: no term columns ({', '.join(c[0] for c in cols.values())}); "
                              "is it a fogdrift batch fleet table?")
    terms = {}
    for name in PLANNED_TERMS:
        vcol, locol, hicol, scol = cols[name]
        labels, v, lo, hi = [], [], [], []
        for i, r in enumerate(rows):
            x, a, b = (_num(r.get(c)) for c in (vcol, locol, hicol))
            if r.get(scol) != "resolved" or not all(map(math.isfinite, (x, a, b))) or not a <= x <= b:
                continue
            labels.append(f"{r.get('file') or i}:{r.get('axis') or ''}")
            v.append(x)
            lo.append(a)
            hi.append(b)
        if v:
            terms[name] = {"labels": labels, "value": v, "lo95": lo, "hi95": hi}
    axes = sorted({str(r.get("axis")) for r in rows if r.get("axis") is not None})
    return FleetPilot(source=str(source), quantity=quantity, n_rows=len(rows), axes=axes, terms=terms,
                      units={t: _unit_text(t, quantity) for t in terms}, notes=notes)


def _num(x) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


# -- the statistics ------------------------------------------------------------------------------------------
def _chi2_bounds(m):
    """(chi2_0.025, chi2_0.975) with ``m - 1`` degrees of freedom (``m``: units, >= 2; scalar or array)."""
    from scipy.stats import chi2

    dof = np.asarray(m, dtype=float) - 1.0
    return chi2.ppf(0.025, dof), chi2.ppf(0.975, dof)


def sd_interval(s, m, w2=0.0):
    """95 % interval of the between-unit SD from the SD ``s`` of ``m`` measured values whose own errors have mean
    variance ``w2`` (same unit as ``s``, squared), taken as known.

    ``[sqrt(max((m-1) s^2 / chi2_0.975 - w2, 0)), sqrt(max((m-1) s^2 / chi2_0.025 - w2, 0))]``; with ``w2 = 0``
    the chi-square interval of a normal SD.  Vectorised over ``s`` (and ``m``).

    Examples
    --------
    >>> lo, hi = sd_interval(1.0, 10)
    >>> round(float(lo), 4), round(float(hi), 4)
    (0.6878, 1.8256)
    """
    q_lo, q_hi = _chi2_bounds(m)
    v = (np.asarray(m, dtype=float) - 1.0) * np.square(s)
    return np.sqrt(np.maximum(v / q_hi - w2, 0.0)), np.sqrt(np.maximum(v / q_lo - w2, 0.0))


def spread_width(m, within_share=0.0):
    """Expected relative 95 % half-width of the between-unit SD from ``m`` units, at ``s = sigma_t``.

    Parameters
    ----------
    m : int or array
        Units (>= 2).
    within_share : float
        ``w2 / sigma_t^2`` in [0, 1): the share of the units' own error variance in the total.  0: the plain
        chi-square width of an SD.

    Returns
    -------
    float or array
        ``(hi - lo) / (2 sigma_b)`` of :func:`sd_interval` at ``s = sigma_t``; inf when ``within_share >= 1``.
    """
    r = float(within_share)
    if not r < 1.0:
        return np.full(np.shape(m), np.inf) if np.ndim(m) else math.inf
    lo, hi = sd_interval(1.0, m, r)
    return (hi - lo) / (2.0 * math.sqrt(1.0 - r))


def mean_width(m, cv):
    """Expected relative 95 % half-width of the type's mean from ``m`` units: ``t_0.975,m-1 cv / sqrt(m)``,
    ``cv = sigma_t / |mean|`` (the total SD of a measured unit over the mean)."""
    from scipy.stats import t as student_t

    m = np.asarray(m, dtype=float)
    return student_t.ppf(0.975, m - 1.0) * cv / np.sqrt(m)


def units_needed(widths, target, m0=2):
    """The smallest ``m`` (grid ``m0, m0 + 1, ...`` of ``widths``) from which every width is <= ``target``; None
    when the last is not."""
    w = np.asarray(widths, dtype=float)
    over = np.flatnonzero(~(w <= target))
    if over.size == 0:
        return m0
    if over[-1] == w.size - 1:
        return None
    return int(m0 + over[-1] + 1)


def term_spread(value, lo95, hi95) -> dict:
    """The pilot's spread of one term (values and bounds in one unit): ``n``, ``mean``, ``sd`` (``s``, over the
    units), ``within_sd`` (``sqrt(w2)``), ``between_sd`` (``sigma_b``), ``total_sd`` (``sqrt(sigma_b^2 + w2)``),
    ``within_share`` (``w2 / total_sd^2``), ``resolved`` (``s^2 > w2``), ``between_sd_95`` (the pilot's own interval,
    :func:`sd_interval`) and ``mean_95`` (t interval)."""
    from scipy.stats import t as student_t

    x = np.asarray(value, dtype=float)
    sd_i = (np.asarray(hi95, dtype=float) - np.asarray(lo95, dtype=float)) / (2.0 * Z95)
    n = x.size
    s = float(np.std(x, ddof=1))
    w2 = float(np.mean(sd_i ** 2))
    b2 = max(s * s - w2, 0.0)
    total = math.sqrt(b2 + w2)
    lo, hi = sd_interval(s, n, w2)
    h = float(student_t.ppf(0.975, n - 1)) * s / math.sqrt(n)
    mean = float(np.mean(x))
    return {"n": n, "mean": mean, "sd": s, "within_sd": math.sqrt(w2), "between_sd": math.sqrt(b2),
            "total_sd": total, "within_share": w2 / total ** 2 if total > 0 else 1.0, "resolved": b2 > 0,
            "between_sd_95": [float(lo), float(hi)], "mean_95": [mean - h, mean + h]}


# -- the plan ----------------------------------------------------------------------------------------------
def parse_fleet_targets(spread, mean, available):
    """(spread targets, mean targets): term -> relative 95 % half-width, from ``--target`` / ``--mean-target``
    text (``"N:20%,B:30%"``).  Defaults: :data:`DEFAULT_SPREAD_TARGET` for every term in ``available`` (or in
    ``--mean-target``) when ``--target`` is absent; :data:`DEFAULT_MEAN_TARGET` for the spread's terms when
    ``--mean-target`` is absent."""
    sp = parse_targets(spread, PLANNED_TERMS) if spread else None
    mn = parse_targets(mean, PLANNED_TERMS) if mean else None
    if sp is None:
        sp = {t: DEFAULT_SPREAD_TARGET for t in (mn or available)}
    if mn is None:
        mn = {t: DEFAULT_MEAN_TARGET for t in sp}
    return sp, mn


@dataclass
class FleetPlan:
    """Result of :func:`make_fleet_plan`.  ``terms``: term -> the pilot's :func:`term_spread` plus ``unit``,
    ``labels``, ``spread_target`` / ``mean_target`` (widths asked; None: not asked), ``spread_units`` /
    ``mean_units`` (units needed; None: more than :data:`MAX_UNITS` or the spread is not resolved),
    ``spread_resolved_units`` (units from which the expected interval of the spread excludes 0), ``curve`` (the
    expected widths at the fleet sizes :data:`CURVE_UNITS`: ``units``, ``spread_width``, ``mean_width``) and, with
    ``units``, ``at_units`` (the widths ``units`` units give)."""

    pilot: FleetPilot
    terms: dict
    units: int | None = None
    notes: list = field(default_factory=list)

    def lines(self) -> list[str]:
        """The first-screen lines: one per planned term, then what ``--units M`` gives."""
        out = []
        for t, r in self.terms.items():
            u = r["unit"]
            lo, hi = r["between_sd_95"]
            head = (f"{t} spread (between-unit SD {_g(r['between_sd'])} {u}, pilot 95 % {_g(lo)}–{_g(hi)}, "
                    f"from {r['n']} pilot units; their own errors {_g(r['within_sd'])} {u})")
            parts = []
            if r["spread_target"] is not None:
                w = f"±{100 * r['spread_target']:.3g} %"
                if not r["resolved"]:
                    parts.append(f"to {w}: not plannable (spread not resolved from the pilot)")
                elif r["spread_units"] is None:
                    parts.append(f"to {w}: more than {MAX_UNITS} units")
                else:
                    parts.append(f"to {w}: {r['spread_units']} units{_range(r['spread_units_range'])}")
            if r["mean_target"] is not None:
                w = f"±{100 * r['mean_target']:.3g} %"
                m = r["mean_units"]
                parts.append(f"type mean ({_g(r['mean'])} {u}) to {w}: "
                             + (f"{m} units" if m is not None else f"more than {MAX_UNITS} units")
                             + _range(r["mean_units_range"]))
            out.append(head + (" " + "; ".join(parts) if parts else ""))
        if self.units is not None:
            bits = []
            for t, r in self.terms.items():
                a = r["at_units"]
                sw = ("not resolved" if not math.isfinite(a["spread_width"]) else
                      f"±{100 * a['spread_width']:.3g} %")
                bits.append(f"{t} spread {sw}, mean ±{100 * a['mean_width']:.3g} %")
            out.append(f"a fleet of {self.units} units gives " + "; ".join(bits))
        return out

    def to_dict(self) -> dict:
        """The ``fleet`` section of ``plan.json`` (non-finite numbers as null)."""
        p = self.pilot
        return _clean({
            "pilot": {"source": p.source, "quantity": p.quantity, "units_read": p.n_rows, "axes": p.axes},
            "width": "relative 95 % half-width, (hi95 - lo95) / (2 value)",
            "spread": "between-unit SD sqrt(max(s^2 - w2, 0)); s: SD of the units' values, w2: mean of their own "
                      "variances ((hi95 - lo95) / (2 * 1.96))^2; interval from chi-square with M - 1 dof on s^2, "
                      "w2 subtracted from both ends",
            "mean": "t interval, t(0.975, M - 1) s / sqrt(M)",
            "max_units": MAX_UNITS, "units": self.units, "terms": self.terms, "notes": self.notes,
            "lines": self.lines()})


def _range(ends) -> str:
    if not ends:
        return ""
    a, b = (str(e) if e is not None else f">{MAX_UNITS}" for e in ends)
    return f" ({a}–{b} over the pilot's 95 % range)" if a != b else ""


def _g(x) -> str:
    return f"{x:.3g}" if x is not None and math.isfinite(x) else "n/a"


def _clean(x):
    if isinstance(x, dict):
        return {k: _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    if isinstance(x, np.generic):
        return _clean(x.item())
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def _ranges(r, grid):
    """Units needed at the two ends of the pilot's own 95 % intervals: the spread's over ``between_sd_95``
    (``[at the upper end, at the lower end]``; None: more than :data:`MAX_UNITS` or not resolved), the mean's over
    the chi-square interval of the total SD (``[at the lower end, at the upper end]``)."""
    w2 = r["within_sd"] ** 2
    spread = None
    if r["spread_target"] is not None and r["resolved"]:
        spread = [units_needed(spread_width(grid, w2 / (b * b + w2)) if b > 0 else np.full(grid.size, np.inf),
                               r["spread_target"]) for b in reversed(r["between_sd_95"])]
    mean = None
    if r["mean_target"] is not None and r["mean"] != 0:
        ends = sd_interval(r["sd"], r["n"])
        mean = [units_needed(mean_width(grid, float(e) / abs(r["mean"])), r["mean_target"]) for e in ends]
    return spread, mean


def make_fleet_plan(pilot: FleetPilot, spread_targets: dict, mean_targets: dict, units: int | None = None,
                    *, explicit: bool = True) -> FleetPlan:
    """Units needed per term for ``spread_targets`` (relative 95 % half-width of the between-unit SD) and
    ``mean_targets`` (of the type's mean); with ``units`` also the widths that many units give.

    Parameters
    ----------
    pilot : FleetPilot
    spread_targets, mean_targets : dict
        Term -> relative 95 % half-width (0.25 = +-25 %).
    units : int, optional
        A fleet size (>= 2) to evaluate.
    explicit : bool
        The targets were asked for: a term with fewer than :data:`MIN_UNITS` resolved units is refused
        (``False``: left out with a note).

    Raises
    ------
    ConfigError
        A targeted term has fewer than :data:`MIN_UNITS` resolved units, or no term can be planned.
    """
    if units is not None and not 2 <= units <= MAX_UNITS:
        raise ConfigError(f"{{opt:units}} must be between 2 and {MAX_UNITS}; got {units}")
    grid = np.arange(2, MAX_UNITS + 1)
    notes = list(pilot.notes)
    out = {}
    for t in [t for t in PLANNED_TERMS if t in spread_targets or t in mean_targets]:
        d = pilot.terms.get(t)
        n = 0 if d is None else len(d["value"])
        if n < MIN_UNITS:
            msg = (f"{t}: {n} unit(s) of {pilot.n_rows} in {pilot.source} resolve it; the fleet plan needs at "
                   f"least {MIN_UNITS}")
            if explicit:
                raise ConfigError(f"{{opt:fleet}} {msg} ({{opt:target}} names it)")
            notes.append(msg + "; not planned")
            continue
        r = term_spread(d["value"], d["lo95"], d["hi95"])
        r.update(unit=pilot.units[t], labels=d["labels"], spread_target=spread_targets.get(t),
                 mean_target=mean_targets.get(t))
        if n < pilot.n_rows:
            notes.append(f"{t}: {n} of {pilot.n_rows} units resolve it; only those enter")
        if not r["resolved"]:
            notes.append(f"{t}: spread not resolved from the pilot: the units' own intervals explain it "
                         f"(SD {_g(r['sd'])} <= own error {_g(r['within_sd'])} {r['unit']})")
        sw = spread_width(grid, r["within_share"]) if r["resolved"] else np.full(grid.size, np.inf)
        cv = r["total_sd"] / abs(r["mean"]) if r["mean"] != 0 else math.inf
        mw = mean_width(grid, cv)
        r["spread_units"] = (units_needed(sw, r["spread_target"]) if r["spread_target"] is not None
                             and r["resolved"] else None)
        r["mean_units"] = units_needed(mw, r["mean_target"]) if r["mean_target"] is not None else None
        r["spread_units_range"], r["mean_units_range"] = _ranges(r, grid)
        if r["resolved"] and r["within_share"] > 0.5 and r["spread_target"] is not None:
            notes.append(f"{t}: the units' own errors are {100 * r['within_share']:.0f} % of the scatter's variance; "
                         "longer records per unit (fogdrift plan on one unit's log) need fewer units")
        lo, _ = sd_interval(1.0, grid, r["within_share"])
        r["spread_resolved_units"] = units_needed(-lo, -1e-12) if r["resolved"] else None
        if units is not None:
            r["at_units"] = {"spread_width": float(sw[units - 2]), "mean_width": float(mw[units - 2])}
        k = CURVE_UNITS - 2  # the widths against fleet size, for the figure and plan.json
        r["curve"] = {"units": CURVE_UNITS.tolist(), "spread_width": sw[k].tolist(), "mean_width": mw[k].tolist()}
        out[t] = r
    if not out:
        raise ConfigError(f"{{opt:fleet}} {pilot.source}: no term is resolved in {MIN_UNITS} or more of its "
                          f"{pilot.n_rows} units; nothing to plan")
    if len(pilot.axes) > 1:
        notes.append(f"units: {pilot.n_rows} rows of axes {', '.join(pilot.axes)} pooled as one type (each axis a "
                     "unit; axes of one IMU may not be independent); --axis NAME plans one axis")
    return FleetPlan(pilot=pilot, terms=out, units=units, notes=notes)
