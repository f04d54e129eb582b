"""``fogdrift model``: drift models fitted on the training block and compared on the test block."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from ._app import (LevelOpt, ModeOpt, ModelRateOpt, OutOpt, WaveletOpt, app, console, csv_list, errors,
                   parse_level, progress, with_load_options)
from ._tables import metrics_table

from ..models import MODEL_NAMES, describe_models

#: Default of --models: every registered model, in report order.
ALL_MODELS = ",".join(MODEL_NAMES)
ModelsOpt = Annotated[str, typer.Option(
    "--models", help="Comma-separated drift models (any case): " + "; ".join(describe_models()) + ".")]
HiddenOpt = Annotated[int, typer.Option("--hidden", help="Elman hidden units.")]
LagsOpt = Annotated[int, typer.Option("--lags", help="Input lags p of Elman/grey-Elman, order of AR.")]
EpochsOpt = Annotated[int, typer.Option("--epochs", help="Maximum training epochs (early stopping on validation).")]
SeedOpt = Annotated[int, typer.Option("--seed", help="Random seed.")]
TrainingOpt = Annotated[str, typer.Option("--training", help="bptt (Adam) or bp (classic traingdx).")]


@app.command()
@with_load_options
def model(
    load,
    models: ModelsOpt = ALL_MODELS,
    hidden: HiddenOpt = 16,
    lags: LagsOpt = 4,
    epochs: EpochsOpt = 2000,
    seed: SeedOpt = 0,
    training: TrainingOpt = "bptt",
    wavelet: WaveletOpt = "db2",
    level: LevelOpt = "4",
    mode: ModeOpt = "symmetric",
    model_rate: ModelRateOpt = 1.0,
    out: OutOpt = Path("out/model"),
):
    """Fit drift models on the training block and compare them on the test block."""
    from ..pipeline import AnalysisConfig, run_models
    from ..report import causal_metrics_rows, metrics_rows, verdict, write_model_outputs

    with errors():
        record = load.load()
        cfg = AnalysisConfig(models=tuple(csv_list(models)), hidden=hidden, lags=lags, epochs=epochs, seed=seed,
                             training=training, wavelet=wavelet, level=parse_level(level), mode=mode,
                             model_rate_hz=model_rate or None)
        with progress("model") as (_, epoch_cb):
            results = run_models(record, cfg, progress=epoch_cb)
        for ma in results:
            console.print(metrics_table(f"axis {ma.name}: one-step metrics on the test block "
                                        f"(target: wavelet drift), dt {ma.dt_s:g} s", metrics_rows(ma)))
            console.print(metrics_table(f"axis {ma.name}: target = causal drift", causal_metrics_rows(ma)))
            for line in verdict(ma):
                console.print("  " + line, highlight=False)
        write_model_outputs(results, out)
        console.print(f"wrote models, metrics.json and figures to {out}")
        # the self-describing bundle 'fogdrift compensate' applies to other logs
        from ..bundle import write_bundle

        console.print(f"bundle: {write_bundle(out / 'bundle', results, cfg, record).path}")
