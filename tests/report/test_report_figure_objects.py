"""The report figures are drawn through matplotlib's object API (``report.figures.subplots``: a Figure on the Agg
canvas) without importing pyplot, and their layout pass (``report.figures._place``) works out each axis's ticks
once while it measures.  Neither may change a pixel: the PNG is the one pyplot and matplotlib's own tick updates
give.
"""

from __future__ import annotations

import contextlib
import io
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

import fogdrift  # noqa: E402
from fogdrift.report import figures  # noqa: E402


def _draw(fig, axs) -> bytes:
    """A log-log grid with long labels, a legend and a suptitle, placed by ``_place``; the PNG's bytes."""
    x = np.logspace(-2, 3, 60)
    for k, ax in enumerate(np.ravel(axs)):
        ax.errorbar(x, 10 ** (k + 1) / np.sqrt(x), yerr=0.1 / np.sqrt(x), fmt="o", ms=3, label="deviation")
        ax.loglog(x, 10 ** (k + 1) / np.sqrt(x), "r-", label="fit N")
        ax.set_xlabel("τ [s]")
        ax.set_ylabel("σ(τ) [deg/h]")
        ax.set_title(f"axis {k}: a title about as long as a fitted model's name")
        ax.legend()
    fig.suptitle("Allan deviation")
    figures._place(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=figures.DPI)
    return buf.getvalue()


@pytest.mark.parametrize("nrows,ncols,sharex", [(1, 3, False), (2, 1, True)])
def test_subplots_draws_the_pixels_of_pyplot_and_registers_nothing(nrows, ncols, sharex):
    plt = figures.pyplot()
    before = plt.get_fignums()
    with matplotlib.rc_context(figures.STYLE):
        fig, axs = plt.subplots(nrows, ncols, figsize=(12.0, 5.0), squeeze=False, sharex=sharex)
        try:
            want = _draw(fig, axs)
        finally:
            plt.close(fig)
        fig, axs = figures.subplots(nrows, ncols, figsize=(12.0, 5.0), squeeze=False, sharex=sharex)
        assert plt.get_fignums() == before  # no figure manager holds it: nothing to close
        got = _draw(fig, axs)
    assert got == want


def test_place_measures_with_the_ticks_of_matplotlibs_own_updates(monkeypatch):
    """``_place`` with each axis's ticks held for the measuring pass puts every axes and sizes every title as it
    does with matplotlib updating the ticks at every query (eight times per axes); afterwards each axis updates its
    ticks itself again."""

    def placed():
        with matplotlib.rc_context(figures.STYLE):
            fig, axs = figures.subplots(1, 3, figsize=(12.0, 4.0), squeeze=False)
            _draw(fig, axs)
        return fig

    fig = placed()
    assert all("_update_ticks" not in vars(axis) for ax in fig.axes for axis in (ax.xaxis, ax.yaxis))
    monkeypatch.setattr(figures, "_ticks_held", lambda axes: contextlib.nullcontext())
    ref = placed()
    for a, b in zip(fig.axes, ref.axes):
        assert a.get_position().bounds == b.get_position().bounds
        assert a.title.get_fontsize() == b.title.get_fontsize()


def test_the_ticks_are_released_when_the_measuring_pass_fails():
    with matplotlib.rc_context(figures.STYLE):
        fig, axs = figures.subplots(1, 2, squeeze=False)
    axes = list(axs.ravel())
    with pytest.raises(RuntimeError):
        with figures._ticks_held(axes):
            assert all("_update_ticks" in vars(ax.xaxis) for ax in axes)
            raise RuntimeError("measuring failed")
    assert all("_update_ticks" not in vars(axis) for ax in axes for axis in (ax.xaxis, ax.yaxis))


def test_save_figure_closes_a_pyplot_figure_and_saves_an_object_one(tmp_path):
    plt = figures.pyplot()
    fig, _ = plt.subplots()
    figures.save_figure(fig, tmp_path / "pyplot.png")
    assert fig.number not in plt.get_fignums()
    fig, _ = figures.subplots()
    figures.save_figure(fig, tmp_path / "object.png")
    assert [(tmp_path / f).read_bytes()[:4] for f in ("pyplot.png", "object.png")] == [b"\x89PNG"] * 2


def test_fig3_is_drawn_without_importing_pyplot(tmp_path):
    """``plot_allan`` (the figure of ``fogdrift allan``) in a fresh interpreter: the PNG is written and
    matplotlib.pyplot is never imported."""
    code = r"""
import json, sys
import numpy as np
from fogdrift.io import from_array
from fogdrift.pipeline import AnalysisConfig, run_allan
from fogdrift.report.figures import plot_allan
y = np.random.default_rng(3).standard_normal((2**12, 2))
res = run_allan(from_array(y, dt_s=0.01, unit="deg/h", axis_names=["gx", "gy"]), AnalysisConfig().validate())
plot_allan(res, sys.argv[1])
print(json.dumps("matplotlib.pyplot" in sys.modules))
"""
    src = str(Path(fogdrift.__file__).resolve().parents[1])
    proc = subprocess.run([sys.executable, "-c", code, str(tmp_path / "allan.png")], capture_output=True, text=True,
                          timeout=600, env={"PATH": "/usr/bin:/bin", "PYTHONPATH": src})
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert json.loads(proc.stdout.strip().splitlines()[-1]) is False
    assert (tmp_path / "allan.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("limits", [None, (1e-2, 1e3)])
def test_log_axes_make_ticks_only_in_view_and_draw_the_same_pixels(monkeypatch, limits):
    """``_place`` hands each log axis the ticks of its LogLocator inside the view only (``_in_view_ticks``): the
    PNG is the one of the full locator, ticks on the view's ends included, with fewer tick objects made."""

    def drawn():
        with matplotlib.rc_context(figures.STYLE):
            fig, axs = figures.subplots(1, 2, figsize=(12.0, 4.0), squeeze=False)
            if limits is not None:
                for ax in axs.ravel():
                    ax.set_xlim(*limits)
            png = _draw(fig, axs)
        return png, sum(len(axis.minorTicks) + len(axis.majorTicks) for ax in fig.axes
                        for axis in (ax.xaxis, ax.yaxis))

    got, n_got = drawn()
    monkeypatch.setattr(figures, "_in_view_ticks", lambda ax: None)
    want, n_want = drawn()
    assert got == want
    assert n_got < n_want
