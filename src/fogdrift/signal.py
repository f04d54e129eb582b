"""The signal description: the facts about a record's numbers, made once by :mod:`fogdrift.io` and handed on.

A :class:`SignalDescription` is a frozen record of the **sampling** (sample interval, where it came
from, the native interval and the block-averaging factor) and of each **channel** (its name, the
physical quantity, the unit as read and where that unit came from, the factor to the internal unit).
:func:`fogdrift.io.load` makes it once, while it reads the file; the record
(:attr:`fogdrift.io.GyroRecord.signal`), the pipeline's results, the bundle and ``compensate`` carry
it and read its fields back.  Nothing downstream re-parses a unit, re-derives the provenance of the
rate from free text, or recomputes the decimation factor.

The quantity chooses the internal unit (:data:`fogdrift.units.INTERNAL_UNITS`): ``"angular_rate"``
is converted to deg/h, ``"specific_force"`` to m/s^2.

Examples
--------
>>> from fogdrift.io import from_array
>>> rec = from_array([0.1, 0.1, 0.2, 0.2], dt_s=0.01, unit="inc:arcsec", axis_names=["gz"])
>>> s = rec.signal
>>> s.sampling.rate_hz, s.sampling.dt_source, s.channels[0].scale_to_internal, s.channels[0].internal_unit
(100.0, 'argument', 100.0, 'deg/h')
>>> s.averaged(2).sampling.block_average_factor
2
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from . import units
from .errors import ConfigError

__all__ = ["Sampling", "Channel", "SignalDescription", "DT_SOURCES", "UNIT_SOURCES", "channel_unit", "record_sampling",
           "RecordUnits", "record_units"]

#: Where a sample interval can come from: the file's time column, the time stamps the format carries
#: (bag, miniSEED, HDF5 time dataset), the sample-rate option (``rate_hz``/``dt_s``, the CLI's
#: ``--rate``), a library argument (:func:`fogdrift.io.from_array`), or a bundle's manifest.
DT_SOURCES = ("time column", "time stamps", "rate option", "argument", "bundle")

#: Where a channel's unit (or a time column's unit) can come from: the ``unit``/``time_unit`` option
#: (``--unit``/``--time-unit``), the file's header (a ``gz[deg/s]`` cell, a ``t_s`` name suffix, a
#: format's metadata), a library argument, or a bundle's manifest.
UNIT_SOURCES = ("option", "header", "argument", "bundle")

#: Relative tolerance of "dt_s = block_average_factor x native_dt_s".
_FACTOR_RTOL = 1e-9


def channel_unit(text, quantity: str | None) -> units.UnitSpec:
    """A channel's unit string (an option, a header cell, a saved description) as a :class:`~fogdrift.units.UnitSpec`.

    The io layer's one door to :func:`fogdrift.units.parse_unit`: the readers, the unit option, the bundle's
    manifest and the saved description all parse through here, so the quantity is always stated (None: a unit
    of any quantity) and the errors are the parser's own.

    Raises
    ------
    ConfigError
        ``text`` is not a unit of ``quantity``; the message lists the valid units.

    Examples
    --------
    >>> channel_unit("g", None).quantity, channel_unit(" deg/s ", "angular_rate").text
    ('specific_force', 'deg/s')
    """
    return units.parse_unit(text, quantity)


def _choice(value, allowed, name):
    if value not in allowed:
        raise ConfigError(f"{name} must be one of {list(allowed)}; got {value!r}")
    return value


@dataclass(frozen=True)
class Sampling:
    """How a record is sampled, and where that came from.

    Attributes
    ----------
    dt_s : float
        Sample interval in s (after block averaging).
    dt_source : str
        One of :data:`DT_SOURCES`.
    native_dt_s : float
        Sample interval in s of the data as read, before block averaging.
    block_average_factor : int
        ``dt_s / native_dt_s``, an integer >= 1 (1 = native rate).
    time_column : str or None
        Name of the time column the interval was taken from (or checked against), else None.
    time_unit : str or None
        Unit of that time column (:data:`fogdrift.units.TIME_UNITS`), else None.
    time_unit_source : str or None
        One of :data:`UNIT_SOURCES` for ``time_unit``, else None.
    """

    dt_s: float
    dt_source: str
    native_dt_s: float | None = None
    block_average_factor: int = 1
    time_column: str | None = None
    time_unit: str | None = None
    time_unit_source: str | None = None

    def __post_init__(self):
        dt = units.check_dt_s(self.dt_s, "dt_s")
        object.__setattr__(self, "dt_s", dt)
        _choice(self.dt_source, DT_SOURCES, "dt_source")
        m = self.block_average_factor
        if isinstance(m, bool) or not isinstance(m, int) or m < 1:
            raise ConfigError(f"block_average_factor must be an integer >= 1; got {m!r}")
        native = dt / m if self.native_dt_s is None else units.check_dt_s(self.native_dt_s, "native_dt_s")
        if abs(m * native - dt) > _FACTOR_RTOL * dt:
            raise ConfigError(f"dt_s {dt!r} is not block_average_factor {m} x native_dt_s {native!r}")
        object.__setattr__(self, "native_dt_s", native)
        if self.time_unit is not None:
            units.time_scale_to_s(self.time_unit)
        if self.time_unit_source is not None:
            _choice(self.time_unit_source, UNIT_SOURCES, "time_unit_source")

    @property
    def rate_hz(self) -> float:
        """Sample rate in Hz, ``1 / dt_s``."""
        return 1.0 / self.dt_s

    @property
    def native_rate_hz(self) -> float:
        """Sample rate of the data as read, in Hz (``block_average_factor / dt_s``)."""
        return self.block_average_factor / self.dt_s

    def averaged(self, m: int) -> "Sampling":
        """The sampling after averaging blocks of ``m`` samples: ``dt_s`` and the factor times ``m``."""
        return replace(self, dt_s=m * self.dt_s, block_average_factor=self.block_average_factor * int(m))

    def to_dict(self) -> dict:
        """JSON-ready dict of the fields plus ``rate_hz`` and ``native_rate_hz``."""
        return {"dt_s": self.dt_s, "rate_hz": self.rate_hz, "dt_source": self.dt_source,
                "native_dt_s": self.native_dt_s, "native_rate_hz": self.native_rate_hz,
                "block_average_factor": self.block_average_factor, "time_column": self.time_column,
                "time_unit": self.time_unit, "time_unit_source": self.time_unit_source}

    @classmethod
    def from_dict(cls, d) -> "Sampling":
        """Inverse of :meth:`to_dict` (the derived rates are ignored); ConfigError on a bad field."""
        if not isinstance(d, dict):
            raise ConfigError(f"sampling must be an object; got {type(d).__name__}")
        try:
            return cls(dt_s=d["dt_s"], dt_source=d["dt_source"], native_dt_s=d.get("native_dt_s"),
                       block_average_factor=d.get("block_average_factor", 1), time_column=d.get("time_column"),
                       time_unit=d.get("time_unit"), time_unit_source=d.get("time_unit_source"))
        except KeyError as exc:
            raise ConfigError(f"sampling has no {exc.args[0]!r}") from None


@dataclass(frozen=True)
class Channel:
    """One channel of a record: its physical quantity and how its numbers were brought to the internal unit.

    Attributes
    ----------
    name : str
        Axis (column) name.
    unit : fogdrift.units.UnitSpec
        The unit the numbers were read in, as parsed once by :func:`channel_unit`
        (``unit.text`` is ``"deg/s"``, ``"inc:arcsec"``, ``"mg"`` ...; ``unit.quantity`` the
        physical quantity).
    unit_source : str
        One of :data:`UNIT_SOURCES`: where the unit came from.
    declared_unit : str or None
        The unit the file declared for this column (None where it declares none); may differ from
        the unit as read when the unit option overrides it.
    scale_to_internal : float
        The factor that was applied to the numbers as read to get the internal unit (for an
        increment unit it includes ``1 / native_dt_s``).
    """

    name: str
    unit: units.UnitSpec
    unit_source: str
    declared_unit: str | None
    scale_to_internal: float

    def __post_init__(self):
        if not isinstance(self.unit, units.UnitSpec):
            raise ConfigError(f"unit must be a fogdrift.units.UnitSpec (from units.parse_unit); got {self.unit!r}")
        _choice(self.unit_source, UNIT_SOURCES, "unit_source")
        try:
            scale = math.nan if isinstance(self.scale_to_internal, bool) else float(self.scale_to_internal)
        except (TypeError, ValueError, OverflowError):
            scale = math.nan
        if not (math.isfinite(scale) and scale > 0):
            raise ConfigError(f"scale_to_internal must be a finite number > 0; got {self.scale_to_internal!r}")
        object.__setattr__(self, "scale_to_internal", scale)
        object.__setattr__(self, "name", str(self.name))
        object.__setattr__(self, "declared_unit", None if self.declared_unit is None else str(self.declared_unit))

    @property
    def quantity(self) -> str:
        """``"angular_rate"`` or ``"specific_force"`` (:data:`fogdrift.units.QUANTITIES`)."""
        return self.unit.quantity

    @property
    def unit_as_read(self) -> str:
        """The unit string as read (``"deg/s"``)."""
        return self.unit.text

    @property
    def internal_unit(self) -> str:
        """The internal unit chosen by the quantity (deg/h or m/s^2)."""
        return self.unit.internal_unit

    def to_dict(self) -> dict:
        """JSON-ready dict: name, quantity, unit_as_read, unit_source, declared_unit, scale_to_internal,
        internal_unit."""
        return {"name": self.name, "quantity": self.quantity, "unit_as_read": self.unit_as_read,
                "unit_source": self.unit_source, "declared_unit": self.declared_unit,
                "scale_to_internal": self.scale_to_internal, "internal_unit": self.internal_unit}

    @classmethod
    def from_dict(cls, d) -> "Channel":
        """Inverse of :meth:`to_dict` (the unit parsed for the stated quantity); ConfigError on a bad field."""
        if not isinstance(d, dict):
            raise ConfigError(f"channel must be an object; got {type(d).__name__}")
        try:
            spec = channel_unit(d["unit_as_read"], d["quantity"])
            return cls(name=d["name"], unit=spec, unit_source=d["unit_source"], declared_unit=d.get("declared_unit"),
                       scale_to_internal=d["scale_to_internal"])
        except KeyError as exc:
            raise ConfigError(f"channel has no {exc.args[0]!r}") from None


@dataclass(frozen=True)
class SignalDescription:
    """The sampling and the channels of a record (see the module docstring).

    Attributes
    ----------
    sampling : Sampling
    channels : tuple of Channel
        One per axis, in the record's column order; names unique.
    """

    sampling: Sampling
    channels: tuple[Channel, ...]

    def __post_init__(self):
        if not isinstance(self.sampling, Sampling):
            raise ConfigError(f"sampling must be a Sampling; got {type(self.sampling).__name__}")
        chans = tuple(self.channels)
        if not chans or not all(isinstance(c, Channel) for c in chans):
            raise ConfigError("channels must be one or more Channel objects")
        names = [c.name for c in chans]
        if len(set(names)) != len(names):
            raise ConfigError(f"channel names must be unique; got {names}")
        object.__setattr__(self, "channels", chans)

    @property
    def names(self) -> tuple[str, ...]:
        """The channels' names."""
        return tuple(c.name for c in self.channels)

    def channel(self, name: str) -> Channel:
        """The channel called ``name``; ConfigError listing the names if there is none."""
        for c in self.channels:
            if c.name == name:
                return c
        raise ConfigError(f"no channel {name!r}; expected one of {list(self.names)}")

    def select(self, idx) -> "SignalDescription":
        """The description of the channels at positions ``idx`` (in that order)."""
        return replace(self, channels=tuple(self.channels[i] for i in idx))

    def averaged(self, m: int) -> "SignalDescription":
        """The description after block averaging by ``m`` (the channels are unchanged)."""
        return replace(self, sampling=self.sampling.averaged(m))

    def to_dict(self) -> dict:
        """JSON-ready: ``{"sampling": {...}, "channels": [{...}, ...]}``."""
        return {"sampling": self.sampling.to_dict(), "channels": [c.to_dict() for c in self.channels]}

    @classmethod
    def from_dict(cls, d) -> "SignalDescription":
        """Inverse of :meth:`to_dict`; ConfigError (one line) on a missing or bad field."""
        if not isinstance(d, dict) or not isinstance(d.get("channels"), list):
            raise ConfigError("signal must be an object with 'sampling' and a list of 'channels'")
        return cls(sampling=Sampling.from_dict(d.get("sampling")),
                   channels=tuple(Channel.from_dict(c) for c in d["channels"]))


