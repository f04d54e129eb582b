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
    """The fit statistic, fitted range, what was left out and why, and every unresolved term's reason."""
    from ..report import noise_notes, readout_text

    for i, note in enumerate(noise_notes(noise)):
        style = "bold" if i == 0 else ("yellow" if note.startswith("fit poor") else "dim")
        console.print(Text(f"  {label}: {note}", style=style), highlight=False)
    console.print(Text(f"  {label}: slope read-outs (IEEE-952 cross-check, not the result): {readout_text(noise)}"),
                  style="dim", highlight=False)
