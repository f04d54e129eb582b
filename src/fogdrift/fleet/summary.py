"""The fleet summary table: its columns as data, and ``summary.parquet`` written and read with pyarrow.

One row per file x axis (a file that failed is one row with ``status = "error"`` and its message).  The
schema is fixed (every column present, nullable) so that DuckDB and pandas see the same columns whether a
batch succeeded, partly failed or was cached::

    duckdb -c "SELECT file, axis, N_dprh, N_lo95_dprh, N_hi95_dprh FROM 'out/summary.parquet' WHERE status <> 'error'"

The file is written through :func:`fogdrift.output.atomic_path`: complete or absent.
"""

from __future__ import annotations

from pathlib import Path

from ..io.readers.base import require
from ..output import atomic_path
from ..noise.terms import ACCEL_TERM_TABLE
from .commands import TERMS

#: The accelerometer's coefficients, with the unit suffix of their columns (``("Q", "mps"), ("N", "mps_rh"),
#: ("B", "ug"), ("K", "mps2_rh"), ("R", "mps2_ph")``): an accelerometer row fills these, a gyro row the
#: :data:`TERMS` columns; the ``{name}_status`` column is shared (:func:`fogdrift.fleet.tasks.split_by_quantity`).
ACCEL_TERMS = tuple((name, spec.suffix.lstrip("_")) for name, spec in ACCEL_TERM_TABLE.items())

__all__ = ["ACCEL_TERMS", "COLUMNS", "SPEC_ITEMS", "UNITS", "write_summary", "read_summary", "schema", "spec_counts",
           "spec_count_lines"]

#: The datasheet items a batch row can be judged on (``--spec``; :data:`fogdrift.spec.ITEMS`, each item once: the
#: gyro's and the accelerometer's bias instability share ``spec_bias_instability``, told apart by ``quantity``).
SPEC_ITEMS = ("arw", "vrw", "bias_instability")

#: The three verdicts of :func:`fogdrift.spec.judge`, in the order they are counted.
SPEC_VERDICTS = ("pass", "fail", "cannot tell")

#: (column, type, unit or meaning).  Types: str, int, float, bool.
COLUMNS: tuple = (
    ("file", "str", "input path relative to the batch's common folder"),
    ("path", "str", "absolute input path"),
    ("sha256", "str", "SHA-256 of the input file (of its files, for a ROS 2 bag directory)"),
    ("command", "str", "batch command"),
    ("axis", "str", "axis name (null when the file failed before its axes were known)"),
    ("status", "str", "ok, cached (unchanged file and settings: not recomputed) or error"),
    ("error", "str", "the error message when status is error"),
    ("warnings", "str", "warnings raised while processing, '; '-separated"),
    ("out_dir", "str", "folder of the file's outputs, relative to the batch folder"),
    ("n_samples", "int", "samples analysed"),
    ("duration_s", "float", "s"),
    ("rate_hz", "float", "Hz, sample rate analysed"),
    ("input_unit", "str", "unit of the input numbers"),
    ("t0_s", "float", "s, time of the first sample"),
    ("temperature_min_c", "float", "deg C"),
    ("temperature_max_c", "float", "deg C"),
    ("temperature_range_c", "float", "deg C"),
    ("temperature_change_c", "float", "deg C, end minus start of the log"),
    ("temperature_slope_c_per_h", "float", "deg C/h, least-squares slope"),
    ("quantity", "str", "what the axis measures, from its unit: angular_rate (gyro: the deg/h-based columns) or "
                        "specific_force (accelerometer: the m/s-based columns)"),
    ("statistic", "str", "Allan-family statistic of the noise fit: adev, hdev or mdev"),
    *[c for name, unit in TERMS for c in (
        (f"{name}_{unit}", "float", f"{name} estimate (null when not in the selected model)"),
        (f"{name}_lo95_{unit}", "float", f"{name} 95 % lower bound"),
        (f"{name}_hi95_{unit}", "float", f"{name} 95 % upper bound (for an absent term: its upper bound)"),
        (f"{name}_status", "str", f"{name}: resolved, unresolved, absent or not_estimable"),
    )],
    *[c for name, unit in ACCEL_TERMS for c in (
        (f"{name}_{unit}", "float", f"accelerometer {ACCEL_TERM_TABLE[name].long_name} {name} "
                                    f"[{ACCEL_TERM_TABLE[name].unit}] (null when not in the selected model)"),
        (f"{name}_lo95_{unit}", "float", f"accelerometer {name} 95 % lower bound [{ACCEL_TERM_TABLE[name].unit}]"),
        (f"{name}_hi95_{unit}", "float", f"accelerometer {name} 95 % upper bound [{ACCEL_TERM_TABLE[name].unit}]"),
    )],
    ("noise_model", "str", "selected noise model, e.g. N+B+K"),
    ("plausible_models", "str", "models within the selection window of the best, '; '-separated"),
    ("fit_quality", "str", "good, acceptable or poor"),
    ("fit_chi2_red", "float", "reduced chi-squared of the noise fit"),
    ("fit_dof", "int", "degrees of freedom of the noise fit"),
    ("fit_p_value", "float", "p-value of the noise fit's chi-squared"),
    ("fit_n_points", "int", "taus in the noise fit"),
    ("fit_tau_min_s", "float", "s"),
    ("fit_tau_max_s", "float", "s"),
    ("b_min_dph", "float", "deg/h, bias instability read at the minimum of the fitted ADEV (IEEE-952 practice)"),
    ("b_min_ug", "float", "ug, an accelerometer's bias instability read at the minimum of the fitted ADEV"),
    ("b_min_tau_s", "float", "s, tau of that minimum"),
    ("b_min_bound_only", "bool", "true when the fitted ADEV still falls at the longest tau (b_min is a bound)"),
    ("outliers", "int", "samples beyond the outlier threshold"),
    ("verdict", "str", "analyze: paper's measure (one step ahead, target = non-causal wavelet drift; not a "
                       "compensation result): which drift model beat persistence on the test block"),
    ("compensation_outcome", "str", "analyze: headline of the heading-error evaluation (evaluation.verdicts.judge: "
                                    ">= 5 % lower RMS AND better at most non-overlapping origins): reduces, mixed, "
                                    "none or undetermined"),
    ("compensation_headline", "str", "analyze: the headline verdict sentence"),
    *[c for item in SPEC_ITEMS for c in (
        (f"spec_{item}", "str", f"--spec: the {item} datasheet limit of the axis's section (gyro or accel): pass, "
                                "fail or cannot tell, judged with the 95 % interval (null: no such limit)"),
        (f"spec_{item}_why", "str", f"--spec: why spec_{item} is what it is"),
    )],
    ("wall_s", "float", "s, processing time of the file (0 when cached)"),
    ("settings_sha256", "str", "SHA-256 of the command and its settings (re-runs skip unchanged files)"),
)

