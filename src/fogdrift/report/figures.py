"""Figures (matplotlib PNG), numbered as in the reference paper (Tang et al. 2012).

Every figure is drawn :data:`FIG_WIDTH_IN` wide at :data:`DPI` (about 1200 px: the report's column width, so a
figure is shown at its own size, full width) with the fonts of :data:`STYLE`.  Time series mark what the
numbers do not use: Fig. 1 and Fig. 5 draw the train / validation / test split; Figs. 8 and 9 shade the first
``score_from`` (= ``lags``) samples of the test block, whose inputs reach into the validation block and which no
metric scores, and scale their y axis on the scored part only.
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import re
import weakref
from pathlib import Path

import numpy as np

from ..noise.terms import ALL_TERMS
from ..output import atomic_path

#: Width [in] of every report figure; with :data:`DPI` about 1200 px.
FIG_WIDTH_IN = 12.0
#: Resolution of the PNG files [dots per inch].
DPI = 100
#: Font sizes and line widths of every figure (legible at the report's column width).
STYLE = {"font.size": 12, "axes.titlesize": 13, "axes.labelsize": 12, "xtick.labelsize": 11, "ytick.labelsize": 11,
         "legend.fontsize": 10, "figure.titlesize": 14, "axes.grid": True, "grid.alpha": 0.3}
#: Colours of the chronological blocks (Fig. 1, Fig. 5).
BLOCK_COLOURS = {"train": "#4c72b0", "val": "#dd8452", "test": "#55a868"}
BLOCK_LABELS = {"train": "training", "val": "validation", "test": "test (held out)"}
#: Colour of the samples no metric scores (start of the test block).
UNSCORED = "0.8"


def pyplot():
    """:mod:`matplotlib.pyplot` on the Agg backend (no window), for the figures drawn through pyplot."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def subplots(nrows=1, ncols=1, *, figsize=None, **kwargs):
    """A figure and its grid of axes, as :func:`matplotlib.pyplot.subplots` makes them (``kwargs`` go to
    :meth:`matplotlib.figure.Figure.subplots`: ``squeeze``, ``sharex`` ...), on matplotlib's Agg canvas.

    Pyplot is not imported: a PNG needs neither its figure manager nor its backend switching (its import, about
    0.02 s on top of the figure's own modules), and no registry holds the figure (:func:`save_figure` has nothing
    to close).  The figure takes the rcParams in force, as pyplot's does, and draws the same pixels.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(nrows, ncols, **kwargs)


def _styled(fn):
    """Draw inside ``matplotlib.rc_context(STYLE)`` (global rcParams stay untouched)."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        import matplotlib

        with matplotlib.rc_context(STYLE):
            return fn(*args, **kwargs)

    return wrapper


#: Superscript digits and minus of the plain-text tick labels of log axes (DejaVu Sans has them all).
_SUPERSCRIPT = str.maketrans("0123456789-", "\u2070\u00b9\u00b2\u00b3\u2074\u2075\u2076\u2077\u2078\u2079\u207b")


def plain_tick_label(label: str) -> str:
    r"""A log-axis tick label of matplotlib (mathtext, ``$\mathdefault{2\times10^{-3}}$``) as the same label in
    plain text (``2×10⁻³``); any other label comes back unchanged.

    Matplotlib's first mathtext label of a process builds its whole mathtext parser (a pyparsing grammar: about
    0.3 s of the first figure, in ``fogdrift allan`` the only mathtext drawn); plain text draws the same digits.

    Examples
    --------
    >>> plain_tick_label(r"$\mathdefault{10^{-2}}$"), plain_tick_label(r"$\mathdefault{2\times10^{1}}$")
    ('10⁻²', '2×10¹')
    >>> plain_tick_label(r"$\mathdefault{0}$"), plain_tick_label(""), plain_tick_label(r"$\alpha$")
    ('0', '', '$\\alpha$')
    """
    m = re.fullmatch(r"\$\\mathdefault\{(-?)([^{}$]*?)(?:\^\{(-?\d+)\})?\}\$", label)
    if m is None:
        return label
    sign, body, exponent = m.groups()
    body = body.replace(r"\times", "\u00d7")
    if "\\" in body or "^" in body:
        return label
    return ("\u2212" if sign else "") + body + ("" if exponent is None else exponent.translate(_SUPERSCRIPT))


