"""Tables and notes the commands share (rows come from :mod:`fogdrift.report`, which owns the formatting)."""

from __future__ import annotations

from ._app import fitted_table, say


def noise_table(title, rows, fit=False, extra=(), quantity="angular_rate"):
    """A Q, N, B, K, R table that fits the terminal (a rich renderable: ``console.print(noise_table(...))``);
    ``extra``: headers of further cells after R; ``fit=True``: the rows end with a fit-quality cell
    (:func:`fogdrift.report.fit_cell`); ``quantity``: whose term headers (the gyro's IEEE-952 units, or the
    accelerometer's: Q [m/s], N [m/s/√h], B [µg], K [m/s²/√h], R [m/s²/h])."""
    from ..report import NOISE_HEADERS

    if quantity != "angular_rate":
        from ..noise.terms import TERMS, term_table

        headers = tuple(term_table(quantity)[t].header for t in TERMS)
    else:
        headers = NOISE_HEADERS
    return fitted_table(title, ("signal",) + headers + tuple(extra) + (("fit",) if fit else ()), rows)


def relabel_note(note: str, quantity: str) -> str:
    """A rendered note of an accelerometer's fit with the rate unit's label corrected: the numbers are already in
    the accelerometer's units (:func:`fogdrift.noise.quantity.express`); B_min in µg, a level or S, M in m/s^2."""
    if quantity == "angular_rate":
        return note
    import re

    note = re.sub(r"(B_min [=<] [-+0-9.e]+) deg/h", r"\1 µg", note)
    note = re.sub(r"(B [-+0-9.e]+) deg/h", r"\1 µg", note)
    return note.replace("deg/h/√s", "m/s²/√s").replace("deg/h", "m/s²")


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
    quantity = getattr(noise, "quantity", "angular_rate")
    for i, note in enumerate(relabel_note(n, quantity) for n in noise_notes(noise)):
        if detailed and note.startswith("outliers:"):
            continue
        say(f"  {label}: {note}", style="bold" if i == 0 else
            ("yellow" if note.startswith(("fit poor", "no model fits")) else "dim"))
    if detailed:
        say(f"  {label}: outliers: {relabel_note(outliers.summary(dt_s), quantity)}", style="yellow")
    say(f"  {label}: slope read-outs (IEEE-952 cross-check, not the result): {readout_text(noise)}", style="dim")