#: Keys under which a record block may state its sampling beside (or instead of) ``signal``: they are never read,
#: and a block with one of them but no ``signal`` is refused (the interval's provenance is not in it).
_RECORD_SAMPLING_SYNONYMS = ("dt_s", "fs_hz", "native_fs_hz", "block_average_factor")


def record_sampling(block, where: str = "the record") -> Sampling | None:
    """The sampling a result document's record block states: its ``signal.sampling``, the one home of the sample
    interval, the native interval and the block-averaging factor in every written document (the ``record`` of
    ``allan.json`` and ``noise.json``, the ``record`` and ``model_record`` of an analysis result).  Every reader of
    a result document gets the sampling here.

    A block that also repeats the sampling as ``dt_s``/``fs_hz``/``native_fs_hz``/``block_average_factor`` beside
    its ``signal`` is read the same way: those keys are ignored.

    Parameters
    ----------
    block : dict or None
        The record block as read (:meth:`fogdrift.io.GyroRecord.metadata` written to JSON).
    where : str
        What the messages name (``"the record"``, ``"the model_record"``); a caller that read a file puts its path
        in front.

    Returns
    -------
    Sampling or None
        None for a block that states no sampling at all (a hand-written result; the caller decides).

    Raises
    ------
    ConfigError
        One line naming ``where``: the block states the interval only under the keys above (no ``signal``), or
        its ``signal.sampling`` is not a valid sampling.

    Examples
    --------
    >>> from fogdrift.io import from_array
    >>> block = from_array([1.0, 2.0, 3.0, 4.0], dt_s=0.01).to_rate(50.0).metadata()
    >>> smp = record_sampling(block)
    >>> smp.rate_hz, smp.native_rate_hz, smp.block_average_factor
    (50.0, 100.0, 2)
    """
    signal = _block_signal(block, where, _RECORD_SAMPLING_SYNONYMS, "its sampling", "'signal.sampling'", "it")
    if signal is None:
        return None
    try:
        return Sampling.from_dict(signal.get("sampling"))
    except ConfigError as exc:
        raise ConfigError(f"{where}'s signal.sampling: {exc}") from None


