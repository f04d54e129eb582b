"""``fogdrift plan``: how long to record, for the Allan fit and the GMWM (``--estimator``).  From a pilot log (the
Allan fit of one gyro axis, as ``fogdrift allan``) or a stated model (``--model "N=0.15 deg/sqrt(h), B=0.5 deg/h"`` with ``--rate``, or a fogdrift JSON), the record
length at which each target term is resolved and reaches its requested 95 % width, checked by Monte-Carlo
(``--monte-carlo N`` seeds; ``--rate``: the sample rate of the record to plan, with a stated model); ``--length`` says what a record of that length supports."""

from __future__ import annotations

import inspect
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import ConfigError
from ._app import JsonOpt, OutOpt, app, echo_record, run, say, with_load_options

DEFAULT_OUT = Path("out/plan")


def _optional_file(func):
    sig = inspect.signature(func)
    params = [p.replace(default=None, annotation=Annotated[Optional[Path], typer.Argument(
        help="Pilot gyro log (omit with --model).")]) if p.name == "file" else p for p in sig.parameters.values()]
    func.__signature__ = sig.replace(parameters=params)
    return func


@app.command()
@_optional_file
@with_load_options
def plan(
    load,
    model: Annotated[Optional[str], typer.Option("--model", help="Stated model instead of a pilot log: terms "
                     "such as \"N=0.15 deg/sqrt(h), B=0.5 deg/h, K=0.02 deg/h^1.5\" (with --rate), or a fogdrift "
                     "allan.json / noise.json / noise_model.json.")] = None,
    target: Annotated[Optional[str], typer.Option("--target", help="Relative 95 % half-width per term, e.g. "
                      "\"B:10%,K:25%,N:2%\" (default N:5%, B:10%, K:25%, Q:25%, R:25% of the model's terms).")] = None,
    length: Annotated[Optional[str], typer.Option("--length", help="Also say what a record of this length "
                      "supports (2h, 30min, 1.5d, 7200s).")] = None,
    monte_carlo: Annotated[int, typer.Option("--monte-carlo", help="Seeds of the Monte-Carlo check at each "
                           "planned length (0: analytic only).")] = 0,
    workers: Annotated[int, typer.Option("--workers", help="Processes for the Monte-Carlo.")] = 1,
    estimator: Annotated[str, typer.Option("--estimator", help="Estimator(s) to plan for: both (default), allan "
                         "(the Allan fit, as fogdrift allan) or gmwm (the GMWM of the model's latent processes, "
                         "as fogdrift noise --method gmwm --model WN+RW+FLICKER ...); with --fleet, the rows of "
                         "that estimator (batch allan/analyze: allan, batch noise: gmwm).")] = "both",
    axis: Annotated[Optional[str], typer.Option("--axis", help="Pilot axis (default: the first gyro axis); with "
                    "--fleet, plan this axis's units alone (default: the gyro axes pooled).")] = None,
    fleet: Annotated[Optional[Path], typer.Option("--fleet", help="Plan a fleet instead: a fogdrift batch output "
                     "folder (or its summary.parquet, or a CSV of its columns) as the pilot units; says how many "
                     "units give each term's between-unit SD to --target (default 25 %) and the type's mean to "
                     "--mean-target (default 10 %).")] = None,
    units: Annotated[Optional[int], typer.Option("--units", help="With --fleet: the widths a fleet of M units "
                     "gives.")] = None,
    mean_target: Annotated[Optional[str], typer.Option("--mean-target", help="With --fleet: relative 95 % "
                           "half-width of the type's mean per term, e.g. \"N:5%,B:10%\".")] = None,
    out: OutOpt = DEFAULT_OUT,
    json_out: JsonOpt = False,
):
    """How long must I record?  The length at which each term is resolved and reaches its target 95 % width
    (Allan fit and GMWM; analytic, checked by Monte-Carlo); writes plan.json and plan.png."""
    with run("plan", out, default_out=DEFAULT_OUT, inputs=[load.file, fleet, model if model and model.strip().lower().endswith(".json") else None], json_out=json_out,
             expect=("plan.json", "plan.png")) as r:
        est = {"both": ("allan", "gmwm"), "allan": ("allan",), "gmwm": ("gmwm",)}.get(str(estimator).strip().lower())
        if est is None:
            raise ConfigError(f"{{opt:estimator}} must be both, allan or gmwm; got {estimator!r}")
        if fleet is not None or units is not None or mean_target is not None:
            return _fleet_plan(r, fleet, load.file, model, target, mean_target, units, axis, length, monte_carlo,
                               est)
        from ..plan import make_plan, parse_length, parse_model, parse_targets, read_model_file
        from ..report import write_json
        from ..report.plan_figure import plot_plan

        if (model is None) == (load.file is None):
            raise ConfigError("give either a pilot log FILE or {opt:model} (one of them)")
        rate = load.rate
        if rate is not None and not rate > 0:
            raise ConfigError(f"{{opt:rate_hz}} must be > 0 Hz; got {rate}")
        if workers < 1 or workers > 64:
            raise ConfigError(f"{{opt:workers}} must be between 1 and 64; got {workers}")
        length_s = None if length is None else parse_length(length)
        if model is not None:
            if model.strip().lower().endswith(".json"):
                m = read_model_file(model, None if rate is None else 1.0 / rate, axis)
            else:
                if rate is None:
                    raise ConfigError("a stated {opt:model} needs the sample rate of the record to plan: {opt:rate_hz} HZ")
                m = parse_model(model, 1.0 / rate)
        else:
            m = _pilot_model(load, axis)
        targets = parse_targets(target, m.terms)
        say(f"model: {m.text()} at {1 / m.dt_s:g} Hz ({m.source})")
        for note in m.notes:
            say(f"  {note}", style="yellow")
        p = make_plan(m, targets, length_s=length_s, monte_carlo=monte_carlo, workers=workers, estimators=est)
        for line in p.lines():
            say(line)
        for note in p.notes[: len(p.notes) - len(m.notes)]:
            say(f"  {note}", style="yellow")
        if p.seeds:
            say(f"  Monte-Carlo seeds {p.seeds[0]}..{p.seeds[-1]} ({len(p.seeds)} per length); widths are 95 % "
                "half-widths relative to the value; 'resolved from': the median record's interval excludes 0",
                style="dim")
        path = write_json(p.to_dict(), r.out.path / "plan.json")
        plot_plan(p, r.out.path / "plan.png")
        r.wrote()
        r.print_json(path)


