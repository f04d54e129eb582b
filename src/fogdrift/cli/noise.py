"""``fogdrift noise``: noise model of every axis by GMWM (wavelet variance) or by the Allan fit.

``--method gmwm`` (default): Haar wavelet variance, WIC model selection over candidate latent models (or one
``--model``), short scales no candidate explains excluded with the reason, the IEEE-952 table (N, K, R, Q, GM T_c
and sigma, one B named by its rule) with 95 % intervals, the J statistic with its caveat, and, for a log, one line
per quantity saying whether N and B agree with the Allan fit of the same record (or why not).  ``--curve TABLE``
fits a published wavelet- or Allan-variance table (the SMAC formats) instead of a log; its unit is the table's
``unit`` column or ``--unit`` (never its ``unit_inferred`` column) and is printed first.  ``--method allan`` runs the Allan noise fit of ``fogdrift allan``.
``--spec FILE`` compares every channel with datasheet limits (:mod:`fogdrift.spec`): pass / fail / cannot tell, judged
with the 95 % interval, B as the IEEE reading B_min; written to spec.json.
"""

from __future__ import annotations

import inspect
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import ConfigError
from ..spec import readings_from_gmwm
from ._app import (JsonOpt, OutOpt, SegmentsOpt, app, console, echo_record, fitted_table, progress, run,
                   say, with_load_options)
from ._screen import print_screen
from ._tables import noise_table, print_noise_notes
# (the --spec helpers live in the light cli._spec; imported here under their old names too)
from ._spec import SpecOpt, channel_kinds, print_spec_comparison, print_spec_for_allan, read_spec_option  # noqa: F401

DEFAULT_OUT = Path("out/noise")

MethodOpt = Annotated[str, typer.Option("--method", help="gmwm (wavelet variance, model selection by WIC) or "
                                                         "allan (the Allan-variance fit of 'fogdrift allan').")]
ModelOpt = Annotated[str, typer.Option("--model", help="GMWM model: 'auto' (select by WIC among the default "
                                                       "candidates) or terms such as 'WN+RW+GM', 'QN+WN+RW+2GM' "
                                                       "(QN, WN, RW, DR, GM, FLICKER).")]
ScalesOpt = Annotated[Optional[int], typer.Option("--scales", help="Number of wavelet scales J (2, 4, ..., 2^J "
                                                                   "samples; default floor(log2 N) - 1).")]
RobustOpt = Annotated[bool, typer.Option("--robust", help="Huber-robust wavelet variance (logs with outliers).")]
CurveOpt = Annotated[Optional[Path], typer.Option("--curve", help="Fit a published table instead of a log (FILE is "
                                                                  "then not given): Haar WV (scale_s, wvar, n_samples, "
                                                                  "sample_rate_hz) or Allan variance (tau_s, avar or "
                                                                  "adev, n_samples, sample_rate_hz); the unit comes "
                                                                  "from its 'unit' column or --unit.")]
SensorOpt = Annotated[Optional[str], typer.Option("--sensor", help="With --curve: the table's sensor_key to fit.")]
def _optional_file(func):
    """Make the FILE argument optional (``--curve`` replaces it)."""
    sig = inspect.signature(func)
    params = [p.replace(default=None, annotation=Annotated[Optional[Path], typer.Argument(
        help="Gyro log: CSV/TXT (optionally .gz), .npy or .npz (omit with --curve).")]) if p.name == "file" else p
        for p in sig.parameters.values()]
    func.__signature__ = sig.replace(parameters=params)
    return func


def _fmt(x, digits=4):
    from ..report.gmwm import fmt

    return fmt(x, digits)


def _interval(lo, hi) -> str:
    return "–" if lo is None or hi is None else f"[{_fmt(lo)}, {_fmt(hi)}]"


