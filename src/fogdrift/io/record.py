"""The in-memory gyro record: :class:`GyroRecord`, block averaging and the modelling-rate rule.

A record is uniformly sampled, in deg/h, with time in s.  Sample ``k`` covers
``[t0_s + k dt_s, t0_s + (k+1) dt_s)``, so ``duration_s = n_samples * dt_s`` and block averages
keep ``t0_s``.  Nothing here reads files (see :mod:`fogdrift.io.load`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import InitVar, dataclass

import numpy as np

from .. import units
from .._util import check_distinct_names
from ..errors import ConfigError, DataFormatError, InsufficientDataError
from ..signal import Channel, Sampling, SignalDescription, channel_unit
from ..temperature import temperature_summary
from .channel_quantity import check_name
from ._checks import first_nonfinite, int_arg, split_keys, take_columns, to_dph

__all__ = ["GyroRecord", "block_average", "from_array", "decimation_factor"]

#: Relative tolerance for "target interval is an integer multiple of dt_s" in :meth:`GyroRecord.block_average`.
_MULTIPLE_RTOL = 1e-6
#: Relative tolerance for "the native rate is an integer multiple of the model rate" (:func:`decimation_factor`).
RATE_RTOL = 1e-9


@dataclass(frozen=True, eq=False, kw_only=True)
class GyroRecord:
    """A uniformly sampled multi-axis record of gyro and/or accelerometer channels, each in its internal unit.

    Parameters
    ----------
    data_internal : ndarray, shape (n_samples, n_axes), float64
        Each channel in its quantity's internal unit (:attr:`quantities`, :data:`fogdrift.units.INTERNAL_UNITS`):
        an angular rate in deg/h, a specific force in m/s^2.  Stored as a read-only view (possibly of a memory
        map): copy it before modifying.  :attr:`rate_dph` reads the same array for a record of gyro channels only.
    dt_s : float, optional
        Sample interval in s (> 0): builds the default :attr:`signal`; with a ``signal`` it may be left out, and
        if given must agree with it.  Read back as the property :attr:`dt_s`, which is ``signal.sampling.dt_s``:
        the record stores its sampling once, in :attr:`signal`.
    axis_names : tuple of str
        One unique name per column of ``data_internal``.
    source : str
        File path, or ``"<array>"``.
    input_unit : str
        Unit of the input numbers as given (``"deg/s"``, ``"inc:arcsec"`` ...).
    scale_to_internal : float
        Factor that was applied to the input numbers to get the internal unit (1 for channels read in several units;
        each channel's own is in :attr:`signal`).  :attr:`scale_to_dph` reads it for a record of gyro channels.
    t0_s : float, optional
        Time of the first sample in s.
    notes : tuple of str, optional
        Provenance ("segment 2 of 3: samples ...", "block-averaged x100 ...").
    sha256 : str or None, optional
        Hex SHA-256 of the input file's bytes, recorded while the file was read (None for
        arrays).
    declared_units : tuple of (str or None), optional
        Unit each axis declared in the file (``gz[deg/s]`` header cells), None where the
        file declares none.  Default: None for every axis.
    block_average_factor : int, optional
        Product of the block-averaging factors applied since loading (1 = native rate; the default signal's):
        as ``dt_s``, an argument only, read back from :attr:`signal`.
    temperature_c : ndarray, shape (n_samples,), optional
        Temperature in deg C carried with the log (``load(..., temperature=NAME)``), one value
        per sample; kept through :meth:`slice`, :meth:`select` and block averaging (averaged
        like the rates).  None when the log has none.  Stored read-only.
    signal : fogdrift.signal.SignalDescription, optional
        The sampling and channels as :func:`fogdrift.io.load` described them while reading (where
        the interval and each unit came from); kept through :meth:`select` and block averaging.
        Default: made here from ``dt_s``, ``input_unit``, ``scale_to_internal``, ``declared_units`` and
        ``block_average_factor`` with the sources ``"argument"``.  Must agree with those fields.
        The one home of the sampling: :attr:`dt_s` and :attr:`block_average_factor` read it.

    Every argument is a keyword.

    Notes
    -----
    Sample ``k`` covers ``[t0_s + k dt_s, t0_s + (k + 1) dt_s)``; ``duration_s`` is
    ``n_samples * dt_s``.  Records compare by identity (they hold arrays).
    """

    data_internal: np.ndarray
    dt_s: InitVar[float | None] = None
    axis_names: tuple[str, ...]
    source: str
    input_unit: str
    scale_to_internal: float
    t0_s: float = 0.0
    notes: tuple[str, ...] = ()
    sha256: str | None = None
    declared_units: tuple[str | None, ...] = ()
    block_average_factor: InitVar[int | None] = None
    temperature_c: np.ndarray | None = None
    signal: SignalDescription | None = None

    def __post_init__(self, dt_s, block_average_factor):
        r = self.data_internal
        if not isinstance(r, np.ndarray) or r.ndim != 2 or r.dtype != np.float64:
            raise ConfigError(
                "data_internal must be a float64 array of shape (n_samples, n_axes); got "
                f"{type(r).__name__} {getattr(r, 'dtype', '')} {getattr(r, 'shape', '')}".rstrip()
            )
        if r.flags.writeable:
            r = r.view()
            r.flags.writeable = False
            object.__setattr__(self, "data_internal", r)
        names = tuple(str(a) for a in self.axis_names)
        if len(names) != r.shape[1]:
            raise ConfigError(f"axis_names must name the {r.shape[1]} columns of data_internal; got {names!r}")
        if len(set(names)) != len(names):
            raise ConfigError(f"axis_names must be unique; got {names!r}")
        check_distinct_names(names, "axis names", "rename a column (the file's header) or select one with "
                                                  "{opt:columns}")
        object.__setattr__(self, "axis_names", names)
        declared = tuple(None if u is None else str(u) for u in self.declared_units) or (None,) * len(names)
        if len(declared) != len(names):
            raise ConfigError(f"declared_units must give one unit (or None) per axis {names!r}; got {declared!r}")
        object.__setattr__(self, "declared_units", declared)
        if dt_s is None and self.signal is None:
            raise ConfigError("a record needs its sample interval: give dt_s (s) or a signal description")
        dt = None if dt_s is None else units.check_dt_s(dt_s, "dt_s")
        object.__setattr__(self, "t0_s", float(self.t0_s))
        object.__setattr__(self, "scale_to_internal", float(self.scale_to_internal))
        object.__setattr__(self, "source", str(self.source))
        object.__setattr__(self, "notes", tuple(str(n) for n in self.notes))
        object.__setattr__(self, "sha256", None if self.sha256 is None else str(self.sha256))
        factor = None if block_average_factor is None else int_arg(block_average_factor, "block_average_factor")
        if factor is not None and factor < 1:
            raise ConfigError(f"block_average_factor must be an integer >= 1; got {factor}")
        if self.temperature_c is not None:
            temp = np.asarray(self.temperature_c)
            if temp.dtype != np.float64 or temp.shape != (r.shape[0],):
                raise ConfigError(
                    f"temperature_c must be a float64 array of shape ({r.shape[0]},), one value per sample; got "
                    f"{temp.dtype} {temp.shape}"
                )
            if temp.flags.writeable:
                temp = temp.view()
                temp.flags.writeable = False
            object.__setattr__(self, "temperature_c", temp)
        if self.signal is None:
            object.__setattr__(self, "signal", self._default_signal(dt, 1 if factor is None else factor))
        else:
            self._check_signal(dt, factor)

    @property
    def rate_dph(self) -> np.ndarray:
        """The angular rates in deg/h: :attr:`data_internal` of a record whose channels are all gyros.

        Raises
        ------
        AttributeError
            The record has accelerometer channels: their numbers are m/s^2, not deg/h (read :attr:`data_internal`).
        """
        self._only_gyros("read .data_internal (each channel in its internal unit)")
        return self.data_internal

    def _only_gyros(self, instead: str) -> None:
        """Refuse a deg/h name on a record with accelerometer channels (AttributeError naming them and ``instead``)."""
        accel = [n for n, q in zip(self.axis_names, self.quantities) if q != "angular_rate"]
        if accel:
            raise AttributeError(f"{', '.join(accel)} of {self.source} hold a specific force in m/s^2, not an angular "
                                 f"rate in deg/h: {instead}")

    @property
    def scale_to_dph(self) -> float:
        """The factor from the input numbers to deg/h: :attr:`scale_to_internal` of a record of gyro channels.

        Raises
        ------
        AttributeError
            The record has accelerometer channels (their factor is to m/s^2: read :attr:`scale_to_internal`).
        """
        self._only_gyros("read .scale_to_internal (the factor to each channel's internal unit)")
        return self.scale_to_internal

    @property
    def quantities(self) -> tuple[str, ...]:
        """Each channel's quantity (``"angular_rate"`` or ``"specific_force"``), from :attr:`signal`."""
        return tuple(c.quantity for c in self.signal.channels)

    def _default_signal(self, dt_s: float, factor: int) -> SignalDescription:
        """The description of a record built from its fields and arguments (no file: every source is
        "argument")."""
        spec = channel_unit(self.input_unit, None)
        sampling = Sampling(dt_s=dt_s, dt_source="argument", block_average_factor=factor)
        return SignalDescription(sampling, tuple(
            Channel(name=n, unit=spec, unit_source="argument", declared_unit=d, scale_to_internal=self.scale_to_internal)
            for n, d in zip(self.axis_names, self.declared_units)))

    def _check_signal(self, dt_s, factor) -> None:
        """``signal`` describes this record: the sampling arguments given (None: not given) and the fields."""
        sig = self.signal
        if not isinstance(sig, SignalDescription):
            raise ConfigError(f"signal must be a fogdrift.signal.SignalDescription; got {type(sig).__name__}")
        smp = sig.sampling
        bad = []
        if dt_s is not None and abs(smp.dt_s - dt_s) > 1e-12 * dt_s:
            bad.append(f"dt_s {smp.dt_s!r} vs {dt_s!r}")
        if factor is not None and smp.block_average_factor != factor:
            bad.append(f"block_average_factor {smp.block_average_factor} vs {factor}")
        if sig.names != self.axis_names:
            bad.append(f"channels {list(sig.names)} vs axes {list(self.axis_names)}")
        mixed = len({(c.unit_as_read, c.scale_to_internal) for c in sig.channels}) > 1
        for c, d in zip(sig.channels, self.declared_units):
            # one unit for all channels: the legacy fields are that unit and its factor; channels of different
            # units (a gyro+accelerometer log): input_unit lists name=unit and scale_to_internal is 1 (no one factor)
            unit_ok = (f"{c.name}={c.unit_as_read}" in self.input_unit.split(",")) if mixed \
                else c.unit_as_read == self.input_unit.strip()
            scale_ok = self.scale_to_internal == 1.0 if mixed else c.scale_to_internal == self.scale_to_internal
            if not unit_ok or not scale_ok or c.declared_unit != d:
                bad.append(f"channel {c.name!r} ({c.quantity}, {c.unit_as_read}, x{c.scale_to_internal:.10g}) vs "
                           f"the record ({self.input_unit}, x{self.scale_to_internal:.10g})")
                break
        if bad:
            raise ConfigError("signal does not describe this record: " + "; ".join(bad))

    @property
    def sampling(self) -> Sampling:
        """The sampling part of :attr:`signal` (interval, its source, native interval, factor)."""
        return self.signal.sampling

    # -- sizes ---------------------------------------------------------------------------------
    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.data_internal.shape[0])

    @property
    def n_axes(self) -> int:
        """Number of axes (columns)."""
        return int(self.data_internal.shape[1])

    @property
    def fs_hz(self) -> float:
        """Sample rate in Hz (``1 / dt_s``)."""
        return 1.0 / self.dt_s

    @property
    def native_fs_hz(self) -> float:
        """Sample rate of the loaded data before block averaging, in Hz."""
        return self.block_average_factor / self.dt_s

    @property
    def duration_s(self) -> float:
        """Record length in s, ``n_samples * dt_s``."""
        return self.n_samples * self.dt_s

    # -- axes and ranges -----------------------------------------------------------------------
    def _axis_index(self, key) -> int:
        n = self.n_axes
        if isinstance(key, (int, np.integer)) and not isinstance(key, bool):
            if -n <= int(key) < n:
                return int(key) % n
        elif isinstance(key, str):
            k = key.strip()
            if k in self.axis_names:
                return self.axis_names.index(k)
            if k.isdigit() and int(k) < n:
                return int(k)
            folded = [i for i, a in enumerate(self.axis_names) if a.lower() == k.lower()]
            if len(folded) == 1:
                return folded[0]
        raise ConfigError(
            f"unknown axis {key!r}; expected one of {list(self.axis_names)} or an index 0..{n - 1}"
        )

    def axis(self, key) -> np.ndarray:
        """Rate of one axis in deg/h, shape (n_samples,), a read-only view.

        Parameters
        ----------
        key : int or str
            Axis name, or 0-based index (negative counts from the end).

        Raises
        ------
        ConfigError
            If ``key`` names no axis.
        """
        return self.data_internal[:, self._axis_index(key)]

    def select(self, keys) -> "GyroRecord":
        """Record with a subset of the axes, in the order given.

        Parameters
        ----------
        keys : int, str or sequence of int/str
            Axis names or 0-based indices; a string may list several separated by commas.

        Raises
        ------
        ConfigError
            If a key is unknown, repeated, or no key is given.
        """
        idx = [self._axis_index(k) for k in split_keys(keys, "keys")]
        if len(set(idx)) != len(idx):
            raise ConfigError(f"keys select an axis twice; expected distinct axes, got {keys!r}")
        signal = self.signal.select(idx)
        chans = signal.channels
        if len({(c.unit_as_read, c.scale_to_internal) for c in chans}) == 1:  # one unit again: its legacy fields
            unit, scale = chans[0].unit_as_read, chans[0].scale_to_internal
        else:
            unit, scale = ",".join(f"{c.name}={c.unit_as_read}" for c in chans), 1.0
        return dataclasses.replace(
            self, data_internal=take_columns(self.data_internal, idx), axis_names=tuple(self.axis_names[i] for i in idx),
            declared_units=tuple(self.declared_units[i] for i in idx), signal=signal, input_unit=unit,
            scale_to_internal=scale,
        )

    def slice(self, start: int, stop: int) -> "GyroRecord":
        """Record of samples ``start .. stop-1`` (Python semantics for negative values).

        ``t0_s`` becomes ``t0_s + start * dt_s``; a note records the range.

        Raises
        ------
        ConfigError
            If the range is empty or outside ``0 .. n_samples``.
        """
        n = self.n_samples
        lo, hi = int_arg(start, "start"), int_arg(stop, "stop")
        lo = lo + n if lo < 0 else lo
        hi = hi + n if hi < 0 else hi
        if not 0 <= lo < hi <= n:
            raise ConfigError(
                f"slice({start!r}, {stop!r}) is empty or out of range; expected 0 <= start < stop <= {n}"
            )
        note = f"slice: samples {lo}-{hi - 1} of {n}"
        temp = None if self.temperature_c is None else self.temperature_c[lo:hi]
        return dataclasses.replace(
            self, data_internal=self.data_internal[lo:hi], t0_s=self.t0_s + lo * self.dt_s, notes=self.notes + (note,),
            temperature_c=temp,
        )

    # -- averaging -----------------------------------------------------------------------------
    def block_average(self, dt_s: float) -> "GyroRecord":
        """Average non-overlapping blocks to the longer sample interval ``dt_s`` (s).

        Parameters
        ----------
        dt_s : float
            Target interval in s; must be an integer multiple ``m`` of ``self.dt_s`` within
            1e-6 relative.  The result has ``dt_s = m * self.dt_s``; the incomplete last
            block is dropped.

        Raises
        ------
        ConfigError
            If ``dt_s`` is not a positive integer multiple (the message suggests the nearest).
        InsufficientDataError
            If the record is shorter than one block.

        See Also
        --------
        to_rate : the same by a target rate in Hz, with the stricter modelling-rate rule.

        Notes
        -----
        ``y_j = (1/m) sum_{k=0}^{m-1} x_{jm+k}``: for rate samples that are averages over their
        interval (integrating gyros, angle increments) this is exactly the average rate over
        the longer interval, so ``t0_s`` is unchanged.
        """
        target = units.check_dt_s(dt_s, "dt_s")
        ratio = target / self.dt_s
        m = int(round(ratio))
        if m < 1 or abs(m * self.dt_s - target) > _MULTIPLE_RTOL * target:
            near = sorted({max(1, math.floor(ratio)), max(1, math.ceil(ratio))})
            hint = " or ".join(f"{k * self.dt_s:.10g} s (x{k})" for k in near)
            raise ConfigError(
                f"block-average interval dt_s={dt_s!r} is not an integer multiple of the sample "
                f"interval {self.dt_s:.10g} s; expected e.g. {hint}, got {ratio:.6g} x dt_s"
            )
        return self._averaged(m)

    def to_rate(self, rate_hz: float) -> "GyroRecord":
        """The record block-averaged to the modelling rate ``rate_hz`` (Hz), by an integer factor only.

        Parameters
        ----------
        rate_hz : float
            Target rate in Hz; ``fs_hz / rate_hz`` must be an integer ``m`` within 1e-9
            relative (see :func:`decimation_factor`).

        Returns
        -------
        GyroRecord
            ``self`` when ``rate_hz`` equals ``fs_hz``; otherwise blocks of ``m`` samples
            averaged (the incomplete last block dropped), ``dt_s = m * self.dt_s``, ``fs_hz``
            the effective rate and ``block_average_factor`` multiplied by ``m``.

        Raises
        ------
        ConfigError
            If ``rate_hz`` is not ``fs_hz`` divided by an integer (the message names the
            nearest valid rates above and below) or is above ``fs_hz``.
        InsufficientDataError
            If the record is shorter than one block.

        Examples
        --------
        >>> rec = from_array(np.arange(8.0), dt_s=0.01)
        >>> low = rec.to_rate(25.0)
        >>> low.fs_hz, low.block_average_factor, low.rate_dph[:, 0].tolist()
        (25.0, 4, [1.5, 5.5])
        >>> rec.to_rate(100.0) is rec
        True
        """
        return self._averaged(decimation_factor(self.dt_s, rate_hz))

    def average_by(self, factor: int) -> "GyroRecord":
        """The record block-averaged by the integer ``factor`` (``self`` when it is 1).

        For a factor already decided, e.g. by :func:`decimation_factor` once per run: the pipeline
        and the CLI hand the factor on instead of deciding it again.

        Raises
        ------
        ConfigError
            If ``factor`` is not an integer >= 1.
        InsufficientDataError
            If the record is shorter than one block.
        """
        m = int_arg(factor, "factor")
        if m < 1:
            raise ConfigError(f"factor must be an integer >= 1; got {factor!r}")
        return self._averaged(m)

    def _averaged(self, m: int) -> "GyroRecord":
        if m == 1:
            return self
        n = self.n_samples
        if n < m:
            raise InsufficientDataError(
                f"block average to {m * self.dt_s:.10g} s needs {m} samples for one block; got {n}",
                needed=m, got=n, path=self.source,
            )
        avg = block_average(self.data_internal, m)
        dropped = n - avg.shape[0] * m
        note = f"block-averaged x{m} ({self.dt_s:.10g} s -> {m * self.dt_s:.10g} s), dropped {dropped} trailing samples"
        temp = None if self.temperature_c is None else block_average(self.temperature_c, m)
        signal = self.signal.averaged(m)
        # the sampling is the averaged signal's (replace() would pass the old dt_s and factor on)
        return dataclasses.replace(self, data_internal=avg, notes=self.notes + (note,), temperature_c=temp,
                                   signal=signal, dt_s=None, block_average_factor=None)

    def metadata(self) -> dict:
        """JSON-serialisable description (no arrays): every field but the data, plus sizes.

        Returns
        -------
        dict
            ``source, sha256, t0_s, n_samples, n_axes, duration_s, axis_names (list), notes (list), temperature,
            signal``.  ``temperature`` is None or the range and drift of the temperature carried with the
            log (:meth:`fogdrift.temperature.TemperatureSummary.to_dict`, deg C and deg C/h);
            ``signal`` is :meth:`fogdrift.signal.SignalDescription.to_dict` of :attr:`signal`, the one place
            the sampling and the units are written: ``signal.sampling`` holds the interval after block averaging
            (``dt_s``, ``rate_hz``), the interval as loaded (``native_dt_s``, ``native_rate_hz``) and
            ``block_average_factor``; each of ``signal.channels`` its quantity, unit as read and where it came
            from, declared unit, factor to the internal unit and the internal unit.  A reader of the written
            block gets them with :func:`fogdrift.signal.record_sampling` and :func:`fogdrift.signal.record_units`.
        """
        temp = None if self.temperature_c is None else temperature_summary(self.temperature_c, self.dt_s).to_dict()
        return {
            "source": self.source,
            "sha256": self.sha256,
            "t0_s": self.t0_s,
            "n_samples": self.n_samples,
            "n_axes": self.n_axes,
            "duration_s": self.duration_s,
            "axis_names": list(self.axis_names),
            "notes": list(self.notes),
            "temperature": temp,
            "signal": self.signal.to_dict(),
        }

    def __repr__(self) -> str:
        return (
            f"GyroRecord(n_samples={self.n_samples}, axes={list(self.axis_names)}, dt_s={self.dt_s:.10g}, "
            f"t0_s={self.t0_s:.10g}, input_unit={self.input_unit!r}, source={self.source!r})"
        )