def _pilot_model(load, axis):
    """The Allan fit of the pilot's axis (as ``fogdrift allan``) as the model to plan for."""
    from ..pipeline import AnalysisConfig, analyse_allan
    from ..plan import model_from_fit

    record = load.load()
    echo_record(load, record)
    quantities = {c.name: c.quantity for c in record.signal.channels}
    names = [a for a in record.axis_names if quantities.get(a, "angular_rate") == "angular_rate"]
    if axis is not None:
        if axis not in record.axis_names:
            raise ConfigError(f"{{opt:axis}} {axis!r} is not an axis of the log ({', '.join(record.axis_names)})")
        names = [axis] if axis in names else []
    if not names:
        raise ConfigError("the planner takes a gyro axis; the log has none"
                          + ("" if axis is None else f" named {axis!r}"))
    fit = analyse_allan(names[0], record.axis(names[0]), record.dt_s, AnalysisConfig()).noise
    dt = record.dt_s
    say(f"pilot: axis {names[0]}, {record.n_samples if hasattr(record, 'n_samples') else len(record.axis(names[0]))}"
        f" samples, Allan fit {'+'.join(fit.selected)}")
    return model_from_fit(fit, dt, source=f"pilot {Path(str(record.source)).name} axis {names[0]}")



def _fleet_plan(r, fleet, file, model, target, mean_target, units, axis, length, monte_carlo, est):
    """``--fleet``: units of the type to record (:mod:`fogdrift.plan.fleet`), from the rows of one estimator
    (``est``); writes plan.json with a ``fleet`` section."""
    from ..plan.fleet import ESTIMATOR_NAMES, fleet_pilot, make_fleet_plan, parse_fleet_targets, read_fleet_table
    from ..plan.fleet import rows_of_estimator
    from ..report.plan_figure import plot_fleet_plan
    from ..report import write_json

    if fleet is None:
        raise ConfigError("{opt:units} and {opt:mean_target} plan a fleet: give {opt:fleet} (a fogdrift batch "
                          "output folder or its summary.parquet)")
    if file is not None or model is not None or length is not None or monte_carlo:
        raise ConfigError("{opt:fleet} plans from the fleet table alone; drop the pilot FILE, {opt:model}, "
                          "{opt:length} and {opt:monte_carlo}")
    rows, path = read_fleet_table(fleet)
    rows, which = rows_of_estimator(rows, est, str(path))
    pilot = fleet_pilot(rows, source=str(path), axis=axis)
    spread, mean = parse_fleet_targets(target, mean_target, tuple(pilot.terms))
    p = make_fleet_plan(pilot, spread, mean, units, explicit=bool(target or mean_target))
    say(f"pilot fleet: {path} ({pilot.n_rows} units{', axes ' + ', '.join(pilot.axes) if pilot.axes else ''}"
        f"{'' if which is None else ', ' + ESTIMATOR_NAMES[which] + ' rows'})")
    for line in p.lines():
        say(line)
    for note in p.notes:
        say(f"  {note}", style="yellow")
    say("  widths are 95 % half-widths relative to the value; spread: the between-unit SD with the units' own "
        "errors taken out; units recorded as the pilot's were", style="dim")
    out = write_json({"fogdrift_result": "plan", "estimator": "fleet (fogdrift batch table"
                                                              f"{'' if which is None else ', ' + ESTIMATOR_NAMES[which]})",
                      "fleet": p.to_dict()}, r.out.path / "plan.json")
    plot_fleet_plan(p, r.out.path / "plan.png")
    r.wrote()
    r.print_json(out)
