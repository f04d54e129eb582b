"""The commands ``fogdrift batch`` can run over many logs: one row of :data:`COMMANDS` each.

A command is a function ``run(record, settings, out_dir) -> list[dict]`` that calls the same library and
report functions as the single command (so each file's folder holds what ``fogdrift allan`` or ``fogdrift
analyze`` would write there) and returns one summary row per axis (:mod:`.summary` names the columns).
Adding a command (the GMWM ``noise`` command, when it lands) is one function and one :class:`CommandSpec`
row::

    COMMANDS["noise"] = CommandSpec("noise", run_noise, "GMWM noise model", settings=("gmwm",))
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from ..errors import ConfigError

__all__ = ["CommandSpec", "COMMANDS", "command_spec", "noise_columns", "record_columns", "run_allan_command",
           "run_analyze_command", "TERMS"]

#: IEEE-952 coefficients in the summary, with the unit suffix of their columns.
TERMS = (("Q", "urad"), ("N", "dprh"), ("B", "dph"), ("K", "dphrh"), ("R", "dph2"))


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


def noise_columns(noise) -> dict:
    """Summary columns of one noise fit: each coefficient with its 95 % interval and estimability, fit quality.

    ``noise_model`` is the set of terms whose 95 % interval excludes zero (``"N+B+K"``): the noise
    model the data resolve.
    """
    row = {}
    resolved = []
    for name, unit in TERMS:
        term = noise.terms[name]
        row[f"{name}_{unit}"] = _f(term.value)
        row[f"{name}_lo95_{unit}"] = _f(term.lo95)
        row[f"{name}_hi95_{unit}"] = _f(term.hi95)
        row[f"{name}_estimable"] = bool(term.estimable)
        if term.estimable and term.lo95 is not None and term.lo95 > 0:
            resolved.append(name)
    row.update(noise_model="+".join(resolved) or "none", fit_method=str(noise.method),
               fit_chi2_red=_f(noise.chi2_red), fit_n_points=int(noise.n_points),
               fit_tau_min_s=_f(noise.tau_min_s), fit_tau_max_s=_f(noise.tau_max_s),
               fitted_terms="+".join(noise.fitted_terms))
    return row


def _config(settings: dict):
    from ..pipeline import AnalysisConfig

    return AnalysisConfig(**settings.get("analysis", {})).validate()


def run_allan_command(record, settings: dict, out_dir) -> list[dict]:
    """``fogdrift allan`` on one record: ``allan.json``, ``allan.csv``, ``allan.png`` and one row per axis."""
    from ..pipeline import run_allan
    from ..report import write_allan_outputs

    results = run_allan(record, _config(settings))
    write_allan_outputs(results, record, out_dir)
    return [{"axis": a.name, **record_columns(record), **noise_columns(a.noise)} for a in results]


def run_analyze_command(record, settings: dict, out_dir) -> list[dict]:
    """``fogdrift analyze`` on one record: ``report.html``, ``analysis.json`` and one row per axis with the verdict."""
    from ..pipeline import run_analysis
    from ..report import verdict, write_report

    result = run_analysis(record, _config(settings))
    write_report(result, record, out_dir)
    return [{"axis": ax.name, **record_columns(record), **noise_columns(ax.original.noise),
             "verdict": " ".join(verdict(ax.models))} for ax in result.axes]


#: The batch commands (``--command``); the GMWM ``noise`` command will be one more row.
COMMANDS: dict[str, CommandSpec] = {
    "allan": CommandSpec("allan", run_allan_command, "Allan variance and IEEE-952 coefficients of every axis"),
    "analyze": CommandSpec("analyze", run_analyze_command,
                           "the whole method (separation, drift models, compensation) with an HTML report"),
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
