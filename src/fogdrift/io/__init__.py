"""Loading gyro logs into a :class:`GyroRecord` (rates in deg/h, time in s).

This is the only package where input units are converted (see :mod:`fogdrift.units`); it does
no analysis.  Supported inputs:

* text (CSV/TXT, optionally ``.gz``): comma, tab, semicolon or whitespace separated, with or
  without one header row; lines (or line tails) starting with ``#`` or ``%`` are comments;
  UTF-8 with or without a byte-order mark; a decimal comma is read when the separator is not
  a comma and the first data row shows it;
* NumPy ``.npy`` (1-D = one axis, 2-D = columns), opened with ``mmap_mode="r"`` so that a
  float64 deg/h record is never copied;
* NumPy ``.npz`` (several 1-D arrays = named columns, or a single 2-D array);
* HDF5 (h5py) and MATLAB ``.mat`` v4/v5/v7 (SciPy) and v7.3 (h5py): a dataset, group,
  variable or struct as named columns, HDF5 ``units`` attributes honoured;
* ROS 1 bags and ROS 2 bag directories (rosbags): ``sensor_msgs/Imu`` angular velocity in rad/s
  (gx, gy, gz) and linear acceleration in m/s^2 (ax, ay, az), each unit declared by the message
  definition; the gyro channels by default (reader option ``fields``: gyro, accel or both); time
  from header stamps or receive time;
* miniSEED (ObsPy): channels as axes, gain as a number or from a response file;
* raw binary records declared by a NumPy dtype ``layout``, with scale factors and a wrapping
  sequence counter whose jumps are gaps, read through a memory map.

The optional readers need the extras ``[hdf5]``, ``[ros]``, ``[seismo]``; a missing package is a
:class:`~fogdrift.io.readers.base.MissingDependencyError` naming the extra.  Any reader can carry a
temperature column (``load(..., temperature=NAME)``) into ``GyroRecord.temperature_c``.
:mod:`fogdrift.io.chunked` reads windows of ``.npy``/raw binary/HDF5 files larger than memory.
User documentation: ``docs/formats.md``.

The format is detected from the file's first bytes, then its name (:mod:`.registry`).  Every
problem with the input raises :class:`~fogdrift.errors.DataFormatError` located as
``<path>:<line>:<column>: <what>; expected <rule>, got <value>``; ``line`` is the 1-based
physical line (header and comments included), ``column`` the column name (files with a
header, arrays) or the 1-based field number (header-less text).  In arrays the location is
the sample index, given in the message ("at sample 12345").  A message that names a setting
writes it ``{opt:NAME}`` (see :mod:`fogdrift.errors`).

Each record carries the SHA-256 of the file's bytes (``GyroRecord.sha256``), computed from
the bytes the reader streamed, not by a second read.

Units are never guessed.  A text header cell ``name[unit]`` names the column ``name`` and
declares its unit: ``gz[deg/s]``, ``gyro x [inc:arcsec]`` (rate units of
:data:`fogdrift.units.RATE_UNITS` or ``inc:<angle>``), ``t[ms]`` (time units of
:data:`fogdrift.units.TIME_UNITS`: s, ms, us, ns); a time column may also declare its unit by
a name suffix (``t_s``, ``time_ms``, :func:`time_unit_of_name`).  A declared unit is used
when the caller gives none (``unit=None``, ``time_unit=None``); the rate columns used must
then declare one unit between them.  A rate (or time) unit that is neither given nor
declared is a :class:`~fogdrift.errors.ConfigError` naming ``{opt:unit}``
(``{opt:time_unit}``), never a default.  The record keeps each axis's declared unit
(``GyroRecord.declared_units``).

Every record carries its signal description (:attr:`GyroRecord.signal`, :mod:`fogdrift.signal`): the
sampling and each channel's unit, quantity and scale, and where the interval and the units came from
(time column, ``rate_hz``, header, ``unit``), made here once while reading; later stages read it back.
Units are parsed by :func:`fogdrift.units.parse_unit` and intervals checked by
:func:`fogdrift.units.check_dt_s` (the one parser and the one validator).

Conventions: sample ``k`` of a record covers ``[t0_s + k dt_s, t0_s + (k+1) dt_s)``, so
``duration_s = n_samples * dt_s`` and block averages keep ``t0_s``.  A record is brought to a
modelling rate only by integer block averaging (:meth:`GyroRecord.to_rate`,
:func:`decimation_factor`).

Layout: :mod:`.record` (the record, averaging), :mod:`.load` (column choice, time, gaps,
units: the same for every format), :mod:`.registry` (which reader), :mod:`.readers` (one
module per format), :mod:`.hashing` (SHA-256).

How to add a reader
-------------------
1. Write ``fogdrift/io/readers/<format>.py`` with one public function
   ``open_table(path, **options) -> Table`` (:class:`fogdrift.io.readers.base.Table`):
   give the column ``names`` (``named=False`` for generated ``col0, col1 ...``), the
   ``units`` the file declares (or None), and either ``data`` (a 2-D float64 array, a view
   of a memory map where the file allows) or a subclass whose ``read(used)`` parses on
   demand.  Set ``time_s`` if the format carries its own time stamps (seconds), and
   ``sha256`` from the bytes read (:func:`fogdrift.io.hashing.hashing_stream` hashes a
   stream as it is read).  Override ``line_of``/``label``/``row_kind`` so that errors say
   where (line and field, or sample/message index).  Raise
   :class:`~fogdrift.errors.DataFormatError` for anything wrong in the file (catch the
   parser's exceptions, :data:`fogdrift.io.readers.base.PARSER_ERRORS`).  Import heavy
   dependencies inside the module: it is imported only when such a file is read.
2. Add one line to :data:`fogdrift.io.registry.READERS`: name, module, magic bytes,
   extensions, accepted reader options (``load(..., reader_options={...})``), each a
   :class:`~fogdrift.io.registry.ReaderOption` (name, type, help, flag): every command of the
   CLI then has its flag, with no edit in :mod:`fogdrift.cli`.
3. Test it like ``tests/io/test_io_formats.py``: values against the writer's, located errors,
   the SHA-256 against :func:`hashlib.sha256` of the file.

Everything else (column choice, time checks, gaps, unit conversion, the record) is shared.
"""

from .hashing import file_sha256
from .load import TIME_COLUMN_NAMES, load, load_segments, time_unit_of_name
from .timebase import DT_TOLERANCE, GAP_FACTOR
from .record import GyroRecord, block_average, decimation_factor, from_array

__all__ = [
    "GyroRecord",
    "load",
    "load_segments",
    "time_unit_of_name",
    "from_array",
    "block_average",
    "decimation_factor",
    "file_sha256",
    "TIME_COLUMN_NAMES",
    "GAP_FACTOR",
    "DT_TOLERANCE",
]