# --------------------------------------------------------------------------------------------
# Functions
# --------------------------------------------------------------------------------------------
def _sampling_property(name: str, doc: str) -> property:
    return property(lambda self: getattr(self.signal.sampling, name), doc=doc)


# Set after the class is made: ``dt_s`` and ``block_average_factor`` are init-only arguments of the dataclass, and
# as attributes they read the one stored sampling, ``signal.sampling``.
GyroRecord.dt_s = _sampling_property("dt_s", "Sample interval in s (``signal.sampling.dt_s``).")
GyroRecord.block_average_factor = _sampling_property(
    "block_average_factor", "Product of the block-averaging factors applied since loading, 1 = native rate "
    "(``signal.sampling.block_average_factor``).")


def block_average(x, factor: int) -> np.ndarray:
    """Average non-overlapping blocks of ``factor`` samples along axis 0.

    Parameters
    ----------
    x : array_like, shape (n_samples, ...)
        Samples (any unit).
    factor : int
        Block length m >= 1.

    Returns
    -------
    ndarray, shape (n_samples // factor, ...), float64
        ``y_j = (1/m) sum_{k=0}^{m-1} x_{jm+k}``; the incomplete last block is dropped.

    Raises
    ------
    ConfigError
        If ``factor`` is not an integer >= 1 or ``x`` is 0-D.
    InsufficientDataError
        If ``x`` has fewer than ``factor`` samples.

    Notes
    -----
    Works on memory maps without a full copy: the kept rows are reshaped (a view) to
    ``(n_blocks, m, ...)`` and reduced along the block axis.

    Examples
    --------
    >>> block_average([1.0, 2.0, 3.0, 4.0, 5.0], 2)
    array([1.5, 3.5])
    """
    if isinstance(factor, bool) or not isinstance(factor, (int, np.integer)) or factor < 1:
        raise ConfigError(f"factor must be an integer >= 1; got {factor!r}")
    arr = np.asarray(x)
    if arr.ndim == 0:
        raise ConfigError("x must have at least one dimension (samples along axis 0); got a scalar")
    m = int(factor)
    n = arr.shape[0]
    nb = n // m
    if nb == 0:
        raise InsufficientDataError(
            f"block average needs {m} samples for one block; got {n}", needed=m, got=n
        )
    blocks = arr[: nb * m].reshape((nb, m) + arr.shape[1:])
    return blocks.mean(axis=1, dtype=np.float64)


