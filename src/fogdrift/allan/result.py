"""The result of an Allan-family computation (:class:`AllanResult`)."""

from __future__ import annotations

import csv
from dataclasses import dataclass

import numpy as np

from ..units import INTERNAL_UNITS, KEY_SUFFIXES
from .statistics import get_statistic

__all__ = ["ARRAY_FIELDS", "AllanResult"]

#: The array fields, in serialisation order (the order of :meth:`AllanResult.column_names`); ``var``/``dev`` stems
#: are replaced by the statistic's.
ARRAY_FIELDS = ("tau_s", "m", "var", "dev", "dev_lo68", "dev_hi68", "dev_lo95", "dev_hi95", "n_terms", "edf",
                "noise_alpha")


@dataclass(frozen=True)
class AllanResult:
    """An Allan-family statistic of one series at a grid of cluster times.

    All arrays have shape ``(n_tau,)``, in the unit of the series (its channel's internal unit: deg/h for a gyro,
    m/s^2 for an accelerometer, :data:`fogdrift.units.INTERNAL_UNITS`; the variance in its square).  The fields are
    generic (``var``, ``dev``, ...) and ``statistic`` says which member of the family they hold.  For a gyro's
    Allan deviation the names ``avar_dph2``, ``adev_dph``, ``adev_lo68_dph``, ``adev_hi68_dph``, ``adev_lo95_dph``
    and ``adev_hi95_dph`` read the same arrays; for another statistic they raise AttributeError (a Hadamard
    deviation is not an Allan deviation).  Serialised results name the columns after the statistic and the
    quantity's unit (:meth:`column_names`): ``avar_dph2``/``adev_dph``, ``hvar_dph2``/``hdev_dph`` or
    ``mvar_dph2``/``mdev_dph`` (and ``<dev>_lo68_dph`` etc.) for a gyro, ``avar_m2ps4``/``adev_mps2`` ... for an
    accelerometer.

    Attributes
    ----------
    tau_s : ndarray
        Cluster times ``m * dt_s`` in s.
    m : ndarray of int
        Cluster sizes (averaging factors).
    var : ndarray
        The statistic's variance, in the square of the series' unit ((deg/h)^2, (m/s^2)^2).
    dev : ndarray
        Its deviation (square root), in the series' unit.
    n_terms : ndarray of int
        Number of squared differences averaged at each tau.
    edf : ndarray
        Equivalent degrees of freedom, clipped to ``[1, n_terms]`` (rule in ``edf_rule``).
    dev_lo68, dev_hi68, dev_lo95, dev_hi95 : ndarray
        Chi-squared confidence bounds of the deviation (68.27 % and 95 %), in the series' unit.
    noise_alpha : ndarray of int
        Power-law alpha assumed for each tau's EDF.
    estimator : str
        Sampling: ``"overlapping"``, ``"non-overlapping"`` or ``"fast"``.
    edf_rule : str
        How alpha and the EDF were chosen, in words.
    dt_s : float
        Sample interval in s.
    n_samples : int
        Number of samples N.
    statistic : str
        ``"adev"`` (Allan), ``"hdev"`` (Hadamard) or ``"mdev"`` (modified Allan); see
        :data:`fogdrift.allan.STATISTICS`.
    """

    tau_s: np.ndarray
    m: np.ndarray
    var: np.ndarray
    dev: np.ndarray
    n_terms: np.ndarray
    edf: np.ndarray
    dev_lo68: np.ndarray
    dev_hi68: np.ndarray
    dev_lo95: np.ndarray
    dev_hi95: np.ndarray
    noise_alpha: np.ndarray
    estimator: str
    edf_rule: str
    dt_s: float
    n_samples: int
    statistic: str = "adev"

    def __len__(self) -> int:
        return int(self.tau_s.size)

    # --- a gyro's Allan deviation by its usual names ---------------------------------------
    def _allan(self, field_name: str) -> np.ndarray:
        if self.statistic != "adev":
            stat = get_statistic(self.statistic)
            raise AttributeError(
                f"this result holds the {stat.long_name} ({self.statistic!r}), not the Allan deviation; "
                f"read {field_name!r} (columns {stat.var_name}_dph2 / {stat.dev_name}_dph when serialised)"
            )
        return getattr(self, field_name)

    @property
    def avar_dph2(self) -> np.ndarray:
        """Allan variance in (deg/h)^2 (``var`` of an ``"adev"`` result)."""
        return self._allan("var")

    @property
    def adev_dph(self) -> np.ndarray:
        """Allan deviation in deg/h (``dev`` of an ``"adev"`` result)."""
        return self._allan("dev")

    @property
    def adev_lo68_dph(self) -> np.ndarray:
        """Lower 68 % bound of the Allan deviation (``dev_lo68``)."""
        return self._allan("dev_lo68")

    @property
    def adev_hi68_dph(self) -> np.ndarray:
        """Upper 68 % bound of the Allan deviation (``dev_hi68``)."""
        return self._allan("dev_hi68")

    @property
    def adev_lo95_dph(self) -> np.ndarray:
        """Lower 95 % bound of the Allan deviation (``dev_lo95``)."""
        return self._allan("dev_lo95")

    @property
    def adev_hi95_dph(self) -> np.ndarray:
        """Upper 95 % bound of the Allan deviation (``dev_hi95``)."""
        return self._allan("dev_hi95")

    # --- serialisation ------------------------------------------------------------------
    def column_names(self, quantity: str = "angular_rate") -> tuple:
        """Serialised column names: ``tau_s, m, <var>_dph2, <dev>_dph, <dev>_lo68_dph, ...``.

        ``quantity`` names the channel's quantity: the arrays hold its internal unit, and the unit suffixes are
        that unit's (:data:`fogdrift.units.KEY_SUFFIXES`: ``dph``/``dph2`` for an angular rate in deg/h,
        ``mps2``/``m2ps4`` for a specific force in m/s^2).

        Examples
        --------
        >>> from fogdrift.allan import allan_variance
        >>> allan_variance([1, 3, 2, 5, 4, 4, 6, 3], 1.0, statistic="mdev").column_names()[:4]
        ('tau_s', 'm', 'mvar_dph2', 'mdev_dph')
        >>> allan_variance([1, 3, 2, 5, 4, 4, 6, 3], 1.0).column_names("specific_force")[2:5]
        ('avar_m2ps4', 'adev_mps2', 'adev_lo68_mps2')
        """
        stat = get_statistic(self.statistic)
        try:
            one, two = KEY_SUFFIXES[quantity]
        except KeyError:
            raise ValueError(f"quantity must be one of {sorted(KEY_SUFFIXES)}; got {quantity!r}") from None

        def name(c: str) -> str:
            if c == "var":
                return f"{stat.var_name}_{two}"
            if c == "dev" or c.startswith("dev_"):
                return stat.dev_name + c[len("dev"):] + f"_{one}"
            return c

        return tuple(name(c) for c in ARRAY_FIELDS)

    def to_dict(self, quantity: str = "angular_rate") -> dict:
        """JSON-serialisable dict: arrays become lists of float/int, units are in the keys
        (:meth:`column_names` of ``quantity``)."""
        out: dict = {"statistic": self.statistic}
        for name, key in zip(ARRAY_FIELDS, self.column_names(quantity)):
            arr = np.asarray(getattr(self, name))
            # tolist(): the Python int / float of every element in one C loop (int(v) / float(v) one call each)
            out[key] = arr.tolist() if arr.dtype.kind in "iu" else arr.astype(np.float64).tolist()
        out.update(
            estimator=self.estimator,
            edf_rule=self.edf_rule,
            dt_s=float(self.dt_s),
            n_samples=int(self.n_samples),
        )
        return out

    def to_csv(self, path, quantity: str = "angular_rate") -> None:
        """Write one row per tau; two ``#`` comment lines, then a header whose names carry units.

        Columns: ``tau_s, m, <var>_dph2 [(deg/h)^2], <dev>_dph [deg/h]``, the four deviation
        bounds in deg/h, ``n_terms, edf, noise_alpha`` (``<var>``/``<dev>``: avar/adev,
        hvar/hdev or mvar/mdev).  ``quantity`` is the channel's (:meth:`column_names`): a specific
        force's columns are ``<var>_m2ps4 [(m/s^2)^2]``, ``<dev>_mps2 [m/s^2]``.
        """
        stat = get_statistic(self.statistic)
        names = self.column_names(quantity)
        unit = INTERNAL_UNITS[quantity]
        one, two = KEY_SUFFIXES[quantity]
        with open(path, "w", newline="") as fh:
            fh.write(
                f"# fogdrift {stat.long_name}; statistic={self.statistic}; estimator={self.estimator}; "
                f"dt_s={self.dt_s!r}; n_samples={self.n_samples}\n"
            )
            fh.write(
                f"# units: tau_s [s]; {stat.var_name}_{two} [({unit})^2]; {stat.dev_name}_* [{unit}]; "
                f"edf rule: {self.edf_rule}\n"
            )
            writer = csv.writer(fh)
            writer.writerow(names)
            cols = [np.asarray(getattr(self, c)) for c in ARRAY_FIELDS]
            for i in range(self.tau_s.size):
                writer.writerow([repr(c[i].item()) if c.dtype.kind == "f" else int(c[i]) for c in cols])