@functools.cache
def _log_formatters():
    """(matplotlib's log-axis formatter class, its plain-text subclass)."""
    from matplotlib.ticker import LogFormatterSciNotation

    class PlainLogFormatter(LogFormatterSciNotation):
        """:class:`~matplotlib.ticker.LogFormatterSciNotation` (same ticks labelled, same rules) in plain text."""

        def __call__(self, x, pos=None):
            return plain_tick_label(super().__call__(x, pos))

    return LogFormatterSciNotation, PlainLogFormatter


def _plain_log_ticks(ax) -> None:
    """Log axes of ``ax`` label their ticks in plain text (:func:`plain_tick_label`)."""
    mathtext, plain = _log_formatters()
    for axis in (ax.xaxis, ax.yaxis):
        for get, put in ((axis.get_major_formatter, axis.set_major_formatter),
                         (axis.get_minor_formatter, axis.set_minor_formatter)):
            f = get()
            if type(f) is mathtext:
                put(plain(f._base, labelOnlyBase=f.labelOnlyBase, minor_thresholds=f.minor_thresholds,
                          linthresh=f._linthresh))


@functools.cache
def _in_view_locator():
    """A locator class that hands on its base locator's ticks inside the axis's view interval only."""
    from matplotlib.ticker import Locator

    class InView(Locator):
        """The ticks of ``base`` (a log axis's :class:`~matplotlib.ticker.LogLocator`) inside the view interval,
        widened by a relative 1e-6 (more than matplotlib's own tolerance), so the same ticks are drawn.

        A log locator returns whole decades beyond both ends of the view (a y axis of 3 decades: 60 minor ticks,
        24 inside); matplotlib makes a tick object (two lines, a grid line, two texts: about 0.4 ms) for every
        location before it drops those outside the view.  Limits, autoscaling and parameters are the base's.
        """

        def __init__(self, base):
            self.base = base

        def set_axis(self, axis):
            super().set_axis(axis)
            self.base.set_axis(axis)

        def __call__(self):
            locs = np.asarray(self.base())
            lo, hi = sorted(self.axis.get_view_interval())
            return locs[(locs >= lo * (1 - 1e-6)) & (locs <= hi * (1 + 1e-6))]

        def tick_values(self, vmin, vmax):
            return self.base.tick_values(vmin, vmax)

        def nonsingular(self, v0, v1):
            return self.base.nonsingular(v0, v1)

        def view_limits(self, vmin, vmax):
            return self.base.view_limits(vmin, vmax)

        def set_params(self, **kwargs):
            self.base.set_params(**kwargs)

    return InView


def _in_view_ticks(ax) -> None:
    """The log axes of ``ax`` make tick objects only for the ticks inside their view (:func:`_in_view_locator`)."""
    from matplotlib.ticker import LogLocator

    in_view = _in_view_locator()
    for axis in (ax.xaxis, ax.yaxis):
        if axis.get_scale() != "log":
            continue
        for get, put in ((axis.get_major_locator, axis.set_major_locator),
                         (axis.get_minor_locator, axis.set_minor_locator)):
            loc = get()
            if type(loc) is LogLocator:
                put(in_view(loc))


#: Space [in] kept between the text of an axes (tick labels, axis labels, title) and the figure's edge or the
#: next axes' text, by :func:`_place`.
PAD_IN = 0.1


