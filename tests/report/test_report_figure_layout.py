"""The report figures are placed by ``report.figures._place`` (one measuring pass) instead of matplotlib's
constrained layout (issue 25: the Fig. 3 PNG of ``fogdrift allan`` took 2.2x as long with it).

What must hold whatever the data: every text of the figure (tick labels, axis labels, titles, legend, suptitle,
block names above the axes) lies inside the PNG, and no axes' text runs into another axes.  The checker is shown
to catch a clipped label (matplotlib's default margins with wide tick labels), so a wrong sign or a missing margin
in ``_place`` fails here.
"""

from __future__ import annotations

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")

from fogdrift.report import figures  # noqa: E402


def _boxes(ax, r) -> list:
    """What an axes puts on the figure: its plotting area, each axis' drawn tick labels with the axis label
    (only the ticks in view count), its title, texts and legend (display pixels)."""
    out = [("area", ax.bbox), ("x axis", ax.xaxis.get_tightbbox(r)), ("y axis", ax.yaxis.get_tightbbox(r))]
    if ax.title.get_text():
        out.append(("title", ax.title.get_window_extent(r)))
    out += [(f"text {t.get_text()!r}", t.get_window_extent(r)) for t in ax.texts if t.get_text()]
    if ax.get_legend() is not None:
        out.append(("legend", ax.get_legend().get_window_extent(r)))
    return [(k, b) for k, b in out if b is not None and b.width > 0 and b.height > 0]


def _problems(fig, tol_px=1.0) -> list[str]:
    """Text outside the figure, and text of one axes on another axes' area or text (display pixels)."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    fb = fig.bbox
    out = []
    axes = [ax for ax in fig.axes if ax.get_subplotspec() is not None]
    items = [(i, k, b) for i, ax in enumerate(axes) for k, b in _boxes(ax, r)]
    sup = getattr(fig, "_suptitle", None)
    if sup is not None and sup.get_text():
        items.append((-1, "suptitle", sup.get_window_extent(r)))
    for i, k, e in items:
        if e.x0 < fb.x0 - tol_px or e.y0 < fb.y0 - tol_px or e.x1 > fb.x1 + tol_px or e.y1 > fb.y1 + tol_px:
            out.append(f"clipped: axes {i} {k} spans {e.bounds} in {fb.bounds}")
    for n, (i, k, a) in enumerate(items):
        for j, q, b in items[n + 1:]:
            ov = (min(a.x1, b.x1) - max(a.x0, b.x0), min(a.y1, b.y1) - max(a.y0, b.y0))
            if i != j and min(ov) > tol_px:
                out.append(f"axes {i} {k} and axes {j} {q} overlap by {ov} px")
    return out


def _wide_figure(nrows, ncols, *, place, log=False, suptitle=True, sharex=False):
    """A grid whose tick labels, labels and titles are wide: the case the margins must be measured for."""
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(nrows, ncols, figsize=(12.0, 7.0), squeeze=False, sharex=sharex)
    x = np.linspace(1e-2, 1e3, 200)
    for k, ax in enumerate(axs.ravel()):
        if log:
            ax.loglog(x, 10 ** (k + 1) / np.sqrt(x), label="a long legend entry [deg/h]")
            ax.set_ylim(3.1, 29.0)  # under one decade: the minor ticks get labels (2x10^0 ...), wider
        else:
            ax.plot(x, -123456.789 + 1e3 * np.sin(x), label="a long legend entry [deg/h]")
        ax.set_ylabel("drift σ(τ) of the axis [deg/h]")
        ax.set_xlabel("t [s]")
        if k == 0 and suptitle:  # Fig. 1 / 5: the block names above the first axes
            ax.text(0.5, 1.02, "validation", transform=ax.get_xaxis_transform(), ha="center", va="bottom")
        else:
            ax.set_title(f"panel {k}: a title as long as a fitted model's name, or longer")
        ax.legend()
    if suptitle:
        fig.suptitle("Drift and white noise of the whole record (Fig. 5)")
    if place:
        figures._place(fig)
    return fig


@pytest.mark.parametrize("nrows,ncols,log,sharex", [(1, 3, True, False), (3, 1, False, True), (2, 1, False, False),
                                                    (1, 1, True, False), (2, 2, False, False)])
def test_place_keeps_every_text_inside_and_apart(nrows, ncols, log, sharex):
    import matplotlib.pyplot as plt

    fig = _wide_figure(nrows, ncols, place=True, log=log, sharex=sharex)
    try:
        assert fig.get_layout_engine() is None
        assert _problems(fig) == []
        # the margins are measured, not generous: the axes keep most of the figure
        area = sum(ax.get_position().width * ax.get_position().height for ax in fig.axes)
        assert area > 0.45
    finally:
        plt.close(fig)


def test_the_checker_sees_a_clipped_label():
    """Matplotlib's default margins (no layout) clip the wide y tick labels of this figure: the check fails."""
    import matplotlib.pyplot as plt

    fig = _wide_figure(1, 3, place=False, log=False)
    try:
        assert any(p.startswith(("clipped", "axes")) for p in _problems(fig))
    finally:
        plt.close(fig)


