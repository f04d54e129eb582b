"""Files ``fogdrift compensate`` writes, streamed: the compensated log (CSV and NPZ), the Allan accumulators
behind the before/after figure, and the figure itself.

Output unit: the log's own unit (so the files are drop-in replacements of the input), declared in the CSV
header (``gz[deg/s]``, readable by :func:`fogdrift.io.load`) and in the NPZ (``unit``).  Columns / arrays:
time ``t_s``, the compensated rate per axis, the subtracted drift estimate per axis (``<axis>_drift``), and for
a Kalman model its 1-sigma (``<axis>_drift_sigma``).  The NPZ is written without holding the arrays: each array
goes to a temporary ``.npy`` (header first, rows appended) and the archive is assembled at the end.

Every file is written through the shared atomic output edge (:func:`fogdrift.output.atomic_path`, recorded in the
output folder's manifest): an error or a Ctrl-C leaves no partial file under a final name.
"""

from __future__ import annotations

import contextlib
import math
import os
import zipfile
from pathlib import Path

import numpy as np

from ..output import TMP_PREFIX
from ..report.figures import pyplot, save_figure, literal

__all__ = ["CsvWriter", "NpzWriter", "AllanAccumulator", "plot_before_after"]


class CsvWriter:
    """Append rows to ``path``: header ``t_s,<axes>[unit],<axes>_drift[unit](,<axes>_drift_sigma[unit])``.

    ``path`` is the temporary name :func:`fogdrift.output.atomic_path` gives (the caller renames it when the whole
    log is written, or the edge removes it): the final name never holds a partial CSV.
    """

    def __init__(self, path, axis_names, unit, with_sigma):
        self.path = Path(path)
        self._fh = open(self.path, "w")
        cols = ["t_s"] + [f"{a}[{unit}]" for a in axis_names] + [f"{a}_drift[{unit}]" for a in axis_names]
        if with_sigma:
            cols += [f"{a}_drift_sigma[{unit}]" for a in axis_names]
        self._fh.write(",".join(cols) + "\n")

    def write(self, t, comp, drift, sigma):
        parts = [t[:, None], comp, drift] + ([sigma] if sigma is not None else [])
        np.savetxt(self._fh, np.hstack(parts), delimiter=",", fmt="%.12g")

    def close(self):
        self._fh.close()

    abort = close


class NpzWriter:
    """An ``.npz`` of known shapes written row block by row block (see the module docstring).

    ``path`` is the temporary name of the archive (:func:`fogdrift.output.atomic_path`); each array goes to a
    temporary ``.npy`` beside it, named ``.fogdrift-tmp-<pid>-...`` (:data:`fogdrift.output.TMP_PREFIX`, so a
    killed run's leftovers are removed by the next run in the folder), and :meth:`abort` removes them.
    """

    def __init__(self, path, n_samples, axis_names, unit, scale_to_dph, with_sigma):
        self.path = Path(path)
        k = len(axis_names)
        shapes = {"t_s": (n_samples,), "compensated": (n_samples, k), "drift_estimate": (n_samples, k)}
        if with_sigma:
            shapes["drift_sigma"] = (n_samples, k)
        stem = self.path.name
        if not stem.startswith(TMP_PREFIX):
            stem = f"{TMP_PREFIX}{os.getpid()}-{stem}"
        self._paths = {name: self.path.with_name(f"{stem}.{name}.npy") for name in shapes}
        self._files = {}
        try:
            for name, shape in shapes.items():
                fh = open(self._paths[name], "wb")
                self._files[name] = fh
                np.lib.format.write_array_header_2_0(fh, {"descr": "<f8", "fortran_order": False, "shape": shape})
        except BaseException:
            self.abort()
            raise
        self._small = {"axis_names": np.array(list(axis_names)), "unit": np.array(unit),
                       "scale_to_dph": np.array(float(scale_to_dph))}
        self.n = 0
        self.n_samples = n_samples

    def write(self, t, comp, drift, sigma):
        arrays = {"t_s": t, "compensated": comp, "drift_estimate": drift}
        if sigma is not None:
            arrays["drift_sigma"] = sigma
        for name, a in arrays.items():
            self._files[name].write(np.ascontiguousarray(a, dtype="<f8").tobytes())
        self.n += t.shape[0]

    def abort(self):
        """Close and remove the temporary member files (after an error or an interruption)."""
        for fh in self._files.values():
            fh.close()
        for p in self._paths.values():
            with contextlib.suppress(OSError):
                os.remove(p)

    def close(self):
        """Assemble the archive at ``path`` from the member files (removed afterwards, also on failure)."""
        try:
            for fh in self._files.values():
                fh.close()
            if self.n != self.n_samples:  # pragma: no cover - the engine emits every sample once
                raise RuntimeError(f"NPZ writer got {self.n} rows, expected {self.n_samples}")
            with zipfile.ZipFile(self.path, "w", compression=zipfile.ZIP_STORED, allowZip64=True) as zf:
                for name in self._files:
                    zf.write(self._paths[name], arcname=name + ".npy")
                for name, a in self._small.items():
                    with zf.open(name + ".npy", "w") as fh:
                        np.lib.format.write_array(fh, a, allow_pickle=False)
        finally:
            self.abort()