#: Keys under which a record block may state its units beside (or instead of) ``signal``: they are never read, and a
#: block with one of them but no ``signal`` is refused (each channel's unit and its provenance are not in it).
_RECORD_UNIT_SYNONYMS = ("input_unit", "declared_units", "scale_to_dph", "rate_unit", "scale_to_internal",
                         "internal_unit")


@dataclass(frozen=True)
class RecordUnits:
    """The units a result document's record block states, read from its ``signal.channels``
    (:func:`record_units`).

    Attributes
    ----------
    channels : tuple of Channel
        One per axis, in the record's order.
    """

    channels: tuple[Channel, ...]

    @property
    def input_unit(self) -> str:
        """The unit the numbers were read in: the one unit, or ``name=unit,...`` when the channels differ (the
        text of :attr:`fogdrift.io.GyroRecord.input_unit`)."""
        texts = [c.unit_as_read for c in self.channels]
        if len(set(texts)) == 1:
            return texts[0]
        return ",".join(f"{c.name}={c.unit_as_read}" for c in self.channels)

    @property
    def declared_units(self) -> tuple[str | None, ...]:
        """The unit each column declared in the file (None where it declared none)."""
        return tuple(c.declared_unit for c in self.channels)

    @property
    def scale_to_internal(self) -> float | None:
        """The one factor from the numbers as read to the internal unit, None when the channels' factors differ."""
        scales = {c.scale_to_internal for c in self.channels}
        return scales.pop() if len(scales) == 1 else None

    @property
    def internal_unit(self) -> str | None:
        """The one internal unit of the channels (deg/h or m/s^2), None for a gyro and accelerometer record."""
        names = {c.internal_unit for c in self.channels}
        return names.pop() if len(names) == 1 else None

    @property
    def all_gyro(self) -> bool:
        """True when every channel is an angular rate."""
        return all(c.quantity == "angular_rate" for c in self.channels)


