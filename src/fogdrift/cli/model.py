"""``fogdrift model``: drift models fitted on the training block and compared on the test block."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer

from ._app import (gyro_only, JsonOpt, LevelOpt, ModeOpt, ModelRateOpt, OutOpt, WaveletOpt, app,
                   check_plausible, console, csv_list, echo_record, parse_level, progress, run, say,
                   with_load_options)
from ._settings import with_settings
from ._tables import metrics_table

from ..models import MODEL_NAMES, describe_models
from ..models.registry import describe_params, parse_model_params

#: Default of --models: every registered model, in report order.
ALL_MODELS = ",".join(MODEL_NAMES)
DEFAULT_OUT = Path("out/model")
ModelsOpt = Annotated[str, typer.Option(
    "--models", help="Comma-separated drift models (any case): " + "; ".join(describe_models().splitlines()) + ".")]
ParamOpt = Annotated[Optional[list[str]], typer.Option(
    "--param", help="A drift model's hyper-parameter, MODEL.NAME=VALUE, repeatable (default: the model's own): "
    + describe_params() + ".")]


def model_axes_text(model_axes, record) -> str:
    """One line: the modelling rate and the bias (and Earth rate) removed from each axis before modelling."""
    from .separate import modelling_rate_text

    parts = []
    for ma in model_axes:
        text = f"{ma.name} {ma.bias_dph:.6g} deg/h"
        if ma.earth_rate_dph:
            text += f" + Earth rate {ma.earth_rate_dph:.6g} deg/h"
        parts.append(text)
    return (f"modelling rate {modelling_rate_text(record, model_axes[0].dt_s, model_axes[0].block_average_factor)}; removed before modelling, the "
            f"training-block mean of each axis: {', '.join(parts)}")


#: The modelling stage's settings (fogdrift.models.settings) that `model` and `analyze` offer as options.
NETWORK_SETTINGS = ("hidden", "lags", "epochs", "seed", "training")


@app.command()
@with_load_options
@with_settings(*NETWORK_SETTINGS)
def model(
    load,
    models: ModelsOpt = ALL_MODELS,
    settings: dict = None,
    param: ParamOpt = None,
    wavelet: WaveletOpt = "db2",
    level: LevelOpt = "4",
    mode: ModeOpt = "symmetric",
    model_rate: ModelRateOpt = 1.0,
    out: OutOpt = DEFAULT_OUT,
    json_out: JsonOpt = False,
):
    """Fit drift models on the training block and compare them on the test block."""
    from ..evaluation import causal_verdict, paper_measure_verdict
    from ..pipeline import AnalysisConfig
    from ..report import causal_metrics_rows, metrics_rows
    from ..workflows.model import run_model, write_model

    with run("model", out, default_out=DEFAULT_OUT, inputs=[load.file], json_out=json_out,
             expect=("metrics.json",)) as r:
        cfg = AnalysisConfig(models=tuple(csv_list(models)), **settings, wavelet=wavelet, level=parse_level(level),
                             mode=mode, model_rate_hz=model_rate or None,
                             model_params=parse_model_params(param)).validate()
        record = load.load()
        gyro_only(record, "model")
        echo_record(load, record)
        findings = check_plausible(record)
        with progress("model", record.axis_names) as (_, epoch_cb):
            done = run_model(record, cfg, progress=epoch_cb, findings=findings)
        results = done.axes
        say(model_axes_text(results, record))
        for ma in results:
            console.print(metrics_table(f"axis {ma.name}: one-step metrics on the test block, paper's measure "
                                        f"(target: non-causal wavelet drift), dt {ma.dt_s:g} s", metrics_rows(ma)))
            console.print(metrics_table(f"axis {ma.name}: target = causal drift", causal_metrics_rows(ma)))
            # the same sentences, labelled the same way, as analyze prints (evaluation.verdicts is their home)
            for v in (causal_verdict(ma), paper_measure_verdict(ma)):
                for line in v.lines:
                    say("  " + line)
        files = write_model(done, r.out.path)  # the self-describing bundle 'fogdrift compensate' applies to other logs
        say(f"bundle: {files['bundle'].path}")
        r.wrote()
        r.print_json(files["metrics"])
