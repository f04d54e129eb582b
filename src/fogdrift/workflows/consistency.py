"""The ``consistency`` workflow: will these noise numbers work in my filter?  The noise model of every axis (the
training log's Allan fit, its GMWM model, or given components), three target models, and their coverage of the
predicted angle (velocity) error on held-out static logs (:mod:`fogdrift.evaluation.consistency`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..errors import ConfigError
from ..io.readers.command_memory import check_records_memory
from ..evaluation.consistency import (check_consistency, components_from_gmwm, components_from_noise_fit,
                                      random_walk_covering, reduced_model, verdict_line)
from ..pipeline import AnalysisConfig
from ..pipeline import run_allan as _allan_fit
from ..report import write_json
from ..signal import channel_unit
from ..spec import channel_kind

__all__ = ["ConsistencyRun", "check_declared_units", "model_components", "run_consistency", "write_consistency",
           "INFLATION_DEFINITION"]

#: What the inflation factor means, stated in consistency.json.
INFLATION_DEFINITION = ("lambda multiplies every component's variance parameter (N^2, K^2, sigma^2, Q^2, R^2); the "
                        "smallest lambda with measured coverage >= nominal; 95 % interval from binomial "
                        "order-statistic ranks")


@dataclass
class ConsistencyRun:
    """What ``fogdrift consistency`` computed.

    Attributes
    ----------
    full : dict
        Axis -> the full noise model (state-space components, IEEE units).
    notes : dict
        Axis -> what the model's construction replaced or left out, in words.
    source : str
        Where the full model came from, in words.
    kinds : dict
        Axis -> ``"gyro"`` or ``"accel"`` (angle or velocity error).
    covering : dict
        Axis -> the random walk covering the bias wander over ``cover_s``
        (:func:`fogdrift.evaluation.consistency.random_walk_covering`).
    results : list of (ConsistencyResult, str)
        Per target model checked, its result and label.
    skipped : list of str
        Labels of targets skipped (an axis without a white or random-walk component).
    settings : dict
        ``training``, ``held_out``, ``calibration_s``, ``horizons_s``, ``cover_s``, ``origin_step_s``.
    """

    full: dict
    notes: dict
    source: str
    kinds: dict
    covering: dict = field(default_factory=dict)
    results: list = field(default_factory=list)
    skipped: list = field(default_factory=list)
    settings: dict = field(default_factory=dict)


def model_components(record, *, method="allan", components=None, source_name="", progress=None):
    """The full noise model of every axis: ``(full, notes, k_bounds, source)`` (``progress``: the per-axis callback
    of the Allan fit, :func:`fogdrift.pipeline.run_allan`).

    ``components``: {axis: components} given (every axis of ``record`` needs one); else the Allan fit of the record
    (``method="allan"``) or its GMWM model (``"gmwm"``).  ``k_bounds``: axis -> the 95 % upper bound of a rate random
    walk the model does not hold (it bounds the covering random walk).
    """
    notes, k_bounds = {}, {}
    if components is not None:
        missing = [a for a in record.axis_names if a not in components]
        if missing:
            raise ConfigError(f"--components has no model for axis {', '.join(missing)} (has {', '.join(components)})")
        return {a: components[a] for a in record.axis_names}, notes, k_bounds, source_name
    if method == "gmwm":
        from ..gmwm.analysis import analyse_gmwm

        full = {}
        for name in record.axis_names:
            ax = analyse_gmwm(name, record.axis(name), record.dt_s)
            full[name], notes[name] = components_from_gmwm(ax)
            if "K_dphrh" not in ax.selection.ieee.terms:
                k = ax.ieee_terms().get("K")
                if k is not None and k.hi95:
                    k_bounds[name] = k.hi95
        return full, notes, k_bounds, f"the GMWM model of {source_name}"
    if method != "allan":
        raise ConfigError(f"--method must be 'allan' or 'gmwm'; got {method!r}")
    full = {}
    for a in _allan_fit(record, AnalysisConfig().validate(), progress=progress):
        full[a.name], notes[a.name] = components_from_noise_fit(a.noise)
        k = a.noise.terms.get("K")
        if k is not None and k.value is None and k.hi95:
            k_bounds[a.name] = k.hi95
    return full, notes, k_bounds, f"the Allan fit of {source_name}"


def check_declared_units(rec, name: str) -> None:
    """ConfigError if a held-out log declares, for a channel, a unit other than the one the unit option made it be
    read in.

    The option (``--unit``) is the training log's; a held-out log read through it would have its own header
    overruled (a log that declares ``gz[rad/s]`` read as deg/s: every angle error 57x small, and "no inflation
    needed").  Units are never guessed: the conflict is refused, naming the file, the column and both units.
    """
    for c in rec.signal.channels:
        if c.declared_unit is None or c.unit_source != "option":
            continue
        try:
            declared = channel_unit(c.declared_unit, c.quantity)
            same = declared.kind == c.unit.kind and declared.factor == c.unit.factor
        except ConfigError:
            same = False
        if not same:
            raise ConfigError(f"{name}: column {c.name} declares {c.declared_unit.strip()!r}, but {{opt:unit}} "
                              f"{c.unit.text!r} (given for the training log) would read it as {c.unit.text}; a "
                              "held-out log is never read against its own header: give the logs in one unit, or "
                              "fix the header")


def run_consistency(record, held_out, *, method="allan", components=None, calibration_s=60.0,
                    horizons_s=(1.0, 10.0, 30.0, 60.0, 300.0), cover_s=60.0, origin_step_s=None, source_name="",
                    held_out_names=(), progress=None) -> ConsistencyRun:
    """Run ``fogdrift consistency``.

    Parameters
    ----------
    record : GyroRecord
        The training log.
    held_out : list of GyroRecord
        Held-out static logs of the same sensor; each needs the training log's axes.
    method, components, source_name, progress
        The full model (:func:`model_components`).
    calibration_s, horizons_s, cover_s, origin_step_s : float
        Calibration window, horizons, the covering horizon and the origin spacing [s] (None: calibration + horizon).
    held_out_names : sequence of str
        Their file names, for messages and the JSON.
    """
    check_records_memory("consistency", record, *held_out)
    names = list(held_out_names) or [f"held-out log {i + 1}" for i in range(len(held_out))]
    for rec, name in zip(held_out, names):
        check_declared_units(rec, name)
    full, notes, k_bounds, source = model_components(record, method=method, components=components,
                                                     source_name=source_name, progress=progress)
    kinds = {c.name: channel_kind(c.quantity) for c in record.signal.channels}
    logs = []
    for rec, name in zip(held_out, names):
        miss = [a for a in record.axis_names if a not in rec.axis_names]
        if miss:
            raise ConfigError(f"{name} has no axis {', '.join(miss)} (it has {', '.join(rec.axis_names)}); "
                              "held-out logs need the training log's axes")
        logs.append(({a: rec.axis(a) for a in record.axis_names}, rec.dt_s))
    covering = {a: random_walk_covering(c, cover_s, calibration_s, k_bound_dphrh=k_bounds.get(a),
                                        quantity=kinds.get(a, "gyro")) for a, c in full.items()}
    cov_models = {a: [c for c in reduced_model(full[a]) if c["kind"] == "white"]
                  + [{"kind": "random_walk", "rrw_dphrh": covering[a]["k_eff_dphrh"]}] for a in full}
    targets = [("full", f"full model ({source})", full),
               ("white+RW", "white + random walk only (Kalibr, VINS, ORB-SLAM3)",
                {a: reduced_model(c) for a, c in full.items()}),
               (f"white+RW covering {cover_s:g} s", f"white + the random walk covering the bias wander over "
                                                    f"{cover_s:g} s", cov_models)]
    run = ConsistencyRun(full, notes, source, kinds, covering,
                         settings={"training": source_name, "held_out": names, "calibration_s": calibration_s,
                                   "horizons_s": list(horizons_s), "cover_s": cover_s,
                                   "origin_step_s": origin_step_s})
    for key, label, comps in targets:
        if any(not comps[a] for a in comps):
            run.skipped.append(label)
            continue
        res = check_consistency(key, comps, logs, t_cal_s=calibration_s, horizons_s=list(horizons_s),
                                step_s=origin_step_s, quantity=kinds)
        res.notes = [f"{a}: {'; '.join(n)}" for a, n in notes.items() if n]
        run.results.append((res, label))
    return run


def write_consistency(run: ConsistencyRun, out_dir, *, training: str = "", held_out=()) -> Path:
    """``consistency.json`` in ``out_dir`` (``training``, ``held_out``: the paths as given)."""
    st = run.settings
    payload = {"fogdrift_result": "consistency", "training": training or st["training"], "quantities": run.kinds,
               "held_out": [str(p) for p in held_out] or st["held_out"], "model_source": run.source,
               "calibration_s": st["calibration_s"], "horizons_s": st["horizons_s"], "cover_s": st["cover_s"],
               "inflation_definition": INFLATION_DEFINITION,
               "targets": [dict(res.to_dict(), label=label, verdicts={a: verdict_line(res, a) for a in res.axes})
                           for res, label in run.results],
               "covering_random_walk": run.covering}
    return write_json(payload, Path(out_dir) / "consistency.json")
