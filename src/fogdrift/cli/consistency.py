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

from .._util import fmt_number
from ..errors import ConfigError
from ..io import file_sha256
from ..io._checks import check_path
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
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigError(f"--components: no such file {path}") from None
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


def verdict_line(res, axis: str) -> str:
    """One sentence per target and axis: the inflation the user needs, or that none is needed.

    Inflation is needed when some horizon and band under-covers beyond counting error (the 95 % interval of its
    λ lies above 1); the factor to use is then the largest λ over horizons and bands (nominal coverage at every
    one).  Otherwise: "no inflation needed" (every λ <= 1) or "... within counting error"."""
    rows = res.axes[axis]["rows"]
    cells = [(*row.inflation[b], row.horizon_s, b, row.n_origins) for row in rows for b in row.inflation
             if math.isfinite(row.inflation[b][0])]
    if not cells:
        return f"{axis}: too few origins to count"
    lam, lo, hi, h, band, n = max(cells)
    if lam <= 1.0:
        return (f"{axis}: no inflation needed: the model covers at least nominally at every horizon (largest "
                f"λ {_fmt(lam)} at {h:g} s, {band} band)")
    significant = [c for c in cells if c[1] > 1.0]
    if not significant:
        return (f"{axis}: no inflation needed within counting error: every λ's 95 % interval reaches 1 (largest "
                f"λ {_fmt(lam)} at {h:g} s, {band} band, {n} origins, interval from {_fmt(lo)})")
    sig = max(significant, key=lambda c: c[1])
    where = "" if sig[3:5] == (h, band) else (f"; beyond counting error at {sig[3]:g} s, {sig[4]} band: λ "
                                              f"{_fmt(sig[0])} [{_fmt(sig[1])}, {_fmt(sig[2])}]")
    return (f"{axis}: inflate the variances by λ = {_fmt(lam)} ({h:g} s, {band} band, 95 % [{_fmt(lo)}, "
            f"{_fmt(hi)}], {n} origins{where}): multiply N, K, σ by {_fmt(math.sqrt(lam))}")


def summary_cell(res, axis: str) -> str:
    """``1.67 [1.14, 2.46]`` when inflation is needed (the rule of :func:`verdict_line`), else ``none (largest
    1.19)``."""
    cells = [(*row.inflation[b],) for row in res.axes[axis]["rows"] for b in row.inflation
             if math.isfinite(row.inflation[b][0])]
    if not cells:
        return "–"
    lam, lo, hi = max(cells)
    if lam <= 1.0 or not any(c[1] > 1.0 for c in cells):
        return f"none (largest {_fmt(lam)})"
    return f"{_fmt(lam)} [{_fmt(lo)}, {_fmt(hi)}]"