def print_gmwm(title, axes, quantities=None, details=False):
    """Per axis: IEEE table (one B, by its rule), the other B readings as details, the comparison with the Allan
    fit when one was made, candidates (WIC, why rejected), excluded scales, J with its caveat.  ``quantities``:
    axis name -> quantity; an accelerometer's reading (:func:`fogdrift.gmwm.quantity.express_gmwm`) shows B in
    ug and its rate levels in m/s^2.  Without ``details`` the candidate table, J and the reasons for each
    excluded scale are one summary line per axis."""
    from ..gmwm.analysis import J_CAVEAT, b_detail_lines, ieee_rows
    from ..gmwm.quantity import accel_rows
    from ..noise.periodic import Q_OVER_ENVELOPE
    from ..noise.quantity import restate_text

    quantities = quantities or {}
    for a in axes:
        sel = a.selection
        q = quantities.get(a.name, "angular_rate")
        rows = accel_rows(ieee_rows(a)) if q == "specific_force" else ieee_rows(a)
        what = " (accelerometer: velocity random walk N, bias instability B)" if q == "specific_force" else ""
        console.print(fitted_table(f"{title} axis {a.name}{what}: GMWM {sel.selected}"
                                   f"{'' if sel.passed_checks else ' (no candidate passed every check)'}, "
                                   "95 % intervals",
                                   ["quantity", "value", "95 % interval", "unit", "from"],
                                   [[r[0], _fmt(r[1]), _interval(r[2], r[3]), r[4], r[5]]
                                    for r in rows]))
        for line in b_detail_lines(a):
            say(f"  {a.name}: {restate_text(line, q)}")
        if a.periodic is not None:
            n_line = sum(x.line_share is not None for x in sel.excluded)
            say(f"  {a.name}: spectrum: {restate_text(a.periodic.text(), q)}; not a latent process: "
                f"{n_line} short scale{'s' if n_line != 1 else ''} it dominates excluded, QN claimed only "
                f"{Q_OVER_ENVELOPE:g}x above its envelope", style="yellow")
        if a.allan_check is not None:
            for line in a.allan_check["lines"]:
                say(f"  {a.name}: GMWM vs Allan fit: {line}",
                    style=None if a.allan_check["agree"] is not False else "yellow")
        fit = sel.fit
        if not details:
            n_pass = sum(c.passed for c in sel.candidates)
            ex = (f"; short scales {_fmt(sel.excluded[0].scale_s)}-{_fmt(sel.excluded[-1].scale_s)} s left out"
                  if sel.excluded else "")
            say(f"  {a.name}: {sel.selected} chosen by WIC from {len(sel.candidates)} candidates ({n_pass} passed "
                f"every check){ex}; fitted scales {_fmt(fit.scale_s[0])}-{_fmt(fit.scale_s[-1])} s; --details "
                "lists the candidates, J and every excluded scale", style="dim")
        else:
            console.print(fitted_table(f"{title} axis {a.name}: candidates (smallest WIC among those passing wins)",
                                       ["candidate", "WIC", "passed", "why rejected"],
                                       [[c.model + (" *" if c.model == sel.selected else ""), _fmt(c.wic),
                                         "yes" if c.passed else "no", "; ".join(c.reasons)]
                                        for c in sel.candidates]))
            say(f"  {a.name}: J = {_fmt(fit.j_stat)}, df {fit.df}, p = {_fmt(fit.j_pvalue, 2)} ({J_CAVEAT})", style="dim")
            for x in sel.excluded:
                say(f"  {a.name}: scale {_fmt(x.scale_s)} s excluded: {x.reason}", style="yellow")
        if sel.scan_note:
            say(f"  {a.name}: {sel.scan_note}", style="yellow")


