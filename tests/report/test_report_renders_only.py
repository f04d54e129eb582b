"""The report only renders what the workflow computed: Fig. 2 is drawn from each axis's ``spectrum`` (the Welch PSD
of :func:`fogdrift.noise.spectral.welch_psd`, taken by :func:`fogdrift.pipeline.run_analysis`), labelled in the
channel's unit, and the temperature line is the result's ``record["temperature"]``; neither runs an estimator at
render time."""

from __future__ import annotations

from types import SimpleNamespace as NS

import numpy as np
import pytest
import scipy.signal

from fogdrift.io import from_array
from fogdrift.noise.spectral import welch_psd
from fogdrift.pipeline import AnalysisConfig, AxisSpectrum, run_analysis
from fogdrift.report import figures
from fogdrift.report import temperature as report_temperature
from fogdrift.report.html import spectrum_block, temperature_block
from fogdrift.temperature import summary_line, temperature_summary


def _forbid_welch(monkeypatch):
    def no_welch(*args, **kwargs):
        raise AssertionError("the report ran a Welch PSD of its own")

    monkeypatch.setattr(scipy.signal, "welch", no_welch)


@pytest.fixture
def ylabels(monkeypatch):
    """The y labels of every figure the report saves."""
    seen = []
    save = figures.save_figure

    def spy(fig, path, **kw):
        seen.append([ax.get_ylabel() for ax in fig.axes])
        return save(fig, path, **kw)

    monkeypatch.setattr(figures, "save_figure", spy)
    return seen


@pytest.mark.parametrize("unit, label", [("m/s^2", "PSD [(m/s²)²/Hz]"), ("deg/s", "PSD [(deg/h)²/Hz]")])
def test_fig2_is_the_workflows_psd_in_the_channels_unit(tmp_path, monkeypatch, ylabels, unit, label):
    """run_analysis stores each axis's PSD (the library's Welch, in the internal unit: m/s^2 for an accelerometer,
    deg/h for a gyro); the report draws exactly that, scipy's Welch failing, labelled with that unit."""
    x = np.random.default_rng(1).standard_normal((2000, 1))
    rec = from_array(x, dt_s=1.0, unit=unit, axis_names=["a"])
    res = run_analysis(rec, AnalysisConfig(models=("ar",), epochs=2))
    spec = res.axes[0].spectrum
    assert spec.unit == {"m/s^2": "m/s^2", "deg/s": "deg/h"}[unit]
    f, p = welch_psd(rec.axis("a"), rec.dt_s)
    np.testing.assert_array_equal(spec.f_hz, f)
    np.testing.assert_array_equal(spec.psd, p)
    assert "spectrum" not in res.axes[0].to_dict()  # the JSON is unchanged: the PSD is for the figure only
    _forbid_welch(monkeypatch)
    html = spectrum_block(res, rec, tmp_path)
    assert html.startswith("<figure><img") and (tmp_path / "fig2_spectrum.png").is_file()
    assert ylabels == [[label]]


def test_a_gyro_and_an_accelerometer_get_one_panel_each(tmp_path, monkeypatch, ylabels):
    _forbid_welch(monkeypatch)
    f = np.linspace(0.0, 50.0, 9)
    axes = [NS(name=n, spectrum=AxisSpectrum(f, np.ones_like(f), u))
            for n, u in (("gx", "deg/h"), ("ax", "m/s^2"), ("gy", "deg/h"))]
    assert spectrum_block(NS(axes=axes), None, tmp_path)
    assert ylabels == [["PSD [(deg/h)²/Hz]", "PSD [(m/s²)²/Hz]"]]


def test_a_result_without_spectra_draws_no_fig2(tmp_path, ylabels):
    assert spectrum_block(NS(axes=[NS(name="gz", spectrum=None)]), None, tmp_path) == ""
    assert ylabels == [] and not (tmp_path / "fig2_spectrum.png").exists()


def test_the_temperature_line_is_the_results_not_recomputed(tmp_path, monkeypatch):
    temp = 20.0 + 0.01 * np.arange(200)
    rec = from_array(np.zeros((200, 1)), dt_s=0.1, axis_names=["gz"])
    rec = type(rec)(**{**rec.__dict__, "temperature_c": temp})
    stored = temperature_summary(temp, rec.dt_s).to_dict()

    def fail(*args, **kwargs):
        raise AssertionError("the report summarised the temperature itself")

    monkeypatch.setattr(report_temperature, "temperature_summary", fail)
    html = temperature_block(NS(record={"temperature": stored}), rec, tmp_path)
    assert summary_line(stored) in html and (tmp_path / "fig_temperature.png").is_file()
    assert temperature_block(NS(record={"temperature": None}), rec, tmp_path) == ""
