"""Allan operator sums of one rate series, taken once and handed on between the stages of a command.

The plausibility check (:func:`fogdrift.plausibility.noise_floor`) and the Allan analysis
(:func:`fogdrift.pipeline.analyse_allan`: display grid, octave fit grid, octave grid with the null taus of a periodic
content, each with its EDF alphas) need the same sums of squared difference operators at overlapping sets of cluster
sizes m.  :class:`AllanSums` computes each m once; every :class:`~fogdrift.allan.AllanResult` is then rebuilt by
:func:`fogdrift.allan.core.result_from_sums`, the function :func:`fogdrift.allan.allan_variance` itself ends in, so
a result is identical field by field to that of ``allan_variance`` with the same options (the compiled kernel sums
each m on its own: the sums do not depend on which m share a pass; tested in ``tests/workflows/test_pipeline_allan_sums.py``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._util import check_series
from . import _kernels, chunked
from .core import _fast_strides, result_from_sums
from .grid import tau_grid
from .statistics import get_statistic
from ..errors import ConfigError, InsufficientDataError
from ..io.chunked import ChunkSource
from ..units import check_dt_s

__all__ = ["AllanSums", "CHUNKED_MIN_SAMPLES", "OUT_OF_CORE_CHUNK"]

#: From this many samples on, the Allan operator sums are taken out of core (:mod:`fogdrift.allan.chunked`, the
#: same terms added in another order: equal to 1e-12 relative, 2e-15 measured at 10^8 samples) instead of through a
#: float64 angle array of N + 1 points: 8 N bytes (0.8 GB at 10^8) against :data:`OUT_OF_CORE_CHUNK` windows.
CHUNKED_MIN_SAMPLES = 1 << 24

#: Start indices per chunk of the out-of-core sums.  At 10^8 samples (octave grid, load 5-6, same process): 2^21
#: (the engine's default) 18.6-26.0 s and 100-118 MB above the input, 2^22 10.1 s and 185 MB, 2^23 5.0-8.7 s and
#: 273 MB; the in-memory kernel 3.7-4.7 s and 800 MB.
OUT_OF_CORE_CHUNK = 1 << 23


def _progress_group(n_m: int, n_phase: int) -> int:
    """Cluster sizes per kernel call when progress is reported: about 1 % of the ``n_m`` asked for, at least 8, and
    no more than keep a call that 8 would run on one thread below :data:`~fogdrift.allan._kernels.PARALLEL_MIN`.

    Each call costs its dispatch and thread setting (about 20 us): ``--taus all`` on 10^5 samples in 3 125 calls of 8
    taus takes 0.46 s, in 157 calls of 160 taus 0.40 s.  The sums do not depend on the grouping (each m is summed on
    its own).
    """
    group = max(8, -(-n_m // 100))
    if 8 * n_phase < _kernels.PARALLEL_MIN:
        group = max(8, min(group, (_kernels.PARALLEL_MIN - 1) // n_phase))
    return group


class AllanSums:
    """The operator sums [(deg/h)^2 samples^2] of one rate series [deg/h] at every cluster size asked for so far.

    Parameters
    ----------
    y : array_like, shape (n_samples,)
        The series in its channel's internal unit (deg/h, m/s^2), finite (checked as
        :func:`fogdrift.allan.allan_variance` checks it, same messages).
    dt_s : float
        Sample interval [s].
    statistic : {"adev", "hdev", "mdev"}
    estimator : {"overlapping", "non-overlapping", "fast"}

    Notes
    -----
    Series of at least :data:`CHUNKED_MIN_SAMPLES` samples (overlapping or non-overlapping ADEV) take the
    out-of-core pass over the array already in memory: the same sums to 1e-12 relative without the angle array.
    """

    def __init__(self, y, dt_s, statistic: str = "adev", estimator: str = "overlapping"):
        self.stat = get_statistic(statistic)
        self.source = y
        self.y = np.ascontiguousarray(check_series(y, "y"))
        self.dt = check_dt_s(dt_s)
        self.dt_in = dt_s
        self.stat.check_sampling(estimator)
        self.estimator = estimator
        self.n = n = self.y.size
        if n < 2:
            raise InsufficientDataError(f"an Allan variance needs at least 2 rate samples, got {n}", needed=2, got=n)
        self.m = np.empty(0, dtype=np.int64)
        self.sums = np.empty(0)

    def holds(self, y, dt_s, statistic: str, estimator: str) -> bool:
        """True when these sums are of this very array (same object or the same memory, shape and dtype), interval,
        statistic and estimator: then they can be reused as they are."""
        same = y is self.source or y is self.y
        if not same and isinstance(y, np.ndarray) and isinstance(self.source, np.ndarray):
            a, b = y.__array_interface__, self.source.__array_interface__
            same = (a["data"] == b["data"] and a["shape"] == b["shape"] and a["strides"] == b["strides"]
                    and a["typestr"] == b["typestr"])
        return bool(same and dt_s == self.dt_in and statistic == self.stat.name and estimator == self.estimator)

    def grid(self, taus) -> np.ndarray:
        """Cluster sizes m of a tau specification (:func:`fogdrift.allan.tau_grid`, default max_fraction)."""
        return tau_grid(self.n, self.dt, taus, statistic=self.stat.name)

    def strides(self, m: np.ndarray) -> np.ndarray:
        """Start-index strides of the estimator at cluster sizes ``m`` (as :func:`fogdrift.allan.allan_variance`)."""
        if self.estimator == "fast":
            return _fast_strides(m)
        return m.copy() if self.estimator == "non-overlapping" else np.ones_like(m)

    @property
    def chunked(self) -> bool:
        """Whether the sums are taken out of core (long overlapping / non-overlapping ADEV)."""
        return (self.n >= CHUNKED_MIN_SAMPLES and self.stat.name == "adev"
                and self.estimator in ("overlapping", "non-overlapping"))

    def compute(self, grids, progress=None) -> None:
        """The sums at every m of ``grids`` not yet computed (one pass); ``progress(done, total)`` counts taus."""
        if progress is not None and not callable(progress):
            raise ConfigError(f"progress must be a callable(done, total) or None, got {progress!r}")
        want = np.unique(np.concatenate([np.asarray(g, dtype=np.int64) for g in grids]))
        m = np.setdiff1d(want, self.m)
        if m.size:
            strides = self.strides(m)
            sums = np.empty(m.size)
            if self.chunked:
                y = self.y
                source = ChunkSource(path=Path("<memory>"), n_samples=self.n, dt_s=self.dt, name="series",
                                     scale_to_internal=1.0, describe="in-memory float64", _read=lambda a, b: y[a:b])
                chunk = OUT_OF_CORE_CHUNK
                mu, offsets = chunked._mean_and_offsets(source, chunk, None)
                sums[:] = chunked._second_difference_sums(chunked._Phase(source, mu, offsets), m, strides, chunk,
                                                          None)
            else:
                p = _kernels.phase_dph_samples(self.y)
                groups = [np.arange(m.size)] if progress is None else \
                    np.array_split(np.arange(m.size), max(1, -(-m.size // _progress_group(m.size, p.size))))
                done = 0
                for g in groups:
                    sums[g] = _kernels.operator_sums(p, m[g], strides[g], self.stat.coefficients, self.stat.windowed)
                    done += g.size
                    if progress is not None:
                        progress(done, m.size)
                del p
            order = np.argsort(np.concatenate([self.m, m]), kind="stable")
            self.m = np.concatenate([self.m, m])[order]
            self.sums = np.concatenate([self.sums, sums])[order]
        if progress is not None and (not m.size or self.chunked):
            progress(max(m.size, 1), max(m.size, 1))

    def result(self, m: np.ndarray, noise_alpha="auto"):
        """The :class:`~fogdrift.allan.AllanResult` at cluster sizes ``m`` (computed before) with ``noise_alpha`` as
        for :func:`fogdrift.allan.allan_variance`."""
        m = np.asarray(m, dtype=np.int64)
        idx = np.searchsorted(self.m, m)
        if idx.size and (idx.max() >= self.m.size or not np.array_equal(self.m[idx], m)):
            raise ConfigError("internal: Allan sums asked at a cluster size not computed")
        return result_from_sums(self.sums[idx], self.n, m, self.strides(m), self.dt, statistic=self.stat.name,
                                estimator=self.estimator, noise_alpha=noise_alpha)
