"""Tables and notes the commands share (rows come from :mod:`fogdrift.report`, which owns the formatting)."""

from __future__ import annotations

from ._app import fitted_table, say


def noise_table(title, rows, fit=False, extra=()):
    """A Q, N, B, K, R table that fits the terminal (a rich renderable: ``console.print(noise_table(...))``);
    ``extra``: headers of further cells after R; ``fit=True``: the rows end with a fit-quality cell
    (:func:`fogdrift.report.fit_cell`)."""
    from ..report import NOISE_HEADERS

    return fitted_table(title, ("signal",) + NOISE_HEADERS + tuple(extra) + (("fit",) if fit else ()), rows)


def metrics_table(title, rows):
    """A metrics table that fits the terminal (a rich renderable)."""
    from ..report import METRICS_HEADERS

    return fitted_table(title, METRICS_HEADERS, rows)


def print_noise_notes(label, noise, outliers=None, dt_s=None):
    """The fit statistic, fitted range, what was left out and why, every unresolved term's reason, the
    outlier summary (the detailed one when ``outliers`` is given) and the slope read-outs as a labelled
    cross-check; one whole line each (never hard-wrapped)."""
    from ..report import noise_notes, readout_text

    detailed = outliers is not None and outliers.count
    for i, note in enumerate(noise_notes(noise)):
        if detailed and note.startswith("outliers:"):
            continue
        say(f"  {label}: {note}", style="bold" if i == 0 else
            ("yellow" if note.startswith(("fit poor", "no model fits")) else "dim"))
    if detailed:
        say(f"  {label}: outliers: {outliers.summary(dt_s)}", style="yellow")
    say(f"  {label}: slope read-outs (IEEE-952 cross-check, not the result): {readout_text(noise)}", style="dim")