class AllanAccumulator:
    """Block sums of the raw and compensated rate for the before/after Allan analysis, in bounded memory.

    Records of up to ``max_points`` samples are kept at the native rate; longer ones are block-averaged by
    ``f = ceil(n / max_points)`` (the Allan variance at tau >= f dt is then computed from these averages,
    exactly for the non-overlapping part of the estimator).
    """

    def __init__(self, n_samples, n_axes, max_points=1 << 22):
        self.f = max(1, math.ceil(n_samples / max_points))
        self._carry = [np.empty((0, n_axes)), np.empty((0, n_axes))]
        self._out = [[], []]

    def add(self, before, after):
        for i, x in enumerate((before, after)):
            x = np.concatenate([self._carry[i], x])
            nb = x.shape[0] // self.f
            self._out[i].append(x[: nb * self.f].reshape(nb, self.f, x.shape[1]).mean(axis=1))  # nb may be 0
            self._carry[i] = x[nb * self.f:]

    def series(self, start: int = 0):
        """(before, after) block series from native sample ``start`` on (rounded up to a whole block)."""
        k0 = -(-int(start) // self.f)
        return tuple(np.concatenate(o)[k0:] for o in self._out)


def plot_before_after(curves, path, title, caveats: dict | None = None) -> Path:
    """ADEV of the log before and after compensation, one panel per axis.

    ``curves``: list of ``(axis, AllanResult before, AllanResult after, label)``.  ``caveats``: axis -> the
    artefact check's sentence (:func:`~fogdrift.evaluation.verdicts.adev_caveat`), printed under that axis's
    panel (red when the lower ADEV is not evidence): a causal drift subtraction lowers the long-τ ADEV of any
    static log, so the curves alone are not evidence.
    """
    import textwrap

    plt = pyplot()  # matplotlib stays lazy (Agg backend), as for every figure of the package
    n = len(curves)
    fig, axs = plt.subplots(1, n, figsize=(5.2 * n, 4.2), squeeze=False)
    for ax, (name, before, after, label) in zip(axs[0], curves):
        positive = False
        for r, color, text in ((before, "k", "log (bias removed)"), (after, "C3", f"compensated: {literal(label)}")):
            ok = np.asarray(r.adev_dph) > 0  # a log scale shows positive ADEVs only (a constant log has none)
            positive = positive or bool(ok.any())
            yerr = np.vstack([r.adev_dph - r.adev_lo68_dph, r.adev_hi68_dph - r.adev_dph])[:, ok]
            ax.errorbar(r.tau_s[ok], r.adev_dph[ok], yerr=yerr, fmt="o-", ms=3, lw=0.8, color=color, label=text)
        ax.set_xscale("log")
        ax.set_yscale("log" if positive else "linear")
        ax.set_xlabel("τ [s]")
        ax.set_ylabel("σ(τ) [deg/h]")
        ax.set_title(literal(f"{title}: {name}"))  # a column name is user text, never mathtext
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        text = (caveats or {}).get(name)
        if text:
            ax.text(0.0, -0.17, literal(textwrap.fill(text, width=80)), transform=ax.transAxes, ha="left", va="top",
                    fontsize=7, color="C3" if "not evidence" in text or "not checked" in text else "k")
    return save_figure(fig, path, dpi=110, bbox_inches="tight")  # atomic, and the figure closed whatever happens
