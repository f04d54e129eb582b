"""Which physical quantity each channel carries: decided once, while a file is read, from its unit.

The quantity of a channel (``"angular_rate"``: a gyro, ``"specific_force"``: an accelerometer) comes from
its unit, never from a guess: a unit declared in the header (``ax[g]``, ``gz[deg/s]``) or the ``unit``
option (``--unit``).  The option has two forms:

``U``
    One unit for every channel (``--unit deg/s``, ``--unit g``); its quantity is the channels' quantity.
``KEY=U[,KEY=U ...]``
    A unit per quantity or per column, for a mixed log or a ``batch`` over a folder of gyro and
    accelerometer files: ``--unit gyro=deg/s,accel=g``.  ``KEY`` is ``gyro``, ``accel`` or a column name
    (``--unit gx=deg/s,ax=mg``); a column's own entry wins over its quantity's.  Each channel is assigned
    to ``gyro`` or ``accel`` by the name rule below.  A channel that no entry covers is refused.

**The name rule** (:func:`quantity_of_name`, case-insensitive, on the column name):

* accelerometer: ``a``/``acc``/``accel`` followed by an axis (``ax``, ``a_y``, ``acc_z``, ``accel1``),
  any name starting ``acc`` (``accel``, ``accelerometer_x``), ``linear_acceleration*``, ``f_x``/``fx``
  (specific force), ``sf*``;
* gyro: ``g``/``gyr``/``gyro`` followed by an axis (``gx``, ``g_y``), any name starting ``gyr``,
  ``w``/``omega`` followed by an axis (``wx``, ``omega_z``) or starting ``omega``, ``angular_velocity*``,
  ``rate*``;
* anything else (``x``, ``z``, ``ch0``) says nothing: it takes the one unit given, and under the
  per-quantity form it needs its own ``name=U`` entry.

**Never silently a gyro:** a channel whose name says accelerometer read in an angular-rate unit (or a
gyro-named channel read in a specific-force unit) is refused in one line naming the channel, the unit and
where it came from.  The internal unit of specific force is m/s^2 (:data:`fogdrift.units.INTERNAL_UNITS`):
an accelerometer channel's numbers in :attr:`fogdrift.io.GyroRecord.data_internal` are in m/s^2 (a record with
accelerometer channels has no ``rate_dph``: that name is the gyro channels' deg/h).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from .. import units
from ..errors import ConfigError
from ..signal import channel_unit

__all__ = ["quantity_of_name", "UnitChoice", "parse_unit_choice", "QUANTITY_WORDS", "KEY_OF_QUANTITY"]

_AXIS = r"[_\-. ]?(?:[xyz]|[0-9])"
_ACCEL = re.compile(rf"^(?:(?:a|acc|accel){_AXIS}|acc.*|linear_acc.*|f{_AXIS}|sf.*)$", re.IGNORECASE)
_GYRO = re.compile(rf"^(?:(?:g|gyr|gyro|w|omega){_AXIS}|gyr.*|omega.*|angular_vel.*|rate.*)$", re.IGNORECASE)

#: What each quantity is called in messages.
QUANTITY_WORDS = {"angular_rate": "an angular-rate (gyro)", "specific_force": "a specific-force (accelerometer)"}
#: The per-quantity key of the ``unit`` option for each quantity.
KEY_OF_QUANTITY = {"angular_rate": "gyro", "specific_force": "accel"}
_QUANTITY_OF_KEY = {v: k for k, v in KEY_OF_QUANTITY.items()}


def quantity_of_name(name) -> str | None:
    """``"specific_force"``, ``"angular_rate"`` or None: what a column's name says it holds (see the module docstring).

    Examples
    --------
    >>> [quantity_of_name(n) for n in ("ax", "a_y", "accel_z", "gx", "gyro", "omega_z", "wx", "z", "t_s")]
    ['specific_force', 'specific_force', 'specific_force', 'angular_rate', 'angular_rate', 'angular_rate', 'angular_rate', None, None]
    """
    text = str(name).strip()
    if _ACCEL.match(text):
        return "specific_force"
    if _GYRO.match(text):
        return "angular_rate"
    return None


@dataclass(frozen=True)
class UnitChoice:
    """The ``unit`` option, parsed once: one unit for all channels, or one per quantity / per column.

    Attributes
    ----------
    text : str
        The option as given.
    single : fogdrift.units.UnitSpec or None
        The one unit (first form).
    by_quantity : dict
        ``{"angular_rate": UnitSpec, "specific_force": UnitSpec}`` entries of the second form.
    by_column : dict
        ``{column name: UnitSpec}`` entries of the second form.
    """

    text: str
    single: units.UnitSpec | None
    by_quantity: dict
    by_column: dict

    def for_channel(self, name: str, where: str) -> units.UnitSpec:
        """The unit of channel ``name``, checked against what its name says (ConfigError, one line, otherwise)."""
        said = quantity_of_name(name)
        if self.single is not None:
            spec = self.single
            check_name(name, spec, f"{{opt:unit}} {self.text!r}", where)
            return spec
        if name in self.by_column:
            spec = self.by_column[name]
            check_name(name, spec, f"{{opt:unit}} entry {name}={spec.text}", where)
            return spec
        if said is None:
            raise ConfigError(
                f"{where}: channel {name!r} has a name that says neither gyro nor accelerometer; give its unit as "
                f"{{opt:unit}} ...,{name}=U (the per-quantity entries gyro=/accel= go by name: gx, gyro*, w*, omega* "
                f"are gyros; ax, acc*, accel*, a_x are accelerometers)")
        spec = self.by_quantity.get(said)
        if spec is None:
            raise ConfigError(
                f"{where}: channel {name!r} is named as {QUANTITY_WORDS[said]} channel but {{opt:unit}} "
                f"{self.text!r} gives no {KEY_OF_QUANTITY[said]}= unit; add {KEY_OF_QUANTITY[said]}=U")
        return spec


def check_name(name: str, spec: units.UnitSpec, given: str, where: str) -> None:
    """Refuse a channel whose name says one quantity read in a unit of the other (one line naming both)."""
    said = quantity_of_name(name)
    if said is not None and said != spec.quantity:
        other = "g, mg, ug, m/s^2" if said == "specific_force" else "deg/s, deg/h, rad/s"
        raise ConfigError(
            f"{where}: channel {name!r} is named as {QUANTITY_WORDS[said]} channel but {given} is "
            f"{QUANTITY_WORDS[spec.quantity]} unit; give it a unit of its quantity ({other}), e.g. "
            f"{{opt:unit}} gyro=deg/s,accel=g for a folder or a log with both (a channel is never silently read "
            f"as the other quantity)")


def parse_unit_choice(text) -> UnitChoice:
    """Parse the ``unit`` option (see the module docstring); ConfigError (one line) for a bad unit or key.

    Examples
    --------
    >>> c = parse_unit_choice("gyro=deg/s,accel=g")
    >>> c.by_quantity["specific_force"].scale_to_internal(), c.single
    (9.80665, None)
    >>> parse_unit_choice("mg").single.quantity
    'specific_force'
    """
    if isinstance(text, units.UnitSpec):
        return UnitChoice(text=text.text, single=text, by_quantity={}, by_column={})
    if not isinstance(text, str) or not text.strip():
        raise ConfigError(f"unit must be a unit string (deg/s, g, ...) or gyro=U,accel=U; got {text!r}")
    s = text.strip()
    if "=" not in s:
        return UnitChoice(text=s, single=channel_unit(s, None), by_quantity={}, by_column={})
    by_q, by_c = {}, {}
    for part in s.split(","):
        key, eq, u = part.partition("=")
        key, u = key.strip(), u.strip()
        if not eq or not key or not u:
            raise ConfigError(f"unit {s!r}: entry {part.strip()!r} is not KEY=UNIT; expected e.g. gyro=deg/s,accel=g")
        if key.lower() in _QUANTITY_OF_KEY:
            q = _QUANTITY_OF_KEY[key.lower()]
            if q in by_q:
                raise ConfigError(f"unit {s!r}: {key.lower()}= given twice")
            by_q[q] = channel_unit(u, q)
        else:
            if key in by_c:
                raise ConfigError(f"unit {s!r}: column {key!r} given twice")
            by_c[key] = channel_unit(u, None)
    return UnitChoice(text=s, single=None, by_quantity=by_q, by_column=by_c)
