"""``fogdrift allan``: Allan variance and IEEE-952 noise coefficients of every axis."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ._app import (EstOpt, FitTausOpt, JsonOpt, OutOpt, TausOpt, app, check_plausible, console, csv_list,
                   echo_record, parse_fit_taus, parse_taus, precheck, progress, run, with_load_options)
from ._tables import noise_table, print_noise_notes

DEFAULT_OUT = Path("out/allan")


@app.command()
@with_load_options
def allan(
    load,
    estimator: EstOpt = "overlapping",
    taus: TausOpt = "octave",
    terms: Annotated[str, typer.Option("--terms", help="Noise terms to fit, e.g. Q,N,B,K,R.")] = "Q,N,B,K,R",
    fit_taus: FitTausOpt = ":",
    out: OutOpt = DEFAULT_OUT,
    json_out: JsonOpt = False,
):
    """Allan variance and IEEE-952 noise coefficients Q, N, B, K, R of every axis."""
    from ..pipeline import AnalysisConfig, run_allan
    from ..report import noise_row, write_allan_outputs

    with run("allan", out, default_out=DEFAULT_OUT, inputs=[load.file], json_out=json_out,
             expect=("allan.json", "allan.csv", "allan.png")) as r:
        term_list = tuple(t.upper() for t in (csv_list(terms) or []))
        precheck(estimator=estimator, terms=term_list)
        cfg = AnalysisConfig(taus=parse_taus(taus), estimator=estimator, fit_tau_s=parse_fit_taus(fit_taus),
                             terms=term_list).validate()
        record = load.load()
        echo_record(load, record)
        check_plausible(record)
        with progress("allan", record.axis_names) as (allan_cb, _):
            results = run_allan(record, cfg, progress=allan_cb)
        console.print(noise_table(f"{load.file.name}: {estimator} ADEV, 95 % intervals in brackets",
                                  [[a.name] + noise_row(a.noise) for a in results]))
        for a in results:
            print_noise_notes(a.name, a.noise)
        files = write_allan_outputs(results, record, r.out.path)
        r.wrote()
        r.print_json(files["json"])
