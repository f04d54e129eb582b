"""``fogdrift separate``: lifting-wavelet separation into drift and white noise."""

from __future__ import annotations

from pathlib import Path

from ._app import (gyro_only, JsonOpt, LevelOpt, ModeOpt, ModelRateOpt, OutOpt, WaveletOpt, app,
                   check_plausible, console, echo_record, parse_level, progress, run, say, with_load_options)
from ._settings import with_settings
from ._tables import noise_table

DEFAULT_OUT = Path("out/separate")


def modelling_rate_text(record, dt_s: float, factor: int) -> str:
    """'1 Hz (100 Hz block-averaged in blocks of 100)' or '100 Hz (the native rate)'.

    ``factor``: the block-average factor the pipeline used (decided once, read back, not recomputed).
    """
    fs = 1.0 / dt_s
    k = int(factor)
    if k <= 1:
        return f"{fs:.6g} Hz (the native rate)"
    return f"{fs:.6g} Hz ({record.fs_hz:.6g} Hz block-averaged in blocks of {k})"


@app.command()
@with_load_options
@with_settings("taus")
def separate(
    load,
    wavelet: WaveletOpt = "db2",
    level: LevelOpt = "4",
    mode: ModeOpt = "symmetric",
    model_rate: ModelRateOpt = 1.0,
    settings: dict = None,
    out: OutOpt = DEFAULT_OUT,
    json_out: JsonOpt = False,
):
    """Lifting-wavelet separation into drift (approximation) and white noise (details)."""
    from ..pipeline import AnalysisConfig
    from ..report import noise_row
    from ..workflows.separate import run_separate, write_separate

    with run("separate", out, default_out=DEFAULT_OUT, inputs=[load.file], json_out=json_out,
             expect=("separation.npz", "separation.csv", "separation_table.csv", "separation.json")) as r:
        cfg = AnalysisConfig(wavelet=wavelet, level=parse_level(level), mode=mode,
                             model_rate_hz=model_rate or None, **settings).validate()
        record = load.load()
        gyro_only(record, "separate")
        echo_record(load, record)
        findings = check_plausible(record)
        with progress("separate", record.axis_names):
            done = run_separate(record, cfg, findings=findings)
        seps = done.axes
        removed = ", ".join(f"{s.name} {s.mean_removed_dph:.6g} deg/h" for s in seps)
        say(f"modelling rate {modelling_rate_text(record, seps[0].dt_s, done.factor)}; the mean of each axis was removed "
            f"before separating (a constant would go wholly into the drift): {removed}")
        for s in seps:
            console.print(noise_table(
                f"axis {s.name}: {wavelet} level {s.level}, {mode}, dt {s.dt_s:g} s "
                f"(max |drift + noise - input| = {abs(s.drift_dph + s.noise_dph - s.rate_dph).max():.2e} deg/h)",
                [[label] + noise_row(aa.noise) for label, aa in s.rows]))
            if s.level_scan:
                say("  level scan: " + "; ".join(
                    f"L{d.level}: noise slope {d.noise_adev_slope:+.2f}" for d in s.level_scan))
        write_separate(done, r.out.path)
        r.wrote()
        r.print_json(r.out.path / "separation.json")
