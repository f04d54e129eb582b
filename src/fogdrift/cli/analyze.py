"""``fogdrift analyze``: the whole method on one recording, with an HTML report."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated, Optional

import typer

from ..errors import ConfigError
from ..models.registry import parse_model_params
from ._app import (gyro_only, JsonOpt, LevelOpt, ModeOpt, ModelRateOpt, OutOpt, SegmentsOpt, TermsOpt, WaveletOpt, app,
                   check_plausible, console, csv_list, echo_record, fitted_table, parse_level, parse_terms,
                   progress, run, say, with_load_options)
from ._screen import print_screen
from ._spec import SpecOpt, print_judgements, read_spec_option
from ._tables import metrics_table, noise_table
from ._settings import with_settings
from .model import ALL_MODELS, NETWORK_SETTINGS, ModelsOpt, ParamOpt, model_axes_text

DEFAULT_OUT = Path("out/analyze")


@app.command()
@with_load_options
@with_settings(*NETWORK_SETTINGS, "train_fraction", "val_fraction", "causal_window_s", "gm_window", "estimator",
               "taus", "statistic", "outliers", "fit_tau_s")
def analyze(
    load,
    latitude: Annotated[Optional[float], typer.Option("--latitude", help="Latitude [deg] for Earth-rate removal.")]
    = None,
    earth_axis: Annotated[Optional[list[str]], typer.Option(
        "--earth-axis", help="AXIS=ORIENTATION (up, down, north, south, east, west), repeatable.")] = None,
    apply_to: Annotated[Optional[Path], typer.Option("--apply-to", help="Second recording: apply the fitted "
                                                     "models unchanged to it (axes matched by name; its bias is "
                                                     "re-estimated on its own training share, and said so).")] = None,
    apply_unit: Annotated[Optional[str], typer.Option(
        "--apply-unit", help="Rate unit of the --apply-to recording (default: --unit, or its header's).")] = None,
    apply_time_unit: Annotated[Optional[str], typer.Option(
        "--apply-time-unit", help="Time unit of the --apply-to recording (default: --time-unit, or its header's).")]
    = None,
    models: ModelsOpt = ALL_MODELS,
    settings: dict = None,
    param: ParamOpt = None,
    wavelet: WaveletOpt = "db2",
    level: LevelOpt = "4",
    mode: ModeOpt = "symmetric",
    model_rate: ModelRateOpt = 1.0,
    terms: TermsOpt = "",
    segments: SegmentsOpt = "auto",
    heading: Annotated[bool, typer.Option(
        "--heading/--no-heading", help="Heading-error evaluation (rolling calibrations: --calibration, "
                                       "--origin-step, --horizons; free-run forecasts) and filtering-artefact check of every model on the test block: "
                                       "printed, stored in analysis.json and leading the report's compensation "
                                       "verdicts (--no-heading skips it).")] = True,
    calibration: Annotated[float, typer.Option(
        "--calibration", help="Heading evaluation: calibration window [s] before each rolling origin.")] = 300.0,
    origin_step: Annotated[float, typer.Option(
        "--origin-step", help="Heading evaluation: spacing of the rolling origins [s].")] = 60.0,
    horizons: Annotated[str, typer.Option(
        "--horizons", help="Heading evaluation: free-run horizons [s], comma-separated.")] = "60,600,3600",
    details: Annotated[bool, typer.Option(
        "--details", help="Also print every table on the console (Table 2, one-step metrics, heading-error and "
                          "artefact tables); by default the console shows the summary and the files hold the rest.")]
    = False,
    pdf: Annotated[bool, typer.Option("--pdf", help="Also write report.pdf (the same HTML printed by headless "
                                                    "Chromium).")] = False,
    noise_method: Annotated[str, typer.Option(
        "--noise-method", help="Noise model of the original output: allan (the Allan fit) or gmwm (also the GMWM "
                               "model selection on the wavelet variance; the report shows its table first, and the Kalman model "
                               "identifies its noise components by GMWM on its training block).")]
    = "allan",
    sensor: Annotated[Optional[str], typer.Option(
        "--sensor", help="Sensor make, model and serial number for the report's first screen and analysis.json "
                         "(logs do not carry it), e.g. 'KVH DSP-1750 s/n 1234'.")] = None,
    spec: SpecOpt = None,
    out: OutOpt = DEFAULT_OUT,
    json_out: JsonOpt = False,
):
    """The whole method: Allan analysis, separation, drift models, compensation, Table 2 and an HTML report."""
    from ..pipeline import AnalysisConfig
    from ..workflows.analyze import prepare_analyze, run_analyze, write_analyze

    with run("analyze", out, default_out=DEFAULT_OUT, inputs=[load.file, apply_to, spec], json_out=json_out,
             expect=("analysis.json", "report.html") + (("report.pdf",) if pdf else ())
             + (("spec.json",) if spec is not None else ())) as r:
        if pdf:  # no Chromium: refused before any work
            from ..report.pdf import find_chromium

            find_chromium()
        limits = read_spec_option(spec)  # a bad spec file: one line, before any work
        earth = {}
        for item in earth_axis or []:
            name, sep, orient = item.partition("=")
            if not sep:
                raise ConfigError(f"--earth-axis must look like AXIS=ORIENTATION (e.g. gz=up), got {item!r}")
            earth[name.strip()] = orient.strip()
        term_list = parse_terms(terms)
        cfg = AnalysisConfig(models=tuple(csv_list(models)), **settings, wavelet=wavelet, level=parse_level(level),
                             mode=mode, model_rate_hz=model_rate or None, terms=term_list,
                             latitude_deg=latitude, earth_axes=earth, noise_method=noise_method,
                             model_params=parse_model_params(param)).validate()
        hs = parse_heading_options(calibration, origin_step, horizons)
        if apply_to is not None and not apply_to.is_file():
            raise ConfigError(f"--apply-to {apply_to}: no such file")
        if (apply_unit or apply_time_unit) and not apply_to:
            raise ConfigError("--apply-unit / --apply-time-unit need --apply-to")
        record = load.load()
        gyro_only(record, "analyze")
        other = None
        if apply_to:
            other = _match_axes(record, load.load(apply_to, unit=apply_unit, time_unit=apply_time_unit), apply_to)
        # the modelling factors decided (a rate that does not divide: one line, before any work), the record screened
        prepared = prepare_analyze(record, cfg, apply_to=other, segments=segments)
        echo_record(load, record)
        if other is not None:
            echo_record(load, other, apply_to, unit_flag="--apply-unit" if apply_unit else "--unit",
                        time_unit_flag="--apply-time-unit" if apply_time_unit else "--time-unit")
        print_screen(record, prepared.screened.findings, prepared.screened.screens, compact=not details)
        if other is not None:
            check_plausible(other)
        with progress("analyze", record.axis_names) as (_, epoch_cb):
            done = run_analyze(record, cfg, apply_to=other, heading=heading, calib_s=calibration, step_s=origin_step,
                               horizons_s=hs, limits=limits, progress=epoch_cb, prepared=prepared)
        result, evaluations = done.result, done.evaluations
        if result.apply_to is not None:
            say(apply_note(result, apply_to))
        if details:
            say(model_axes_text([ax.models for ax in result.axes], record))
            _print_details(result, load.file.name, apply_to.name if apply_to else "", evaluations)
        print_summary(result, record, evaluated=heading, apply_name=apply_to.name if apply_to else "")
        if limits is not None:  # the workflow judged; the report shows the judgements
            print_judgements(limits, done.judgements, r.out.path, source=spec.name, compact=True)
        files = write_analyze(done, r.out.path, pdf=pdf, sensor=sensor, spec_source=spec.name if spec else "")
        path, bundle, comp = files["report"], files["bundle"], files["compensated"]
        r.wrote()
        say(f"report: {path.resolve()}{'  (+ report.pdf)' if pdf else ''}  ({result.wall_s:.1f} s); every table "
            "there, in analysis.json, or with --details")
        say(f"bundle: {bundle.path} (apply it: fogdrift compensate {bundle.path} LOG --unit {record.input_unit}); "
            f"compensated test block: {_file_pattern([p.name for p in comp], list(record.axis_names))} (deg/h)")
        r.print_json(r.out.path / "analysis.json")


def _file_pattern(names: list, axes: list) -> str:
    """``compensated_test_<axis>.csv (gx, gy)`` for one file per axis named alike, else the names.

    >>> _file_pattern(["compensated_test_gx.csv", "compensated_test_gy.csv"], ["gx", "gy"])
    'compensated_test_<axis>.csv (gx, gy)'
    >>> _file_pattern(["a.csv"], ["gx"])
    'a.csv'
    """
    if len(names) < 2 or len(names) != len(axes) or axes[0] not in names[0]:
        return ", ".join(names)
    head, _, tail = names[0].partition(axes[0])
    if any(n != f"{head}{a}{tail}" for n, a in zip(names, axes)):
        return ", ".join(names)
    return f"{head}<axis>{tail} ({', '.join(axes)})"


def _match_axes(record, other, path):
    """The --apply-to recording's axes matched to the fitted ones BY NAME; refuses axes without a model."""
    fitted = list(record.axis_names)
    extra = [a for a in other.axis_names if a not in fitted]
    if extra:
        raise ConfigError(f"--apply-to {path}: axes {extra} have no fitted model (the fitted recording has "
                          f"{fitted}); axes are matched by name: select matching ones with --columns")
    missing = [a for a in fitted if a not in other.axis_names]
    if missing:
        say(f"--apply-to {path.name}: axes {missing} are not in this recording: not applied there", style="yellow")
    return other


