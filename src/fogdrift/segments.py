"""Which samples a noise fit uses: ``--segments auto|whole|A:B`` from the record screen (:mod:`fogdrift.screen`).

:func:`plan_segments` screens every axis and decides its segments (``auto``: the quiet segments of a disturbed
axis, at the quietest segment's level; ``whole``; explicit ranges in s); :func:`segment_lines` says it in words;
:func:`longest_segment` is what a method that cannot pool segments fits.  The pooled Allan variance is
:func:`fogdrift.allan.allan_variance_segments`.  Units: s, samples.
"""

from __future__ import annotations

import math

import numpy as np

from .errors import ConfigError
from .health import frozen_stretch
from .screen import ScreenResult, dynamic_adev, screen_record

__all__ = ["SEGMENT_MODES", "parse_segments", "plan_segments", "segment_lines", "longest_segment", "MAX_LISTED"]


#: The values of ``--segments`` besides explicit ``A:B`` ranges: ``auto`` fits the quiet segments of a record its
#: screen calls disturbed (the whole record when it is stationary), ``whole`` always fits the whole record.
SEGMENT_MODES = ("auto", "whole")


def parse_segments(text, dt_s, n_samples) -> tuple | None:
    """``"auto"``/``"whole"`` as themselves, or ``"A:B,C:D"`` (seconds from the first sample; an empty end is the
    record's end) as ``((start, stop), ...)`` sample indices.

    Examples
    --------
    >>> parse_segments("0:10,20:", 0.5, 100)
    ((0, 20), (40, 100))
    >>> parse_segments("auto", 0.5, 100)
    'auto'
    """
    t = str(text).strip().lower()
    if t in SEGMENT_MODES:
        return t
    out = []
    for part in t.split(","):
        a, sep, b = part.partition(":")
        try:
            if not sep:
                raise ValueError
            lo = int(round(float(a or 0.0) / dt_s))
            hi = n_samples if b.strip() == "" else int(round(float(b) / dt_s))
        except ValueError:
            raise ConfigError(f"{{opt:segments}} takes 'auto', 'whole' or ranges in s such as '0:600,7000:'; got "
                              f"{text!r}") from None
        lo, hi = max(0, lo), min(n_samples, hi)
        if hi - lo < 2:
            raise ConfigError(f"{{opt:segments}}: the range {part.strip()!r} holds fewer than 2 samples of the "
                              f"{n_samples * dt_s:g}-s record")
        out.append((lo, hi))
    out.sort()
    if any(b0 > a1 for (_, b0), (a1, _) in zip(out, out[1:])):
        raise ConfigError(f"{{opt:segments}}: the ranges of {text!r} overlap")
    return tuple(out)


def plan_segments(record, mode="auto") -> tuple[dict, dict]:
    """Screen every axis of a record and decide which samples each axis's noise fit uses.

    Returns ``(segments, screens)``: axis name -> ``((start, stop), ...)`` or None (the whole record), and axis
    name -> the screen's :meth:`ScreenResult.to_dict` plus ``mode`` and ``segments_used`` (None: whole record).
    ``mode``: ``"auto"`` (the quiet segments where the screen finds a disturbance), ``"whole"``, or explicit
    ranges from :func:`parse_segments` (the same for every axis).
    """
    chosen = parse_segments(mode, record.dt_s, record.n_samples) if isinstance(mode, str) else tuple(mode)
    segments, screens = {}, {}
    # pieces down to 1 % of the record are pooled (the pooled Allan variance takes each at the taus it holds):
    # a log with short shocks spread over it keeps most of its quiet samples
    min_quiet_s = max(0.01 * record.n_samples, 100) * record.dt_s
    for name in record.axis_names:
        r = screen_record(record.axis(name), record.dt_s, min_quiet_s=min_quiet_s)
        dropped = []
        frozen = frozen_stretch(record.axis(name)) if chosen == "auto" else None
        healthy = tuple((a, b) for a, b in ((0, frozen[0]), (frozen[1], record.n_samples)) if b - a >= 2) \
            if frozen is not None else ()
        if healthy:  # a frozen (stuck) stretch is no quiet noise: the fit takes the rest (fogdrift.health)
            use = healthy
        elif chosen == "auto":
            use, dropped = (None, []) if r.stationary or not r.quiet_segments else _homogeneous(r)
        elif chosen == "whole":
            use = None
        else:
            use = chosen
        segments[name] = use
        screens[name] = {**r.to_dict(), "mode": chosen if isinstance(chosen, str) else "ranges",
                         **({"frozen": [int(frozen[0]), int(frozen[1])]} if healthy else {}),
                         "segments_used": None if use is None else [[int(a), int(b)] for a, b in use],
                         "segments_dropped": dropped, "text": r.text()}
        if not r.stationary:
            screens[name]["dynamic_adev"] = record_dynamic_adev(record.axis(name), record.dt_s)
    return segments, screens


