"""``fogdrift batch``: one command over many logs on Dask, with a Parquet summary and a fleet page.

The library side is :mod:`fogdrift.fleet`; ``--command`` takes a name of its command table
(:data:`fogdrift.fleet.COMMANDS`), so a new batch command is one row there and needs nothing here.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import ConfigError
from ..spec import B_COMPARED
from ._app import (FLAGS, TermsOpt, app, csv_list, parse_terms, precheck, progress_count, run, say,
                   with_load_options)
from ._settings import with_settings
from ._spec import SpecOpt, read_spec_option, spec_settings
from .noise import ModelOpt, RobustOpt, ScalesOpt

FLAGS.update({"glob": "--glob", "command": "--command", "scheduler": "--scheduler", "workers": "--workers"})


def _set_items(items) -> dict:
    out = {}
    for item in items or []:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ConfigError(f"--set must look like NAME=VALUE (an analysis setting), got {item!r}")
        text = value.strip()
        for conv in (int, float):
            try:
                out[key.strip()] = conv(text)
                break
            except ValueError:
                continue
        else:
            out[key.strip()] = None if text.lower() == "none" else text
    return out


DEFAULT_OUT = Path("out/batch")


def _print_spec_counts(rows, limits: dict, source: str) -> None:
    """The batch's datasheet comparison in counts: one line per judged item (pass / fail / cannot tell), and which B
    was compared; the verdict and reason of every axis are the summary's ``spec_<item>`` columns."""
    from ..fleet.summary import spec_count_lines

    lines = spec_count_lines(rows)
    title = f"datasheet comparison: {limits['sensor'] or source}" + (f" ({source})" if limits["sensor"] else "")
    if not lines:
        say(f"{title}: no axis was judged (the spec has {', '.join(sorted({l.kind for l in limits['limits']}))} "
            "limits only, or every file failed)", style="yellow")
    else:
        say(f"{title}, axes per verdict (each axis judged against its own section, gyro or accel; the reasons are "
            "the summary's spec_<item>_why columns):")
        for line in lines:
            say(f"  {line}")
    say(f"  {B_COMPARED}", style="dim")


def _command_help() -> str:
    from ..fleet.commands import COMMANDS  # light: the table, not the commands' libraries

    return "Command per file: " + "; ".join(f"{c.name} ({c.description})" for c in COMMANDS.values()) + "."


