"""The report's sections as a table: adding a section is one module with a ``render`` function and one row here.

:func:`fogdrift.report.html.render_report` reads :data:`SECTIONS` in order: the ``recording`` rows build the
"Recording" section (once per report), the ``axis`` rows build each axis's section (once per axis, for the fitted
recording and for the ``apply_to`` one).  A row names its function by module and name (imported when the report
is drawn, as the model registry loads a model), so a section module may use anything in :mod:`fogdrift.report`
without an import cycle.

The contract of a render function (``""`` when the section does not apply, e.g. no temperature in the log):

* ``recording``: ``render(result, record, fig_dir) -> str`` (HTML);
* ``axis``: ``render(ax, result, fig_dir, pre, fig_offset, evaluated) -> str`` (HTML), with ``ax`` one
  :class:`fogdrift.pipeline.AnalysisAxis`, ``pre`` the prefix of ids and figure files (``""`` or
  ``"apply_to_"``), ``fig_offset`` the figure-number offset, ``evaluated`` False after ``analyze --no-heading``.

Figures are written under ``fig_dir`` (PNG, embedded as base64 by :func:`fogdrift.report.html._img`); every label
made from user text goes through :func:`fogdrift.report.figures.literal`.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

from ..errors import ConfigError

__all__ = ["Section", "SECTIONS", "sections"]

SCOPES = ("recording", "axis")


@dataclass(frozen=True)
class Section:
    """One row of the report's section table.

    Attributes
    ----------
    key : str
        Stable name of the section.
    scope : {"recording", "axis"}
        Once per report (inside "Recording") or once per axis.
    module, function : str
        Dotted module and name of the render function (contract in the module docstring).
    description : str
        What the section shows, in words.
    """

    key: str
    scope: str
    module: str
    function: str
    description: str

    def render(self, *args) -> str:
        """Call the section's render function (its module is imported on first use)."""
        return getattr(importlib.import_module(self.module), self.function)(*args)


#: The report's sections in page order.
SECTIONS: tuple[Section, ...] = (
    Section("signal", "recording", "fogdrift.report.html", "signal_block",
            "Fig. 1: the gyro output of every axis with the train / validation / test split"),
    Section("spectrum", "recording", "fogdrift.report.html", "spectrum_block", "Fig. 2: the output's spectrum"),
    Section("temperature", "recording", "fogdrift.report.html", "temperature_block",
            "rate and temperature against time, with the temperature's range and drift (logs with a temperature)"),
    Section("gmwm", "axis", "fogdrift.report.gmwm", "gmwm_axis_block",
            "the GMWM noise table (analyze --noise-method gmwm), first"),
    Section("noise", "axis", "fogdrift.report.html", "noise_block",
            "the Allan-fit noise table, its notes and slope read-outs, Fig. 3"),
    Section("separation", "axis", "fogdrift.report.html", "separation_block",
            "drift / noise separation of the whole record, Figs. 5 and 6"),
    Section("compensation", "axis", "fogdrift.report.html", "compensation_block",
            "heading error, artefact check, causal skill, the paper's measure and Table 2"),
)


def sections(scope: str) -> tuple[Section, ...]:
    """The rows of one scope, in page order.

    Examples
    --------
    >>> [s.key for s in sections("recording")]
    ['signal', 'spectrum', 'temperature']
    """
    if scope not in SCOPES:
        raise ConfigError(f"report section scope must be one of {list(SCOPES)}; got {scope!r}")
    return tuple(s for s in SECTIONS if s.scope == scope)
