"""``--spec FILE`` on the command line: the option, and the datasheet comparison printed on the console.

A light module (typer and the CLI's console only; :mod:`fogdrift.spec` is imported when a comparison runs), so that
``allan``, ``noise``, ``analyze`` and ``batch`` share the option without importing one another: ``fogdrift allan
--help`` imports no other command.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..spec import B_COMPARED, channel_kind, compare, judgement_line, read_spec, readings_from_noise_fit
from ._app import console, fitted_table, say

__all__ = ["SpecOpt", "channel_kinds", "read_spec_option", "print_spec_comparison", "print_spec_for_allan",
           "spec_settings"]

SpecOpt = Annotated[Optional[Path], typer.Option(
    "--spec", help="Datasheet limits (YAML or JSON, each with its unit, e.g. gyro: {arw: \"2 deg/sqrt(h)\", "
                   "bias_instability: \"0.007 deg/s\"}): pass / fail / cannot tell per channel, judged with the 95 % "
                   "interval (data/specs/adis16405.yaml is an example).")]


def read_spec_option(spec: Path | None):
    """The parsed spec of ``--spec`` (:func:`fogdrift.spec.read_spec`), or None without it.  Called before any work:
    a bad spec file is one line (:class:`~fogdrift.errors.ConfigError`), nothing computed."""
    if spec is None:
        return None

    return read_spec(spec)


def spec_settings(limits: dict, source: str) -> dict:
    """A parsed spec (:func:`fogdrift.spec.read_spec`) back as the mapping of a spec file, each limit as written
    (``{"source": "adis16405.yaml", "sensor": ..., "gyro": {"arw": "2 deg/sqrt(h)"}, ...}``): the plain, JSON-able
    ``settings["spec"]`` of a batch (:func:`fogdrift.fleet.commands.spec_from_settings` parses it in each task).
    Part of the settings hash: a changed limit recomputes the files."""
    out = {"source": source, "sensor": limits["sensor"]}
    for lim in limits["limits"]:
        out.setdefault(lim.kind, {})[lim.item] = lim.text
    return out


def channel_kinds(record) -> dict:
    """Axis name -> ``"gyro"`` or ``"accel"`` from the record's channel quantities (gyro when not stated)."""
    sig = getattr(record, "signal", None)
    chans = {c.name: getattr(c, "quantity", None) for c in getattr(sig, "channels", ())} if sig is not None else {}
    return {name: channel_kind(chans.get(name)) for name in record.axis_names}


def print_spec_comparison(spec: dict, channels: dict, out_dir=None, *, source: str = "") -> list:
    """Judge ``spec`` (:func:`fogdrift.spec.read_spec`) on ``channels`` (name -> (kind, {item: Reading})), print the
    table and the line saying which B was compared; write spec.json into ``out_dir`` when given.  Returns the
    judgements.  (Callable from any command that has Allan or GMWM readings.)"""
    return print_judgements(spec, compare(spec, channels), out_dir, source=source)


def print_judgements(spec: dict, js: list, out_dir=None, *, source: str = "", compact: bool = False) -> list:
    """Print judgements made already (:func:`fogdrift.spec.compare`) as :func:`print_spec_comparison` does;
    ``compact``: one :func:`fogdrift.spec.judgement_line` per judgement instead of the table (``analyze``'s short
    console summary, the lines of the report's first screen)."""
    from ..report import write_json

    title = f"datasheet comparison: {spec['sensor'] or source}" + (f" ({source})" if spec["sensor"] and source else "")
    if not js:
        say(f"{title}: no limit applies to these channels (the spec has "
            f"{', '.join(sorted({l.kind for l in spec['limits']}))} limits only)", style="yellow")
    elif compact:
        say(f"{title}, every limit an upper limit, judged with the 95 % interval:", style="bold")
        for j in js:
            say(f"  [{j.verdict.upper()}] {judgement_line(j)}")
    else:
        console.print(fitted_table(title + "; every limit read as an upper limit",
                                   ["channel", "term", "limit", "estimate, 95 % interval", "verdict", "why"],
                                   [[j.channel, j.limit.item, j.limit.text, j.estimate, j.verdict, j.reason]
                                    for j in js]))
    say(f"  {B_COMPARED}", style="dim")
    if out_dir is not None:
        write_json({"fogdrift_result": "spec", "spec": source, "sensor": spec["sensor"],
                    "b_compared": B_COMPARED, "judgements": [j.to_dict() for j in js]}, Path(out_dir) / "spec.json")
    return js


def print_spec_for_allan(limits: dict, results, record, out_dir, source: str) -> list:
    """``--spec`` after an Allan fit (``fogdrift allan``, ``noise --method allan``): the comparison of every axis of
    ``results`` (:func:`fogdrift.pipeline.run_allan`), printed and written to ``out_dir/spec.json``."""
    kinds = channel_kinds(record)
    return print_spec_comparison(limits, {a.name: (kinds[a.name], readings_from_noise_fit(a.noise, kinds[a.name]))
                                          for a in results}, out_dir, source=source)