@contextlib.contextmanager
def _ticks_held(axes):
    """Inside the block, each axis of ``axes`` works out its ticks once (locations, labels, positions).

    Matplotlib's tight box of one axes updates the ticks of an axis once for the axis, once for its label's
    position and once for each spine along it (Axis._update_ticks: the locator run and every tick label formatted
    and moved again): eight updates per axes where two serve, and a draw three per axis (the axis, its label's
    siblings, the spines).  While :func:`_place` measures, and while :func:`save_figure` draws the placed figure,
    no axes moves and no limit changes, so every update gives the ticks of the first; the first is kept for the
    block (the same pixels).
    """
    held = []
    try:
        for ax in axes:
            for axis in (ax.xaxis, ax.yaxis):
                update = getattr(axis, "_update_ticks", None)
                ticks = None if update is None else update()
                if not isinstance(ticks, list):  # another matplotlib's private method: measured as it measures
                    continue
                axis._update_ticks = functools.partial(list, ticks)  # a fresh list each call, as matplotlib's
                held.append(axis)
        yield
    finally:
        for axis in held:
            del axis._update_ticks  # matplotlib's method again


#: The figures :func:`_place` laid out: their axes stay where they are through the draw, so :func:`save_figure`
#: may hold their ticks (a figure saved with ``bbox_inches`` or laid out elsewhere updates its own).
_PLACED = weakref.WeakSet()


def _place(fig, pad_in=PAD_IN):
    """Place the axes of ``fig`` (one :func:`matplotlib.pyplot.subplots` grid, no layout engine) so that every
    axes' tick labels, axis labels and texts fit inside the figure without running into the neighbours'.

    One measuring pass: each axes' tight box in a provisional position, as constrained layout measures it (the
    title's and axis labels' widths left out: they are centred); the overhangs [in] do not depend on the
    position.  Then :meth:`~matplotlib.figure.Figure.subplots_adjust` with those margins plus ``pad_in`` [in],
    a suptitle on top, and a title wider than its axes' slot drawn smaller (down to 7 pt) so that it meets no
    neighbour.  It replaces ``layout="constrained"``, which measured every tick label twice before the draw
    (the Fig. 3 PNG of ``fogdrift allan`` took 2.2x as long); the ticks measured here are the ones the draw uses.
    """
    axes = [ax for ax in fig.axes if ax.get_subplotspec() is not None]
    _PLACED.add(fig)
    for ax in axes:
        _plain_log_ticks(ax)
        _in_view_ticks(ax)
    nrows, ncols = axes[0].get_subplotspec().get_gridspec().get_geometry()
    w, h = fig.get_size_inches()
    sup = getattr(fig, "_suptitle", None)
    sup = sup if sup is not None and sup.get_text() else None

    def adjust(left, right, bottom, top, col_gap, row_gap):
        aw = (w - left - right - (ncols - 1) * col_gap) / ncols  # width [in] of one axes
        ah = (h - bottom - top - (nrows - 1) * row_gap) / nrows
        fig.subplots_adjust(left=left / w, right=1 - right / w, bottom=bottom / h, top=1 - top / h,
                            wspace=col_gap / aw if ncols > 1 else None, hspace=row_gap / ah if nrows > 1 else None)
        return aw

    adjust(0.9, 0.2, 0.6, 0.5 + (0.4 if sup else 0.0), 1.0, 0.8)  # provisional: about the final axes size
    renderer = fig.canvas.get_renderer()
    dpi = fig.dpi
    left, right = np.zeros(ncols), np.zeros(ncols)
    below, above = np.zeros(nrows), np.zeros(nrows)
    with _ticks_held(axes):
        for ax in axes:
            ss = ax.get_subplotspec()
            tb, bb = ax.get_tightbbox(renderer, for_layout_only=True), ax.bbox
            c0, c1, r0, r1 = ss.colspan.start, ss.colspan.stop - 1, ss.rowspan.start, ss.rowspan.stop - 1
            left[c0] = max(left[c0], (bb.x0 - tb.x0) / dpi)
            right[c1] = max(right[c1], (tb.x1 - bb.x1) / dpi)
            below[r1] = max(below[r1], (bb.y0 - tb.y0) / dpi)
            above[r0] = max(above[r0], (tb.y1 - bb.y1) / dpi)
    top = above[0] + pad_in
    if sup:
        sup.set_y(1 - pad_in / h)
        sup.set_verticalalignment("top")
        top += sup.get_window_extent(renderer).height / dpi + pad_in
    col_gap = float(np.max(right[:-1] + left[1:])) + pad_in if ncols > 1 else 0.0
    row_gap = float(np.max(below[:-1] + above[1:])) + pad_in if nrows > 1 else 0.0
    lm, rm = left[0] + pad_in, right[-1] + pad_in
    aw = adjust(lm, rm, below[-1] + pad_in, top, col_gap, row_gap)
    for ax in axes:  # a centred title may reach half-way into a gap, and to the figure's edge
        c0, c1 = ax.get_subplotspec().colspan.start, ax.get_subplotspec().colspan.stop - 1
        reach = min(col_gap / 2 if c0 > 0 else lm, col_gap / 2 if c1 < ncols - 1 else rm) - pad_in / 2
        slot = (c1 - c0 + 1) * aw + (c1 - c0) * col_gap + 2 * max(reach, 0.0)
        for _ in range(6):  # glyph widths do not scale exactly with the size (hinting): measure again
            width = ax.title.get_window_extent(renderer).width / dpi if ax.title.get_text() else 0.0
            if width <= slot or ax.title.get_fontsize() <= 7.0:
                break
            ax.title.set_fontsize(max(7.0, ax.title.get_fontsize() * min(slot / width, 0.97)))