def apply_note(result, path) -> str:
    """One line saying what --apply-to re-estimated and what it kept."""
    cfg = result.config
    parts = []
    fitted = {a.name: a.models for a in result.axes}
    for ax in result.apply_to.axes:
        ma, src = ax.models, fitted.get(ax.name)
        e, f = ma.split["train"]
        parts.append(f"{ax.name} {ma.bias_dph:+.4g} deg/h on its first {(f - e) * ma.dt_s:g} s "
                     f"(fitted recording: {src.bias_dph:+.4g} deg/h)" if src is not None else ax.name)
    return (f"--apply-to {path.name}: models applied unchanged (axes by name); bias re-estimated on its own "
            f"training share ({cfg.train_fraction:g}): " + "; ".join(parts)
            + "; Earth rate, wavelet, level and modelling rate as for the fitted recording")


def parse_heading_options(calibration: float, origin_step: float, horizons: str) -> tuple:
    """The heading-evaluation settings checked before any work; returns the horizons [s]."""
    import math

    for flag, v in (("--calibration", calibration), ("--origin-step", origin_step)):
        if not (math.isfinite(v) and v > 0):
            raise ConfigError(f"{flag} must be a positive number of seconds, got {v!r}")
    try:
        hs = tuple(float(h) for h in csv_list(horizons))
    except ValueError:
        raise ConfigError(f"--horizons must be numbers of seconds separated by commas, got {horizons!r}") from None
    if not hs or not all(math.isfinite(h) and h > 0 for h in hs):
        raise ConfigError(f"--horizons must be positive numbers of seconds separated by commas, got {horizons!r}")
    return hs


