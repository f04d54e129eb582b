"""The report's record screen, as data: what disturbs each axis, where, and what the noise fit used.

Read from the results the pipeline already made (each axis's ``original.screen``, the screen's dict from
:func:`fogdrift.segments.plan_segments`, and ``original.whole_noise``, the whole record's fit beside the quiet
segments' one); nothing is recomputed.  Rows of strings with units, so the same content goes into ``report.html``
(first screen) and ``analysis.json`` (``report_summary.screen``).
"""

from __future__ import annotations

from ..noise.terms import TERM_HEADERS, TERMS
from .tables import _fmt, noise_row

__all__ = ["screen_summary", "MAX_INTERVAL_ROWS"]

#: Disturbed intervals listed per axis on the first screen (the strongest, in time order); the rest are counted in
#: one row and listed in analysis.json.
MAX_INTERVAL_ROWS = 6


def _unit(ax) -> str:
    return "m/s²" if getattr(ax.original.noise, "quantity", "angular_rate") == "specific_force" else "deg/h"


def _used_text(scr: dict) -> str:
    """Which samples the noise fit used, in s."""
    dt, n = scr["dt_s"], scr["n_samples"]
    used = scr.get("segments_used")
    if not used:
        why = ("stationary" if scr["stationary"] else
               "--segments whole" if scr.get("mode") == "whole" else "no quiet segment long enough")
        return f"the whole record, {n * dt:g} s ({why})"
    span = sum(b - a for a, b in used) * dt
    where = ", ".join(f"{a * dt:g}–{b * dt:g} s" for a, b in used[:4])
    if len(used) > 4:
        where += f" and {len(used) - 4} more"
    what = "quiet segments" if scr.get("mode") == "auto" else "segments"
    return f"{what} {where}: {span:g} s of {n * dt:g} s" + (", pooled without bridging a gap" if len(used) > 1 else "")


def _screen_text(scr: dict) -> str:
    ivs = scr.get("intervals") or []
    if not ivs:
        return f"stationary (no window above {scr['threshold']:.2g}× the quiet level)"
    cover = sum(d["end_s"] - d["start_s"] for d in ivs) / (scr["n_samples"] * scr["dt_s"])
    return (f"disturbed: {len(ivs)} interval{'s' if len(ivs) > 1 else ''} over {100 * cover:.0f} % of the record, "
            f"peak {max(d['peak'] for d in ivs):.2g}× the quiet level")


def screen_summary(result) -> dict | None:
    """The first screen's record screen: ``axes`` (``headers``, ``rows``: per axis the screen's verdict, the quiet
    level, the detection threshold, what the noise fit used, and N and B from that fit and from the whole record),
    ``intervals`` (``headers``, ``rows``: axis, character, start, end, peak against the quiet level; at most
    :data:`MAX_INTERVAL_ROWS` per axis, the others counted), ``disturbed`` (the axes with an interval) and
    ``false_alarm``.  None when no axis was screened.

    Examples
    --------
    >>> screen_summary(type("R", (), {"axes": []})()) is None
    True
    """
    axes = [ax for ax in result.axes if getattr(ax.original, "screen", None)]
    if not axes:
        return None
    n_head, b_head = TERM_HEADERS["N"], TERM_HEADERS["B"]
    headers = ["axis", "screen", "quiet level (RMS of a quiet window after a line) [{u}]", "detection threshold",
               "the noise fit uses", f"{n_head}: fit used", f"{n_head}: whole record", f"{b_head}: fit used",
               f"{b_head}: whole record"]
    rows, iv_rows, disturbed = [], [], []
    units = {_unit(ax) for ax in axes}
    headers[2] = headers[2].format(u=units.pop() if len(units) == 1 else "rate unit of each axis")
    for ax in axes:
        scr = ax.original.screen
        used = dict(zip(TERMS, noise_row(ax.original.noise)))
        whole_fit = getattr(ax.original, "whole_noise", None)
        whole = dict(zip(TERMS, noise_row(whole_fit))) if whole_fit is not None else None
        same = "the same (whole record fitted)"
        rows.append([ax.name, _screen_text(scr), _fmt(scr["quiet_level"], 4),
                     f"{scr['threshold']:.3g}× the quiet level (false-alarm rate {scr['false_alarm']:g})",
                     _used_text(scr), used["N"], whole["N"] if whole else same, used["B"],
                     whole["B"] if whole else same])
        ivs = scr.get("intervals") or []
        if ivs:
            disturbed.append(ax.name)
        top = sorted(sorted(ivs, key=lambda d: -d["peak"])[:MAX_INTERVAL_ROWS], key=lambda d: d["start_s"])
        unit = _unit(ax)
        for d in top:
            step = "" if d.get("step") is None else f"; mean change {d['step']:+.3g} {unit}"
            iv_rows.append([ax.name, d["kind"] + step, f"{d['start_s']:g}", f"{d['end_s']:g}",
                            f"{d['peak']:.2g}×", _fmt(d["peak"] * scr["quiet_level"], 3),
                            _fmt(scr["quiet_level"], 3)])
        if len(ivs) > len(top):
            rest = [d for d in ivs if d not in top]
            iv_rows.append([ax.name, f"{len(rest)} more (weaker) intervals, each in analysis.json",
                            f"{min(d['start_s'] for d in rest):g}", f"{max(d['end_s'] for d in rest):g}",
                            f"≤ {max(d['peak'] for d in rest):.2g}×", "–", _fmt(scr["quiet_level"], 3)])
    u = headers[2].rsplit("[", 1)[1].rstrip("]")
    iv_headers = ["axis", "character", "start [s]", "end [s]", "peak (deviation ratio to the quiet level)",
                  f"peak level [{u}]", f"quiet level [{u}]"]
    return {"axes": {"headers": headers, "rows": rows}, "intervals": {"headers": iv_headers, "rows": iv_rows},
            "disturbed": disturbed, "false_alarm": axes[0].original.screen["false_alarm"]}