def save_figure(fig, path, **savefig) -> Path:
    """Write ``fig`` to ``path`` atomically (complete or absent) and close it, whatever happens.

    ``savefig`` keywords go to :meth:`matplotlib.figure.Figure.savefig` (default ``dpi=DPI``); every figure of
    the package is saved here.
    """
    path = Path(path)
    try:
        held = _ticks_held(fig.axes) if fig in _PLACED and not savefig.get("bbox_inches") else contextlib.nullcontext()
        with atomic_path(path) as tmp, held:
            fig.savefig(tmp, **{"dpi": DPI, **savefig})
    finally:
        if fig.canvas.manager is not None:  # a pyplot figure: pyplot holds it until it is closed
            pyplot().close(fig)
    return path


def _safe(name) -> str:
    """An axis or model name as a file-name part (deterministic; no path separators)."""
    return re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._") or "axis"


def literal(text) -> str:
    r"""``text`` (a column, axis, model or file name: user text) drawn as written by matplotlib.

    Matplotlib reads a string with an even number of ``$`` as mathtext, and a bad expression (a column named
    ``$\bogus{$``) raises only when the figure is drawn, after the JSON was written.  An escaped ``\$`` is drawn
    as ``$`` and never starts mathtext.  Every label, title, legend entry and tick label that carries user text
    goes through this function (the figures of :mod:`fogdrift.report`, :mod:`fogdrift.report.gmwm`,
    :mod:`fogdrift.report.temperature` and the fleet page).

    Examples
    --------
    >>> print(literal(r"$\bogus{$"), literal("gx"))
    \$\bogus{\$ gx
    """
    return str(text).replace("$", r"\$")


