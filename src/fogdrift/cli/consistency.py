"""``fogdrift consistency``: will these noise numbers work in my filter?  Measured on held-out static logs.

The noise model of every axis comes from the training log's own Allan fit (``--method gmwm``: its GMWM model; or
``--components FILE``: a JSON of
noise components per axis, e.g. from an export); three target models are checked on every ``--held-out`` log
(same sensor, same axes): the full model, the white + random-walk model that Kalibr / VINS / ORB-SLAM3 keep, and
the white + random-walk model whose random walk covers the bias wander over ``--cover`` seconds.  Per target,
axis and horizon: the coverage of the 68 % and 95 % bands of the predicted angle error after a ``--calibration``
window, and the smallest variance inflation factor that gives nominal coverage, with its 95 % interval and the
number of independent origins (:mod:`fogdrift.evaluation.consistency`).  Writes consistency.json.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated, List, Optional

import typer

from .. import documents
from .._util import fmt_number
from ..errors import ConfigError
from ..io import file_sha256
from ..io._checks import check_path
from ..units import S_PER_H
from ._app import (JsonOpt, OutOpt, app, check_plausible, console, echo_record, fitted_table, progress, run,
                   say, warn, with_load_options)

DEFAULT_OUT = Path("out/consistency")

HeldOutOpt = Annotated[Optional[List[Path]], typer.Option(
    "--held-out", metavar="<path>", help="A held-out static log of the same sensor (repeat the option for "
                                         "several); read with the same reading options as FILE.")]
CalOpt = Annotated[float, typer.Option("--calibration", help="Static calibration window [s] before each origin; "
                                                             "the bias is its mean.")]
HorizonsOpt = Annotated[str, typer.Option("--horizons", help="Comma-separated horizons [s] after the calibration.")]
CoverOpt = Annotated[float, typer.Option("--cover", help="Horizon [s] over which the white + random-walk target's "
                                                         "random walk must cover the bias wander.")]
StepOpt = Annotated[Optional[float], typer.Option("--origin-step", help="Origin spacing [s]; default calibration + "
                                                                        "horizon (non-overlapping windows).")]
MethodOpt = Annotated[str, typer.Option("--method", help="Noise model of the training log: allan (the Allan fit of "
                                                       "'fogdrift allan') or gmwm (the GMWM model of 'fogdrift "
                                                       "noise').")]
ComponentsOpt = Annotated[Optional[Path], typer.Option(
    "--components", help="JSON noise model instead of the training log's Allan fit: the JSON of 'fogdrift export' "
                         "(its gyro channels' state_space components), {axis: [components]} or {\"axes\": {axis: "
                         "[components]}} (IEEE-952 units, fogdrift.models.statespace).")]


def _parse_horizons(text: str) -> list[float]:
    try:
        h = [float(t) for t in text.split(",") if t.strip()]
    except ValueError:
        h = []
    if not h or not all(math.isfinite(x) and x > 0 for x in h):
        raise ConfigError(f"--horizons must be comma-separated numbers > 0 [s]; got {text!r}")
    return sorted(set(h))


def _read_components(path: Path) -> dict:
    """{axis: components} from a JSON file (one line error on anything else)."""
    from ..models.statespace import check_components

    try:
        data = documents.read(path, yaml=False)
    except FileNotFoundError:
        raise ConfigError(f"--components: no such file {path}") from None
    except documents.DocumentError as exc:
        raise ConfigError(f"--components: {exc}") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ConfigError(f"--components: {path} is no JSON file ({exc})") from None
    if isinstance(data, dict) and isinstance(data.get("channels"), list):  # a 'fogdrift export --target json' file
        data = {ch.get("name"): (ch.get("state_space") or {}).get("components") for ch in data["channels"]
                if isinstance(ch, dict) and ch.get("quantity", "gyro") == "gyro"}
    if isinstance(data, dict) and isinstance(data.get("axes"), dict):
        data = data["axes"]
    if not isinstance(data, dict) or not data:
        raise ConfigError(f"--components: {path} must hold {{axis: [components]}} or {{\"axes\": {{...}}}}")
    out = {}
    for axis, comps in data.items():
        if isinstance(comps, dict) and "components" in comps:
            comps = comps["components"]
        try:
            out[str(axis)] = check_components(comps)
        except ConfigError as exc:
            raise ConfigError(f"--components: {path}, axis {axis}: {exc}") from None
    return out


def _fmt(x, d=3) -> str:
    """``d`` significant digits, ``–`` when missing or not finite: :func:`fogdrift._util.fmt_number`."""
    return fmt_number(x, d)


def _lam_cell(t) -> str:
    lam, lo, hi = t
    return f"{_fmt(lam)} [{_fmt(lo)}, {_fmt(hi)}]"


def print_result(res, label: str, kinds=None) -> None:
    """The coverage table of one target model and its verdict lines (angle error in deg for gyro axes, velocity
    error in m/s for accelerometer axes)."""
    from ..evaluation.consistency import verdict_line

    kinds = kinds or {}
    accel = {a for a in res.axes if kinds.get(a) == "accel"}
    rows = []
    for axis, v in res.axes.items():
        for r in v["rows"]:
            rows.append([axis, f"{r.horizon_s:g}", r.n_origins, f"{_fmt(r.sigma_pred, 4)} {r.unit}",
                         f"{_fmt(r.rms, 4)} {r.unit}",
                         f"{100 * r.coverage['68 %']:.1f} %", f"{100 * r.coverage['95 %']:.1f} %",
                         _lam_cell(r.inflation["68 %"]), _lam_cell(r.inflation["95 %"])])
    console.print(fitted_table(
        f"{label}: {'velocity' if accel == set(res.axes) else 'angle' if not accel else 'angle / velocity'} error "
        f"after a {res.t_cal_s:g} s calibration, coverage and smallest variance inflation λ (95 % interval)",
        ["axis", "h [s]", "origins", "σ pred", "RMS", "in 68 % band", "in 95 % band", "λ for 68 %",
         "λ for 95 %"], rows))
    for axis in res.axes:
        say("  " + verdict_line(res, axis))


def _model_text(comps, kind: str = "gyro") -> str:
    """The components in words, in the channel's units (an accelerometer's hold m/s^2 in place of deg/h)."""
    accel = kind == "accel"
    parts = []
    for c in comps:
        k = c["kind"]
        if k == "white":
            parts.append(f"VRW {S_PER_H * c['arw_dprh']:.3g} m/s/√h" if accel else f"N {c['arw_dprh']:.3g} deg/√h")
        elif k == "random_walk":
            parts.append(f"K {c['rrw_dphrh']:.3g} (m/s²)/√h" if accel else f"K {c['rrw_dphrh']:.3g} deg/h^1.5")
        elif k == "gauss_markov":
            parts.append(f"GM σ {c['sigma_dph']:.3g} {'m/s²' if accel else 'deg/h'} T_c {c['tc_s']:.3g} s")
        elif k == "quantization":
            parts.append(f"Q {c['q_urad'] / 4.8481368:.3g} m/s" if accel else f"Q {c['q_urad']:.3g} µrad")
        else:
            parts.append(f"R {c['ramp_dph2']:.3g} {'(m/s²)/h' if accel else 'deg/h²'}")
    return ", ".join(parts) or "(none)"


@app.command()
@with_load_options
def consistency(
    load,
    held_out: HeldOutOpt = None,
    calibration: CalOpt = 60.0,
    horizons: HorizonsOpt = "1,10,30,60,300",
    cover: CoverOpt = 60.0,
    origin_step: StepOpt = None,
    method: MethodOpt = "allan",
    components: ComponentsOpt = None,
    out: OutOpt = DEFAULT_OUT,
    json_out: JsonOpt = False,
):
    """Will these noise numbers work in my filter?  Coverage of the predicted angle error on held-out static logs
    (full model, white + random walk, white + the random walk that covers the bias wander), and the smallest
    variance inflation that gives nominal coverage; writes consistency.json."""
    with run("consistency", out, default_out=DEFAULT_OUT, inputs=[load.file, *(held_out or []), components],
             json_out=json_out, expect=("consistency.json",)) as r:
        from ..evaluation.consistency import summary_cell
        from ..workflows.consistency import run_consistency, write_consistency

        if not held_out:
            raise ConfigError("give at least one --held-out log (a static log of the same sensor, not the "
                              "training log)")
        for path in held_out:  # every input exists before the training log is read and fitted
            check_path(path, allow_dir=True)
        h = _parse_horizons(horizons)
        if not (math.isfinite(calibration) and calibration > 0):
            raise ConfigError(f"--calibration must be a number > 0 [s]; got {calibration!r}")
        if not (math.isfinite(cover) and cover > 0):
            raise ConfigError(f"--cover must be a number > 0 [s]; got {cover!r}")
        if origin_step is not None and not (math.isfinite(origin_step) and origin_step > 0):
            raise ConfigError(f"--origin-step must be a number > 0 [s]; got {origin_step!r}")
        method = method.lower()
        if method not in ("allan", "gmwm"):
            raise ConfigError(f"--method must be 'allan' or 'gmwm'; got {method!r}")
        given = None if components is None else _read_components(components)
        record = load.load()
        echo_record(load, record)
        check_plausible(record)
        train_sha = file_sha256(load.file)
        logs = []
        for path in held_out:
            logs.append(load.load(path))
            if file_sha256(path) == train_sha:
                warn(f"{path.name} is the training log itself (same SHA-256): its coverage is no held-out evidence")
        with progress("consistency", record.axis_names) as (axis_cb, _):
            done = run_consistency(record, logs, method=method, components=given, calibration_s=calibration,
                                   horizons_s=h, cover_s=cover, origin_step_s=origin_step,
                                   source_name=components.name if given is not None else load.file.name,
                                   held_out_names=[p.name for p in held_out],
                                   progress=axis_cb if given is None and method == "allan" else None)
        kinds = done.kinds  # gyro: angle error [deg]; accel: velocity error [m/s]
        for axis, comps in done.full.items():
            say(f"{axis}: full model from {done.source}: {_model_text(comps, kinds.get(axis, 'gyro'))}"
                + ("" if not done.notes.get(axis) else f" ({'; '.join(done.notes[axis])})"))
        say(f"held out: {', '.join(p.name for p in held_out)}; calibration {calibration:g} s, horizons "
            f"{', '.join(f'{x:g}' for x in h)} s; origins "
            f"{'calibration + horizon' if origin_step is None else f'{origin_step:g} s'} "
            "apart (non-overlapping windows), pooled over the held-out logs")
        for label in done.skipped:
            say(f"{label}: skipped (an axis has no white or random-walk component)", style="yellow")
        for res, label in done.results:
            print_result(res, label, kinds)
        if done.results:
            axes = list(done.results[0][0].axes)
            console.print(fitted_table(
                "inflation factor per target model: the largest λ over horizons and bands (95 % interval); "
                "'none' when no row under-covers beyond counting error",
                ["target"] + axes, [[res.target] + [summary_cell(res, a) for a in axes] for res, _ in done.results]))
        for axis, d in done.covering.items():
            say(f"{axis}: {d['sentence']}")
        path = write_consistency(done, r.out.path, training=str(load.file), held_out=held_out)
        r.wrote()
        r.print_json(path)