def print_result(res, label: str, kinds=None) -> None:
    """The coverage table of one target model and its verdict lines (angle error in deg for gyro axes, velocity
    error in m/s for accelerometer axes)."""
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
            parts.append(f"VRW {3600 * c['arw_dprh']:.3g} m/s/√h" if accel else f"N {c['arw_dprh']:.3g} deg/√h")
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
    with run("consistency", out, default_out=DEFAULT_OUT, inputs=[load.file, *(held_out or [])],
             json_out=json_out, expect=("consistency.json",)) as r:
        from ..evaluation.consistency import (check_consistency, components_from_noise_fit, random_walk_covering,
                                              reduced_model)
        from ..report import write_json

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
        notes, k_bounds = {}, {}
        if given is None and method == "gmwm":
            from ..evaluation.consistency import components_from_gmwm
            from ..gmwm.analysis import analyse_gmwm

            full = {}
            with progress("consistency", record.axis_names):
                for name in record.axis_names:
                    ax = analyse_gmwm(name, record.axis(name), record.dt_s)
                    full[name], notes[name] = components_from_gmwm(ax)
                    if "K_dphrh" not in ax.selection.ieee.terms:
                        k = ax.ieee_terms().get("K")
                        if k is not None and k.hi95:
                            k_bounds[name] = k.hi95
            source = f"the GMWM model of {load.file.name}"
        elif given is None:
            from ..pipeline import AnalysisConfig, run_allan

            with progress("consistency", record.axis_names) as (allan_cb, _):
                fits = run_allan(record, AnalysisConfig().validate(), progress=allan_cb)
            full = {}
            for a in fits:
                full[a.name], notes[a.name] = components_from_noise_fit(a.noise)
                k = a.noise.terms.get("K")
                if k is not None and k.value is None and k.hi95:
                    k_bounds[a.name] = k.hi95
            source = f"the Allan fit of {load.file.name}"
        else:
            missing = [a for a in record.axis_names if a not in given]
            if missing:
                raise ConfigError(f"--components has no model for axis {', '.join(missing)} "
                                  f"(has {', '.join(given)})")
            full = {a: given[a] for a in record.axis_names}
            source = f"{components.name}"
        from .noise import channel_kinds

        kinds = channel_kinds(record)  # gyro: angle error [deg]; accel: velocity error [m/s]
        for axis, comps in full.items():
            say(f"{axis}: full model from {source}: {_model_text(comps, kinds.get(axis, 'gyro'))}"
                + ("" if not notes.get(axis) else f" ({'; '.join(notes[axis])})"))
        train_sha = file_sha256(load.file)
        logs = []
        for path in held_out:
            rec = load.load(path)
            if file_sha256(path) == train_sha:
                warn(f"{path.name} is the training log itself (same SHA-256): its coverage is no held-out evidence")
            miss = [a for a in record.axis_names if a not in rec.axis_names]
            if miss:
                raise ConfigError(f"{path.name} has no axis {', '.join(miss)} (it has {', '.join(rec.axis_names)}); "
                                  "held-out logs need the training log's axes")
            logs.append(({a: rec.axis(a) for a in record.axis_names}, rec.dt_s))
        say(f"held out: {', '.join(p.name for p in held_out)}; calibration {calibration:g} s, horizons "
            f"{', '.join(f'{x:g}' for x in h)} s; origins "
            f"{'calibration + horizon' if origin_step is None else f'{origin_step:g} s'} "
            "apart (non-overlapping windows), pooled over the held-out logs")
        covering = {a: random_walk_covering(c, cover, calibration, k_bound_dphrh=k_bounds.get(a),
                                            quantity=kinds.get(a, "gyro")) for a, c in full.items()}
        cov_models = {a: [c for c in reduced_model(full[a]) if c["kind"] == "white"]
                      + [{"kind": "random_walk", "rrw_dphrh": covering[a]["k_eff_dphrh"]}] for a in full}
        targets = [("full", f"full model ({source})", full),
                   ("white+RW", "white + random walk only (Kalibr, VINS, ORB-SLAM3)",
                    {a: reduced_model(c) for a, c in full.items()}),
                   (f"white+RW covering {cover:g} s", f"white + the random walk covering the bias wander over "
                                                      f"{cover:g} s", cov_models)]
        results = []
        for key, label, comps in targets:
            if any(not comps[a] for a in comps):
                say(f"{label}: skipped (an axis has no white or random-walk component)", style="yellow")
                continue
            res = check_consistency(key, comps, logs, t_cal_s=calibration, horizons_s=h, step_s=origin_step,
                                    quantity=kinds)
            res.notes = [f"{a}: {'; '.join(n)}" for a, n in notes.items() if n]
            print_result(res, label, kinds)
            results.append((res, label))
        if results:
            axes = list(results[0][0].axes)
            console.print(fitted_table(
                "inflation factor per target model: the largest λ over horizons and bands (95 % interval); "
                "'none' when no row under-covers beyond counting error",
                ["target"] + axes, [[res.target] + [summary_cell(res, a) for a in axes] for res, _ in results]))
        for axis, d in covering.items():
            say(f"{axis}: {d['sentence']}")
        payload = {"fogdrift_result": "consistency", "training": str(load.file), "quantities": kinds,
                   "held_out": [str(p) for p in held_out], "model_source": source,
                   "calibration_s": calibration, "horizons_s": h, "cover_s": cover,
                   "inflation_definition": "lambda multiplies every component's variance parameter (N^2, K^2, "
                                           "sigma^2, Q^2, R^2); the smallest lambda with measured coverage >= "
                                           "nominal; 95 % interval from binomial order-statistic ranks",
                   "targets": [dict(res.to_dict(), label=label,
                                    verdicts={a: verdict_line(res, a) for a in res.axes}) for res, label in results],
                   "covering_random_walk": covering}
        path = write_json(payload, r.out.path / "consistency.json")
        r.wrote()
        r.print_json(path)