def test_suptitle_sits_above_the_axes_titles():
    import matplotlib.pyplot as plt

    fig = _wide_figure(2, 1, place=True)
    try:
        fig.canvas.draw()
        r = fig.canvas.get_renderer()
        sup = fig._suptitle.get_window_extent(r)
        top_of_axes = max(ax.get_tightbbox(r).y1 for ax in fig.axes)
        assert sup.y0 >= top_of_axes and sup.y1 <= fig.bbox.y1
    finally:
        plt.close(fig)


def test_plot_allan_size_and_no_text_clipped(tmp_path, monkeypatch):
    """Fig. 3 of three axes (one with a long name): 16.8 x 4.8 in at 100 dpi = 1680 x 480 px as before, drawn
    once without a layout engine, nothing clipped."""
    from PIL import Image

    from fogdrift.io import from_array
    from fogdrift.pipeline import AnalysisConfig, run_allan

    rng = np.random.default_rng(7)
    n, dt = 2**14, 0.01
    y = np.column_stack([0.5 * rng.standard_normal(n), rng.standard_normal(n) + 1e-3 * np.cumsum(rng.standard_normal(n)),
                         2.0 * rng.standard_normal(n)])
    rec = from_array(y, dt_s=dt, unit="deg/h", axis_names=["gx", "gyro y (the long name of a column)", "gz"])
    res = run_allan(rec, AnalysisConfig().validate())
    seen = {}
    save = figures.save_figure

    def checked_save(fig, path, **kw):
        seen["engine"] = fig.get_layout_engine()
        seen["problems"] = _problems(fig)
        return save(fig, path, **kw)

    monkeypatch.setattr(figures, "save_figure", checked_save)
    path = figures.plot_allan(res, tmp_path / "allan.png")
    assert seen["engine"] is None
    assert seen["problems"] == []
    with Image.open(path) as im:
        assert im.size == (1680, 480)


@pytest.mark.parametrize("mathtext,plain", [
    (r"$\mathdefault{10^{3}}$", "10³"),
    (r"$\mathdefault{10^{-12}}$", "10⁻¹²"),
    (r"$\mathdefault{10^{0}}$", "10⁰"),
    (r"$\mathdefault{2\times10^{1}}$", "2×10¹"),
    (r"$\mathdefault{5\times10^{-4}}$", "5×10⁻⁴"),
    (r"$\mathdefault{-10^{2}}$", "−10²"),
    (r"$\mathdefault{0}$", "0"),
    ("", ""),
    ("0.5", "0.5"),
    (r"$\mathdefault{10^{2.50}}$", r"$\mathdefault{10^{2.50}}$"),  # not an integer exponent: left to mathtext
    (r"$\alpha^{2}$", r"$\alpha^{2}$"),
])
def test_plain_tick_label(mathtext, plain):
    assert figures.plain_tick_label(mathtext) == plain


def test_log_axes_get_the_same_labels_in_plain_text():
    """Every tick label matplotlib's formatter gives (decades, labelled minor ticks under one decade, blanks)
    comes back from the plain formatter as the same label without mathtext."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import LogFormatterSciNotation

    fig = _wide_figure(1, 2, place=True, log=True)
    try:
        labels = []
        for ax in fig.axes:
            for axis in (ax.xaxis, ax.yaxis):
                for f, locs in ((axis.get_major_formatter(), axis.get_majorticklocs()),
                                (axis.get_minor_formatter(), axis.get_minorticklocs())):
                    assert type(f).__name__ == "PlainLogFormatter"
                    ref = LogFormatterSciNotation(10.0, labelOnlyBase=f.labelOnlyBase)
                    ref.set_axis(axis)
                    ref.set_locs(locs)
                    f.set_locs(locs)
                    want = [ref(x) for x in locs]
                    got = [f(x) for x in locs]
                    assert got == [figures.plain_tick_label(s) for s in want]
                    assert [bool(s) for s in got] == [bool(s) for s in want]
                    labels += got
        labels = [s for s in labels if s]
        assert labels and not any("$" in s for s in labels)
        assert "2×10¹" in labels  # the y axis spans less than a decade: its minor ticks are labelled
    finally:
        plt.close(fig)
