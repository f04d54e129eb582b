"""The report's one-sentence compensation verdict (outcome and colour) and its compensation tables, from
hand-made heading-error and artefact results whose outcome is known by construction."""

from __future__ import annotations

from types import SimpleNamespace as NS

import pytest

from fogdrift.evaluation import ArtefactResult, ArtefactRow, headline_verdict
from fogdrift.evaluation.verdicts import independent_origins
from fogdrift.report.html import _artefact_table, _heading_table, _verdict_li


def _row(model, h, rms, ratio, n=30, step_s=300.0):
    """The model is better (worse) than constant bias at every non-overlapping origin when its ratio is < 1 (> 1)."""
    k = independent_origins(n, step_s, h)
    return NS(model=model, horizon_s=h, n_origins=n, rms_deg=rms, ratio_to_bias=ratio, median_abs_deg=rms,
              p90_abs_deg=2 * rms, wins_vs_bias=0.5, predicted_sigma_deg=None, inside_sigma=None, n_independent=k,
              better_independent=k if ratio < 1 else 0, worse_independent=k if ratio > 1 else 0)


def _heading(kalman_60, kalman_600, n=30, step_s=300.0):
    """Constant bias and Kalman at 60 s and 600 s; 30 origins every 300 s: all independent at both horizons."""
    rows = [_row("constant bias", 60.0, 1.0, 1.0, n, step_s), _row("Kalman", 60.0, kalman_60, kalman_60, n, step_s),
            _row("constant bias", 600.0, 8.0, 1.0, n, step_s),
            _row("Kalman", 600.0, 8.0 * kalman_600, kalman_600, n, step_s)]
    return NS(axis="gx", calib_s=300.0, step_s=step_s, horizons_s=(60.0, 600.0), rows=rows, notes=[])


def _artefacts(flagged=()):
    row = ArtefactRow(model="Kalman", gains={0.01: 0.5 if flagged else 1.0, 0.1: 1.0}, step_survival={10.0: 0.9},
                      ramp_survival=0.8, adev_ratio={0.01: 0.7, 0.1: None}, flagged_hz=tuple(flagged))
    base = ArtefactRow(model="constant bias", gains={0.01: 1.0, 0.1: 1.0}, step_survival={10.0: 1.0},
                       ramp_survival=1.0, adev_ratio={0.01: 1.0, 0.1: None}, flagged_hz=())
    return ArtefactResult(axis="gx", dt_s=1.0, amplitude_dph=3.0, frequencies_hz=[0.01, 0.1], step_delays_s=(10.0,),
                          rows=[base, row])


@pytest.mark.parametrize("k60, k600, flagged, outcome", [
    (0.80, 1.00, (), "reduces"),      # -20 % at 60 s, no change at 600 s, artefact check clean
    (0.80, 1.10, (), "mixed"),        # -20 % at 60 s but +10 % at 600 s
    (0.80, 1.00, (0.01,), "mixed"),   # reduces, but removes real rate at 0.01 Hz
    (0.97, 1.03, (), "none"),         # within +-5 % everywhere: not material
    (1.20, 1.30, (), "none"),         # worse everywhere
])
def test_headline_outcome_by_construction(k60, k600, flagged, outcome):
    v = headline_verdict(_heading(k60, k600), _artefacts(flagged))
    assert v.data["outcome"] == outcome, v.lines
    assert len(v.lines) == 1 and v.lines[0].startswith("gx: ")
    if outcome != "none":
        assert v.data["model"] == "Kalman" and "20 %" in v.lines[0]


def test_overlapping_origins_are_not_judged():
    """30 origins every 60 s: at 600 s only 1 + 29*60/600 = 3 have non-overlapping horizons, and at 60 s all 30
    count; with 9 origins nothing can be judged at all."""
    assert independent_origins(30, 60.0, 600.0) == 3 and independent_origins(30, 60.0, 60.0) == 30
    v = headline_verdict(_heading(1.0, 0.5, step_s=60.0), None)  # halves the error, but only where not judged
    assert v.data["outcome"] == "none" and v.data["judged_horizons_s"] == [60.0]
    v = headline_verdict(_heading(0.5, 0.5, n=9), None)
    assert v.data["outcome"] == "undetermined" and "cannot judge" in v.lines[0]
    assert headline_verdict(None, None, axis="gz", reason="--no-heading").data["outcome"] == "undetermined"


