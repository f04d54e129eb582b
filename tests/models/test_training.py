"""The cell-agnostic recurrent training loop (fogdrift.models.training), driven by a cell it has never seen.

The cell here is a small LSTM written in this file with only ``init``, ``step`` and a pytree state
``(h, c)``: the loop must train it without any change, which is what "a GRU or LSTM reuses it"
means. Independent checks: one epoch equals one optax Adam step on a loss written here with a
Python loop over ``step`` (float64, rel 1e-10); vmapped multi-seed training equals separate runs;
early stopping keeps the best-validation epoch.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

jax = pytest.importorskip("jax")
import jax.numpy as jnp  # noqa: E402
import optax  # noqa: E402

from fogdrift.errors import ConfigError  # noqa: E402
from fogdrift.models.training import (  # noqa: E402
    RecurrentCell,
    fit_recurrent,
    fit_recurrent_many,
    train_config,
    window_data,
)


@dataclass(frozen=True)
class LSTMCell(RecurrentCell):
    """Textbook LSTM (input, forget, output gates; tanh candidate) with a linear read-out."""

    n_outputs: int = 1

    def init(self, key, n_in, n_hidden, dtype=jnp.float32):
        k_w, k_v = jax.random.split(key)
        lim = 1.0 / math.sqrt(n_hidden)
        return {"W": jax.random.uniform(k_w, (4 * n_hidden, n_in + n_hidden), dtype, -lim, lim),
                "b": jnp.zeros((4 * n_hidden,), dtype),
                "V": jax.random.uniform(k_v, (self.n_outputs, n_hidden), dtype, -lim, lim),
                "c": jnp.zeros((self.n_outputs,), dtype)}

    def initial_state(self, n_hidden, batch_shape=(), dtype=jnp.float32):
        zeros = jnp.zeros(tuple(batch_shape) + (n_hidden,), dtype)
        return (zeros, zeros)

    def step(self, params, state, x):
        h, c = state
        i, f, o, u = jnp.split(params["W"] @ jnp.concatenate([x, h]) + params["b"], 4)
        c = jax.nn.sigmoid(f) * c + jax.nn.sigmoid(i) * jnp.tanh(u)
        h = jax.nn.sigmoid(o) * jnp.tanh(c)
        return (h, c), params["V"] @ h + params["c"]


@pytest.fixture
def x64():
    old = jax.config.jax_enable_x64
    jax.config.update("jax_enable_x64", True)
    yield
    jax.config.update("jax_enable_x64", old)


def _sine_rows(n=240, p=2, seed=0):
    """Rows (u(k) = [y(k-1), y(k-2)], target y(k)) of a noisy sine."""
    rng = np.random.default_rng(seed)
    y = np.sin(2 * np.pi * np.arange(n + p) / 40.0) + rng.normal(0, 0.05, n + p)
    u = np.stack([y[p - 1 - i: n + p - 1 - i] for i in range(p)], axis=1)
    return u, y[p:]


def test_one_epoch_is_one_adam_step_on_the_sse_loss(x64):
    u, t = _sine_rows(20)
    config = train_config(epochs=1, window=None, batch_size=None, clip_norm=None, learning_rate=0.01)
    data = window_data(u, t, t.size, config, dtype="float64")  # no validation rows: the training loss is monitored
    cell = LSTMCell()
    result = fit_recurrent(cell, 3, config, data, seed=4)

    def sse(params):  # eq. (12) with a plain Python loop over the cell's own step
        state, total = cell.initial_state(3, (), jnp.float64), 0.0
        for k in range(t.size):
            state, y = cell.step(params, state, jnp.asarray(u[k]))
            total = total + (y[0] - t[k]) ** 2
        return total

    params0 = cell.init(jax.random.key(4), 2, 3, dtype=jnp.float64)
    opt = optax.adam(0.01)
    updates, _ = opt.update(jax.grad(sse)(params0), opt.init(params0), params0)
    expected = optax.apply_updates(params0, updates)
    for key in expected:
        np.testing.assert_allclose(result.params[key], np.asarray(expected[key]), rtol=1e-10, atol=1e-12)
    assert result.n_epochs == 1 and result.best_epoch == 0
    assert result.loss_curve[0] == pytest.approx(float(sse(expected)), rel=1e-10)


def test_windowed_multi_seed_training_of_a_new_cell(x64):
    u, t = _sine_rows(240)
    n_train = 180
    config = train_config(epochs=80, patience=8, window=16, batch_size=64, learning_rate=0.02)
    data = window_data(u, t, n_train, config, dtype="float64")
    assert (data.window, data.n_train, data.n_val) == (16, 180, 60) and data.groups == 4
    cell = LSTMCell()
    many = fit_recurrent_many(cell, 4, config, data, seeds=[0, 1])
    single = fit_recurrent(cell, 4, config, data, seed=1)
    assert (many[1].n_epochs, many[1].best_epoch) == (single.n_epochs, single.best_epoch)
    for key in single.params:
        np.testing.assert_allclose(many[1].params[key], single.params[key], rtol=1e-9, atol=1e-10)
    assert np.max(np.abs(many[0].params["W"] - many[1].params["W"])) > 1e-3
    for r in many:
        assert r.loss_curve[r.best_epoch] < 0.5 * r.loss_curve[0]  # it learned
        assert r.val_curve[r.best_epoch] <= r.val_curve.min() * (1 + 1e-4)  # best-validation weights kept
        assert r.n_epochs == config.epochs or r.n_epochs - 1 - r.best_epoch >= config.patience


def test_train_config_and_seeds_errors():
    for kwargs, word in (({"loss": "mae"}, "loss"), ({"training": "rtrl"}, "training"),
                         ({"optimizer": "sgd"}, "optimizer"), ({"learning_rate": -1.0}, "learning_rate"),
                         ({"epochs": 0}, "epochs"), ({"window": 0}, "window"), ({"clip_norm": 0}, "clip_norm"),
                         ({"weight_decay": -1}, "weight_decay")):
        with pytest.raises(ConfigError, match=word):
            train_config(**kwargs)
    u, t = _sine_rows(20)
    config = train_config(epochs=2)
    with pytest.raises(ConfigError, match="seeds"):
        fit_recurrent_many(LSTMCell(), 2, config, window_data(u, t, 30, config), seeds=[])
