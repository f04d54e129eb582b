"""The streaming compensator: native-rate samples in, causally compensated native-rate samples out.

Per axis, in order (the design of ``fogdrift compensate``):

1. the log's rate [deg/h] is block-averaged by the bundle's integer factor ``m`` to the modelling rate, and the
   bias + Earth-rate projection are removed: ``z[j] = mean(x[jm .. jm+m-1]) - bias - earth``;
2. a :class:`~fogdrift.models.causal_predictor.CausalPredictor` gives the drift estimate ``p[j]`` of modelling
   sample ``j`` from ``z[:j]`` only (the model's one-step prediction; for drift models made from the causal
   wavelet drift);
3. **native-rate correction: zero-order hold of the causal prediction.** Every native sample of modelling
   interval ``j`` gets ``p[j]`` (the prediction of that interval's mean drift, made from data that end where
   the interval starts), so native sample ``i`` uses input samples ``< m * floor(i / m)`` only;
4. output ``compensated = x - bias - p`` [deg/h]: the Earth-rate projection is a real rotation and stays in the
   output; where a model has no prediction yet (the causal drift's window, the model's lags) ``p`` is 0, i.e.
   bias-only compensation, and the summary says for how long.

Bias.  ``bias="keep"``: the bundle's training bias.  ``bias=S`` (seconds): the bias is re-estimated as the mean
of the first ``round(S / dt_model)`` modelling samples of the new log minus the Earth rate; until that window
has passed the output uses the bundle's bias and no drift model (so every output stays causal), afterwards
the re-estimated bias and the model, whose history then starts at the log's first sample.

Streaming.  Input arrives in chunks of any size; the engine processes fixed segments of ``K`` modelling
intervals (``K m`` native samples, ``K = max(256, 2**18 // m)``, fixed by ``m`` alone), so the models are
called with identical arguments whatever the chunking and chunked and whole-file runs are identical.  Memory
is bounded by a segment plus a chunk (plus, while re-estimating the bias, the calibration window).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConfigError, InsufficientDataError
from ..models.causal_predictor import CausalPredictor, causal_weights

__all__ = ["AxisPlan", "OutputBlock", "StreamCompensator", "segment_blocks"]

#: The constant-bias-only compensator (no drift model), always available.
BIAS_ONLY = "bias"


def _block_means(x, nb: int, m: int) -> np.ndarray:
    """Means of ``nb`` consecutive blocks of ``m`` rows, by sequential elementwise sums.

    ``ndarray.mean(axis=1)`` may sum in an order that depends on the data's memory alignment (SIMD paths), which
    would make the output depend on how the input was chunked; elementwise additions do not.
    """
    blocks = x[: nb * m].reshape(nb, m, x.shape[1])
    acc = blocks[:, 0, :].copy()
    for j in range(1, m):
        acc += blocks[:, j, :]
    return acc / m


def segment_blocks(factor: int) -> int:
    """Modelling intervals per processing segment for a block-average factor (fixed: outputs depend on it)."""
    return max(256, (1 << 18) // int(factor))


@dataclass(frozen=True)
class AxisPlan:
    """One log axis and what compensates it.

    Attributes
    ----------
    log_name : str
        Axis (column) name in the log.
    bundle_axis : fogdrift.bundle.BundleAxis
        The bundle axis it is matched to.
    model_name : str
        Registry name of the model, or ``"bias"`` for constant-bias compensation only.
    """

    log_name: str
    bundle_axis: object
    model_name: str

    @property
    def model(self):
        return None if self.model_name == BIAS_ONLY else self.bundle_axis.models[self.model_name]


@dataclass
class OutputBlock:
    """A run of compensated native samples, in order. Arrays are (n,) or (n, n_axes), deg/h."""

    t_s: np.ndarray
    rate_dph: np.ndarray
    compensated_dph: np.ndarray
    drift_dph: np.ndarray
    sigma_dph: np.ndarray | None


@dataclass
class _AxisState:
    plan: AxisPlan
    predictor: CausalPredictor | None
    bias_total_dph: float  # removed from the block means before modelling (bias + Earth rate)
    bias_out_dph: float  # removed from the output (bias only; re-estimated when asked)
    first_active: int | None = None  # first native sample compensated by the drift model


@dataclass
class StreamCompensator:
    """Push ``(t_s, rate_dph)`` chunks, collect :class:`OutputBlock` s; see the module docstring.

    Parameters
    ----------
    plans : list of AxisPlan
        One per log column, in column order.
    factor : int
        Native samples per modelling interval.
    model_dt_s : float
        Modelling interval [s].
    wavelet, mode : str
        Lifting wavelet and boundary mode (bundle).
    bias : "keep" or float
        ``"keep"`` or the length [s] of the window at the start of the log the bias is re-estimated on.
    keep_model_rate : bool
        Keep the raw modelling-rate block means (:attr:`block_means_dph`) for evaluations.
    segment : int or None
        Modelling intervals per segment; None: :func:`segment_blocks` of ``factor``.  The outputs depend on it
        (the models' fixed-length histories restart at segment boundaries), never on the chunking of the input.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> from fogdrift.models import Persistence
    >>> ax = SimpleNamespace(name="gz", bias_dph=1.0, earth_rate_dph=0.0, causal_window=2, level=1,
    ...                      models={"persistence": Persistence().fit([0.0])})
    >>> eng = StreamCompensator([AxisPlan("gz", ax, "persistence")], factor=2, model_dt_s=1.0, wavelet="haar",
    ...                         mode="periodization")
    >>> x = np.array([1.0, 1.0, 3.0, 3.0, 5.0, 5.0, 7.0, 7.0]).reshape(-1, 1)
    >>> out = eng.push(np.arange(8) * 0.5, x) + eng.finish()
    >>> np.concatenate([o.drift_dph[:, 0] for o in out]).tolist()  # held over each 1-s interval
    [0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 3.0, 3.0]

    (z = block means - bias = [0, 2, 4, 6]; the Haar causal drift of 2-sample windows is [nan, 1, 3, 5];
    persistence predicts interval j from interval j - 1.)
    """

    plans: list
    factor: int
    model_dt_s: float
    wavelet: str
    mode: str
    bias: object = "keep"
    keep_model_rate: bool = True
    segment: int | None = None
    block_means_dph: list = field(default_factory=list, init=False)
    n_in: int = field(default=0, init=False)
    n_out: int = field(default=0, init=False)

    def __post_init__(self):
        if isinstance(self.factor, bool) or not isinstance(self.factor, (int, np.integer)) or self.factor < 1:
            raise ConfigError(f"factor must be an integer >= 1; got {self.factor!r}")
        self.factor = int(self.factor)
        if self.bias == "keep":
            self.n_cal = 0
        else:
            try:
                seconds = float(self.bias)
            except (TypeError, ValueError):
                seconds = float("nan")
            if not seconds > 0:
                raise ConfigError(f"bias must be 'keep' or a re-estimation window > 0 s; got {self.bias!r}; "
                                  "pass {opt:bias} keep or re-estimate:SECONDS")
            self.n_cal = max(1, int(round(seconds / self.model_dt_s)))
        self.seg_blocks = segment_blocks(self.factor) if self.segment is None else int(self.segment)
        if self.seg_blocks < 1:
            raise ConfigError(f"segment must be >= 1 modelling interval; got {self.segment!r}")
        self.seg_native = self.seg_blocks * self.factor
        self._axes = []
        for plan in self.plans:
            ax = plan.bundle_axis
            model = plan.model
            predictor = None
            if model is not None:
                g = causal_weights(ax.causal_window, self.wavelet, ax.level, self.mode)
                predictor = CausalPredictor(model, g)
            self._axes.append(_AxisState(plan, predictor, ax.bias_dph + ax.earth_rate_dph, ax.bias_dph))
        self._buf_t, self._buf_x, self._buf_n = [], [], 0
        self._held = []  # segments waiting for the bias re-estimate
        self._n_blocks = 0  # modelling intervals processed (or held)
        self.re_estimated_bias_dph = None
        self.has_sigma = any(a.predictor is not None and a.predictor.rate_input for a in self._axes)

    @property
    def n_axes(self) -> int:
        return len(self._axes)

    # -- input --------------------------------------------------------------------------------------
    def push(self, t_s, rate_dph) -> list:
        """Add native samples ``rate_dph`` (n, n_axes) [deg/h] stamped ``t_s`` (n,); returns finished blocks."""
        x = np.asarray(rate_dph, dtype=np.float64)
        if x.ndim != 2 or x.shape[1] != self.n_axes:
            raise ConfigError(f"rate_dph must have shape (n, {self.n_axes}); got {x.shape}")
        self._buf_t.append(np.asarray(t_s, dtype=np.float64))
        self._buf_x.append(x)
        self._buf_n += x.shape[0]
        self.n_in += x.shape[0]
        out = []
        while self._buf_n >= self.seg_native:
            t, xs = self._take(self.seg_native)
            out += self._segment(t, xs, final=False)
        return out

    def finish(self) -> list:
        """Process what is left (a last, shorter segment); returns the remaining blocks."""
        out = []
        if self._buf_n:
            t, xs = self._take(self._buf_n)
            out += self._segment(t, xs, final=True)
        elif self._held:
            out += self._segment(np.empty(0), np.empty((0, self.n_axes)), final=True)
        return out

    def _take(self, n):
        t = np.concatenate(self._buf_t)
        x = np.concatenate(self._buf_x)
        self._buf_t, self._buf_x = [t[n:]], [x[n:]]
        self._buf_n -= n
        return t[:n], x[:n]

    # -- processing ---------------------------------------------------------------------------------
    def _segment(self, t, x, final: bool) -> list:
        m = self.factor
        nb = x.shape[0] // m
        means = _block_means(x, nb, m)
        if self.keep_model_rate:
            self.block_means_dph.append(means)
        seg = (t, x, means, self._n_blocks)
        self._n_blocks += nb
        if self.n_cal and self.re_estimated_bias_dph is None:
            self._held.append(seg)
            if self._n_blocks < self.n_cal and not final:
                return []
            if self._n_blocks < self.n_cal:
                raise InsufficientDataError(
                    f"re-estimating the bias needs {self.n_cal * self.model_dt_s:g} s of the log; it has only "
                    f"{self._n_blocks * self.model_dt_s:g} s (pass {{opt:bias}} keep or a shorter window)",
                    needed=self.n_cal, got=self._n_blocks)
            cal = np.concatenate([s[2] for s in self._held])[: self.n_cal]
            level = [math.fsum(cal[:, k]) / self.n_cal for k in range(self.n_axes)]  # order-independent
            self.re_estimated_bias_dph = []
            for k, a in enumerate(self._axes):
                earth = a.plan.bundle_axis.earth_rate_dph
                a.bias_total_dph = float(level[k])
                a.bias_out_dph = float(level[k]) - earth
                self.re_estimated_bias_dph.append(a.bias_out_dph)
            held, self._held = self._held, []
            out = []
            for i, s in enumerate(held):
                out.append(self._emit(*s, final=final and i == len(held) - 1))
            return out
        return [self._emit(*seg, final=final)]

    def _emit(self, t, x, means, block0, final) -> OutputBlock:
        m = self.factor
        n = x.shape[0]
        nb = means.shape[0]
        extra = final and n > nb * m  # a last, incomplete interval: its estimate is the prediction after the log
        comp = np.empty_like(x)
        drift = np.zeros_like(x)
        sigma = np.full_like(x, np.nan) if self.has_sigma else None
        block_of = block0 + np.arange(n) // m  # modelling interval of each native sample
        calibrating = block_of < self.n_cal
        for k, a in enumerate(self._axes):
            bundle_bias = a.plan.bundle_axis.bias_dph
            bias = np.where(calibrating, bundle_bias, a.bias_out_dph) if self.n_cal else a.bias_out_dph
            if a.predictor is not None:
                p = a.predictor.push(means[:, k] - a.bias_total_dph, extra=extra)
                p_native = np.repeat(p, m)[:n]
                active = np.isfinite(p_native) & ~calibrating
                drift[:, k] = np.where(active, p_native, 0.0)
                if sigma is not None and a.predictor.sigma is not None:
                    sigma[:, k] = np.where(active, np.repeat(a.predictor.sigma, m)[:n], np.nan)
                if a.first_active is None and active.any():
                    a.first_active = self.n_out + int(np.argmax(active))
            elif a.first_active is None and (~calibrating).any():
                a.first_active = self.n_out + int(np.argmax(~calibrating))
            comp[:, k] = x[:, k] - bias - drift[:, k]
        self.n_out += n
        return OutputBlock(t, x, comp, drift, sigma)

    # -- summary ------------------------------------------------------------------------------------
    def first_active(self) -> list:
        """Per axis, the first native sample index where the drift model (or, bias only, the final bias) acts."""
        return [a.first_active for a in self._axes]

    def model_rate_series(self) -> np.ndarray:
        """Raw block means [deg/h] at the modelling rate, shape (n_blocks, n_axes) (``keep_model_rate``)."""
        if not self.block_means_dph:
            return np.empty((0, self.n_axes))
        return np.concatenate(self.block_means_dph)

    def biases(self) -> list:
        """Per axis (bias removed from the output, bias + Earth rate removed before modelling) [deg/h]."""
        return [(a.bias_out_dph, a.bias_total_dph) for a in self._axes]
