"""Figures (matplotlib PNG), numbered as in the reference paper (Tang et al. 2012)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..output import atomic_path

def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig, path) -> Path:
    path = Path(path)
    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=110, bbox_inches="tight")
    finally:
        _plt().close(fig)
    return path


def _safe(name) -> str:
    """An axis or model name as a file-name part (deterministic; no path separators)."""
    return re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).strip("._") or "axis"


# -------------------------------------------------------------------------------------------------------------
# figures


def plot_allan(axes_list, path, title=None) -> Path:
    """Fig. 3: log-log deviation with 68 % error bars, the fitted curve over the fitted range (points used marked,
    left-out taus shaded), each selected term's asymptote, and the fit statistic."""
    plt = _plt()
    n = len(axes_list)
    fig, axs = plt.subplots(1, n, figsize=(5.6 * n, 4.6), squeeze=False)
    for ax, aa in zip(axs[0], axes_list):
        r, fit = aa.allan, aa.noise
        label = {"adev": "ADEV", "hdev": "HDEV", "mdev": "MDEV"}.get(getattr(r, "statistic", "adev"), "deviation")
        yerr = np.vstack([r.dev_dph - r.dev_lo68_dph, r.dev_hi68_dph - r.dev_dph])
        ax.errorbar(r.tau_s, r.dev_dph, yerr=yerr, fmt="o", ms=3, color="k", lw=0.8, mfc="white",
                    label=f"{label} (68 % CI)")
        used = np.isin(np.round(r.tau_s, 12), np.round(fit.fit_tau_s, 12))
        ax.plot(r.tau_s[used], r.dev_dph[used], "o", ms=4.5, color="k", zorder=4, label="fitted points")
        for e in fit.excluded:
            ax.axvspan(e["tau_min_s"] / 1.2, e["tau_max_s"] * 1.2, color="0.85", zorder=0, label="left out")
        tau = np.logspace(np.log10(fit.tau_min_s), np.log10(fit.tau_max_s), 200)
        ax.loglog(tau, fit.model_dev_dph(tau), "r-", lw=1.6, label=f"fit {'+'.join(fit.selected)}")
        for name, style in zip(("Q", "N", "B", "K", "R"), ("--", "-.", ":", "--", "-.")):
            if name in fit.selected and fit.terms[name].value:
                ax.loglog(tau, fit.term_dev_dph(name, tau), style, lw=0.9, label=name)
        pos = r.dev_lo68_dph > 0
        lo = np.nanmin(r.dev_lo68_dph[pos]) if np.any(pos) else np.nanmin(r.dev_dph)
        ax.set_ylim(lo / 3, np.nanmax(r.dev_hi68_dph) * 3)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("τ [s]")
        ax.set_ylabel(f"{label} σ(τ) [deg/h]")
        ax.set_title(f"{title or label}: {aa.name}\nχ²_red {fit.chi2_red:.3g}, p = {fit.p_value:.2g} ({fit.quality})",
                     fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    return _save(fig, path)


def plot_signal(record, path) -> Path:
    """Fig. 1: the rate signal of every axis over time."""
    plt = _plt()
    fig, axs = plt.subplots(record.n_axes, 1, figsize=(9, 2.2 * record.n_axes), squeeze=False, sharex=True)
    t = record.t0_s + np.arange(record.n_samples) * record.dt_s
    step = max(1, record.n_samples // 20000)  # plot at most ~20k points per axis
    for ax, name in zip(axs[:, 0], record.axis_names):
        ax.plot(t[::step], np.asarray(record.axis(name))[::step], lw=0.4)
        ax.set_ylabel(f"{name} [deg/h]")
        ax.grid(alpha=0.3)
    axs[-1, 0].set_xlabel("t [s]")
    fig.suptitle("Gyro output (Fig. 1)")
    return _save(fig, path)


def plot_spectrum(record, path) -> Path:
    """Fig. 2: Welch power spectral density of every axis."""
    from scipy.signal import welch

    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4))
    for name in record.axis_names:
        x = np.asarray(record.axis(name), dtype=float)
        f, p = welch(x - x.mean(), fs=record.fs_hz, nperseg=min(len(x), 4096))
        ax.loglog(f[1:], p[1:], lw=0.8, label=name)
    ax.set_xlabel("f [Hz]")
    ax.set_ylabel("PSD [(deg/h)²/Hz]")
    ax.set_title("Spectrum of the output (Fig. 2)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return _save(fig, path)


def plot_separation(sep, path) -> Path:
    """Fig. 5: drift and white noise over time."""
    plt = _plt()
    t = np.arange(sep.rate_dph.size) * sep.dt_s
    fig, axs = plt.subplots(2, 1, figsize=(9, 4.5), sharex=True)
    axs[0].plot(t, sep.rate_dph, lw=0.4, color="0.7", label="input")
    axs[0].plot(t, sep.drift_dph, lw=1.0, color="C3", label=f"drift (approximation, level {sep.level})")
    axs[0].set_ylabel("[deg/h]")
    axs[0].legend(fontsize=7)
    axs[1].plot(t, sep.noise_dph, lw=0.4, color="C0", label="white noise (details)")
    axs[1].set_ylabel("[deg/h]")
    axs[1].set_xlabel("t [s]")
    axs[1].legend(fontsize=7)
    for ax in axs:
        ax.grid(alpha=0.3)
    fig.suptitle(f"Drift and white noise, axis {sep.name}, dt = {sep.dt_s:g} s (Fig. 5)")
    return _save(fig, path)


def plot_separation_allan(sep, path) -> Path:
    """Fig. 6: ADEV of original, drift and noise."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for (label, aa), color in zip(sep.rows, ("k", "C3", "C0")):
        r = aa.allan
        yerr = np.vstack([r.dev_dph - r.dev_lo68_dph, r.dev_hi68_dph - r.dev_dph])
        ax.errorbar(r.tau_s, r.dev_dph, yerr=yerr, fmt="o-", ms=3, lw=0.8, color=color, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("τ [s]")
    ax.set_ylabel("σ(τ) [deg/h]")
    ax.set_title(f"Allan deviation of drift and noise, axis {sep.name} (Fig. 6)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return _save(fig, path)


def plot_models(model_axis, path, fig_no=8, *, residual=False) -> Path:
    """Fig. 8: one-step predictions against the test-block drift; with ``residual``, Fig. 9: drift minus
    each one-step prediction (the residual drift after compensation)."""
    plt = _plt()
    e, _ = model_axis.split["test"]
    y = model_axis.drift_blocks["test"]
    t = (e + np.arange(y.size)) * model_axis.dt_s
    fig, ax = plt.subplots(figsize=(9, 4))
    if not residual:
        ax.plot(t, y, "k-", lw=1.6, label="wavelet drift (test block)")
    for label, yhat in model_axis.predictions.items():
        ax.plot(t, y - yhat if residual else yhat, lw=0.8 if residual else 0.9, label=label)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("residual [deg/h]" if residual else "drift [deg/h]")
    what = "Residual after drift compensation" if residual else "One-step drift models"
    ax.set_title(f"{what}, axis {model_axis.name} (Fig. {fig_no})")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return _save(fig, path)


def plot_residuals(model_axis, path, fig_no=9) -> Path:
    """Fig. 9: residual drift after compensation (drift minus one-step model) on the test block."""
    return plot_models(model_axis, path, fig_no, residual=True)


