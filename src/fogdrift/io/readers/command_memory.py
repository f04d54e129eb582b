"""The memory a command needs for a record, estimated before its work and held to the memory budget.

A command's peak resident memory grows with the record: the float64 table (8 bytes per sample and axis) and the
command's full-length working arrays beside it, on top of a fixed part (the interpreter and the libraries).  The
estimate is

    need = FIXED_BYTES + n_samples x n_axes x COMMAND_BYTES_PER_SAMPLE[command]

with the constants measured (peak RSS by ``/usr/bin/time -v``) on one-axis float32 ``.npy`` logs of 10^6 to
10^8 samples: ``bench/RESULTS.md``, section "Memory of every command at 10^8 samples (issue
36)".  A record of several axes is counted once per axis (conservative: the per-axis working arrays of one axis
are freed before the next).  The workflows call :func:`check_records_memory` before any work; a need above the
budget of :mod:`fogdrift.io.readers.limits` (``FOGDRIFT_MAX_MEMORY``, default half the machine's memory) is
refused in one line naming the need, the budget and the variable that raises it.
"""

from __future__ import annotations

from ...errors import ConfigError, ResourceLimitError
from .limits import ENV_MEMORY, format_bytes, memory_budget

__all__ = ["FIXED_BYTES", "COMMAND_BYTES_PER_SAMPLE", "command_memory_need", "check_command_memory",
           "check_records_memory"]

#: The fixed part [bytes]: the interpreter and the libraries (277-342 MB peak RSS at 10^6 samples), raised to the
#: upper envelope just below 2^24 samples, where the Allan sums still go through an in-memory angle array
#: (:data:`fogdrift.allan.sums.CHUNKED_MIN_SAMPLES`; ``noise`` 757 MB at 1.6 x 10^7 samples), so that the estimate
#: is above every measured peak (10^6, 10^7, 1.6 x 10^7, 10^8 samples).
FIXED_BYTES = 600_000_000

#: Peak bytes per sample and axis, per command: (peak RSS at 10^8 - at 10^6 samples) / (10^8 - 10^6), rounded up to
#: half a byte (``bench/RESULTS.md`` "Memory of every command at 10^8 samples"; the float64 record is 8
#: of them).  ``export LOG`` takes the ``allan`` row (:func:`fogdrift.pipeline.run_allan`); ``consistency`` counts
#: the samples of the training log and of every held-out log (two records in memory at once).
COMMAND_BYTES_PER_SAMPLE: dict[str, float] = {
    "allan": 11.5,       # 11.42 measured
    "separate": 11.0,    # 10.94
    "model": 12.0,       # 11.60
    "noise": 12.0,       # 11.65
    "analyze": 11.5,     # 11.07 (--models persistence,ar --no-heading)
    "consistency": 12.5,  # 12.15 per counted sample (10^8 training + 10^8 held-out)
}


def command_memory_need(command: str, n_samples: int, n_axes: int = 1) -> int:
    """Bytes ``command`` needs at its peak for a record of ``n_samples`` x ``n_axes`` (the module's estimate).

    Examples
    --------
    >>> command_memory_need("allan", 10**8) > command_memory_need("allan", 10**7) > FIXED_BYTES
    True
    """
    try:
        per = COMMAND_BYTES_PER_SAMPLE[command]
    except KeyError:
        raise ConfigError(f"no memory estimate for command {command!r}; expected one of "
                          f"{sorted(COMMAND_BYTES_PER_SAMPLE)}") from None
    return int(FIXED_BYTES + max(int(n_samples), 0) * max(int(n_axes), 1) * per)


def check_command_memory(command: str, n_samples: int, n_axes: int = 1, path=None) -> None:
    """ResourceLimitError if ``command`` on ``n_samples`` x ``n_axes`` needs more than the memory budget
    (``FOGDRIFT_MAX_MEMORY``); called before the command's work, so nothing is computed or written."""
    budget = memory_budget()
    need = command_memory_need(command, n_samples, n_axes)
    if budget is not None and need > budget:
        axes = f"{int(n_axes)} ax{'is' if int(n_axes) == 1 else 'es'}"
        raise ResourceLimitError(
            f"fogdrift {command} on {int(n_samples)} samples x {axes} needs about {format_bytes(need)} of memory "
            f"({format_bytes(FIXED_BYTES)} + {COMMAND_BYTES_PER_SAMPLE[command]:g} bytes per sample and axis); "
            f"expected at most the memory budget {format_bytes(budget)} ({ENV_MEMORY}); refused before any work; "
            f"raise it with the environment variable {ENV_MEMORY} (0: no limit) if the machine has the memory",
            limit=ENV_MEMORY, path=path)


def check_records_memory(command: str, *records) -> None:
    """:func:`check_command_memory` for records already read (GyroRecords; None skipped): their samples added,
    counted at the most axes among them (``consistency``: the training log and its held-out logs)."""
    recs = [r for r in records if r is not None]
    if recs:
        check_command_memory(command, sum(int(r.n_samples) for r in recs), max(int(r.n_axes) for r in recs),
                             getattr(recs[0], "source", None))
