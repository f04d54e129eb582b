"""Training loop of recurrent drift models, written against a small "cell" interface.

A recurrent cell is anything with

* ``init(key, n_in, n_hidden, dtype=...) -> params`` (a pytree of arrays) and
* ``step(params, h, x) -> (h, y)``: one time step of **one** sample (``x`` shape (n_in,),
  ``y`` shape (n_out,); ``h`` any pytree of arrays whose leaves have a leading hidden axis).

:class:`RecurrentCell` turns those two into a batched scan (``jax.vmap`` of ``step`` inside a
``jax.lax.scan``); a cell may override :meth:`RecurrentCell.scan` with a faster formulation
(the Elman cell does) and :meth:`RecurrentCell.initial_state` for a non-array state (an LSTM's
``(h, c)``). Everything else here is cell-agnostic, so a GRU or LSTM reuses it unchanged:

* :func:`train_config` validates the training hyper-parameters into a :class:`TrainConfig`;
* :func:`window_data` cuts one chronological sequence of (input, target) rows, training rows
  first and validation rows after them, into consecutive windows for truncated BPTT;
* :func:`fit_recurrent` trains one weight set; :func:`fit_recurrent_many` trains one weight set
  per seed at once (``jax.vmap`` over the seeds), each with its own early stopping;
* :func:`make_optimizer` builds the optax optimizer (Adam/AdamW with clipping); MATLAB's
  ``traingdx`` (batch gradient descent, momentum, adaptive learning rate) is built in.

Truncated BPTT: gradients flow through time only inside a window; the state entering window j
is the state window j - 1 ended with in the full forward pass of the *previous* epoch (no
gradient). Training ``"bp"`` stops the gradient at the carried state of every step (classic
Elman BP, BPTT truncated to depth 1, MATLAB ``staticderiv``). Early stopping: after every epoch
one forward pass over all windows gives the training and validation losses; training stops
after ``patience`` epochs without a relative validation improvement above 0.01 %, or after
``epochs``, and the best-validation parameters are kept. A stopped model is frozen, so results
do not depend on how epochs are chunked or how many seeds are trained together.

This module and :mod:`fogdrift.models.elman` are the only ones that import JAX.

References
----------
J. L. Elman, "Finding structure in time", Cognitive Science 14(2):179-211, 1990.
MATLAB Neural Network Toolbox, ``traingdx`` (method notes §4.2); modern practice (Adam, clipping,
early stopping on a chronological validation block, several seeds): method notes §4.3.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Callable

import jax
import jax.numpy as jnp
import numpy as np
import optax

from ..errors import ConfigError
from . import compile_cache

compile_cache.enable(jax)  # the networks' XLA programs kept between commands (compile_cache)

__all__ = [
    "RecurrentCell",
    "TrainConfig",
    "train_config",
    "TrainingData",
    "window_data",
    "TrainResult",
    "make_optimizer",
    "fit_recurrent",
    "fit_recurrent_many",
    "TRAINGDX",
]

LOSSES = ("sse", "mse")
TRAININGS = ("bptt", "bp")
OPTIMIZERS = ("adam", "traingdx")
#: MATLAB traingdx defaults (method notes §4.2): momentum, lr increase/decrease, max perf increase.
TRAINGDX = {"mc": 0.9, "lr_inc": 1.05, "lr_dec": 0.7, "max_perf_inc": 1.04}
#: Relative improvement of the validation loss that resets the patience counter.
IMPROVE_RTOL = 1e-4
#: Epochs run per compiled call (the host checks the stopping rule between chunks).
CHUNK = 25

_tmap = jax.tree_util.tree_map


# ------------------------------------------------------------------------------------------
# the cell interface
# ------------------------------------------------------------------------------------------
class RecurrentCell:
    """Base of recurrent cells: ``init`` and ``step`` are required, the rest has defaults.

    Subclasses should be frozen dataclasses: the cell is hashed to key the compiled training
    step, so two equal cells share one compilation.
    """

    def init(self, key, n_in: int, n_hidden: int, dtype=jnp.float32):  # pragma: no cover - abstract
        """Random parameters (a pytree of arrays) from the PRNG ``key``."""
        raise NotImplementedError

    def step(self, params, h, x):  # pragma: no cover - abstract
        """One step of one sample: ``(h(k-1), x(k)) -> (h(k), y(k))``, ``y`` of shape (n_out,)."""
        raise NotImplementedError

    def initial_state(self, n_hidden: int, batch_shape: tuple = (), dtype=jnp.float32):
        """Zero state, shape ``batch_shape + (n_hidden,)``; override for a pytree state."""
        return jnp.zeros(tuple(batch_shape) + (int(n_hidden),), dtype=dtype)

    def scan(self, params, h0, xs, *, stop_context_gradient: bool = False):
        """Run over a batch of sequences.

        Parameters
        ----------
        params
            As returned by :meth:`init`.
        h0 : pytree, leaves of shape (B, ...)
            State before the first step, one per sequence.
        xs : array, shape (T, B, n_in)
            Time-major inputs.
        stop_context_gradient : bool
            Treat the carried state as a constant for the gradient (classic Elman "BP").

        Returns
        -------
        h_end : pytree, leaves of shape (B, ...)
            State after the last step.
        ys : array, shape (T, B, n_out)
            Outputs.
        """
        batched = jax.vmap(lambda h, x: self.step(params, h, x))

        def body(h, x):
            if stop_context_gradient:
                h = jax.lax.stop_gradient(h)
            return batched(h, x)

        return jax.lax.scan(body, h0, xs)


# ------------------------------------------------------------------------------------------
# configuration and data layout
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class TrainConfig:
    """Validated training hyper-parameters (see :func:`train_config` for their meaning)."""

    loss: str
    training: str
    optimizer: str
    learning_rate: float
    epochs: int
    patience: int
    window: int | None
    batch_size: int | None
    clip_norm: float | None
    weight_decay: float


def _integer(name, value, lo):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < lo:
        raise ConfigError(f"{name} must be an integer >= {lo}; got {value!r}")
    return int(value)


def train_config(*, loss="sse", training="bptt", optimizer=None, learning_rate=None, epochs=2000, patience=100,
                 window=64, batch_size=2048, clip_norm=1.0, weight_decay=0.0) -> TrainConfig:
    """Validate training hyper-parameters and resolve their ``None`` defaults.

    Parameters
    ----------
    loss : {"sse", "mse"}
        Sum of squared errors (eq. (12) of Tang et al. 2012) or their mean.
    training : {"bptt", "bp"}
        Truncated BPTT inside windows, or classic Elman BP (gradient stopped at the state).
    optimizer : {"adam", "traingdx"} or None
        None: ``"adam"`` for ``"bptt"``, ``"traingdx"`` for ``"bp"``.
    learning_rate : float or None
        None: 1e-3 for Adam, 0.01 for traingdx (MATLAB default).
    epochs, patience : int
        Maximum epochs; epochs without a validation improvement before stopping.
    window : int or None
        Truncated-BPTT window [steps]; None: the whole sequence.
    batch_size : int or None
        Target steps per update (Adam only); None: one full-batch update per epoch.
    clip_norm : float or None
        Global gradient-norm clipping (Adam only).
    weight_decay : float
        Decoupled weight decay (AdamW) when > 0 (Adam only).

    Returns
    -------
    TrainConfig

    Raises
    ------
    ConfigError
        A value outside its rule (the message names the parameter).

    Examples
    --------
    >>> train_config(training="bp").optimizer, train_config(training="bp").learning_rate
    ('traingdx', 0.01)
    """
    if loss not in LOSSES:
        raise ConfigError(f"loss must be one of {LOSSES}; got {loss!r}")
    if training not in TRAININGS:
        raise ConfigError(f"training must be one of {TRAININGS}; got {training!r}")
    epochs, patience = _integer("epochs", epochs, 1), _integer("patience", patience, 1)
    if optimizer is None:
        optimizer = "adam" if training == "bptt" else "traingdx"
    elif optimizer not in OPTIMIZERS:
        raise ConfigError(f"optimizer must be one of {OPTIMIZERS} or None; got {optimizer!r}")
    lr = learning_rate
    if lr is None:
        lr = 1e-3 if optimizer == "adam" else 0.01
    if not (isinstance(lr, (int, float)) and not isinstance(lr, bool) and lr > 0 and math.isfinite(lr)):
        raise ConfigError(f"learning_rate must be a positive number or None; got {learning_rate!r}")
    if window is not None:
        window = _integer("window", window, 1)
    if batch_size is not None:
        batch_size = _integer("batch_size", batch_size, 1)
    if clip_norm is not None and not (isinstance(clip_norm, (int, float)) and clip_norm > 0):
        raise ConfigError(f"clip_norm must be a positive number or None; got {clip_norm!r}")
    if not (isinstance(weight_decay, (int, float)) and weight_decay >= 0):
        raise ConfigError(f"weight_decay must be a number >= 0; got {weight_decay!r}")
    return TrainConfig(loss=loss, training=training, optimizer=optimizer, learning_rate=float(lr), epochs=epochs,
                       patience=patience, window=window, batch_size=batch_size,
                       clip_norm=None if clip_norm is None else float(clip_norm), weight_decay=float(weight_decay))


@dataclass(frozen=True)
class TrainingData:
    """Windowed training data (from :func:`window_data`).

    Attributes
    ----------
    arrays : tuple
        ``(inputs (W, n_win, n_in), targets (W, n_win), train_mask, val_mask, counts)``, time-major,
        padded with masked rows; ``counts`` holds the row counts and the stopping rule as arrays.
    n_in, window, n_windows, groups, n_train, n_val : int
        Input width, window length, number of windows (a multiple of ``groups``), interleaved
        update groups per epoch, training and validation rows.
    dtype : str
        Floating dtype of the arrays.
    """

    arrays: tuple
    n_in: int
    window: int
    n_windows: int
    groups: int
    n_train: int
    n_val: int
    dtype: str


def window_data(inputs, targets, n_train: int, config: TrainConfig, *, dtype="float32") -> TrainingData:
    """Cut one chronological sequence of rows into windows for truncated BPTT.

    Parameters
    ----------
    inputs : ndarray, shape (n_rows, n_in)
        Input vector of every step, in time order.
    targets : ndarray, shape (n_rows,)
        Target of every step.
    n_train : int
        Rows ``[0, n_train)`` are training rows, the rest validation rows (chronologically after
        them; the state runs on through them, they never enter the gradient).
    config : TrainConfig
        ``window``, ``batch_size`` and ``optimizer`` set the layout.
    dtype : str
        Floating dtype of the arrays.

    Returns
    -------
    TrainingData

    Notes
    -----
    Windows are consecutive, ``window`` rows each (the last one padded and masked). With Adam and
    a ``batch_size``, the windows are dealt into G = ceil(n_windows / (batch_size // window))
    interleaved groups (group g holds windows g, g + G, ...; fixed, no shuffling) and each
    epoch makes G updates; ``traingdx`` is always full-batch.
    """
    u = np.asarray(inputs, dtype=np.float64)
    t = np.asarray(targets, dtype=np.float64)
    n_rows = u.shape[0]
    rows = np.arange(n_rows)
    m_tr, m_va = (rows < n_train).astype(np.float64), (rows >= n_train).astype(np.float64)
    win = n_rows if config.window is None else min(int(config.window), n_rows)
    n_win = -(-n_rows // win)
    if config.optimizer == "traingdx" or config.batch_size is None:
        groups = 1
    else:
        groups = -(-n_win // max(1, int(config.batch_size) // win))
    n_win = groups * -(-n_win // groups)  # whole groups; padding windows are masked out
    pad = n_win * win - n_rows
    dt = jnp.dtype(dtype)

    def shape(a):
        a = np.concatenate([a, np.zeros((pad,) + a.shape[1:])])
        a = np.swapaxes(a.reshape((n_win, win) + a.shape[1:]), 0, 1)  # time-major (win, n_win, ...)
        return jnp.asarray(np.ascontiguousarray(a), dtype=dt)

    n_va = n_rows - int(n_train)
    counts = {"n_tr": jnp.asarray(int(n_train), dt), "n_va": jnp.asarray(n_va, dt),
              "patience": jnp.asarray(config.patience, jnp.int32), "epochs": jnp.asarray(config.epochs, jnp.int32)}
    return TrainingData(arrays=(shape(u), shape(t), shape(m_tr), shape(m_va), counts), n_in=int(u.shape[1]),
                        window=int(win), n_windows=int(n_win), groups=int(groups), n_train=int(n_train),
                        n_val=int(n_va), dtype=str(dt))


@dataclass(frozen=True)
class TrainResult:
    """Outcome of one training run.

    Attributes
    ----------
    params : pytree of ndarray
        Best-validation parameters (float arrays of the training dtype).
    loss_curve, val_curve : ndarray, shape (n_epochs,)
        Training loss and the monitored loss (validation, or training when there are no
        validation rows) after each epoch.
    best_epoch : int
        0-based epoch of ``params``.
    n_epochs : int
        Epochs run.
    """

    params: object
    loss_curve: np.ndarray
    val_curve: np.ndarray
    best_epoch: int
    n_epochs: int


# ------------------------------------------------------------------------------------------
# optimizers
# ------------------------------------------------------------------------------------------
def make_optimizer(learning_rate: float, *, clip_norm=None, weight_decay: float = 0.0):
    """Adam (AdamW when ``weight_decay`` > 0), after global-norm clipping when ``clip_norm`` is set.

    Examples
    --------
    >>> opt = make_optimizer(1e-3, clip_norm=1.0)
    >>> state = opt.init({"w": jnp.zeros(2)})
    """
    parts = []
    if clip_norm:
        parts.append(optax.clip_by_global_norm(clip_norm))
    if weight_decay > 0:
        parts.append(optax.adamw(learning_rate, weight_decay=weight_decay))
    else:
        parts.append(optax.adam(learning_rate))
    return optax.chain(*parts)


def _optimizer_of(cfg):
    return make_optimizer(cfg["lr"], clip_norm=cfg["clip_norm"], weight_decay=cfg["weight_decay"])


def _init_opt_state(params, cfg):
    if cfg["optimizer"] == "adam":
        return _optimizer_of(cfg).init(params)
    zeros = _tmap(jnp.zeros_like, params)
    return {"lr": jnp.asarray(cfg["lr"], dtype=jax.tree_util.tree_leaves(params)[0].dtype), "dX": zeros}


# ------------------------------------------------------------------------------------------
# the compiled epoch (private; inputs assumed clean)
# ------------------------------------------------------------------------------------------
def _window_pass(cell, params, u_w, h0s, bp):
    """Forward over all windows at once: u_w (W, n_win, n_in), h0s (n_win, ...) -> outputs (W, n_win), states."""
    h_end, ys = cell.scan(params, h0s, u_w, stop_context_gradient=bp)
    return ys[..., 0], h_end


def _group(x, g, n_groups):
    """Windows g, g + G, g + 2G, ... of a time-major (W, n_win, ...) array -> (W, n_win / G, ...)."""
    x4 = x.reshape((x.shape[0], x.shape[1] // n_groups, n_groups) + x.shape[2:])
    return jax.lax.dynamic_index_in_dim(x4, g, axis=2, keepdims=False)


def _group_state(h, g, n_groups):
    """States of windows g, g + G, ...: leaves (n_win, ...) -> (n_win / G, ...)."""
    return h.reshape((h.shape[0] // n_groups, n_groups) + h.shape[1:])[:, g]


def _batch_loss(params, data, h0s, g, cfg):
    """Loss of one interleaved group of training windows (the whole set when there is one group)."""
    u_w, t_w, m_tr, _, _ = data
    n_groups = cfg["groups"]
    u, t, m = (_group(a, g, n_groups) for a in (u_w, t_w, m_tr))
    h0 = _tmap(lambda h: _group_state(h, g, n_groups), h0s)
    out, _ = _window_pass(cfg["cell"], params, u, h0, cfg["training"] == "bp")
    sse = jnp.sum((out - t) ** 2 * m)
    return sse if cfg["loss"] == "sse" else sse / jnp.maximum(jnp.sum(m), 1.0)


def _full_pass(params, data, h0s, cfg):
    """Forward over every window: (training loss, validation loss, final state of each window)."""
    u_w, t_w, m_tr, m_va, counts = data
    out, h_end = _window_pass(cfg["cell"], params, u_w, h0s, False)
    err2 = (out - t_w) ** 2
    sse_tr, sse_va = jnp.sum(err2 * m_tr), jnp.sum(err2 * m_va)
    if cfg["loss"] == "mse":
        sse_tr = sse_tr / counts["n_tr"]
        sse_va = sse_va / jnp.maximum(counts["n_va"], 1.0)
    return sse_tr, sse_va, h_end


def _shift_context(h_end, h0s):
    """State entering window j is the state window j-1 ended with (previous pass); window 0 keeps its own."""
    return jax.lax.stop_gradient(
        _tmap(lambda e, h: jnp.concatenate([h[0][None], e[:-1]], axis=0), h_end, h0s))


def _adam_updates(params0, opt0, data, h0s, cfg):
    opt = _optimizer_of(cfg)

    def update(c, g):
        p, o = c
        grads = jax.grad(_batch_loss)(p, data, h0s, g, cfg)
        updates, o = opt.update(grads, o, p)
        return (optax.apply_updates(p, updates), o), None

    (params, opt_state), _ = jax.lax.scan(update, (params0, opt0), jnp.arange(cfg["groups"]))
    return params, opt_state


def _traingdx_update(params0, opt0, data, h0s, epoch, cfg):
    """MATLAB traingdx (one batch): momentum + adaptive lr, reject steps raising perf > 4 %."""
    perf, grads = jax.value_and_grad(_batch_loss)(params0, data, h0s, 0, cfg)
    lr = opt0["lr"]
    g_desc = _tmap(jnp.negative, grads)
    dx_prev = _tmap(lambda d, g: jnp.where(epoch == 0, lr * g, d), opt0["dX"], g_desc)
    mc = TRAINGDX["mc"]
    dx = _tmap(lambda d, g: mc * d + (1.0 - mc) * lr * g, dx_prev, g_desc)
    trial = _tmap(jnp.add, params0, dx)
    perf2 = _batch_loss(trial, data, h0s, 0, cfg)
    accept = perf2 / perf <= TRAINGDX["max_perf_inc"]
    lr_new = jnp.where(accept, jnp.where(perf2 < perf, lr * TRAINGDX["lr_inc"], lr), lr * TRAINGDX["lr_dec"])
    dx_new = _tmap(lambda d, g: jnp.where(accept, d, lr_new * g), dx, g_desc)
    params = _tmap(lambda t, p: jnp.where(accept, t, p), trial, params0)
    return params, {"lr": lr_new.astype(lr.dtype), "dX": dx_new}


def _epoch(carry, _, data, cfg):
    """One epoch: one update per group of windows, then a full pass for the stopping rule."""
    params0, opt0, h0s, best, best_val, best_epoch, wait, stopped, epoch = carry
    counts = data[4]
    if cfg["optimizer"] == "adam":
        params, opt_state = _adam_updates(params0, opt0, data, h0s, cfg)
    else:
        params, opt_state = _traingdx_update(params0, opt0, data, h0s, epoch, cfg)

    loss_tr, loss_va, h_end = _full_pass(params, data, h0s, cfg)
    monitor = jnp.where(counts["n_va"] > 0, loss_va, loss_tr)
    active = jnp.logical_not(stopped)
    threshold = jnp.where(jnp.isfinite(best_val), best_val * (1.0 - IMPROVE_RTOL), jnp.inf)
    improved = active & (monitor < threshold)
    best = _tmap(lambda b, p: jnp.where(improved, p, b), best, params)
    best_val = jnp.where(improved, monitor, best_val)
    best_epoch = jnp.where(improved, epoch, best_epoch)
    wait = jnp.where(improved, 0, wait + active.astype(wait.dtype))
    now_stopped = stopped | (wait >= counts["patience"]) | (epoch + 1 >= counts["epochs"])
    # a stopped model is frozen, so results do not depend on how epochs are chunked or batched
    params = _tmap(lambda n, p: jnp.where(stopped, p, n), params, params0)
    opt_state = _tmap(lambda n, o: jnp.where(stopped, o, n), opt_state, opt0)
    h0s = _tmap(lambda n, o: jnp.where(stopped, o, n), _shift_context(h_end, h0s), h0s)
    carry = (params, opt_state, h0s, best, best_val, best_epoch, wait, now_stopped, epoch + active.astype(epoch.dtype))
    return carry, (loss_tr, monitor, active)


def _static(cell, config: TrainConfig, data: TrainingData) -> tuple:
    """Hashable description of everything the compiled epoch depends on besides array values."""
    return (("cell", cell), ("loss", config.loss), ("training", config.training), ("optimizer", config.optimizer),
            ("lr", config.learning_rate), ("clip_norm", config.clip_norm), ("weight_decay", config.weight_decay),
            ("groups", data.groups))


@functools.lru_cache(maxsize=64)
def _chunk_fn(static: tuple, batched: bool):
    cfg = dict(static)

    def run(carry, data):
        return jax.lax.scan(lambda c, x: _epoch(c, x, data, cfg), carry, None, length=CHUNK)

    if batched:
        run = jax.vmap(run, in_axes=(0, None))
    return jax.jit(run)


def _init_carry(cell, n_hidden, config: TrainConfig, data: TrainingData, seed):
    dt = jnp.dtype(data.dtype)
    params = cell.init(jax.random.key(int(seed)), data.n_in, int(n_hidden), dtype=dt)
    h0s = cell.initial_state(int(n_hidden), (data.n_windows,), dt)
    cfg = dict(_static(cell, config, data))
    return (params, _init_opt_state(params, cfg), h0s, params, jnp.asarray(jnp.inf, dt),
            jnp.asarray(0, jnp.int32), jnp.asarray(0, jnp.int32), jnp.asarray(False), jnp.asarray(0, jnp.int32))


# ------------------------------------------------------------------------------------------
# public entry points
# ------------------------------------------------------------------------------------------
def fit_recurrent(cell, n_hidden: int, config: TrainConfig, data: TrainingData, *, seed: int = 0,
                  progress: Callable | None = None) -> TrainResult:
    """Train one weight set of ``cell`` on windowed data, with early stopping.

    Parameters
    ----------
    cell : RecurrentCell
        Hashable cell (``init``/``step``; see the module docstring).
    n_hidden : int
        Hidden units.
    config : TrainConfig
        From :func:`train_config`.
    data : TrainingData
        From :func:`window_data` (built with the same ``config``).
    seed : int
        Seed of the weight initialisation, ``jax.random.key(seed)``; nothing else is random.
    progress : callable or None
        ``progress(epoch, max_epochs, train_loss, monitored_loss)`` after every epoch (called in
        batches of 25 epochs).

    Returns
    -------
    TrainResult
    """
    fn = _chunk_fn(_static(cell, config, data), False)
    carry = _init_carry(cell, n_hidden, config, data, seed)
    tr_curve, va_curve = [], []
    while True:
        carry, (tr, va, active) = fn(carry, data.arrays)
        n_new = int(np.asarray(active).sum())
        tr, va = np.asarray(tr)[:n_new], np.asarray(va)[:n_new]
        if progress is not None:
            for i in range(n_new):
                progress(len(tr_curve) + i + 1, config.epochs, float(tr[i]), float(va[i]))
        tr_curve.extend(tr.tolist())
        va_curve.extend(va.tolist())
        if bool(carry[7]):
            break
    return TrainResult(params=_tmap(np.asarray, carry[3]), loss_curve=np.asarray(tr_curve, dtype=np.float64),
                       val_curve=np.asarray(va_curve, dtype=np.float64), best_epoch=int(carry[5]),
                       n_epochs=len(tr_curve))


def fit_recurrent_many(cell, n_hidden: int, config: TrainConfig, data: TrainingData, *, seeds,
                       progress: Callable | None = None) -> list[TrainResult]:
    """Train one weight set per seed at once (``jax.vmap`` over the weight sets).

    Same arguments as :func:`fit_recurrent`, with ``seeds`` (a non-empty sequence of int) instead of
    ``seed``. ``progress`` gets the mean losses of the models still training. Every result
    equals ``fit_recurrent(..., seed=s)`` up to floating-point reassociation: each model keeps
    its own stopping epoch (a stopped model is frozen while the others continue).

    Returns
    -------
    list of TrainResult
        In the order of ``seeds``.
    """
    seeds = list(seeds)
    if not seeds:
        raise ConfigError("seeds must hold at least one seed; got an empty sequence")
    carries = [_init_carry(cell, n_hidden, config, data, s) for s in seeds]
    carry = _tmap(lambda *xs: jnp.stack(xs), *carries)
    fn = _chunk_fn(_static(cell, config, data), True)
    tr_all, va_all, act_all = [], [], []
    done = 0
    while True:
        carry, (tr, va, active) = fn(carry, data.arrays)
        tr, va, active = np.asarray(tr), np.asarray(va), np.asarray(active)
        tr_all.append(tr)
        va_all.append(va)
        act_all.append(active)
        if progress is not None:
            for i in range(tr.shape[1]):
                live = active[:, i]
                if live.any():
                    done += 1
                    progress(done, config.epochs, float(tr[live, i].mean()), float(va[live, i].mean()))
        if bool(np.all(np.asarray(carry[7]))):
            break
    tr_all, va_all = np.concatenate(tr_all, axis=1), np.concatenate(va_all, axis=1)
    act_all = np.concatenate(act_all, axis=1)
    out = []
    for j in range(len(seeds)):
        n_ep = int(act_all[j].sum())
        out.append(TrainResult(params=_tmap(lambda v: np.asarray(v[j]), carry[3]),
                               loss_curve=np.asarray(tr_all[j][:n_ep], dtype=np.float64),
                               val_curve=np.asarray(va_all[j][:n_ep], dtype=np.float64),
                               best_epoch=int(carry[5][j]), n_epochs=n_ep))
    return out