def _envelope(t, y, max_points=4000):
    """Bin a long series: (t of each bin, min, max, mean); short series come back unbinned.

    ``t`` is the times of ``y``, or ``(t0, dt)`` for ``t0 + arange(n) * dt``: the same values, built a block of
    bins at a time instead of as two 8-bytes-per-sample arrays."""
    y = np.asarray(y, dtype=float)
    lazy = isinstance(t, tuple)
    if y.size <= 2 * max_points:
        return (t[0] + np.arange(y.size) * t[1] if lazy else t), y, y, y
    k = int(np.ceil(y.size / max_points))
    n = (y.size // k) * k
    yy = y[:n].reshape(-1, k)
    if lazy:
        rows = max(1, (1 << 20) // k)
        tb = np.concatenate([(t[0] + np.arange(a * k, min(a + rows, n // k) * k) * t[1]).reshape(-1, k).mean(axis=1)
                             for a in range(0, n // k, rows)])
    else:
        tb = t[:n].reshape(-1, k).mean(axis=1)
    return tb, yy.min(axis=1), yy.max(axis=1), yy.mean(axis=1)


def _draw_split(ax, split_s, *, label=True):
    """Shade the blocks ``{"train": (t0, t1), ...}`` [s] and name them above the plot."""
    for name, (a, b) in split_s.items():
        ax.axvspan(a, b, color=BLOCK_COLOURS.get(name, "0.9"), alpha=0.10, lw=0, zorder=0)
        ax.axvline(a, color=BLOCK_COLOURS.get(name, "0.5"), lw=1.0, ls="--", zorder=1)
        if label:
            ax.text((a + b) / 2, 1.02, literal(BLOCK_LABELS.get(name, name)), transform=ax.get_xaxis_transform(),
                    ha="center", va="bottom", fontsize=11, color=BLOCK_COLOURS.get(name, "k"))


def _limits(*arrays, pad=0.08):
    """y limits covering the finite values of ``arrays`` (the scored part), padded."""
    vals = np.concatenate([np.asarray(a, dtype=float).ravel() for a in arrays])
    vals = vals[np.isfinite(vals)]
    if vals.size == 0:
        return None
    lo, hi = float(vals.min()), float(vals.max())
    span = hi - lo or abs(hi) or 1.0
    return lo - pad * span, hi + pad * span


# -------------------------------------------------------------------------------------------------------------
# figures


#: Above this many taus (``--taus all``: one per averaging factor) Fig. 3 draws the deviation as a line in its 68 %
#: band instead of one error bar per tau.
DENSE_TAUS = 200


@_styled
def plot_allan(axes_list, path, title=None) -> Path:
    """Fig. 3: log-log deviation with 68 % error bars, the fitted curve over the fitted range (points used marked,
    left-out taus shaded), each selected term's asymptote, and the fit statistic."""
    n = len(axes_list)
    size = (FIG_WIDTH_IN, 5.6) if n == 1 else (5.6 * n, 4.8)
    fig, axs = subplots(1, n, figsize=size, squeeze=False)
    for ax, aa in zip(axs[0], axes_list):
        r, fit = aa.allan, aa.noise
        label = {"adev": "ADEV", "hdev": "HDEV", "mdev": "MDEV"}.get(getattr(r, "statistic", "adev"), "deviation")
        if r.tau_s.size > DENSE_TAUS:  # a band and a line: thousands of error bars hide each other (and cost ~1 ms each)
            ax.fill_between(r.tau_s, r.dev_lo68, r.dev_hi68, color="0.55", alpha=0.45, lw=0,
                            label="68 % CI")
            ax.plot(r.tau_s, r.dev, "-", color="k", lw=0.8, label=label)
        else:
            yerr = np.vstack([r.dev - r.dev_lo68, r.dev_hi68 - r.dev])
            ax.errorbar(r.tau_s, r.dev, yerr=yerr, fmt="o", ms=4, color="k", lw=0.8, mfc="white",
                        label=f"{label} (68 % CI)")
        used = np.isin(np.round(r.tau_s, 12), np.round(fit.fit_tau_s, 12))
        ax.plot(r.tau_s[used], r.dev[used], "o", ms=5, color="k", zorder=4, label="fitted points")
        for i, e in enumerate(fit.excluded):
            ax.axvspan(e["tau_min_s"] / 1.2, e["tau_max_s"] * 1.2, color="0.85", zorder=0,
                       label="left out" if i == 0 else None)
        # the printed model, exactly (every selected term, S and M included), over the fitted range only
        tau = np.unique(np.round(np.logspace(np.log10(fit.tau_min_s), np.log10(fit.tau_max_s), 400) / fit.dt_s)
                        ) * fit.dt_s
        no_fit = getattr(fit, "no_fit", None)
        ax.loglog(tau, fit.model_dev_dph(tau), "r--" if no_fit else "r-", lw=2.0,
                  label=literal(f"best candidate {'+'.join(fit.selected)} (no model fits)" if no_fit else
                                f"fit {'+'.join(fit.selected)}"))
        for name, style in zip(ALL_TERMS, itertools.cycle(("--", "-.", ":"))):
            t = fit.terms.get(name)
            if name in fit.selected and t is not None and t.value:
                ax.loglog(tau, fit.term_dev_dph(name, tau), style, lw=1.2, label=name)
        pos = r.dev_lo68 > 0
        lo = np.nanmin(r.dev_lo68[pos]) if np.any(pos) else np.nanmin(r.dev)
        ax.set_ylim(lo / 3, np.nanmax(r.dev_hi68) * 3)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("τ [s]")
        unit = "m/s²" if getattr(fit, "quantity", "angular_rate") == "specific_force" else "deg/h"
        ax.set_ylabel(f"{label} σ(τ) [{unit}]")
        ax.set_title(literal(f"{title or label}: {aa.name}   χ²_red {fit.chi2_red:.3g}, p = {fit.p_value:.2g} "
                     f"({'no model fits' if no_fit else fit.quality})"))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(ncols=2 if n == 1 else 1)
    _place(fig)
    return save_figure(fig, path)


@_styled
def plot_signal(record, path, split_s=None) -> Path:
    """Fig. 1: the rate of every axis over time (min/max envelope of long records and the mean), with the
    train / validation / test blocks shaded when ``split_s`` ``{"train": (t0, t1), ...}`` [s] is given."""
    fig, axs = subplots(record.n_axes, 1, figsize=(FIG_WIDTH_IN, 1.0 + 2.3 * record.n_axes), squeeze=False,
                            sharex=True)
    for i, (ax, name) in enumerate(zip(axs[:, 0], record.axis_names)):
        tb, lo, hi, mean = _envelope((record.t0_s, record.dt_s), record.axis(name))
        if lo is not mean:
            ax.fill_between(tb, lo, hi, color="C0", alpha=0.35, lw=0, label="min–max per bin")
        ax.plot(tb, mean, lw=0.6, color="C0", label="mean per bin" if lo is not mean else None)
        if split_s:
            _draw_split(ax, split_s, label=i == 0)
        ax.set_ylabel(literal(f"{name} [deg/h]"))
    axs[-1, 0].set_xlabel("t [s]")
    fig.suptitle("Gyro output (Fig. 1)" + ("; dashed: train / validation / test split" if split_s else ""))
    _place(fig)
    return save_figure(fig, path)


def _power_unit(unit: str) -> str:
    """The unit of a PSD of a series in ``unit``: ``"deg/h"`` -> ``"(deg/h)²/Hz"``, ``"m/s^2"`` -> ``"(m/s²)²/Hz"``."""
    return f"({unit.replace('^2', '²')})²/Hz"


@_styled
def plot_spectrum(axes, path) -> Path:
    """Fig. 2: the Welch power spectral density of every axis, as the workflow computed it (each axis's
    ``spectrum``, :class:`fogdrift.pipeline.AxisSpectrum`; the DC bin left out), one panel per unit (a gyro's in
    (deg/h)²/Hz, an accelerometer's in (m/s²)²/Hz)."""
    units = list(dict.fromkeys(ax.spectrum.unit for ax in axes))
    fig, axs = subplots(len(units), 1, figsize=(FIG_WIDTH_IN, 4.8 if len(units) == 1 else 7.6), squeeze=False)
    for ax, unit in zip(axs[:, 0], units):
        for a in axes:
            if a.spectrum.unit == unit:
                ax.loglog(a.spectrum.f_hz[1:], a.spectrum.psd[1:], lw=1.0, label=literal(a.name))
        ax.set_xlabel("f [Hz]")
        ax.set_ylabel(f"PSD [{_power_unit(unit)}]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    axs[0, 0].set_title("Spectrum of the output (Fig. 2)")
    _place(fig)
    return save_figure(fig, path)


@_styled
def plot_separation(sep, path, split=None) -> Path:
    """Fig. 5: drift and white noise over time; ``split`` ``{"train": [i0, i1), ...}`` (sample indices at the
    separation's rate) draws the blocks the models use (they separate inside each block)."""
    t = np.arange(sep.rate_dph.size) * sep.dt_s
    fig, axs = subplots(2, 1, figsize=(FIG_WIDTH_IN, 6.0), sharex=True)
    tb, lo, hi, mean = _envelope(t, sep.rate_dph)
    if tb is not t:
        axs[0].fill_between(tb, lo, hi, color="0.75", lw=0, label="input (min–max per bin)")
    else:
        axs[0].plot(t, sep.rate_dph, lw=0.5, color="0.65", label="input")
    axs[0].plot(t, sep.drift_dph, lw=1.4, color="C3", label=f"drift (approximation, level {sep.level})")
    axs[0].set_ylabel("[deg/h]")
    axs[0].legend(loc="upper right")
    tb, lo, hi, mean = _envelope(t, sep.noise_dph)
    if tb is not t:
        axs[1].fill_between(tb, lo, hi, color="C0", alpha=0.6, lw=0, label="white noise (details, min–max per bin)")
    else:
        axs[1].plot(t, sep.noise_dph, lw=0.5, color="C0", label="white noise (details)")
    axs[1].set_ylabel("[deg/h]")
    axs[1].set_xlabel("t [s]")
    axs[1].legend(loc="upper right")
    if split:
        for i, ax in enumerate(axs):
            _draw_split(ax, {k: (a * sep.dt_s, b * sep.dt_s) for k, (a, b) in split.items()}, label=i == 0)
    fig.suptitle(literal(f"Drift and white noise of the whole record, axis {sep.name}, dt = {sep.dt_s:g} s (Fig. 5)"))
    _place(fig)
    return save_figure(fig, path)


@_styled
def plot_separation_allan(sep, path) -> Path:
    """Fig. 6: ADEV of original, drift and noise."""
    fig, ax = subplots(figsize=(FIG_WIDTH_IN, 5.2))
    for (label, aa), color in zip(sep.rows, ("k", "C3", "C0")):
        r = aa.allan
        yerr = np.vstack([r.dev - r.dev_lo68, r.dev_hi68 - r.dev])
        ax.errorbar(r.tau_s, r.dev, yerr=yerr, fmt="o-", ms=4, lw=1.0, color=color, label=literal(label))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("τ [s]")
    ax.set_ylabel("σ(τ) [deg/h]")
    ax.set_title(literal(f"Allan deviation of drift and noise, axis {sep.name} (Fig. 6)"))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    _place(fig)
    return save_figure(fig, path)


def _test_axis(model_axis):
    e, _ = model_axis.split["test"]
    y = model_axis.drift_blocks["test"]
    return (e + np.arange(y.size)) * model_axis.dt_s, y, int(getattr(model_axis, "score_from", 0) or 0)


def _label(model_axis, label):
    model = model_axis.fitted.get(label)
    if getattr(model, "input_kind", "drift") == "rate":
        return literal(f"{label} (estimates the rate's drift, not the wavelet drift)")
    return literal(label)


def _shade_unscored(ax, t, k, dt):
    if k > 0:
        ax.axvspan(t[0] - dt / 2, t[min(k, t.size) - 1] + dt / 2, color=UNSCORED, alpha=0.6, lw=0, zorder=0,
                   label=f"first {k} samples: not scored")


@_styled
def plot_models(model_axis, path, fig_no=8, *, residual=False) -> Path:
    """Fig. 8: one-step predictions against the test-block drift, over the whole test block and zoomed on its
    largest excursion; with ``residual``, Fig. 9 (:func:`plot_residuals`)."""
    if residual:
        return plot_residuals(model_axis, path, fig_no)
    t, y, k = _test_axis(model_axis)
    dt = model_axis.dt_s
    fig, axs = subplots(2, 1, figsize=(FIG_WIDTH_IN, 8.0))
    scored = slice(k, None)
    centre = k + int(np.nanargmax(np.abs(y[scored]))) if y.size > k else 0
    half = max(30, y.size // 20)
    lo, hi = max(k, centre - half), min(y.size, centre + half)
    for ax, part in zip(axs, (slice(0, y.size), slice(lo, hi))):
        _shade_unscored(ax, t, k if part.start == 0 else 0, dt)
        ax.plot(t[part], y[part], "k-", lw=2.2, label="wavelet drift (test block)")
        for label, yhat in model_axis.predictions.items():
            ax.plot(t[part], yhat[part], lw=1.0, label=_label(model_axis, label))
        lim = _limits(y[max(part.start, k):part.stop],
                      *[p[max(part.start, k):part.stop] for p in model_axis.predictions.values()])
        if lim:
            ax.set_ylim(*lim)
        ax.set_xlabel("t [s]")
        ax.set_ylabel("drift [deg/h]")
    axs[0].set_title(literal(f"One-step drift models, axis {model_axis.name} (Fig. {fig_no}): test block"))
    axs[1].set_title(f"zoom on the largest drift excursion, t = {t[lo]:g} – {t[hi - 1]:g} s")
    axs[0].legend(ncols=2, loc="best")
    _place(fig)
    return save_figure(fig, path)


@_styled
def plot_residuals(model_axis, path, fig_no=9) -> Path:
    """Fig. 9: residual drift after compensation (wavelet drift minus each model's one-step prediction) on the
    test block, one panel per model, each scaled on its scored part and labelled with its RMS."""
    t, y, k = _test_axis(model_axis)
    preds = list(model_axis.predictions.items())
    n = max(1, len(preds))
    fig, axs = subplots(n, 1, figsize=(FIG_WIDTH_IN, 1.2 + 1.55 * n), sharex=True, squeeze=False)
    for ax, (label, yhat) in zip(axs[:, 0], preds):
        r = y - yhat
        _shade_unscored(ax, t, k, model_axis.dt_s)
        ax.plot(t, r, lw=0.8, color="C3")
        ax.axhline(0.0, color="k", lw=0.6)
        rs = r[k:][np.isfinite(r[k:])]
        rms = float(np.sqrt(np.mean(rs**2))) if rs.size else float("nan")
        lim = _limits(rs, pad=0.1)
        if lim:
            ax.set_ylim(*lim)
        ax.text(0.005, 0.95, _label(model_axis, label) + f": RMS {rms:.3g} deg/h (scored part)",
                transform=ax.transAxes, va="top", fontsize=11,
                bbox={"facecolor": "white", "alpha": 0.85, "edgecolor": "none"})
        ax.set_ylabel("[deg/h]")
    axs[-1, 0].set_xlabel("t [s]")
    fig.suptitle(literal(f"Residual drift after one-step compensation, axis {model_axis.name} (Fig. {fig_no}); "
                         "y scales differ between panels; grey: not scored"))
    _place(fig)
    return save_figure(fig, path)


@_styled
def plot_dynamic_adev(allan_axes, path) -> Path | None:
    """The dynamic Allan deviation of each disturbed axis (its screen's ``dynamic_adev``: ADEV over sliding windows)
    as an image over time x tau, the disturbed intervals marked above it; None when no axis has one."""
    shown = [a for a in allan_axes if (getattr(a, "screen", None) or {}).get("dynamic_adev")]
    if not shown:
        return None
    fig, axs = subplots(len(shown), 1, figsize=(FIG_WIDTH_IN, 3.4 * len(shown) + 0.6), squeeze=False)
    for ax, a in zip(axs[:, 0], shown):
        d = a.screen["dynamic_adev"]
        t, tau, adev = np.asarray(d["t_s"]), np.asarray(d["tau_s"]), np.asarray(d["adev"], dtype=np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            img = np.log10(np.where(adev > 0, adev, np.nan))
        mesh = ax.pcolormesh(t, tau, img.T, shading="nearest", cmap="viridis")
        ax.set_yscale("log")
        ax.set_xlabel("window centre t [s]")
        ax.set_ylabel("τ [s]")
        unit = "m/s²" if getattr(a.noise, "quantity", "angular_rate") == "specific_force" else "deg/h"
        fig.colorbar(mesh, ax=ax, label=f"log10 ADEV [{unit}]")
        for iv in a.screen.get("intervals") or ():
            ax.axvspan(iv["start_s"], iv["end_s"], ymin=0.96, ymax=1.0, color="red", lw=0)
        ax.set_title(literal(f"{a.name}: dynamic ADEV (windows of {d['window_s']:.4g} s); red: disturbed intervals"))
    _place(fig)
    fig.subplots_adjust(hspace=0.55)  # each panel's title clear of the time ticks above it
    return save_figure(fig, path)
