"""Estimator-style interface shared by every drift model.

Contract (scikit-learn shape, see ``docs`` and the style examples):

* the constructor only stores hyper-parameters, under the names given, keyword-only;
* ``fit(y_train, y_val=None)`` learns from the training block (and may use the chronologically
  following validation block for early stopping) and returns ``self``; everything learned ends
  in ``_``; normalisation statistics, shifts etc. come from ``y_train`` only;
* ``predict(y, history=None)`` gives **one-step-ahead** predictions from measured data:
  ``out[k]`` predicts ``y[k]`` from ``history`` (the measured samples immediately before
  ``y``) and ``y[:k]``; entries with too little history are NaN;
* ``forecast(h, history=None)`` runs free for ``h`` steps after the end of ``history``
  (default: after the end of the training block), feeding predictions back;
* ``get_state()`` gives the fitted state as data (a JSON-ready dict and a dict of arrays) and
  ``set_state(meta, arrays)`` takes it back; the model does no file I/O:
  :mod:`fogdrift.models.model_files` writes and reads model files (JSON + NPZ, no pickle).

Series are 1-D float arrays of drift samples in deg/h at a fixed sample interval.
"""

from __future__ import annotations

import inspect

from .._util import check_series
from ..errors import ConfigError, NotFittedError

__all__ = ["DriftModel", "check_series"]


class DriftModel:
    """Base class of drift models: parameter handling, fitted check, fitted state as data.

    Subclasses implement ``fit``, ``predict``, ``forecast`` and the two state hooks
    ``_get_state() -> (meta: dict, arrays: dict[str, ndarray])`` and
    ``_set_state(meta, arrays)``; ``meta`` must be JSON-serialisable.  :meth:`get_state` and
    :meth:`set_state` are their public faces (the first checks that the model is fitted).
    """

    #: Name shown in tables and reports (the registry row repeats it for CLI help).
    label = "model"
    #: True when ``fit`` uses ``y_val`` (early stopping); False: ``y_val`` is accepted and ignored.
    uses_validation = False
    #: What the model is fed when it compensates a gyro: ``"drift"`` (a separated drift series, the
    #: paper's framing; the causal drift in real time) or ``"rate"`` (the bias-removed rate itself, e.g.
    #: a Kalman filter whose noise model includes the white noise).
    input_kind = "drift"

    @classmethod
    def _param_names(cls) -> list[str]:
        sig = inspect.signature(cls.__init__)
        return [p.name for p in sig.parameters.values() if p.name != "self" and p.kind != p.VAR_KEYWORD]

    def get_params(self, serialisable: bool = False) -> dict:
        """Hyper-parameters exactly as given to the constructor; ``serialisable=True``: as a model file or a result
        document holds them, callables (progress callbacks) as None."""
        params = {name: getattr(self, name) for name in self._param_names()}
        if serialisable:
            return {k: (None if callable(v) else v) for k, v in params.items()}
        return params

    def set_params(self, **params):
        valid = set(self._param_names())
        for key, value in params.items():
            if key not in valid:
                raise ConfigError(f"{type(self).__name__} has no parameter {key!r}; valid: {sorted(valid)}")
            setattr(self, key, value)
        return self

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"

    # -- fitted state -------------------------------------------------------------------
    def _is_fitted(self) -> bool:
        return any(k.endswith("_") and not k.startswith("__") for k in vars(self))

    def _check_fitted(self) -> None:
        if not self._is_fitted():
            raise NotFittedError(f"{type(self).__name__} is not fitted yet; call fit(y_train) first")

    def _validate(self):
        """The one validation hook of a model: check the hyper-parameters, raise ConfigError naming the bad one.

        Called by ``fit`` (and wherever a model needs its checked settings); it may return what it derived
        (the Elman models their training configuration, the Kalman filter its ``dt_s``).  The default checks
        nothing.
        """
        return None

    def _get_state(self):  # pragma: no cover - abstract
        raise NotImplementedError

    def _set_state(self, meta: dict, arrays: dict) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    # -- state as data ------------------------------------------------------------------------
    def get_state(self) -> tuple[dict, dict]:
        """The fitted state as data: ``(meta, arrays)``.

        ``meta`` is a JSON-ready dict (numbers, strings, lists), ``arrays`` a dict of NumPy arrays by name;
        :func:`~fogdrift.models.model_files.save_model` writes them, with :meth:`get_params`, to a model file.

        Raises
        ------
        NotFittedError
            The model is not fitted.
        """
        self._check_fitted()
        return self._get_state()

    def set_state(self, meta: dict, arrays: dict):
        """Take a fitted state as :meth:`get_state` gives it; returns ``self``.

        The hyper-parameters come from the constructor; ``KeyError``, ``TypeError``, ``ValueError`` or
        ``IndexError`` say that ``meta``/``arrays`` do not describe a fitted model of this class.
        """
        self._set_state(meta, arrays)
        return self
