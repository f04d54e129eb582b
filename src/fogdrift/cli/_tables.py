"""Tables and notes the commands share (rows come from :mod:`fogdrift.report`, which owns the formatting)."""

from __future__ import annotations

from ._app import fitted_table, say


def noise_table(title, rows):
    """A Q, N, B, K, R table that fits the terminal (a rich renderable: ``console.print(noise_table(...))``)."""
    from ..report import NOISE_HEADERS

    return fitted_table(title, ("signal",) + NOISE_HEADERS, rows)


def metrics_table(title, rows):
    """A metrics table that fits the terminal (a rich renderable)."""
    from ..report import METRICS_HEADERS

    return fitted_table(title, METRICS_HEADERS, rows)


def print_noise_notes(label, noise):
    """The not-estimable notes and slope read-outs of a noise fit, one whole line each (never hard-wrapped)."""
    from ..report import not_estimable_notes, readout_text

    for note in not_estimable_notes(noise):
        say(f"  {label} {note}", style="dim")
    say(f"  {label} slope read-outs (cross-check): {readout_text(noise)}")
