"""``fogdrift allan``: Allan variance and IEEE-952 noise coefficients of every axis."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ._app import (EstOpt, FitTausOpt, OutOpt, TausOpt, app, console, csv_list, errors, parse_fit_taus,
                   parse_taus, progress, with_load_options)
from ._tables import noise_table, print_noise_notes


@app.command()
@with_load_options
def allan(
    load,
    estimator: EstOpt = "overlapping",
    taus: TausOpt = "octave",
    terms: Annotated[str, typer.Option("--terms", help="Noise terms to fit, e.g. Q,N,B,K,R.")] = "Q,N,B,K,R",
    fit_taus: FitTausOpt = ":",
    out: OutOpt = Path("out/allan"),
):
    """Allan variance and IEEE-952 noise coefficients Q, N, B, K, R of every axis."""
    from ..pipeline import AnalysisConfig, run_allan
    from ..report import noise_row, write_allan_outputs

    with errors():
        record = load.load()
        cfg = AnalysisConfig(taus=parse_taus(taus), estimator=estimator, fit_tau_s=parse_fit_taus(fit_taus),
                             terms=tuple(t.upper() for t in csv_list(terms)))
        with progress("allan") as (allan_cb, _):
            results = run_allan(record, cfg, progress=allan_cb)
        console.print(noise_table(
            f"{load.file.name}: {record.n_samples} samples at {record.fs_hz:g} Hz ({record.duration_s:.1f} s), "
            f"{estimator} ADEV, 95 % intervals in brackets",
            [[a.name] + noise_row(a.noise) for a in results]))
        for a in results:
            print_noise_notes(a.name, a.noise)
        temp = record.metadata()["temperature"]
        if temp is not None:
            from ..temperature import summary_line

            console.print("  " + summary_line(temp), highlight=False)
        files = write_allan_outputs(results, record, out)
        console.print(f"wrote {files['json']}, {files['csv']}, {files['png']}")
