"""What a command says before its fit: the plausibility findings and the record screen of each axis."""

from __future__ import annotations

from pathlib import Path

from ._app import FLAGS, say, warn

__all__ = ["print_screen"]

def print_screen(record, findings, screens, gmwm=None, compact=False) -> None:
    """Print what a workflow found before its fit: each plausibility finding as a warning (one line each), then
    each axis's record screen (what disturbs it, where, what the fit uses).  ``gmwm``: the segment plan, to say
    that GMWM fits the longest segment."""
    from ..segments import segment_lines

    for finding in findings:
        warn(f"{Path(str(record.source)).name}: {finding.render(FLAGS)}")
    for name in record.axis_names:
        for line in segment_lines(name, screens[name], compact=compact):
            if gmwm is not None and gmwm[name] and line.endswith("fits it all") and len(gmwm[name]) > 1:
                line += "; GMWM: the longest of them"
            say(f"  {line}", style=None if screens[name]["stationary"] else "yellow")