def decimation_factor(native_dt_s: float, rate_hz: float) -> int:
    """Integer block-average factor that takes a record sampled every ``native_dt_s`` to ``rate_hz``.

    The modelling-rate rule: a record is only ever block-averaged by an integer factor, so
    ``rate_hz`` must be the native rate ``1 / native_dt_s`` divided by an integer ``m``
    (within 1e-9 relative).  Non-integer resampling would mix noise between samples and
    change the Allan variance at short tau.

    Parameters
    ----------
    native_dt_s : float
        Sample interval of the record in s.
    rate_hz : float
        Wanted rate in Hz.

    Returns
    -------
    int
        ``m >= 1`` with ``rate_hz = 1 / (m * native_dt_s)``; 1 when the rates are equal.

    Raises
    ------
    ConfigError
        If ``rate_hz`` is not finite and > 0, is above the native rate, or does not divide
        it by an integer; the message names the nearest valid rates and the option
        ``{opt:model_rate_hz}``.

    Examples
    --------
    >>> decimation_factor(0.01, 3.125)
    32
    >>> decimation_factor(0.01, 3.0)
    Traceback (most recent call last):
    ...
    fogdrift.errors.ConfigError: model rate 3 Hz does not divide the native 100 Hz by an integer; nearest valid rates: 3.03 Hz (/33), 2.941 Hz (/34); pass model_rate_hz=
    """
    dt = units.check_dt_s(native_dt_s, "native_dt_s")
    try:
        fs = float(rate_hz)
    except (TypeError, ValueError):
        fs = math.nan
    if isinstance(rate_hz, bool) or not (math.isfinite(fs) and fs > 0):
        raise ConfigError(f"model rate must be a finite number of Hz > 0, got {rate_hz!r}; pass {{opt:model_rate_hz}}")
    native = 1.0 / dt
    ratio = native / fs
    m = round(ratio)
    if m >= 1 and abs(ratio - m) <= RATE_RTOL * ratio:
        return int(m)
    if ratio < 1:
        valid = [native / k for k in (1, 2, 3)]
        shown = _distinct(fs, *valid)
        listing = ", ".join(f"{s} Hz (/{k})" for k, s in enumerate(shown[1:], start=1))
        raise ConfigError(
            f"model rate {shown[0]} Hz is above the native {native:.10g} Hz; expected the native rate divided "
            f"by an integer (block averaging cannot raise the rate): {listing} ...; pass {{opt:model_rate_hz}}"
        )
    lo = math.floor(ratio)
    req, above, below = _distinct(fs, native / lo, native / (lo + 1))
    raise ConfigError(
        f"model rate {req} Hz does not divide the native {native:.10g} Hz by an integer; nearest valid rates: "
        f"{above} Hz (/{lo}), {below} Hz (/{lo + 1}); pass {{opt:model_rate_hz}}"
    )


