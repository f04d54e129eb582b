"""The compensated test block that ``fogdrift analyze`` writes beside its report.

One CSV per axis, ``compensated_test_<axis>.csv``, at the modelling rate, readable by
:func:`fogdrift.io.load` (units declared in the header, time column ``t_s``):

``t_s``
    start of each modelling-rate sample [s] (the record's time origin; sample ``k`` covers
    ``[t_s, t_s + dt)``, as in :class:`fogdrift.io.GyroRecord`).
``measured[deg/h]``
    the block-averaged gyro output, as measured (bias and Earth rate included).
``<model>[deg/h]``
    the compensated rate of each model (its registry name, e.g. ``ar``, ``gm11``, ``grey-elman``): ``measured - bias - p``, where ``bias`` is the training-block
    bias and ``p`` the model's causal one-step prediction of the drift made from the real-time (causal)
    drift of the samples before; the Earth-rate projection is a real rotation and stays in the output,
    exactly as ``fogdrift compensate`` does (:mod:`fogdrift.compensate.engine`).  Empty during a model's
    warm-up (no prediction yet).
``bias[deg/h]``
    the constant-bias compensation (``measured - bias``), the baseline every model is judged against.

The models keep the history of the training and validation blocks (they were fitted on the same record), so
unlike ``fogdrift compensate`` on a new log there is no cold start at the first test sample.

Examples
--------
>>> import tempfile
>>> from fogdrift.io import from_array, load
>>> from fogdrift.pipeline import AnalysisConfig, run_models
>>> from fogdrift.simulate import simulate
>>> rec = from_array(simulate(4000, dt_s=1.0, arw_dprh=0.5, rrw_dphrh=2.0, seed=1), dt_s=1.0, axis_names=("gz",))
>>> cfg = AnalysisConfig(models=("ar", "persistence"))
>>> [path] = write_compensated_test_block(run_models(rec, cfg), tempfile.mkdtemp(), t0_s=rec.t0_s)
>>> back = load(path, columns=["measured", "ar"])
>>> back.axis_names, back.dt_s, back.n_samples
(('measured', 'ar'), 1.0, 800)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._util import safe_name
from ..models.registry import MODELS
from ..output import atomic_path

__all__ = ["write_compensated_test_block", "compensated_test_block"]


def compensated_test_block(model_axis, t0_s: float = 0.0) -> dict[str, np.ndarray]:
    """Columns of the compensated test block of one :class:`fogdrift.pipeline.ModelAxis` (see the module doc).

    Returns an ordered dict ``column name -> array`` (rates in deg/h, time in s).
    """
    ma = model_axis
    e, f = ma.split["test"]
    offset = ma.bias_dph + ma.earth_rate_dph
    measured = np.asarray(ma.rate_dph[e:f], dtype=np.float64) + offset  # rate_dph has bias and Earth removed
    cols = {"t_s": t0_s + (e + np.arange(f - e)) * ma.dt_s, "measured": measured,
            "bias": measured - ma.bias_dph}
    names = {spec.label: spec.name for spec in MODELS}
    for label, yhat in ma.causal_predictions.items():
        cols[names.get(label, label)] = measured - ma.bias_dph - np.asarray(yhat, dtype=np.float64)
    return cols


def write_compensated_test_block(model_axes, out_dir, *, t0_s: float = 0.0) -> list[Path]:
    """Write ``compensated_test_<axis>.csv`` per axis into ``out_dir`` (atomically); returns the paths."""
    paths = []
    for ma in model_axes:
        cols = compensated_test_block(ma, t0_s)
        names = list(cols)
        header = ",".join(["t_s"] + [f"{n}[deg/h]" for n in names[1:]])
        data = np.column_stack([cols[n] for n in names])
        path = Path(out_dir) / f"compensated_test_{safe_name(ma.name)}.csv"
        with atomic_path(path) as tmp:
            with open(tmp, "w") as fh:
                fh.write(header + "\n")
                for row in data:  # NaN (warm-up) as an empty field, which the CSV reader reads as missing
                    fh.write(",".join("" if not np.isfinite(v) else f"{v:.12g}" for v in row) + "\n")
        paths.append(path)
    return paths