def _print_details(result, title, apply_title, evaluations) -> None:
    """Every table of the run on the console (``--details``): Table 2, one-step metrics, GMWM, heading error,
    artefacts and every verdict line."""
    from ..evaluation.verdicts import paper_measure_verdict, table2_marks
    from ..report import fit_cell, metrics_rows, noise_row
    from .compensate import print_evaluation

    for res, name in ((result, title), (result.apply_to, apply_title)):
        if res is None:
            continue
        for ax in res.axes:
            ev = getattr(ax, "evaluation", None)
            marks = table2_marks(ax.table2, ev.artefacts) if ev is not None and ev.artefacts is not None else {}
            console.print(noise_table(f"{name} axis {ax.name}: Table 2 (test block, {ax.models.dt_s:g} s "
                                      "samples; 95 % intervals)",
                                      [["original (whole record, native rate)"] + noise_row(ax.original.noise)
                                       + [fit_cell(ax.original.noise)]]
                                      + [[row.label + (f" FLAGGED: {marks[row.label]}" if row.label in marks else "")]
                                         + noise_row(row.analysis.noise) + [fit_cell(row.analysis.noise)]
                                         for row in ax.table2],
                                      fit=True))
            console.print(metrics_table(f"{name} axis {ax.name}: one-step metrics on the test block (paper's "
                                        "measure)", metrics_rows(ax.models)))
            if ev is None:  # with an evaluation, its verdicts (printed below) carry the same labelled sentence
                for line in paper_measure_verdict(ax.models).lines:
                    say("  " + line)
            if ax.gmwm is not None:
                from .noise import print_gmwm

                print_gmwm(f"{name} (whole record, native rate)", [ax.gmwm])
    for ev in evaluations:
        for note in ev.notes:
            say("  " + note)
        print_evaluation([ev.heading] if ev.heading else [], [ev.artefacts] if ev.artefacts else [], ev.verdicts)


