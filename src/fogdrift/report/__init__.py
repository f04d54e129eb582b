"""Render fogdrift results: tables (rows of strings with units), figures (matplotlib PNG), JSON/CSV files and
one self-contained HTML report (and its PDF).

This package only reads results produced by the library (:mod:`fogdrift.pipeline`); the library never imports
it.  Figures follow the reference paper's numbering (Tang et al. 2012): 1 signal, 2 spectrum, 3 Allan, 5 drift
and white noise, 6 Allan of the drift, 8 model against drift, 9 residual, 10–11 the same on a second recording.

* :mod:`.tables` -- rows of strings with units (noise coefficients, one-step metrics), shared with the console;
* :mod:`.figures` -- the PNG figures (every one saved by ``save_figure``; user text drawn literally by ``literal``);
* :mod:`.files` -- the per-command output files (strict JSON, CSV, NPZ), each written atomically;
* :mod:`.sections` -- the report's sections as a table (one render function + one row adds a section);
* :mod:`.html` -- ``report.html``, built from that table; :mod:`.pdf` -- ``report.pdf``;
* :mod:`.gmwm` -- ``fogdrift noise`` outputs and the GMWM report section; :mod:`.temperature` -- the rate and
  temperature figure.
"""

from .figures import (pyplot, _safe, save_figure, plot_allan, plot_models, plot_residuals, plot_separation,
                      plot_separation_allan, plot_signal, plot_spectrum)
from .files import write_allan_outputs, write_json, write_model_outputs, write_separation_outputs
from .tables import (METRICS_HEADERS, NOISE_HEADERS, b_headline, b_min_cell, shaped_cell, causal_metrics_rows, fit_cell, fit_summary, metrics_rows, noise_notes,
                     noise_row, not_estimable_notes, readout_text, term_text)

__all__ = [
    "NOISE_HEADERS",
    "METRICS_HEADERS",
    "noise_row",
    "term_text",
    "fit_summary",
    "fit_cell",
    "b_min_cell",
    "b_headline",
    "shaped_cell",
    "readout_text",
    "noise_notes",
    "not_estimable_notes",
    "metrics_rows",
    "causal_metrics_rows",
    "write_json",
    "write_allan_outputs",
    "write_separation_outputs",
    "write_model_outputs",
    "write_report",
    "plot_allan",
    "plot_signal",
    "plot_spectrum",
    "plot_separation",
    "plot_separation_allan",
    "plot_models",
    "plot_residuals",
]


def __getattr__(name):
    """``write_report`` is imported on first use: the HTML report's module brings the evaluation verdicts, the model
    registry and the report's sections, which the per-command outputs (``allan``, ``noise``) never use."""
    if name == "write_report":
        from .html import write_report

        return write_report
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
