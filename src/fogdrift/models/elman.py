"""Elman recurrent network and the grey (AGO) Elman drift model, in JAX.

Functional core
---------------
One Elman cell as in Tang et al. (2012), eq. (11), and Elman (1990)::

    h(k) = f(W_u u(k) + W_c h(k-1) + b_h)        context c(k) = h(k-1), unit-weight copy
    y(k) = W_o h(k) + b_o                        linear output

with ``f`` = tanh ("tanh", MATLAB ``tansig``) or the logistic function ("logsig").
:func:`init_params`, :func:`elman_forward` (a ``jax.lax.scan`` over time) and
:func:`elman_loss` (eq. (12), sum of squared errors, or the mean) are pure functions;
:class:`ElmanCell` is the same cell behind the interface of :mod:`fogdrift.models.training`,
which holds the windowed truncated-BPTT / BP training loop, early stopping and the optimizers.

Estimators
----------
:class:`Elman` is a one-step drift predictor whose input at step k is the last ``lags``
samples (z-scored with training-block statistics) and whose hidden state runs along the
series. :class:`GreyElman` is the paper's "AGO -> Elman -> IAGO" model (method notes §4.1 (b)).
:func:`fit_many` trains one model per seed at once with ``jax.vmap``.

This module and :mod:`fogdrift.models.training` are the only fogdrift modules that import JAX.
Everything runs unchanged on CPU or GPU. float32 is the default; ``dtype="float64"`` needs JAX's
64-bit mode switched on by the caller (``JAX_ENABLE_X64=1`` or
``jax.config.update("jax_enable_x64", True)``).

References
----------
J. L. Elman, "Finding structure in time", Cognitive Science 14(2):179-211, 1990.
Tang Xiaqing et al., Chinese J. Lasers 39(10):1008003, 2012, eqs. (9)-(13).
MATLAB Neural Network Toolbox, ``newelm`` / ``traingdx`` (method notes §4.2).
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from .._util import check_series
from ..errors import ConfigError, FogdriftWarning, InsufficientDataError
from .base import DriftModel
from .training import (
    LOSSES,
    TRAINGDX,  # noqa: F401  (MATLAB traingdx constants, kept importable from here)
    TRAININGS,
    RecurrentCell,
    TrainResult,
    fit_recurrent,
    fit_recurrent_many,
    train_config,
    window_data,
)

__all__ = ["init_params", "elman_forward", "elman_loss", "ElmanCell", "Elman", "GreyElman", "fit_many"]

_ACTIVATIONS = ("tanh", "logsig")
_DTYPES = ("float32", "float64")

# ------------------------------------------------------------------------------------------
# functional core
# ------------------------------------------------------------------------------------------
def _activation_fn(activation: str):
    if activation == "tanh":
        return jnp.tanh
    if activation == "logsig":
        return jax.nn.sigmoid
    raise ConfigError(f"activation must be one of {_ACTIVATIONS}; got {activation!r}")


def init_params(key, n_inputs: int, n_hidden: int, n_outputs: int = 1, dtype=jnp.float32) -> dict:
    """Random Elman weights, uniform on ±1/sqrt(n_hidden) (the ``torch.nn.RNN`` rule).

    Parameters
    ----------
    key : jax.Array
        PRNG key, e.g. ``jax.random.key(0)``; it is split into one key per weight block.
    n_inputs, n_hidden, n_outputs : int
        Sizes r, n and m of eq. (11).
    dtype : jnp dtype
        Floating dtype of every array.

    Returns
    -------
    dict
        ``W_u`` (n_hidden, n_inputs), ``W_c`` (n_hidden, n_hidden), ``b_h`` (n_hidden,),
        ``W_o`` (n_outputs, n_hidden), ``b_o`` (n_outputs,) (zeros).

    Examples
    --------
    >>> p = init_params(jax.random.key(0), 4, 16)
    >>> p["W_c"].shape
    (16, 16)
    """
    for name, v in (("n_inputs", n_inputs), ("n_hidden", n_hidden), ("n_outputs", n_outputs)):
        if int(v) != v or v < 1:
            raise ConfigError(f"{name} must be an integer >= 1; got {v!r}")
    k_u, k_c, k_b, k_o = jax.random.split(key, 4)
    lim = 1.0 / math.sqrt(n_hidden)

    def u(k, shape):
        return jax.random.uniform(k, shape, dtype=dtype, minval=-lim, maxval=lim)

    return {
        "W_u": u(k_u, (n_hidden, n_inputs)),
        "W_c": u(k_c, (n_hidden, n_hidden)),
        "b_h": u(k_b, (n_hidden,)),
        "W_o": u(k_o, (n_outputs, n_hidden)),
        "b_o": jnp.zeros((n_outputs,), dtype=dtype),
    }


def elman_forward(params, inputs, h0=None, activation="tanh", *, stop_context_gradient=False):
    """Run the Elman network of eq. (11) over a sequence (``jax.lax.scan`` over time).

    Parameters
    ----------
    params : dict
        Weights as returned by :func:`init_params`.
    inputs : array, shape (T, n_inputs) or (T,)
        Input vectors u(k), k = 0..T-1.
    h0 : array, shape (n_hidden,), optional
        Context before the first step, h(-1); zeros by default.
    activation : {"tanh", "logsig"}
        Hidden transfer function f.
    stop_context_gradient : bool
        If True the carried context is wrapped in ``jax.lax.stop_gradient``: gradients treat
        c(k) = h(k-1) as a constant input (classic Elman "BP", i.e. BPTT truncated to depth 1,
        MATLAB ``staticderiv``). The forward values are unchanged.

    Returns
    -------
    outputs : jax.Array, shape (T, n_outputs)
    hidden : jax.Array, shape (T, n_hidden)

    Notes
    -----
    The input projection W_u u(k) + b_h and the read-out are computed outside the scan, so
    the sequential part is only ``h <- f(a(k) + W_c h)``.

    Examples
    --------
    Method notes §4.3 / R14:

    >>> p = {"W_u": jnp.array([[0.5], [-0.3]]), "W_c": jnp.array([[0.1, 0.2], [0.0, -0.4]]),
    ...      "b_h": jnp.array([0.05, -0.05]), "W_o": jnp.array([[1.0, -2.0]]), "b_o": jnp.array([0.1])}
    >>> out, _ = elman_forward(p, jnp.array([1.0, 0.5, -1.0]))
    >>> [round(float(v), 6) for v in out[:, 0]]
    [1.273271, 0.506186, -0.84859]
    """
    f = _activation_fn(activation)
    inputs = jnp.asarray(inputs)
    if inputs.ndim == 1:
        inputs = inputs[:, None]
    if inputs.ndim != 2 or inputs.shape[1] != params["W_u"].shape[1]:
        raise ConfigError(
            f"inputs must have shape (T, {params['W_u'].shape[1]}) to match W_u; got {inputs.shape}"
        )
    w_c = params["W_c"]
    if h0 is None:
        h0 = jnp.zeros((w_c.shape[0],), dtype=w_c.dtype)
    pre = inputs @ params["W_u"].T + params["b_h"]

    def step(h, a):
        if stop_context_gradient:
            h = jax.lax.stop_gradient(h)
        h = f(a + w_c @ h)
        return h, h

    _, hidden = jax.lax.scan(step, h0, pre)
    outputs = hidden @ params["W_o"].T + params["b_o"]
    return outputs, hidden


def elman_loss(params, inputs, targets, *, h0=None, activation="tanh", loss="sse", training="bptt", mask=None):
    """Training loss of eq. (12): sum (``"sse"``) or mean (``"mse"``) of squared errors.

    Parameters
    ----------
    params, inputs, h0, activation
        As in :func:`elman_forward`.
    targets : array, shape (T,) or (T, n_outputs)
    loss : {"sse", "mse"}
    training : {"bptt", "bp"}
        ``"bptt"``: exact gradient through the whole sequence; ``"bp"``: the context is a
        constant input for the gradient (``stop_context_gradient=True``).
    mask : array, shape (T,), optional
        1 where a step counts, 0 where it does not; ``"mse"`` divides by ``mask.sum()``.

    Returns
    -------
    jax.Array
        Scalar loss.
    """
    if loss not in LOSSES:
        raise ConfigError(f"loss must be one of {LOSSES}; got {loss!r}")
    if training not in TRAININGS:
        raise ConfigError(f"training must be one of {TRAININGS}; got {training!r}")
    out, _ = elman_forward(params, inputs, h0, activation, stop_context_gradient=(training == "bp"))
    targets = jnp.asarray(targets).reshape(out.shape[0], -1)
    err2 = jnp.sum((out - targets) ** 2, axis=1)
    if mask is None:
        total, count = jnp.sum(err2), err2.shape[0]
    else:
        mask = jnp.asarray(mask, dtype=err2.dtype)
        total, count = jnp.sum(err2 * mask), jnp.sum(mask)
    return total if loss == "sse" else total / count




@dataclass(frozen=True)
class ElmanCell(RecurrentCell):
    """The Elman cell of eq. (11) behind the :class:`~fogdrift.models.training.RecurrentCell` interface.

    Parameters
    ----------
    activation : {"tanh", "logsig"}
        Hidden transfer function f.
    n_outputs : int
        Linear outputs m.

    Notes
    -----
    :meth:`step` is one step of one sample. :meth:`scan` (used by the training loop) computes
    the input projection W_u u(k) + b_h and the read-out outside the time loop and runs the
    recurrence h <- f(a(k) + h W_cᵀ) on all sequences at once; it equals a scan of :meth:`step`
    (and :func:`elman_forward`) to rounding.

    Examples
    --------
    >>> cell = ElmanCell("tanh")
    >>> p = cell.init(jax.random.key(0), 4, 16)
    >>> h, y = cell.step(p, jnp.zeros(16), jnp.ones(4))
    >>> h.shape, y.shape
    ((16,), (1,))
    """

    activation: str = "tanh"
    n_outputs: int = 1

    def init(self, key, n_in, n_hidden, dtype=jnp.float32):
        return init_params(key, n_in, n_hidden, self.n_outputs, dtype=dtype)

    def step(self, params, h, x):
        h = _activation_fn(self.activation)(params["W_u"] @ x + params["W_c"] @ h + params["b_h"])
        return h, params["W_o"] @ h + params["b_o"]

    def scan(self, params, h0, xs, *, stop_context_gradient=False):
        f = _activation_fn(self.activation)
        w_c_t = params["W_c"].T
        pre = xs @ params["W_u"].T + params["b_h"]

        def body(h, a):
            if stop_context_gradient:
                h = jax.lax.stop_gradient(h)
            h = f(a + h @ w_c_t)
            return h, h

        h_end, hid = jax.lax.scan(body, h0, pre)
        return h_end, hid @ params["W_o"].T + params["b_o"]


@functools.partial(jax.jit, static_argnames=("activation",))
def _forward_jit(params, inputs, h0, activation):
    return elman_forward(params, inputs, h0, activation)


# ------------------------------------------------------------------------------------------
# estimators
# ------------------------------------------------------------------------------------------
def _bucket(n: int) -> int:
    """Pad lengths to 2^k (k >= 6) so predict compiles once per size class."""
    return max(64, 1 << (int(n) - 1).bit_length())


class Elman(DriftModel):
    """Elman recurrent network as a one-step drift predictor (Tang et al. 2012, eq. (11)).

    Input u(k) = the last ``lags`` samples [y(k-1), ..., y(k-p)], z-scored with the mean and
    std of the training block; context = previous hidden state (unit-weight copy); linear
    output = z-scored prediction of y(k). The hidden state runs along the whole series.

    Parameters
    ----------
    lags : int
        Number p of past samples fed as input.
    hidden : int
        Hidden (and context) units.
    activation : {"tanh", "logsig"}
        Hidden transfer function (MATLAB ``tansig`` / ``logsig``).
    loss : {"sse", "mse"}
        Sum of squared errors as in eq. (12), or their mean (z-scored units).
    training : {"bptt", "bp"}
        ``"bptt"``: back-propagation through time (exact within each window, see ``window``).
        ``"bp"``: classic Elman BP, the context is a constant input for the gradient (BPTT
        truncated to depth 1, ``jax.lax.stop_gradient`` on the carried state).
    optimizer : {"adam", "traingdx"} or None
        Update rule. None: ``"adam"`` (optax) for ``"bptt"``, ``"traingdx"`` for ``"bp"``.
        ``"traingdx"`` is MATLAB's batch gradient descent with momentum 0.9 and adaptive
        learning rate (x1.05 after an improving step, x0.7 and step rejected when the loss
        grows by more than 4 %, momentum reset), method notes §4.2.
    learning_rate : float or None
        None: 1e-3 for Adam, 0.01 for traingdx (MATLAB default).
    epochs : int
        Maximum number of epochs (passes over the training block).
    patience : int
        Stopping rule: after every epoch the training and validation losses are computed in
        one forward pass over all windows; training stops after ``patience`` epochs without a
        validation improvement of more than 0.01 % (relative), or after ``epochs``. The
        parameters of the best validation epoch are kept.
    val_fraction : float
        If ``fit`` gets no ``y_val``, the last ``val_fraction`` of ``y_train`` (chronological)
        is held out for early stopping. 0 disables the hold-out (the training loss is
        monitored instead).
    window : int or None
        Truncated BPTT: the training sequence is cut into consecutive windows of ``window``
        steps. Gradients flow through time only inside a window; the context entering window
        j is the hidden state window j-1 ended with in the full forward pass at the end of
        the *previous* epoch (carried, no gradient). None, or a window at least as long as the
        data, gives exact full-sequence BPTT from a zero context.
    batch_size : int or None
        Target number of steps per gradient update (Adam only). The windows are dealt into
        G = ceil(n_windows / (batch_size // window)) interleaved groups (group g holds windows
        g, g+G, ...; fixed, no shuffling) and each epoch makes G updates. None, or data no
        longer than ``batch_size``, gives one full-batch update per epoch. ``traingdx`` is
        always full-batch (as MATLAB).
    clip_norm : float or None
        Global gradient-norm clipping (Adam only).
    weight_decay : float
        Decoupled weight decay (AdamW) if > 0 (Adam only).
    seed : int
        Seed of the weight initialisation (``jax.random.key(seed)``); nothing else is random.
    dtype : {"float32", "float64"}
        Network dtype; float64 needs ``jax_enable_x64``.
    progress : callable or None
        ``progress(epoch, n_epochs, train_loss, val_loss)`` called after every epoch (in
        batches of 25 epochs). Written as null in a model file (:func:`~fogdrift.models.save_model`).

    Attributes
    ----------
    params_ : dict of ndarray
        Best-validation weights (see :func:`init_params` for shapes).
    x_mean_, x_std_ : float
        Mean and std [deg/h] of the training part (hold-out excluded) used for z-scoring.
    n_train_ : int
        Samples in the training part (hold-out excluded).
    history_ : ndarray, shape (lags,)
        Last samples of ``y_train`` [deg/h], start of free-run forecasts.
    context_ : ndarray, shape (hidden,)
        Hidden state after running over ``y_train``.
    loss_curve_, val_curve_ : ndarray, shape (n_epochs_,)
        Training and validation loss per epoch (``loss`` on z-scored targets).
    best_epoch_, n_epochs_ : int
        Epoch of the kept parameters; epochs run.
    """

    label = "Elman"
    uses_validation = True  # early stopping (and the best-epoch choice) on y_val or the held-out tail

    def __init__(self, *, lags=4, hidden=16, activation="tanh", loss="sse", training="bptt", optimizer=None,
                 learning_rate=None, epochs=2000, patience=100, val_fraction=0.2, window=64, batch_size=2048,
                 clip_norm=1.0, weight_decay=0.0, seed=0, dtype="float32", progress=None):
        self.lags = lags
        self.hidden = hidden
        self.activation = activation
        self.loss = loss
        self.training = training
        self.optimizer = optimizer
        self.learning_rate = learning_rate
        self.epochs = epochs
        self.patience = patience
        self.val_fraction = val_fraction
        self.window = window
        self.batch_size = batch_size
        self.clip_norm = clip_norm
        self.weight_decay = weight_decay
        self.seed = seed
        self.dtype = dtype
        self.progress = progress

    # -- validation -----------------------------------------------------------------------
    def _validate(self):
        """Check every hyper-parameter; returns the validated :class:`TrainConfig`."""
        def integer(name, lo):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
                raise ConfigError(f"{name} must be an integer >= {lo}; got {v!r}")
            return int(v)

        def choice(name, options):
            v = getattr(self, name)
            if v not in options:
                raise ConfigError(f"{name} must be one of {options}; got {v!r}")
            return v

        integer("lags", 1), integer("hidden", 1), integer("seed", 0)
        choice("activation", _ACTIVATIONS)
        dtype = choice("dtype", _DTYPES)
        config = train_config(loss=self.loss, training=self.training, optimizer=self.optimizer,
                              learning_rate=self.learning_rate, epochs=self.epochs, patience=self.patience,
                              window=self.window, batch_size=self.batch_size, clip_norm=self.clip_norm,
                              weight_decay=self.weight_decay)
        vf = self.val_fraction
        if not (isinstance(vf, (int, float)) and 0.0 <= vf < 1.0):
            raise ConfigError(f"val_fraction must be in [0, 1); got {vf!r}")
        if self.progress is not None and not callable(self.progress):
            raise ConfigError(f"progress must be callable or None; got {self.progress!r}")
        if dtype == "float64" and not jax.config.jax_enable_x64:
            raise ConfigError(
                "dtype='float64' needs JAX 64-bit mode; set JAX_ENABLE_X64=1 or call "
                "jax.config.update('jax_enable_x64', True) first, or use dtype='float32'"
            )
        return config

    def _cell(self) -> ElmanCell:
        return ElmanCell(activation=self.activation)

    # -- data transforms ---------------------------------------------------------------------
    def _design(self, s: np.ndarray, x1_start: float = 0.0):
        """Inputs and targets for every step k = p..len(s)-1 (float64, private).

        Returns ``(U (T, p), target (T,), c, d)`` with the restore rule
        ``y_hat(k) = x_mean_ + x_std_ * (c * out(k) + d(k))``.
        """
        p = self.lags
        z = (s - self.x_mean_) / self.x_std_
        lags = np.lib.stride_tricks.sliding_window_view(z, p)[: len(z) - p, ::-1]
        return np.ascontiguousarray(lags), z[p:], 1.0, 0.0

    def _stats_extra(self, s_fit: np.ndarray) -> None:
        """Hook for subclasses: more training-block statistics."""

    # -- fitting ------------------------------------------------------------------------------
    def _prepare(self, y_train, y_val):
        """Validate, set the training-part statistics, and window the (input, target) rows.

        Returns ``(TrainConfig, TrainingData, y_train as array)``.
        """
        config = self._validate()
        p = int(self.lags)
        y = check_series(y_train, "y_train", min_length=p + 2)
        if y_val is None:
            n_va = int(round(self.val_fraction * y.size))
            s_fit, s_va = y[: y.size - n_va], y[y.size - n_va:]
        else:
            s_fit, s_va = y, check_series(y_val, "y_val")
        if s_fit.size < p + 2:
            raise InsufficientDataError(
                f"the training part has {s_fit.size} samples; lags={p} needs at least {p + 2}",
                needed=p + 2, got=int(s_fit.size),
            )
        # normalisation from the training part only (method notes §4.1, §5.1)
        self.x_mean_ = float(np.mean(s_fit))
        std = float(np.std(s_fit))
        if not std > 0:
            warnings.warn("training block is constant; z-scoring with std 1", FogdriftWarning, stacklevel=3)
            std = 1.0
        self.x_std_ = std
        self.n_train_ = int(s_fit.size)
        self._stats_extra(s_fit)
        # one sequence: training rows, then validation rows whose lags reach back into the training part
        u, t, _, _ = self._design(np.concatenate([s_fit, s_va]))
        data = window_data(u, t, s_fit.size - p, config, dtype=self.dtype)
        return config, data, y

    def _finish(self, result: TrainResult, y_block):
        self.params_ = {k: np.asarray(v) for k, v in result.params.items()}
        self.loss_curve_ = result.loss_curve
        self.val_curve_ = result.val_curve
        self.best_epoch_ = result.best_epoch
        self.n_epochs_ = result.n_epochs
        self._set_start_state(y_block)
        return self

    def fit(self, y_train, y_val=None):
        """Train on ``y_train`` [deg/h], early-stopping on ``y_val`` (or the held-out tail).

        ``y_val`` must follow ``y_train`` immediately in time; its lags reach back into
        ``y_train``. The z-score statistics come from ``y_train`` (hold-out excluded) only.
        Returns ``self``.
        """
        config, data, y = self._prepare(y_train, y_val)
        result = fit_recurrent(self._cell(), int(self.hidden), config, data, seed=self.seed, progress=self.progress)
        return self._finish(result, y)

    # -- prediction ----------------------------------------------------------------------------
    def _params_j(self):
        dt = jnp.dtype(str(self.params_["W_c"].dtype))
        return {k: jnp.asarray(v, dtype=dt) for k, v in self.params_.items()}, dt

    def _run(self, s: np.ndarray, x1_start: float = 0.0):
        """One-step outputs over ``s`` (steps p..len-1): (y_hat (T,), last hidden state)."""
        u, _, c, d = self._design(s, x1_start)
        params, dt = self._params_j()
        n = u.shape[0]
        if n == 0:
            return np.empty(0), np.zeros(self.params_["W_c"].shape[0])
        u_pad = np.zeros((_bucket(n), u.shape[1]))
        u_pad[:n] = u
        h0 = jnp.zeros((self.params_["W_c"].shape[0],), dtype=dt)
        out, hid = _forward_jit(params, jnp.asarray(u_pad, dtype=dt), h0, self.activation)
        out = np.asarray(out[:n, 0], dtype=np.float64)
        return self.x_mean_ + self.x_std_ * (c * out + d), np.asarray(hid[n - 1], dtype=np.float64)

    def _set_start_state(self, y_block: np.ndarray) -> None:
        _, h_last = self._run(y_block)
        self.context_ = h_last
        self.history_ = np.array(y_block[-self.lags:], dtype=np.float64)
        self.x1_last_ = float(np.sum((y_block - self.x_mean_) / self.x_std_))

    def predict(self, y, *, history=None):
        """One-step-ahead predictions [deg/h]: ``out[k]`` predicts ``y[k]`` from ``history`` + ``y[:k]``.

        The context starts at zero at the first step that has ``lags`` samples; pass a few
        hundred samples of ``history`` so it has settled. Entries without ``lags`` samples
        before them are NaN.
        """
        self._check_fitted()
        y = check_series(y, "y")
        hist = np.empty(0) if history is None else check_series(history, "history")
        s = np.concatenate([hist, y])
        yhat, _ = self._run(s)
        full = np.full(s.size, np.nan)
        full[self.lags:] = yhat
        return full[hist.size:]

    def _next_z(self, out, x1_prev):
        """Free-run restore in z units: z_hat(k) from the network output (plain Elman: out)."""
        return out

    def _free_inputs(self, zwin, x1_prev):
        return zwin

    def forecast(self, h: int, *, history=None):
        """Free-run forecast [deg/h] of ``h`` steps after ``history`` (default: after ``y_train``).

        Predictions are fed back as inputs; for :class:`GreyElman` the AGO is restored with
        eq. (13), x0*(t) = x1*(t) - x1*(t-1).
        """
        self._check_fitted()
        if isinstance(h, bool) or not isinstance(h, (int, np.integer)) or h < 0:
            raise ConfigError(f"h must be an integer >= 0; got {h!r}")
        if history is None:
            hist, ctx, x1 = self.history_, self.context_, self.x1_last_
        else:
            hist = check_series(history, "history", min_length=self.lags)
            _, ctx = self._run(hist)
            x1 = float(np.sum((hist - self.x_mean_) / self.x_std_))
        f = np.tanh if self.activation == "tanh" else (lambda a: 1.0 / (1.0 + np.exp(-a)))
        w = {k: np.asarray(v, dtype=np.float64) for k, v in self.params_.items()}
        zwin = ((hist[-self.lags:] - self.x_mean_) / self.x_std_)[::-1].copy()
        hcur = np.asarray(ctx, dtype=np.float64)
        out = np.empty(int(h))
        for t in range(int(h)):
            u = self._free_inputs(zwin, x1)
            hcur = f(w["W_u"] @ u + w["W_c"] @ hcur + w["b_h"])
            z_hat = self._next_z(float(w["W_o"][0] @ hcur + w["b_o"][0]), x1)
            zwin = np.concatenate([[z_hat], zwin[:-1]])
            x1 += z_hat
            out[t] = self.x_mean_ + self.x_std_ * z_hat
        return out

    # -- fitted state as data (the ``progress`` callable is a parameter, saved as null) ---------
    def _get_state(self):
        meta = {"x_mean_": self.x_mean_, "x_std_": self.x_std_, "n_train_": self.n_train_,
                "best_epoch_": self.best_epoch_, "n_epochs_": self.n_epochs_, "x1_last_": self.x1_last_}
        meta.update(self._extra_meta())
        arrays = {f"params_{k}": v for k, v in self.params_.items()}
        arrays.update(history_=self.history_, context_=self.context_, loss_curve_=self.loss_curve_,
                      val_curve_=self.val_curve_)
        return meta, arrays

    def _extra_meta(self) -> dict:
        return {}

    def _set_state(self, meta, arrays):
        for key in ("x_mean_", "x_std_", "x1_last_"):
            setattr(self, key, float(meta[key]))
        for key in ("n_train_", "best_epoch_", "n_epochs_"):
            setattr(self, key, int(meta[key]))
        for key, value in meta.items():
            if key not in ("x_mean_", "x_std_", "x1_last_", "n_train_", "best_epoch_", "n_epochs_"):
                setattr(self, key, value)
        self.params_ = {k[len("params_"):]: np.asarray(v) for k, v in arrays.items() if k.startswith("params_")}
        for key in ("history_", "context_", "loss_curve_", "val_curve_"):
            setattr(self, key, np.asarray(arrays[key]))


class GreyElman(Elman):
    """Grey Elman network: AGO of the drift -> Elman on AGO values -> IAGO (Tang et al. 2012, §5).

    The drift x0 is z-scored with training-block statistics, then accumulated (AGO, eq. (10)):
    x1(k) = sum_{i<=k} z(i), from the first training sample (for ``predict``/``forecast`` with
    ``history``, from the first sample of ``history``; the AGO continues through it). The
    network maps the last p AGO values to x1(k); the loss (eq. (12)) is on x1.

    Two framings of the AGO values, ``ago_frame``:

    * ``"latest"`` (default): the p lagged AGO values are given relative to the *measured*
      x1(k-1), i.e. u_i = x1(k-1-i) - x1(k-1), i = 1..p (minus partial sums of z), and the
      network predicts x1(k) - x1(k-1). This keeps the AGO-target design while staying in
      the training range: raw AGO values of the test block lie outside the training range
      (x1 grows like k times the mean, method notes §4.1), where tanh units saturate. It is
      the plain Elman with its inputs mapped by a fixed invertible (triangular) matrix, so
      it has the same information; any difference in skill comes from the training.
    * ``"global"``: the paper-literal framing. x1 itself is z-scored with the mean and std of
      the training-block x1, the inputs are x1(k-1..k-p) and the target x1(k). Out-of-range
      test inputs are the caller's risk (kept for replication).

    One-step predictions are restored with the measured previous sum,
    y0_hat(k) = x1_hat(k) - x1(k-1) (method notes §4.1, §5.5); free-run forecasts with
    eq. (13), x0*(t) = x1*(t) - x1*(t-1), both terms predicted.

    Parameters
    ----------
    ago_frame : {"latest", "global"}
        See above. Every other parameter is as in :class:`Elman`.

    Attributes
    ----------
    x1_mean_, x1_std_ : float
        (``"global"`` only) z-scoring of the training-block AGO (z units).
    x1_last_ : float
        AGO (z units) at the end of ``y_train``: start of free-run forecasts.
    """

    label = "grey-Elman"

    def __init__(self, *, lags=4, hidden=16, activation="tanh", loss="sse", training="bptt", optimizer=None,
                 learning_rate=None, epochs=2000, patience=100, val_fraction=0.2, window=64, batch_size=2048,
                 clip_norm=1.0, weight_decay=0.0, seed=0, dtype="float32", progress=None, ago_frame="latest"):
        super().__init__(lags=lags, hidden=hidden, activation=activation, loss=loss, training=training,
                         optimizer=optimizer, learning_rate=learning_rate, epochs=epochs, patience=patience,
                         val_fraction=val_fraction, window=window, batch_size=batch_size, clip_norm=clip_norm,
                         weight_decay=weight_decay, seed=seed, dtype=dtype, progress=progress)
        self.ago_frame = ago_frame

    def _validate(self):
        if self.ago_frame not in ("latest", "global"):
            raise ConfigError(f"ago_frame must be 'latest' or 'global'; got {self.ago_frame!r}")
        return super()._validate()

    def _stats_extra(self, s_fit):
        x1 = np.cumsum((s_fit - self.x_mean_) / self.x_std_)
        self.x1_mean_ = float(np.mean(x1))
        self.x1_std_ = float(np.std(x1)) or 1.0

    def _design(self, s, x1_start=0.0):
        p = self.lags
        z = (s - self.x_mean_) / self.x_std_
        zl = np.lib.stride_tricks.sliding_window_view(z, p)[: len(z) - p, ::-1]  # z(k-1), ..., z(k-p)
        if self.ago_frame == "latest":
            return -np.cumsum(zl, axis=1), z[p:], 1.0, 0.0
        x1 = x1_start + np.cumsum(z)
        x1l = np.lib.stride_tricks.sliding_window_view(x1, p)[: len(x1) - p, ::-1]  # x1(k-1), ..., x1(k-p)
        m, sd = self.x1_mean_, self.x1_std_
        u = (x1l - m) / sd
        # x0_hat(k) = x1_hat(k) - x1(k-1) with x1_hat = m + sd * out  (measured x1(k-1))
        return u, (x1[p:] - m) / sd, sd, m - x1l[:, 0]

    def _free_inputs(self, zwin, x1_prev):
        if self.ago_frame == "latest":
            return -np.cumsum(zwin)
        x1l = x1_prev - np.concatenate([[0.0], np.cumsum(zwin)[:-1]])
        return (x1l - self.x1_mean_) / self.x1_std_

    def _next_z(self, out, x1_prev):
        if self.ago_frame == "latest":
            return out
        return self.x1_mean_ + self.x1_std_ * out - x1_prev  # eq. (13)

    def _extra_meta(self):
        if hasattr(self, "x1_mean_"):
            return {"x1_mean_": self.x1_mean_, "x1_std_": self.x1_std_}
        return {}

    def _set_state(self, meta, arrays):
        super()._set_state(meta, arrays)
        for key in ("x1_mean_", "x1_std_"):
            if key in meta:
                setattr(self, key, float(meta[key]))


def fit_many(model, y_train, y_val=None, *, seeds):
    """Train one copy of ``model`` per seed at once (``jax.vmap`` over the weight sets).

    Parameters
    ----------
    model : Elman or GreyElman
        Template; its hyper-parameters are used, ``seed`` is replaced by each of ``seeds``.
    y_train, y_val : array
        As in :meth:`Elman.fit`.
    seeds : sequence of int
        One model per seed.

    Returns
    -------
    list of Elman
        Fitted copies, in the order of ``seeds``; each equals ``type(model)(..., seed=s).fit(...)``
        up to floating-point reassociation. Every model keeps its own early-stopping epoch
        (a stopped model is frozen while the others continue).
    """
    if not isinstance(model, Elman):
        raise ConfigError(f"fit_many needs an Elman or GreyElman model; got {type(model).__name__}")
    seeds = list(seeds)
    if not seeds:
        raise ConfigError("seeds must hold at least one seed; got an empty sequence")
    models = [type(model)(**{**model.get_params(), "seed": s}) for s in seeds]
    base = models[0]
    config, data, y = base._prepare(y_train, y_val)
    for m in models[1:]:
        m._validate()
        for key in ("x_mean_", "x_std_", "n_train_", "x1_mean_", "x1_std_"):
            if hasattr(base, key):
                setattr(m, key, getattr(base, key))
    results = fit_recurrent_many(base._cell(), int(base.hidden), config, data, seeds=seeds, progress=model.progress)
    for m, result in zip(models, results):
        m._finish(result, y)
    return models