@app.command()
@with_load_options(file="none")
@with_settings("estimator", "taus", "statistic", "outliers", "fit_tau_s")
def batch(
    inputs: Annotated[list[Path], typer.Argument(help="Logs, folders (with --glob), ROS 2 bag folders or wildcards.")],
    load,
    glob: Annotated[Optional[str], typer.Option("--glob", help="Files to take inside folders, e.g. '*.csv.gz'.")]
    = None,
    command: Annotated[str, typer.Option("--command", help=_command_help())] = "allan",
    scheduler: Annotated[Optional[str], typer.Option(
        "--scheduler", help="Dask scheduler address (tcp://host:8786) of an existing cluster; 'local' for a local "
                            "cluster of worker processes; 'serial' for no Dask. Default: chosen by the work's size "
                            "(serial below 268 MB of input, for one file or on one usable core; else local).")] = None,
    workers: Annotated[Optional[int], typer.Option("--workers", help="Worker processes of the local cluster "
                                                                     "(default: the usable cores, at most one per "
                                                                     "file); given, the default is the local "
                                                                     "cluster.")] = None,
    settings: dict = None,
    terms: TermsOpt = "",
    models: Annotated[Optional[str], typer.Option("--models", help="analyze: drift models (default: all).")] = None,
    model_rate: Annotated[Optional[float], typer.Option("--model-rate", help="analyze: modelling rate [Hz].")] = None,
    epochs: Annotated[Optional[int], typer.Option("--epochs", help="analyze: training epochs.")] = None,
    seed: Annotated[Optional[int], typer.Option("--seed", help="analyze: random seed.")] = None,
    model: ModelOpt = "auto",
    scales: ScalesOpt = None,
    robust: RobustOpt = False,
    spec: SpecOpt = None,
    set_: Annotated[Optional[list[str]], typer.Option(
        "--set", help="Any other analysis setting NAME=VALUE (fogdrift.pipeline.AnalysisConfig), repeatable.")] = None,
    fail_on_error: Annotated[bool, typer.Option(
        "--fail-on-error/--allow-failures", help="Exit 1 if any file failed (the default; the batch still goes "
                                                 "on and writes every other file's results); --allow-failures "
                                                 "exits 0 all the same.")] = True,
    out: Annotated[Path, typer.Option("--out", help="Batch folder: one folder per file, summary.parquet, "
                                                    "fleet.html.")] = DEFAULT_OUT,
):
    """Run allan, noise or analyze over many logs x axes on Dask; write summary.parquet and a fleet page."""
    from ..fleet import BatchOutputDir, command_spec, run_batch

    with run("batch", out, default_out=DEFAULT_OUT, inputs=list(inputs) + ([spec] if spec else []),
             expect=("summary.parquet", "fleet.html"), out_class=BatchOutputDir):
        command_spec(command)
        limits = read_spec_option(spec)  # read once, before any work: a bad spec is one line
        if load.gaps not in ("error", "longest"):
            raise ConfigError(f"{{opt:gaps}} must be 'error' or 'longest' in a batch, got {load.gaps!r}")
        term_list = parse_terms(terms)
        precheck(estimator=settings["estimator"], terms=term_list)
        analysis = {"taus": settings["taus"], "estimator": settings["estimator"],
                    "fit_tau_s": list(settings["fit_tau_s"]),
                    "terms": None if term_list is None else list(term_list),
                    "statistic": settings["statistic"], "outliers": settings["outliers"]}
        if command == "analyze":
            extra = {"models": csv_list(models), "model_rate_hz": model_rate, "epochs": epochs, "seed": seed}
            analysis.update({k: v for k, v in extra.items() if v is not None})
        analysis.update(_set_items(set_))
        gmwm = {"model": model, "levels": scales, "robust": robust}
        if command != "noise" and (model.lower() != "auto" or scales is not None or robust):
            raise ConfigError("{opt:model}, {opt:scales} and {opt:robust} are options of --command noise (GMWM); "
                              f"got --command {command}")
        if scales is not None and scales < 1:
            raise ConfigError(f"{{opt:scales}} must be an integer >= 1; got {scales}")
        kwargs = {k: v for k, v in load.load_kwargs().items() if v not in (None, {})}
        settings = {"load": kwargs, "gaps": load.gaps, "analysis": analysis}
        if command == "noise":  # only what was given: a default run keeps the settings hash of earlier runs
            settings["gmwm"] = {k: v for k, v in gmwm.items() if v not in (None, False, "auto")}
        if limits is not None:  # only with --spec: a run without one keeps the settings hash of earlier runs
            settings["spec"] = spec_settings(limits, spec.name)
        with progress_count(f"batch {command}", "files") as update:
            def progress(done, total, name):
                update(done, total, note=f"last finished: {name}")

            result = run_batch(inputs, out, command=command, settings=settings, pattern=glob, scheduler=scheduler,
                               workers=workers, progress=progress, flags=FLAGS)
        say(f"{result.n_files} files on {result.scheduler} in {result.wall_s:.1f} s: {result.n_ok} done, "
            f"{result.n_cached} unchanged (skipped), {result.n_error} failed")
        for row in result.rows:
            if row.get("status") == "error":
                say(f"  {row['file']}: {row.get('error')}", style="red")
        if limits is not None:
            _print_spec_counts(result.rows, limits, spec.name)
        say(f"summary: {result.summary_path}")
        if result.page_path is not None:
            say(f"fleet page: {result.page_path}")
        if fail_on_error and result.n_error:
            say(f"exit code 1: {result.n_error} of {result.n_files} files failed (--allow-failures exits 0)",
                style="red")
            raise typer.Exit(code=1)