def _distinct(*values: float) -> list[str]:
    """The values printed with the fewest significant digits (>= 4) that tell them apart."""
    for digits in range(4, 18):
        shown = [f"{v:.{digits}g}" for v in values]
        if len(set(shown)) == len(set(values)):
            return shown
    return [repr(v) for v in values]


def from_array(rate, *, dt_s, unit="deg/h", axis_names=None, source="<array>") -> GyroRecord:
    """Wrap an array of rates (or angle increments) as a :class:`GyroRecord`.

    Parameters
    ----------
    rate : array_like, shape (n_samples,) or (n_samples, n_axes)
        Rates in ``unit``.  A float64 deg/h array is not copied (the record holds a
        read-only view of it).
    dt_s : float
        Sample interval in s (> 0).
    unit : str
        Rate unit from :data:`fogdrift.units.RATE_UNITS` or ``"inc:<angle>"`` for an angle
        increment per sample (``"inc:deg"``, ``"inc:rad"``, ``"inc:arcsec"``).
    axis_names : sequence of str, optional
        Default ``("axis0", "axis1", ...)``.
    source : str
        Where the numbers came from (used in messages).

    Returns
    -------
    GyroRecord
        ``sha256`` is None (no file).

    Raises
    ------
    ConfigError
        Bad ``dt_s``, ``unit`` or ``axis_names``.
    DataFormatError
        Non-numeric data, wrong number of dimensions, or a NaN/inf value (the message gives
        the sample index; ``column`` is the axis name), also after conversion to deg/h.
    InsufficientDataError
        Zero samples.

    Examples
    --------
    >>> rec = from_array([0.1, 0.1, 0.2], dt_s=0.01, unit="inc:arcsec")
    >>> rec.rate_dph[:, 0]
    array([10., 10., 20.])
    """
    dt = units.check_dt_s(dt_s, "dt_s")
    spec = channel_unit(unit, None)  # any quantity: a gyro's deg/h or an accelerometer's m/s^2, g ...
    sampling = Sampling(dt_s=dt, dt_source="argument")
    try:
        arr = np.asarray(rate)
        if arr.dtype.kind not in "biuf":
            arr = np.asarray(rate, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise DataFormatError(
            f"rate is not numeric; expected an array of numbers, got {type(rate).__name__}", path=source
        ) from exc
    if arr.ndim == 1:
        arr = arr.reshape(-1, 1)
    if arr.ndim != 2:
        raise DataFormatError(
            f"rate has shape {arr.shape}; expected (n_samples,) or (n_samples, n_axes)", path=source
        )
    if axis_names is None:
        names = [f"axis{j}" for j in range(arr.shape[1])]
    else:
        names = [axis_names] if isinstance(axis_names, str) else [str(a) for a in axis_names]
        if len(names) != arr.shape[1] or len(set(names)) != len(names):
            raise ConfigError(
                f"axis_names must be {arr.shape[1]} unique names (one per column); got {axis_names!r}"
            )
    for name in names:
        check_name(name, spec, f"unit {unit!r}", str(source))
    n = arr.shape[0]
    if n == 0:
        raise InsufficientDataError("rate has 0 samples; expected at least 1", needed=1, got=0, path=source)
    bad = first_nonfinite(arr)
    if bad is not None:
        i, j = bad
        raise DataFormatError(
            f"non-finite value at sample {i}; expected a finite number, got {float(arr[i, j])!r}",
            path=source, column=names[j],
        )
    scale = spec.scale_to_internal(dt)
    data = to_dph(arr, scale)
    if scale != 1.0:
        bad = first_nonfinite(data)
        if bad is not None:
            i, j = bad
            raise DataFormatError(
                f"value at sample {i} overflows in {units.INTERNAL_UNITS[spec.quantity]}; expected |value| * "
                f"{scale:.6g} below "
                f"{np.finfo(np.float64).max:.3g}, got {float(arr[i, j])!r} {unit}", path=source, column=names[j],
            )
    signal = SignalDescription(sampling, tuple(
        Channel(name=n, unit=spec, unit_source="argument", declared_unit=None, scale_to_internal=scale) for n in names))
    return GyroRecord(
        data_internal=data, dt_s=dt, axis_names=tuple(names), source=str(source),
        input_unit=unit, scale_to_internal=scale, signal=signal,
    )