@app.command()
@_optional_file
@with_load_options
def noise(
    load,
    method: MethodOpt = "gmwm",
    model: ModelOpt = "auto",
    scales: ScalesOpt = None,
    robust: RobustOpt = False,
    curve: CurveOpt = None,
    sensor: SensorOpt = None,
    spec: SpecOpt = None,
    out: OutOpt = DEFAULT_OUT,
    json_out: JsonOpt = False,
    segments: SegmentsOpt = "auto",
    details: Annotated[bool, typer.Option("--details", help="Also print each axis's candidate table (WIC, why "
                                          "rejected), J and the reason for every excluded scale.")] = False,
):
    """Noise model of every axis: GMWM model selection (wavelet variance) with the IEEE-952 table and 95 %
    intervals, or the Allan fit; writes noise.json, wvar.csv (gmwm) and noise.png (and spec.json with --spec)."""
    method = method.lower()
    expect = ("noise.json", "wvar.csv", "noise.png") if method == "gmwm" else ("noise.json", "noise.png")
    expect += ("spec.json",) if spec is not None else ()
    with run("noise", out, default_out=DEFAULT_OUT, inputs=[load.file, curve, spec], json_out=json_out,
             expect=expect) as r:
        from ..gmwm.analysis import analyse_wvar, candidates_for, read_curve_table
        from ..report.gmwm import write_gmwm_outputs
        from ..workflows.allan import screen
        from ..workflows.noise import run_noise, write_noise

        if method not in ("gmwm", "allan"):
            raise ConfigError(f"{{opt:method}} must be 'gmwm' or 'allan'; got {method!r}")
        if (curve is None) == (load.file is None):
            raise ConfigError("give either a log FILE or {opt:curve} TABLE (one of them)")
        limits = read_spec_option(spec)  # refuse a bad spec before any work
        if method == "allan":
            if curve is not None or model.lower() != "auto" or scales is not None or robust:
                raise ConfigError("--curve, --model, --scales and --robust belong to --method gmwm; the Allan "
                                  "fit selects its terms itself (use 'fogdrift allan --terms' to fix them)")
            return _allan(load, r, limits, spec, segments)
        candidates_for(model)  # refuse a bad --model before reading anything
        if scales is not None and scales < 1:
            raise ConfigError(f"{{opt:scales}} must be >= 1; got {scales}")
        if curve is not None:
            table = read_curve_table(curve, sensor=sensor, unit=load.unit, axes=None if load.columns is None
                                     else [c.strip() for c in load.columns.split(",")])
            wvs = table.wvars
            if scales is not None:
                wvs = [wv.select(wv.level <= scales) for wv in wvs]
            say(f"{curve.name}: unit: {table.unit}, {table.unit_source}"
                f"{'' if table.unit == 'deg/h' else '; converted to deg/h'}; published {table.kind} curve"
                f"{'' if sensor is None else ' of ' + sensor}"
                f"{' (as wavelet variance, WV(2τ) = AVAR(τ)/2)' if table.kind != 'wavelet variance' else ''}, "
                f"axes {', '.join(w.axis_names[0] for w in wvs)}, {wvs[0].n_samples} samples at dt "
                f"{wvs[0].dt_s:g} s")
            with progress("noise"):
                axes = [analyse_wvar(w.axis_names[0], w, model=model) for w in wvs]
            source, meta = str(curve), None
            kinds = {a.name: "gyro" for a in axes}
        else:
            if sensor is not None:
                raise ConfigError("--sensor belongs to --curve")
            record = load.load()
            echo_record(load, record)
            # the checks before either fit (plausibility, the record screen); GMWM (one wavelet variance) fits the
            # longest quiet segment of a disturbed axis, the Allan cross-check pools the quiet segments
            screened = screen(record, segments, command="noise")
            print_screen(record, screened.findings, screened.screens, gmwm=screened.segments)
            with progress("noise", record.axis_names):
                done = run_noise(record, model=model, levels=scales, robust=robust, screened=screened)
            axes, quantities = done.axes, done.quantities
            source, meta = str(record.source), record.metadata()
            kinds = channel_kinds(record)
        print_gmwm((curve or load.file).name, axes, None if curve else quantities, details=details)
        if limits is not None:
            print_spec_comparison(limits, {a.name: (kinds[a.name], readings_from_gmwm(a, kinds[a.name]))
                                           for a in axes}, r.out.path, source=spec.name)
        files = write_noise(done, r.out.path) if curve is None else write_gmwm_outputs(axes, r.out.path, source=source,
                                                                                      record=meta)
        r.wrote()
        r.print_json(files["json"])


def _allan(load, r, limits=None, spec_path=None, segments="auto"):
    """--method allan: the Allan noise fit of every axis (as 'fogdrift allan'), written as noise.json/noise.png."""
    from ..report import noise_row, plot_allan, write_json
    from ..workflows.allan import run_allan, screen

    record = load.load()
    echo_record(load, record)
    screened = screen(record, segments)
    print_screen(record, screened.findings, screened.screens)
    with progress("noise", record.axis_names) as (allan_cb, _):
        results = run_allan(record, progress=allan_cb, screened=screened).results
    console.print(noise_table(f"{load.file.name}: Allan fit, 95 % intervals in brackets",
                              [[a.name] + noise_row(a.noise) for a in results]))
    for a in results:
        print_noise_notes(a.name, a.noise, a.outliers, record.dt_s)
    if limits is not None:
        print_spec_for_allan(limits, results, record, r.out.path, spec_path.name)
    path = write_json({"fogdrift_result": "noise", "method": "allan", "source": str(record.source),
                       "record": record.metadata(), "axes": [a.to_dict() for a in results]}, r.out.path / "noise.json")
    plot_allan(results, r.out.path / "noise.png")
    r.wrote()
    r.print_json(path)