def test_verdict_badge_and_tables_render():
    v = headline_verdict(_heading(0.8, 1.0), _artefacts((0.01,)))
    li = _verdict_li({"outcome": v.data["outcome"], "sentence": v.lines[0]})
    assert li.startswith('<li class="v-mixed"><span class="badge">MIXED</span>gx: Kalman')
    h = _heading_table(_heading(0.8, 1.1))
    assert h.index("constant bias") < h.index("Kalman")  # constant bias first at each horizon
    assert '<td class="good">0.8</td>' in h and '<td class="bad">1.1</td>' in h
    a = _artefact_table(_artefacts((0.01,)))
    assert '<td class="flag">0.5 ⚑</td>' in a and "sinusoid 0.1 Hz: gain" in a and "ramp: surviving slope" in a


def test_recording_rows_read_the_sampling_from_the_signal_description():
    """The rate rows come from the record blocks' signal.sampling; synonyms beside it are not read."""
    import json

    import numpy as np

    from fogdrift.io import from_array
    from fogdrift.report.summary import recording_rows

    rec = from_array(np.zeros((400, 1)), dt_s=0.01, axis_names=["gz"])
    res = NS(source="run/g.csv", record=json.loads(json.dumps(rec.metadata())),
             model_record=json.loads(json.dumps(rec.to_rate(25.0).metadata())))
    rows = dict(recording_rows(res))
    assert rows["sample rate"] == "100 Hz (dt 0.01 s)"
    assert rows["modelling rate"] == "25 Hz (native 100 Hz averaged in blocks of 4)"
    res.record.update(dt_s=1.0, fs_hz=1.0, native_fs_hz=1.0)
    res.model_record.update(fs_hz=1.0, native_fs_hz=3.0, block_average_factor=3)
    assert dict(recording_rows(res)) == rows
    res.model_record = {}
    assert dict(recording_rows(res))["modelling rate"] == "native rate"


def test_unit_rows_read_the_units_from_the_signal_description(tmp_path):
    """The unit rows come from the record block's signal.channels; the old keys beside it are not read, and a
    block with only the old keys is refused in one line."""
    import json

    import numpy as np
    import pytest

    from fogdrift.errors import ConfigError
    from fogdrift.io import from_array, load
    from fogdrift.report.settings import unit_row
    from fogdrift.report.summary import recording_rows

    rec = from_array(np.zeros((400, 1)), dt_s=0.01, unit="deg/s", axis_names=["gz"])
    block = json.loads(json.dumps(rec.metadata()))
    res = NS(source="run/g.csv", record=block, model_record={})
    assert dict(recording_rows(res))["rate unit"] == "deg/s (given by the user (--unit)); converted to deg/h"
    assert unit_row(block) == ("rate unit (as read)", "deg/s × 3600 = deg/h")
    old = {"input_unit": "rad/s", "declared_units": ["rad/s"], "scale_to_dph": 1.0, "rate_unit": "deg/h"}
    res.record = {**block, **old}
    assert dict(recording_rows(res))["rate unit"] == "deg/s (given by the user (--unit)); converted to deg/h"
    assert unit_row(res.record) == unit_row(block)
    with pytest.raises(ConfigError, match="^the record states its units only as input_unit, declared_units"):
        unit_row(old)
    acc = from_array(np.zeros((400, 2)), dt_s=0.01, unit="mg", axis_names=["ax", "ay"])
    assert unit_row(json.loads(json.dumps(acc.metadata()))) == ("unit (as read)", "mg × 0.00980665 = m/s^2")
    p = tmp_path / "imu.csv"
    p.write_text("t_s,gx[deg/s],ax[g]\n" + "".join(f"{0.01 * i},0.1,1.0\n" for i in range(40)))
    mixed = json.loads(json.dumps(load(p).metadata()))
    assert unit_row(mixed) == ("unit (as read)", "gx deg/s × 3600 = deg/h, ax g × 9.80665 = m/s^2")
    res.record = mixed
    assert dict(recording_rows(res))["rate unit"] == "gx=deg/s,ax=g (declared in the file's header); converted to deg/h"
