"""Files of the per-command outputs: strict JSON, CSV tables and curves, NPZ series, each written atomically."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

from .._util import RawJson, strict_json
from ..allan.result import ARRAY_FIELDS
from ..models import save_model
from ..noise import TERM_TABLE
from ..output import atomic_path
from ..units import INTERNAL_UNITS
from .figures import _safe, plot_allan, plot_dynamic_adev, plot_models, plot_residuals, plot_separation, plot_separation_allan

__all__ = ["write_json", "allan_document", "allan_csv_rows", "write_allan_outputs", "write_separation_outputs",
           "write_model_outputs"]


def write_json(obj, path, *, indent: int | None = 2, sort_keys: bool = False) -> Path:
    """Write :func:`fogdrift._util.strict_json` of ``obj`` (NaN and infinity as null) to ``path`` atomically
    (complete or absent, :func:`fogdrift.output.atomic_path`): the one JSON writer of the result files."""
    path = Path(path)
    text = strict_json(obj, indent=indent, sort_keys=sort_keys)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def _noise_csv_rows(label, aa):
    cells = []
    for name in TERM_TABLE:
        t = aa.noise.terms[name]
        cells += [t.value, t.lo95, t.hi95]
    return [label] + ["" if c is None else repr(float(c)) for c in cells]


def _noise_csv_header():

    head = ["signal"]
    for name, spec in TERM_TABLE.items():
        head += [f"{name}{spec.suffix}", f"{name}_lo95{spec.suffix}", f"{name}_hi95{spec.suffix}"]
    return head


def _write_rows_csv(path, header, rows) -> Path:
    path = Path(path)
    with atomic_path(path) as tmp, open(tmp, "w") as fh:
        fh.write(",".join(header) + "\n")
        fh.writelines([",".join(map(str, row)) + "\n" for row in rows])
    return path


def allan_document(allan_axes, record) -> dict:
    """The ``allan.json`` document of a record's Allan analysis: ``source``, ``record`` (its metadata) and ``axes``
    (each axis's ``to_dict()``), before the strict-JSON writing (:func:`write_json`)."""
    return {"source": record.source, "record": record.metadata(), "axes": [a.to_dict() for a in allan_axes]}


#: The float columns of ``allan.csv`` and ``allan.json``, as :class:`~fogdrift.allan.AllanResult` fields.
_FLOAT_FIELDS = ("tau_s", "dev", "var", "edf", "dev_lo68", "dev_hi68", "dev_lo95", "dev_hi95")
#: ``repr`` of the non-finite floats.
_NON_FINITE = frozenset({"nan", "inf", "-inf"})


def _float_texts(allan) -> dict:
    """``repr`` of every value of each float column (field -> list of texts): what ``allan.csv`` writes and, finite,
    what JSON writes (``float.__repr__``); made once for both files (25 000 taus: 0.09 s a file)."""
    return {f: list(map(repr, np.asarray(getattr(allan, f), dtype=np.float64).tolist())) for f in _FLOAT_FIELDS}


def allan_csv_rows(allan_axes, texts=None) -> list:
    """The rows of ``allan.csv`` (axis, tau_s, m, dev, var, n_terms, edf, lo68, hi68, lo95, hi95), one per tau of
    every axis (a tuple of texts): each float as ``repr`` of its Python float, each integer as its Python int's text.
    ``texts``: :func:`_float_texts` of each axis, made already."""
    rows = []
    for i, a in enumerate(allan_axes):
        r = a.allan
        t = _float_texts(r) if texts is None else texts[i]
        # column by column (one C loop each), not one numpy scalar per cell
        m, n_terms = (list(map(str, np.asarray(c).astype(np.int64).tolist())) for c in (r.m, r.n_terms))
        rows += zip(itertools.repeat(a.name, r.tau_s.size), t["tau_s"], m, t["dev"], t["var"], n_terms,
                    t["edf"], t["dev_lo68"], t["dev_hi68"], t["dev_lo95"], t["dev_hi95"])
    return rows


def _with_encoded_floats(axis_doc: dict, allan, quantity: str, texts: dict) -> None:
    """In one axis's ``allan.json`` entry, each float column that is the list of ``allan``'s values becomes its JSON
    text, made from ``texts`` (``repr``, infinities as null): the same bytes as :func:`fogdrift._util.strict_json`
    writes for the list.  A column that is not that list (one with a NaN: NaN never equals itself) stays a list."""
    cols = axis_doc.get("allan") if isinstance(axis_doc, dict) else None
    if not isinstance(cols, dict):
        return
    for field, key in zip(ARRAY_FIELDS, allan.column_names(quantity)):
        vals = cols.get(key)
        if field not in texts or not isinstance(vals, list) or not vals:
            continue
        if vals != np.asarray(getattr(allan, field), dtype=np.float64).tolist():
            continue
        text = ", ".join(texts[field])
        if "n" in text:  # an infinity ("inf", "-inf"; a finite repr has no "n"): strict JSON writes null
            text = ", ".join("null" if v in _NON_FINITE else v for v in texts[field])
        cols[key] = RawJson("[" + text + "]")


def write_allan_outputs(allan_axes, record, out_dir) -> dict:
    """``allan.json`` (:func:`allan_document`), ``allan.csv`` (curve of every axis, with units) and ``allan.png``."""
    out = Path(out_dir)
    texts = [_float_texts(a.allan) for a in allan_axes]
    doc = allan_document(allan_axes, record)
    for a, axis_doc, t in zip(allan_axes, doc["axes"], texts):
        _with_encoded_floats(axis_doc, a.allan, getattr(a.noise, "quantity", "angular_rate"), t)
    write_json(doc, out / "allan.json")
    rows = allan_csv_rows(allan_axes, texts)
    quantities = set(getattr(record, "quantities", ("angular_rate",)))
    mixed = len(quantities) != 1
    if not mixed:  # the curve's unit in the column names (allan.json's keys: AllanResult.column_names)
        names = allan_axes[0].allan.column_names(next(iter(quantities)))
    else:  # gyro and accelerometer axes: each row says its unit
        names = tuple(c.replace("_dph2", "_internal2").replace("_dph", "_internal")
                      for c in allan_axes[0].allan.column_names())
        units = {n: INTERNAL_UNITS[q] for n, q in zip(record.axis_names, record.quantities)}
        rows = [row + (units[row[0]],) for row in rows]
    tau, m, var, dev, lo68, hi68, lo95, hi95 = names[:8]
    _write_rows_csv(out / "allan.csv", ["axis", tau, m, dev, var, "n_terms", "edf", lo68, hi68, lo95, hi95]
                    + (["unit"] if mixed else []), rows)
    plot_allan(allan_axes, out / "allan.png")
    files = {"json": out / "allan.json", "csv": out / "allan.csv", "png": out / "allan.png"}
    dyn = plot_dynamic_adev(allan_axes, out / "allan_dynamic.png")  # a disturbed axis's ADEV over time
    if dyn is not None:
        files["dynamic_png"] = dyn
    return files


def write_separation_outputs(seps, out_dir) -> dict:
    """Drift and noise series (CSV and NPZ), Fig. 5 and 6 per axis, the Q..R table (JSON and CSV)."""
    out = Path(out_dir)
    arrays = {}
    for s in seps:
        arrays[f"{s.name}_input_dph"] = s.rate_dph
        arrays[f"{s.name}_drift_dph"] = s.drift_dph
        arrays[f"{s.name}_noise_dph"] = s.noise_dph
    with atomic_path(out / "separation.npz") as tmp:
        np.savez(tmp, dt_s=np.array(seps[0].dt_s), **arrays)
    n = seps[0].rate_dph.size
    cols = ["t_s"] + list(arrays)
    data = np.column_stack([np.arange(n) * seps[0].dt_s] + [arrays[c] for c in cols[1:]])
    with atomic_path(out / "separation.csv") as tmp:
        np.savetxt(tmp, data, delimiter=",", header=",".join(cols), comments="", fmt="%.10g")
    rows = [_noise_csv_rows(f"{s.name}:{label}", aa) for s in seps for label, aa in s.rows]
    _write_rows_csv(out / "separation_table.csv", _noise_csv_header(), rows)
    write_json({"axes": [s.to_dict() for s in seps]}, out / "separation.json")
    files = {}
    for s in seps:
        files[f"fig5_{s.name}"] = plot_separation(s, out / f"fig5_drift_noise_{_safe(s.name)}.png")
        files[f"fig6_{s.name}"] = plot_separation_allan(s, out / f"fig6_allan_{_safe(s.name)}.png")
    return files


def write_model_outputs(model_axes, out_dir) -> dict:
    """Saved models (JSON + NPZ), metrics JSON, Fig. 8 and 9 per axis."""
    out = Path(out_dir)
    for ma in model_axes:
        for label, model in ma.fitted.items():
            safe = label.replace("(", "").replace(")", "").replace(",", "").replace(" ", "_").lower()
            save_model(model, out / "models" / f"{_safe(ma.name)}_{_safe(safe)}")
        plot_models(ma, out / f"fig8_models_{_safe(ma.name)}.png")
        plot_residuals(ma, out / f"fig9_residual_{_safe(ma.name)}.png")
    write_json({"axes": [ma.to_dict() for ma in model_axes]}, out / "metrics.json")
    return {"dir": out}


