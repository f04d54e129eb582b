"""``fogdrift allan``: Allan-family variance and IEEE-952 noise identification of every axis."""

from __future__ import annotations

from pathlib import Path

from ..temperature import summary_line
from ._app import (JsonOpt, OutOpt, SegmentsOpt, TermsOpt, app, console, echo_record, parse_terms, precheck,
                   progress, run, with_load_options)
from ._screen import print_screen
from ._settings import with_settings
from ._tables import noise_table, print_noise_notes, relabel_note
from ._spec import SpecOpt, print_spec_for_allan, read_spec_option

DEFAULT_OUT = Path("out/allan")


@app.command()
@with_load_options
@with_settings("estimator", "taus", "statistic", "outliers", "fit_tau_s")
def allan(
    load,
    settings: dict = None,
    terms: TermsOpt = "",
    segments: SegmentsOpt = "auto",
    out: OutOpt = DEFAULT_OUT,
    json_out: JsonOpt = False,
    spec: SpecOpt = None,
):
    """Allan variance and IEEE-952 noise coefficients Q, N, B, K, R of every axis: the terms are selected from
    the data, with 95 % intervals, the fit's chi-squared and p-value, and what was left out and why."""
    from ..pipeline import AnalysisConfig
    from ..report import fit_cell, noise_row, shaped_cell
    from ..workflows.allan import run_allan, screen, write_allan

    with run("allan", out, default_out=DEFAULT_OUT, inputs=[load.file, spec], json_out=json_out,
             expect=("allan.json", "allan.csv", "allan.png") + (("spec.json",) if spec is not None else ())) as r:
        term_list = parse_terms(terms)
        precheck(terms=term_list)
        cfg = AnalysisConfig(terms=term_list, **settings).validate()
        limits = read_spec_option(spec)  # read before the work: a bad spec file is one line, nothing computed
        record = load.load()
        echo_record(load, record)
        screened = screen(record, segments)  # the checks before any fit: plausibility, the record screen
        print_screen(record, screened.findings, screened.screens)
        with progress("allan", record.axis_names) as (allan_cb, _):
            done = run_allan(record, cfg, progress=allan_cb, screened=screened)
        results = done.results
        name = {"adev": "ADEV", "hdev": "HDEV", "mdev": "MDEV"}[cfg.statistic]
        by_quantity = {}
        for a in results:  # one table per quantity: gyro terms, then accelerometer terms (their own units)
            by_quantity.setdefault(getattr(a.noise, "quantity", "angular_rate"), []).append(a)
        for quantity, group in by_quantity.items():
            what = "" if quantity == "angular_rate" else "accelerometer (velocity random walk N, bias instability B) "
            console.print(noise_table(f"{load.file.name}: {what}{cfg.estimator} {name}, 95 % intervals in brackets "
                                      "(– (< x): not in the selected model, x its upper bound; [0, x]: in the "
                                      "model but not resolved from zero; B: the IEEE reading min ADEV/0.664, < x "
                                      "where the ADEV has no minimum; no model fits: ≈ x a term's read-out along "
                                      "its own slope, < x the curve's own bound)",
                                      [[a.name] + noise_row(a.noise) + [relabel_note(shaped_cell(a.noise), quantity),
                                                                        fit_cell(a.noise)]
                                       for a in group], fit=True, extra=("periodic / Markov",), quantity=quantity))
        for a in results:
            print_noise_notes(a.name, a.noise, a.outliers, record.dt_s)
        temp = record.metadata()["temperature"]
        if temp is not None:
            console.print("  " + summary_line(temp), highlight=False)
        if limits is not None:
            print_spec_for_allan(limits, results, record, r.out.path, spec.name)
        files = write_allan(done, r.out.path)
        r.wrote()
        r.print_json(files["json"])