#: Short console labels of the report's headline rows (the report keeps the long ones).
_SHORT_LABELS = {"selected noise model": "model", "selected noise model (WIC)": "model (WIC)",
                 "periodic / Markov terms (IEEE-952 Annex C)": "periodic / Markov",
                 "χ²_red (fit quality, p)": "fit χ²_red", "fitted τ range [s]": "fitted τ [s]"}


def _short_label(label: str) -> str:
    """``"N angle random walk [deg/√h]"`` -> ``"N [deg/√h]"``; other rows by :data:`_SHORT_LABELS`."""
    if label in _SHORT_LABELS:
        return _SHORT_LABELS[label]
    head, _, unit = label.rpartition(" [")
    sym = head.split(" ")[0].rstrip(",")
    return f"{sym} [{unit}" if unit and head else label


def _terse(cell: str) -> str:
    """The console's short form of a headline cell (the report keeps the long one): no p-value beside χ²_red,
    "best" for "best candidate"."""
    cell = re.sub(r", p = [^)]*\)", ")", cell)
    return cell.replace("(best candidate ", "(best ")


def _stacked(cell: str) -> str:
    """A cell's interval or remark on a second line, so that three axes fit an 80-column terminal."""
    for sep in (" [", " (", " at "):
        head, found, tail = cell.partition(sep)
        if found and head:
            return f"{head}\n{cell[len(head) + 1:]}"
    return cell


def print_summary(result, record, *, evaluated: bool, apply_name: str = "") -> None:
    """The console's summary, the report's first screen in short: the noise headline of every axis (terms that
    no axis resolves are left to the report), then one compensation verdict per axis, judged in heading error on
    held-out data."""
    from ..report.summary import OUTCOME_LABELS, noise_headline, verdict_items

    headers, rows = noise_headline(result)
    keep = []
    for row in rows:
        sym = row[0].split(" ")[0]
        optional = sym in ("K", "R", "Q", "periodic") and all(c.startswith(("–", "n/e")) for c in row[1:])
        if not optional:
            keep.append([_short_label(row[0])] + list(row[1:]))
    keep = [[row[0]] + [_stacked(_terse(c)) for c in row[1:]] for row in keep]
    console.print(fitted_table(f"Noise of the original output: {headers[0]}, 95 % intervals",
                               [""] + [h.replace("axis ", "") for h in headers[1:]], keep))
    say("  – (< x): not in the model, x its 95 % bound; n/e: not estimable (see report)", style="dim")
    for res, name in ((result, ""), (getattr(result, "apply_to", None), apply_name)):
        if res is None:
            continue
        ev = next((ax.evaluation for ax in res.axes if getattr(ax, "evaluation", None) is not None), None)
        if ev is not None:
            st = ev.settings
            e, f = res.axes[0].models.split["test"]
            block = (f - e) * res.axes[0].models.dt_s
            say(f"compensation verdict{' on ' + name if name else ''}: heading error on the held-out last "
                f"{100 * (1 - res.config.train_fraction - res.config.val_fraction):.0f} % ({block:.4g} s), "
                f"{st['calibration_window_s']:g}-s calibrations every {st['origin_step_s']:g} s, against constant "
                "bias:", style="bold")
        short = {ax.name: ax.evaluation.headline.short for ax in res.axes
                 if getattr(ax, "evaluation", None) is not None and ax.evaluation.headline is not None}
        for item in verdict_items(res, evaluated=evaluated):
            say(f"  [{OUTCOME_LABELS.get(item['outcome'], item['outcome'])}] "
                f"{short.get(item['axis']) or item['sentence']}")
