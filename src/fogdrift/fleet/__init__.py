"""Fleets: one command over many logs on Dask, a Parquet summary and a fleet page (extra ``[fleet]``).

Production and acceptance labs characterise many gyros and sessions and compare them.  :func:`run_batch`
runs a command of :data:`COMMANDS` (``allan``, ``analyze``; GMWM ``noise`` is one row to add) over many
inputs, one Dask task per file:

* per file, a folder with what the single command writes (``allan.json``/``.csv``/``.png`` or
  ``report.html``/``analysis.json``) and ``batch.json`` (SHA-256 of the file and of the settings: a re-run
  skips unchanged files);
* ``summary.parquet``: one row per file x axis (:data:`fogdrift.fleet.summary.COLUMNS`), readable by
  DuckDB, pandas and pyarrow; a file that fails is a row with its error;
* ``fleet.html``: a control chart per coefficient across the files (:mod:`.page`).

Layout: :mod:`.commands` (the command table and the summary row of one axis), :mod:`.tasks` (one file),
:mod:`.runner` (inputs, Dask), :mod:`.summary` (the Parquet schema), :mod:`.page` (the HTML page).
The out-of-core Allan variance for single logs larger than memory is :mod:`fogdrift.allan.chunked`.
"""

from .commands import COMMANDS, CommandSpec, command_spec
from .runner import BatchOutputDir, BatchResult, find_inputs, run_batch, settings_sha256
from .summary import COLUMNS, read_summary, write_summary

__all__ = ["run_batch", "BatchResult", "BatchOutputDir", "find_inputs", "settings_sha256", "COMMANDS", "CommandSpec",
           "command_spec", "COLUMNS", "read_summary", "write_summary"]
