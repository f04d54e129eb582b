"""The commands ``fogdrift batch`` can run over many logs: one row of :data:`COMMANDS` each.

A command is a function ``run(record, settings, out_dir) -> list[dict]`` that calls the same workflow
(:mod:`fogdrift.workflows`) as the single command (so each file's folder holds what ``fogdrift allan`` or ``fogdrift
analyze`` would write there) and returns one summary row per axis (:mod:`.summary` names the columns; a
noise fit fills them with :func:`noise_columns`).  It runs inside the file's own
:class:`~fogdrift.output.OutputDir`, so every file it writes through :func:`~fogdrift.output.atomic_path`
(as the report functions do) is complete or absent.  Adding a command (the GMWM ``noise`` command, when it
lands) is one function and one row of :data:`COMMANDS`::

    def run_noise_command(record, settings, out_dir):
        results = ...                       # the calls `fogdrift noise` makes, writing into out_dir
        return [{"axis": a.name, **record_columns(record), **noise_columns(a.noise)} for a in results]

    COMMANDS["noise"] = CommandSpec("noise", run_noise_command, "GMWM noise model of every axis")
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from ..errors import ConfigError, FogdriftError
from ..noise.terms import TERM_TABLE
from ..spec import channel_kind, compare, judge_noise_fit, parse_spec, readings_from_gmwm, spec_columns

__all__ = ["CommandSpec", "COMMANDS", "command_spec", "noise_columns", "record_columns", "run_allan_command",
           "run_analyze_command", "TERMS", "spec_from_settings", "axis_kind"]

#: IEEE-952 coefficients in the summary, with the unit suffix of their columns, read from the term table
#: (``("Q", "urad"), ("N", "dprh"), ("B", "dph"), ("K", "dphrh"), ("R", "dph2")``).
TERMS = tuple((name, spec.suffix.lstrip("_")) for name, spec in TERM_TABLE.items())


@dataclass(frozen=True)
class CommandSpec:
    """One batch command.

    Parameters
    ----------
    name : str
        ``--command`` value.
    run : callable
        ``run(record, settings: dict, out_dir: Path) -> list[dict]``: writes the command's files into
        ``out_dir`` and returns one row per axis (keys: columns of :data:`fogdrift.fleet.summary.COLUMNS`).
    description : str
        For ``--help`` and messages.
    """

    name: str
    run: Callable
    description: str = ""


def _f(x):
    if x is None:
        return None
    x = float(x)
    return x if x == x and abs(x) != float("inf") else None


def record_columns(record) -> dict:
    """Summary columns that describe the record (duration, rate, unit, temperature)."""
    meta = record.metadata()
    row = {"n_samples": record.n_samples, "duration_s": record.duration_s, "rate_hz": record.fs_hz,
           "input_unit": record.input_unit, "t0_s": record.t0_s}
    temp = meta.get("temperature")
    for key in ("min_c", "max_c", "range_c", "change_c", "slope_c_per_h"):
        row[f"temperature_{key}"] = None if temp is None else _f(temp[key])
    return row


def ieee_columns(terms, b_min: dict) -> dict:
    """The one column mapper of the IEEE-952 coefficients, for the Allan fit and GMWM alike.

    Parameters
    ----------
    terms : mapping
        Term name (``Q``, ``N``, ``B``, ``K``, ``R``) -> an object with ``value``, ``lo95``, ``hi95`` (in the
        units of :data:`fogdrift.noise.TERM_UNITS`) and ``status``: a :class:`fogdrift.noise.NoiseTerm` or a
        :class:`fogdrift.gmwm.analysis.GmwmTerm`.
    b_min : dict
        The IEEE reading min ADEV / 0.664 in the shape of ``NoiseFit.b_min`` (``value`` [deg/h], ``tau_s`` [s],
        ``bound_only``); GMWM's through :meth:`fogdrift.gmwm.ieee.BiasInstability.as_b_min`.  ``{}``: none.

    Returns
    -------
    dict
        ``{name}_{unit}``, ``{name}_lo95_{unit}``, ``{name}_hi95_{unit}``, ``{name}_status`` per term, then
        ``b_min_dph``, ``b_min_tau_s``, ``b_min_bound_only``.
    """
    row = {}
    for name, unit in TERMS:
        term = terms[name]
        row[f"{name}_{unit}"] = _f(term.value)
        row[f"{name}_lo95_{unit}"] = _f(term.lo95)
        row[f"{name}_hi95_{unit}"] = _f(term.hi95)
        row[f"{name}_status"] = str(term.status)
    b = b_min or {}
    row.update(b_min_dph=_f(b.get("value")), b_min_tau_s=_f(b.get("tau_s")),
               b_min_bound_only=None if b.get("value") is None else bool(b.get("bound_only")))
    return row


def noise_columns(noise) -> dict:
    """Summary columns of one noise fit (:class:`fogdrift.noise.NoiseFit`).

    Each coefficient with its 95 % interval and status (``resolved``, ``unresolved``, ``absent`` with
    ``hi95`` its upper bound, ``not_estimable``); the selected model (``noise_model``, e.g. ``"N+B+K"``)
    and the plausible ones; the fit's quality, chi-squared, dof, p-value and tau range; the IEEE reading of
    the bias instability at the curve's minimum.
    """
    row = ieee_columns(noise.terms, noise.b_min)
    row.update(statistic=str(noise.statistic), noise_model="+".join(noise.selected) or "none",
               plausible_models="; ".join(noise.plausible) or None, fit_quality=str(noise.quality),
               fit_chi2_red=_f(noise.chi2_red), fit_dof=int(noise.dof), fit_p_value=_f(noise.p_value),
               fit_n_points=int(len(noise.fit_tau_s)), fit_tau_min_s=_f(noise.tau_min_s),
               fit_tau_max_s=_f(noise.tau_max_s),
               outliers=None if not noise.outliers else int(noise.outliers.get("count") or 0))
    return row


def spec_from_settings(settings: dict):
    """The datasheet limits of a batch (``settings["spec"]``: a spec file's mapping, e.g. ``{"sensor": "ADIS16405",
    "gyro": {"arw": "2 deg/sqrt(h)"}, "accel": {"vrw": "0.2 m/s/sqrt(h)"}}``), parsed by
    :func:`fogdrift.spec.parse_spec`; None without one.  ConfigError (one line) for a bad spec."""
    data = settings.get("spec")
    if data is None:
        return None
    source = data.get("source") if isinstance(data, dict) else None
    return parse_spec(data, source=f"spec {source}" if source else "settings spec")


def axis_kind(record, name: str) -> str:
    """``"gyro"`` or ``"accel"``: the spec section an axis is judged against (its channel's quantity)."""
    try:
        quantity = record.signal.channel(name).quantity
    except (FogdriftError, AttributeError):  # no such channel / no signal description: a gyro, as everywhere else
        quantity = None
    return channel_kind(quantity)


def _spec_allan(limits, record, name: str, noise) -> dict:
    """``spec_<item>`` / ``spec_<item>_why`` columns of an Allan fit (none without a spec)."""
    if limits is None:
        return {}
    return spec_columns(judge_noise_fit(limits, name, noise, axis_kind(record, name)))


def _spec_gmwm(limits, record, axis) -> dict:
    """``spec_<item>`` / ``spec_<item>_why`` columns of a GMWM axis (none without a spec)."""
    if limits is None:
        return {}
    kind = axis_kind(record, axis.name)
    return spec_columns(compare(limits, {axis.name: (kind, readings_from_gmwm(axis, kind))}))


def _config(settings: dict):
    from ..pipeline import AnalysisConfig

    return AnalysisConfig(**settings.get("analysis", {})).validate()


def run_allan_command(record, settings: dict, out_dir) -> list[dict]:
    """``fogdrift allan`` on one record: ``allan.json``, ``allan.csv``, ``allan.png`` and one row per axis.

    The workflow of the ``allan`` command (:func:`fogdrift.workflows.allan.run_allan` and ``write_allan``), so the
    files are the ones it writes.
    """
    from ..workflows.allan import run_allan, write_allan

    limits = spec_from_settings(settings)
    done = run_allan(record, _config(settings), segments=settings.get("segments", "auto"))
    write_allan(done, out_dir)
    return [{"axis": a.name, **record_columns(record), **noise_columns(a.noise),
             **_spec_allan(limits, record, a.name, a.noise)} for a in done.results]


def run_analyze_command(record, settings: dict, out_dir) -> list[dict]:
    """``fogdrift analyze`` on one record (:func:`fogdrift.workflows.analyze.run_analyze` and ``write_analyze``): the
    heading-error and artefact evaluation (on by default, as in the single command), ``report.html``,
    ``analysis.json``, the model ``bundle/``, the compensated test block per axis (``compensated_test_<axis>.csv``)
    and one row per axis with the verdicts."""
    from ..evaluation.verdicts import paper_measure_verdict
    from ..workflows.analyze import run_analyze, write_analyze

    limits = spec_from_settings(settings)
    done = run_analyze(record, _config(settings), limits=limits, segments=settings.get("segments", "auto"))
    write_analyze(done, out_dir, spec_source=(settings.get("spec") or {}).get("source") or "")
    result = done.result
    evaluations = {ax.name: ax.evaluation for ax in result.axes}
    spec_cols = {ax.name: spec_columns([j for j in done.judgements if j.channel == ax.name]) for ax in result.axes} \
        if limits is not None else {}
    rows = []
    for ax in result.axes:
        ev = evaluations.get(ax.name)
        rows.append({"axis": ax.name, **record_columns(record), **noise_columns(ax.original.noise),
                     "verdict": " ".join(paper_measure_verdict(ax.models).lines),
                     "compensation_outcome": None if ev is None else str(ev.outcome),
                     "compensation_headline": None if ev is None else " ".join(ev.headline.lines),
                     **spec_cols.get(ax.name, {})})
    return rows


def run_noise_command(record, settings: dict, out_dir) -> list[dict]:
    """``fogdrift noise`` (GMWM) on one record (:func:`fogdrift.workflows.noise.run_noise` and ``write_noise``):
    ``noise.json``, ``wvar.csv``, ``noise.png`` and one row per axis.

    ``settings["gmwm"]`` holds the options of ``fogdrift noise`` (``model``: ``"auto"`` = selection by WIC,
    or a fixed model such as ``"WN+RW+GM"``; ``levels``: the number of scales J; ``robust``: Huber WV);
    missing keys take that command's defaults.  Row: each IEEE-952 coefficient the selected model
    implies with its 95 % interval (``resolved`` when the interval excludes zero, ``absent`` when the model
    has no such term), the selected model, the J test's p-value (``fit_quality`` ``good`` when every check
    passed, else ``poor``) and the bias instability at the AVAR minimum implied by the model.
    """
    from ..workflows.noise import run_noise, write_noise

    opts = settings.get("gmwm", {})
    limits = spec_from_settings(settings)
    done = run_noise(record, model=opts.get("model", "auto"), levels=opts.get("levels"),
                     robust=bool(opts.get("robust", False)), segments=settings.get("segments", "auto"))
    write_noise(done, out_dir)
    return [{"axis": a.name, **record_columns(record), **gmwm_columns(a), **_spec_gmwm(limits, record, a)}
            for a in done.axes]


def gmwm_columns(axis) -> dict:
    """Summary columns of one GMWM axis (:class:`fogdrift.gmwm.analysis.GmwmAxis`)."""
    sel = axis.selection
    ie = sel.ieee
    # the model's ADEV minimum, or its 95 % bound where it lies beyond the scales used (gmwm.ieee)
    row = {"statistic": "wvar", **ieee_columns(axis.ieee_terms(), ie.b_min.as_b_min())}
    fit = sel.fit
    row.update(noise_model=str(sel.selected), fit_quality="good" if sel.passed_checks else "poor",
               fit_dof=int(fit.df), fit_p_value=_f(fit.j_pvalue),
               fit_n_points=int(len(axis.wvar.scale_s) - len(sel.excluded)))
    return row


COMMANDS: dict[str, CommandSpec] = {
    "allan": CommandSpec("allan", run_allan_command, "Allan variance and IEEE-952 coefficients of every axis"),
    "analyze": CommandSpec("analyze", run_analyze_command,
                           "the whole method (separation, drift models, compensation) with an HTML report"),
    "noise": CommandSpec("noise", run_noise_command, "GMWM noise model of every axis (fogdrift noise)"),
}


def command_spec(name: str) -> CommandSpec:
    """The :data:`COMMANDS` row of ``name``; ConfigError listing the commands otherwise.

    Examples
    --------
    >>> command_spec("allan").name
    'allan'
    """
    try:
        return COMMANDS[name]
    except (KeyError, TypeError):
        raise ConfigError(f"unknown batch command {name!r}; expected one of {list(COMMANDS)} in {{opt:command}}") \
            from None
