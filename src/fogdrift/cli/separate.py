"""``fogdrift separate``: lifting-wavelet separation into drift and white noise."""

from __future__ import annotations

from pathlib import Path

from ._app import (LevelOpt, ModeOpt, ModelRateOpt, OutOpt, TausOpt, WaveletOpt, app, console, errors,
                   parse_level, parse_taus, with_load_options)
from ._tables import noise_table


@app.command()
@with_load_options
def separate(
    load,
    wavelet: WaveletOpt = "db2",
    level: LevelOpt = "4",
    mode: ModeOpt = "symmetric",
    model_rate: ModelRateOpt = 1.0,
    taus: TausOpt = "octave",
    out: OutOpt = Path("out/separate"),
):
    """Lifting-wavelet separation into drift (approximation) and white noise (details)."""
    from ..pipeline import AnalysisConfig, run_separation
    from ..report import noise_row, write_separation_outputs

    with errors():
        record = load.load()
        cfg = AnalysisConfig(wavelet=wavelet, level=parse_level(level), mode=mode,
                             model_rate_hz=model_rate or None, taus=parse_taus(taus))
        seps = run_separation(record, cfg)
        for s in seps:
            console.print(noise_table(
                f"axis {s.name}: {wavelet} level {s.level}, {mode}, dt {s.dt_s:g} s "
                f"(max |drift + noise - input| = {abs(s.drift_dph + s.noise_dph - s.rate_dph).max():.2e} deg/h)",
                [[label] + noise_row(aa.noise) for label, aa in s.rows]))
            if s.level_scan:
                console.print("  level scan: " + "; ".join(
                    f"L{d.level}: noise slope {d.noise_adev_slope:+.2f}" for d in s.level_scan))
        write_separation_outputs(seps, out)
        console.print(f"wrote drift/noise series, figures and tables to {out}")
