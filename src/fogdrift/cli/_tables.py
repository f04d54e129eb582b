"""Rich tables the commands share (rows come from :mod:`fogdrift.report`, which owns the formatting)."""

from __future__ import annotations

from rich.text import Text

from ._app import console, table


def noise_table(title, rows):
    from ..report import NOISE_HEADERS

    return table(title, ("signal",) + NOISE_HEADERS, rows)


def metrics_table(title, rows):
    from ..report import METRICS_HEADERS

    return table(title, METRICS_HEADERS, rows)


def print_noise_notes(label, noise):
    from ..report import not_estimable_notes, readout_text

    for note in not_estimable_notes(noise):
        console.print(Text(f"  {label} {note}", style="dim"), highlight=False)
    console.print(Text(f"  {label} slope read-outs (cross-check): {readout_text(noise)}"), highlight=False)