#: Unit (or meaning) of every column.
UNITS = {name: unit for name, _, unit in COLUMNS}


def schema():
    """The pyarrow schema of :data:`COLUMNS` (every column nullable)."""
    pa = require("pyarrow", "fleet", "writing the batch summary (Parquet)")
    types = {"str": pa.string(), "int": pa.int64(), "float": pa.float64(), "bool": pa.bool_()}
    return pa.schema([pa.field(name, types[kind], nullable=True, metadata={"unit": unit})
                      for name, kind, unit in COLUMNS])


def write_summary(rows: list[dict], path) -> Path:
    """Write rows (dicts; missing keys are null, unknown keys are an error) as a Parquet file.

    Raises
    ------
    KeyError
        A row has a key that is not a column (a bug in a command's row function).
    """
    pa = require("pyarrow", "fleet", "writing the batch summary (Parquet)")
    pq = require("pyarrow.parquet", "fleet", "writing the batch summary (Parquet)")
    sch = schema()
    names = set(sch.names)
    for row in rows:
        extra = set(row) - names
        if extra:
            raise KeyError(f"summary row has unknown columns {sorted(extra)}")
    table = pa.Table.from_pylist([{n: row.get(n) for n in sch.names} for row in rows], schema=sch)
    path = Path(path)
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return path


def read_summary(path) -> list[dict]:
    """Rows of a ``summary.parquet`` as dicts (pyarrow, no pandas needed)."""
    pq = require("pyarrow.parquet", "fleet", "reading the batch summary (Parquet)")
    return pq.read_table(Path(path)).to_pylist()


def spec_counts(rows) -> dict:
    """``(kind, item)`` -> ``{"pass": n, "fail": n, "cannot tell": n}`` over the rows' ``spec_<item>`` columns, kind
    ``gyro`` or ``accel`` from the row's ``quantity`` (error rows and rows without a verdict are not counted).

    Examples
    --------
    >>> spec_counts([{"quantity": "angular_rate", "spec_arw": "pass"},
    ...              {"quantity": "specific_force", "spec_vrw": "fail", "spec_bias_instability": "cannot tell"}])
    {('gyro', 'arw'): {'pass': 1, 'fail': 0, 'cannot tell': 0}, ('accel', 'vrw'): {'pass': 0, 'fail': 1, \
'cannot tell': 0}, ('accel', 'bias_instability'): {'pass': 0, 'fail': 0, 'cannot tell': 1}}
    """
    out: dict = {}
    for row in rows:
        if row.get("status") == "error":
            continue
        kind = "accel" if row.get("quantity") == "specific_force" else "gyro"
        for item in SPEC_ITEMS:
            verdict = row.get(f"spec_{item}")
            if verdict is None:
                continue
            counts = out.setdefault((kind, item), dict.fromkeys(SPEC_VERDICTS, 0))
            counts[verdict] = counts.get(verdict, 0) + 1
    return out


def spec_count_lines(rows) -> list[str]:
    """One line per judged ``kind item`` for the batch's console summary: ``gyro arw: 3 pass, 0 fail, 0 cannot tell
    (of 3 axes)``; empty when no row was judged."""
    lines = []
    for (kind, item), c in spec_counts(rows).items():
        n = sum(c.values())
        lines.append(f"{kind} {item}: " + ", ".join(f"{c.get(v, 0)} {v}" for v in SPEC_VERDICTS)
                     + f" (of {n} ax{'is' if n == 1 else 'es'})")
    return lines
