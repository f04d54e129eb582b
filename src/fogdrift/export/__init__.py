"""``fogdrift export``: the noise model of a gyro / accelerometer result written for the estimators people run.

Modules, one concept each:

* :mod:`~fogdrift.export.conversions`: unit conversions (IEEE units <-> SI densities, continuous <-> discrete);
* :mod:`~fogdrift.export.model`: the per-channel noise model taken from a saved ``allan`` / ``noise`` result, and
  the ``--missing`` policy for terms the record does not resolve;
* :mod:`~fogdrift.export.discretize`: the filter-ready continuous-time state-space model and its exact (Van Loan)
  discretisation;
* :mod:`~fogdrift.export.targets`: the one registry of targets (name -> writer, file name, units, source);
* :mod:`~fogdrift.export.writers`: one writer per target.

:func:`build_context` gathers channels from result files; :func:`render` returns the text of one target.
"""

from __future__ import annotations

from ..errors import ConfigError
from .conversions import _rate
from .model import MISSING_POLICIES, ChannelModel, channels_from_result, load_result
from .targets import TARGETS, ExportContext, get_target, target_names

__all__ = ["MISSING_POLICIES", "TARGETS", "ExportContext", "ChannelModel", "build_context", "render",
           "target_names", "parse_targets", "channels_from_files"]


def channels_from_files(paths, quantity: str | None) -> list[ChannelModel]:
    """Channels of ``quantity`` (``"gyro"`` / ``"accel"``; None: each axis as its units say) from result files."""
    out = []
    for p in paths or ():
        out += channels_from_result(load_result(p), str(p), expect=quantity)
    return out


def build_context(gyro=(), accel=(), *, results=(), channels=(), rate_hz=None, missing="bound",
                  topic="/imu0") -> ExportContext:
    """An :class:`ExportContext` from ``--gyro`` / ``--accel`` result files, ``--result`` files (each axis taken as
    what its units say: a six-channel result), and/or ready channels.

    ``rate_hz`` defaults to the records' sample rate (one rate for all channels, else it must be given).

    Raises
    ------
    ConfigError
        No channel, an unknown ``missing`` policy, or records at different rates without ``rate_hz``.
    """
    if missing not in MISSING_POLICIES:
        raise ConfigError(f"{{opt:missing}} must be one of {', '.join(MISSING_POLICIES)}; got {missing!r}")
    chans = (list(channels) + channels_from_files(gyro, "gyro") + channels_from_files(accel, "accel")
             + channels_from_files(results, None))
    if not chans:
        raise ConfigError("nothing to export: pass a log, or a result file with {opt:gyro} / {opt:accel} / "
                          "{opt:result}")
    names = {}
    for ch in chans:
        key = (ch.quantity, ch.name)
        if key in names:
            raise ConfigError(f"two {ch.quantity} channels are called {ch.name!r} ({names[key]} and {ch.source_file}); "
                              "export one result per quantity")
        names[key] = ch.source_file
    if rate_hz is None:
        rates = sorted({round(ch.rate_hz, 9) for ch in chans})
        if len(rates) != 1:
            raise ConfigError(f"the records have different sample rates ({', '.join(f'{r:g}' for r in rates)} Hz); "
                              "pass the filter's IMU rate with {opt:rate}")
        rate_hz = rates[0]

    rate = _rate(rate_hz)
    return ExportContext(gyro=[c for c in chans if c.quantity == "gyro"],
                         accel=[c for c in chans if c.quantity == "accel"],
                         rate_hz=rate, missing=missing, topic=topic)


def parse_targets(text: str) -> list[str]:
    """``"kalibr,orbslam3"`` or ``"all"`` -> target names (an unknown name is refused listing the valid ones)."""
    items = [t.strip().lower() for t in str(text).split(",") if t.strip()]
    if not items:
        raise ConfigError(f"no export target given; expected one or more of {', '.join(TARGETS)}, or 'all'")
    if items == ["all"]:
        return target_names()
    return [get_target(t).name for t in items]


def render(target: str, ctx: ExportContext) -> str:
    """The text of ``target``'s file for ``ctx`` (its notes are added to ``ctx.notes``)."""
    return get_target(target).writer(ctx)