#: The dynamic ADEV of a disturbed axis: windows of 1/8 of the record, a quarter-window step, octave taus up to a
#: quarter of the window.
DYNAMIC_WINDOWS = 8


def record_dynamic_adev(rate, dt_s) -> dict:
    """The dynamic Allan deviation of a whole record on the default grid (:func:`fogdrift.screen.dynamic_adev`), as
    JSON-able lists: ``t_s`` (window centres [s]), ``tau_s`` [s], ``adev`` (windows x taus, in the rate's unit)."""
    n = len(rate)
    window_s = n * dt_s / DYNAMIC_WINDOWS
    m_max = max(1, int(window_s / dt_s / 4))
    taus = dt_s * 2.0 ** np.arange(0, int(math.log2(m_max)) + 1)
    t, tau, adev = dynamic_adev(rate, dt_s, window_s, window_s / 4.0, taus)
    return {"t_s": [float(v) for v in t], "tau_s": [float(v) for v in tau],
            "adev": [[float(v) for v in row] for row in np.asarray(adev)], "window_s": float(window_s)}


def _homogeneous(r: ScreenResult) -> tuple:
    """The quiet segments that may be pooled: those whose median window level is within ``sqrt(threshold)`` of the
    quietest segment's.  A disturbance only adds to the sensor's own noise, so the quietest piece is the sensor;
    a piece above it by more than half the detection threshold (in log) is a disturbance's tail (a teleseism's
    coda, a slow recovery) that the window detector did not reach, and pooling it would mix two levels.
    Returns ``(segments, [{"start_s", "end_s", "ratio"}, ...] dropped)``."""
    L = int(r.window)
    med = []
    for a, b in r.quiet_segments:
        lv = np.asarray(r.levels[a // L:max(a // L + 1, b // L)], dtype=np.float64)
        med.append(float(np.median(lv)) if lv.size else math.inf)
    ref = min(med)
    tol = math.sqrt(max(float(r.threshold), 1.0))
    keep, dropped = [], []
    for (a, b), m in zip(r.quiet_segments, med):
        if m <= ref * tol:
            keep.append((int(a), int(b)))
        else:
            dropped.append({"start_s": a * r.dt_s, "end_s": b * r.dt_s, "ratio": m / ref})
    return tuple(keep), dropped


#: More disturbed intervals than this on one axis are summarised in one console line.
MAX_LISTED = 4


def segment_lines(name, screen, *, compact: bool = False) -> list[str]:
    """The console lines of one axis's screen: what disturbs the record, and what the fit uses (``compact``: one
    short line per axis, for a summary such as ``analyze``'s first screen; the JSON and the report hold the rest)."""
    dt = screen["dt_s"]
    n = screen["n_samples"]
    ivs = screen.get("intervals") or []
    used = screen.get("segments_used")
    if compact:
        if screen["stationary"]:
            return [f"{name}: stationary (no disturbance found); the noise fit uses the whole record"]
        cover = sum(d["end_s"] - d["start_s"] for d in ivs) / (n * dt)
        peak = max((d.get("peak") or 0.0 for d in ivs), default=0.0)
        fitted = (f"noise fit: quiet {sum(b - a for a, b in used) * dt:.4g} of {n * dt:.4g} s" if used
                  else "noise fit: the whole record, disturbance included")
        return [f"{name}: disturbed {100 * cover:.0f} % ({len(ivs)} interval{'s' if len(ivs) != 1 else ''}, peak "
                f"{peak:.2g}x); {fitted}"]
    if len(ivs) > MAX_LISTED:  # disturbed throughout: one line, the intervals are in the JSON
        kinds = {}
        for d in ivs:
            kinds[d["kind"]] = kinds.get(d["kind"], 0) + 1
        cover = sum(d["end_s"] - d["start_s"] for d in ivs) / (n * dt)
        top = max(ivs, key=lambda d: d.get("peak") or 0.0)
        head = (f"{name}: screen: disturbed throughout: {len(ivs)} intervals ("
                + ", ".join(f"{v} {k}{'s' if v > 1 else ''}" for k, v in kinds.items())
                + f") over {100 * cover:.0f} % of the record, peak {top.get('peak', 0):.2g}x the quiet level at "
                f"t = {top['start_s']:g}-{top['end_s']:g} s")
        used = screen.get("segments_used")
        if used and screen["mode"] == "auto" and len(used) > MAX_LISTED:  # one line: what disturbs it, what is fitted
            span = sum(b - a for a, b in used) * dt
            return [f"{head}; the noise fit uses the quiet {span:.4g} s of {n * dt:.4g} s ({len(used)} segments, "
                    "pooled without bridging a gap; each in the JSON's screen); --segments whole fits it all"] + \
                [f"{name}: left out {d['start_s']:g}-{d['end_s']:g} s too: below the detection threshold but "
                 f"{d['ratio']:.2g}x the level of the quietest segment (a disturbance's tail; not pooled with it)"
                 for d in screen.get("segments_dropped") or ()]
        out = [head + " (each in the JSON's screen)"]
    else:
        out = [f"{name}: screen: {line}" for line in screen["text"].splitlines()]
    used = screen.get("segments_used")
    if used:
        what = ("the quiet segment" if len(used) == 1 else "the quiet segments") if screen["mode"] == "auto" else \
            "the segments"
        if screen.get("frozen"):
            what = f"the healthy part (the frozen samples {screen['frozen'][0]}-{screen['frozen'][1] - 1} left out):"
        span = sum(b - a for a, b in used) * dt
        where = (", ".join(f"{a * dt:g}-{b * dt:g} s" for a, b in used) if len(used) <= MAX_LISTED else
                 f"({len(used)} of them, from {used[0][0] * dt:g} s to {used[-1][1] * dt:g} s; each in the JSON)")
        out.append(f"{name}: the noise fit uses {what} {where} ({span:g} s of {n * dt:g} s"
                   + (", pooled without bridging a gap" if len(used) > 1 else "") + "); --segments whole fits it all")
    elif not screen["stationary"]:
        out.append(f"{name}: the noise fit uses the whole record (--segments {screen['mode']}); its figures include "
                   "the disturbance")
    for d in screen.get("segments_dropped") or ():
        out.append(f"{name}: left out {d['start_s']:g}-{d['end_s']:g} s too: below the detection threshold but "
                   f"{d['ratio']:.2g}x the level of the quietest segment (a disturbance's tail; not pooled with it)")
    return out


def longest_segment(rate, segments):
    """The samples of the longest of ``segments`` (the whole ``rate`` for None): what a method that cannot pool
    segments (GMWM's wavelet variance here) fits on a disturbed record."""
    if not segments:
        return rate
    a, b = max(segments, key=lambda s: s[1] - s[0])
    return rate[a:b]