def record_units(block, where: str = "the record") -> RecordUnits | None:
    """The units a result document's record block states: its ``signal.channels`` (each channel's quantity, unit as
    read, where the unit came from, declared unit, factor to the internal unit), the one home of the units in every
    written document (the ``record`` of ``allan.json`` and ``noise.json``, the ``record`` and ``model_record`` of an
    analysis result).  Every reader of a result document gets the units here.

    A block that also repeats the units as ``input_unit``/``declared_units``/``scale_to_dph``/``rate_unit``/
    ``scale_to_internal``/``internal_unit`` beside its ``signal`` is read the same way: those keys are ignored.

    Parameters
    ----------
    block : dict or None
        The record block as read (:meth:`fogdrift.io.GyroRecord.metadata` written to JSON).
    where : str
        What the messages name; a caller that read a file puts its path in front.

    Returns
    -------
    RecordUnits or None
        None for a block that states no units at all (a hand-written result; the caller decides).

    Raises
    ------
    ConfigError
        One line naming ``where``: the block states the units only under the keys above (no ``signal``), or its
        ``signal.channels`` is not a valid list of channels.

    Examples
    --------
    >>> from fogdrift.io import from_array
    >>> u = record_units(from_array([1.0, 2.0, 3.0], dt_s=0.01, unit="deg/s").metadata())
    >>> u.input_unit, u.scale_to_internal, u.internal_unit
    ('deg/s', 3600.0, 'deg/h')
    """
    signal = _block_signal(block, where, _RECORD_UNIT_SYNONYMS, "its units", "'signal.channels'", "them")
    if signal is None:
        return None
    chans = signal.get("channels")
    if not isinstance(chans, list) or not chans:
        raise ConfigError(f"{where}'s signal.channels: expected a list of one or more channels; got {chans!r}")
    try:
        return RecordUnits(tuple(Channel.from_dict(c) for c in chans))
    except ConfigError as exc:
        raise ConfigError(f"{where}'s signal.channels: {exc}") from None


def _block_signal(block, where, synonyms, what, home, pronoun):
    """A written record block's ``signal`` object, or None when the block states none (nor ``what`` under its old
    ``synonyms``: refused, one line naming ``where`` and the ``home`` this fogdrift reads)."""
    if not isinstance(block, dict):
        return None
    signal = block.get("signal")
    if signal is None:
        old = [k for k in synonyms if block.get(k) is not None]
        if old:
            raise ConfigError(f"{where} states {what} only as {', '.join(old)}, not in {home} where this fogdrift "
                              f"reads {pronoun}; re-run the fogdrift command that wrote the file")
        return None
    if not isinstance(signal, dict):
        raise ConfigError(f"{where}'s signal: expected an object; got {type(signal).__name__}")
    return signal
