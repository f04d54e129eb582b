"""The noise-process table: one definition per process, read by every estimator, model, export and simulator.

=======  ===============  ==========================  ==========================  ======================  =========
letter   module           Allan variance              GMWM (per sample)           Kalman component        SI (gyro)
=======  ===============  ==========================  ==========================  ======================  =========
Q        quantization     3 Q^2 / tau^2               QN: 6 q2 / tau^2            quantization (white)    rad
N        white            N^2 / tau                   WN: sigma2 / tau            white (measurement)     rad/s/√Hz
B        flicker          0.4413 B^2 (flat)           FLICKER: b2 c(tau/2)        Gauss-Markov terms      rad/s
K        random_walk      K^2 tau / 3                 RW: gamma2 (tau^2+2)/12tau  random_walk state       rad/s²/√Hz
R        ramp             R^2 tau^2 / 2               DR: omega^2 tau^2 / 16      ramp (or random walk)   rad/s²
S        sinusoid         Annex C.7 (lines)           (scales it dominates left   left out (bounded)      rad/s
                                                      out)
M        gauss_markov     Annex C.6 hump              GM: AR(1), :func:`ar1_wv`   gauss_markov state      rad/s
=======  ===============  ==========================  ==========================  ======================  =========

Each row (:class:`NoiseProcess`, one module per process) also gives the Hadamard and modified-Allan laws, the PSD,
the accelerometer (IEEE 1293) identity, the simulators (IEEE parametrisation and per-sample) and whether the term is
claimed only from a sustained slope.  The Allan fit (:mod:`fogdrift.noise`) builds its design from the rows' laws
and shapes; GMWM (:mod:`fogdrift.gmwm.processes`) its latent processes from the rows' :class:`LatentSpec`; the
Kalman model (:mod:`fogdrift.models.statespace`) its components and densities from the rows' :class:`ComponentSpec`;
the exports (:mod:`fogdrift.export.conversions`) the SI unit of each term; the simulators
(:func:`fogdrift.simulate.simulate`, :func:`fogdrift.gmwm.simulate.simulate_latent`) the rows' ``simulate``.

Adding a process is one module plus one row: write the module with its ``PROCESS`` and add it to :data:`_ROWS` (or,
from outside the package, :func:`register`); ``docs/extending.md`` shows it.

Examples
--------
>>> from fogdrift.noise.processes import process, power_law_names
>>> power_law_names()
('Q', 'N', 'B', 'K', 'R')
>>> p = process("RRW")                      # any spelling: letter, key, GMWM name or alias
>>> p.name, p.key, p.latent.name, p.term.unit, p.slope_rule
('K', 'random_walk', 'RW', 'deg/h^1.5', True)
"""

from __future__ import annotations

from collections.abc import Mapping
from contextlib import contextmanager
from types import MappingProxyType

import numpy as np

from ...errors import ConfigError
from . import flicker, gauss_markov, quantization, ramp, random_walk, sinusoid, white
from .base import ComponentSpec, LatentSpec, NoiseProcess, TermLaw, TermSpec

__all__ = [
    "NoiseProcess", "TermSpec", "TermLaw", "LatentSpec", "ComponentSpec",
    "PROCESSES", "process", "processes", "power_law_names", "shaped_names", "register", "unregister", "registered",
    "latent_processes", "component_specs", "version", "power_law_sdf", "model_sdf", "TableView",
]

#: The rows, in the order of the Allan-fit columns: the power-law terms by their power of tau, then S and M.
_ROWS = (quantization.PROCESS, white.PROCESS, flicker.PROCESS, random_walk.PROCESS, ramp.PROCESS,
         sinusoid.PROCESS, gauss_markov.PROCESS)

_TABLE: dict[str, NoiseProcess] = {p.name: p for p in _ROWS}
#: The live table (letter -> row); :func:`register` adds to it.
PROCESSES = MappingProxyType(_TABLE)


_ORDERED: list = []  # the ordered rows, rebuilt after each change of the table
_NAMES: dict = {}  # "power" / "shaped" -> their letters, rebuilt after each change of the table (a fit asks ~10^4 times)


def version() -> int:
    """A number that changes whenever :func:`register` or :func:`unregister` changes the table (for caches)."""
    return _VERSION[0]


_VERSION = [0]


def processes() -> tuple:
    """Every row: the power-law terms (the built-in Q, N, B, K, R in order of their power of tau, then registered ones
    in order of registration), then the shaped terms (S, M, then registered ones).

    The built-in power-law terms always come first, so the first five Allan-fit coefficients stay Q..R.
    """
    if not _ORDERED:
        rows = list(_TABLE.values())
        _ORDERED.append(tuple(p for p in rows if p.power_law) + tuple(p for p in rows if not p.power_law))
    return _ORDERED[0]


def _changed() -> None:
    _ORDERED.clear()
    _NAMES.clear()
    _VERSION[0] += 1


def power_law_names() -> tuple:
    """Letters of the power-law terms (the linear columns of the Allan fit), in order of their power of tau."""
    names = _NAMES.get("power")
    if names is None:
        names = _NAMES["power"] = tuple(p.name for p in processes() if p.power_law)
    return names


def shaped_names() -> tuple:
    """Letters of the shaped Annex C terms (S, M, ...)."""
    names = _NAMES.get("shaped")
    if names is None:
        names = _NAMES["shaped"] = tuple(p.name for p in processes() if not p.power_law)
    return names


def _spellings(p: NoiseProcess) -> tuple:
    out = [p.name, p.key.upper()]
    if p.latent is not None:
        out += [p.latent.name, *p.latent.aliases]
    return tuple(s.upper() for s in out)


class TableView(Mapping):
    """A read-only mapping built from the rows by ``build()`` (a dict), rebuilt only when the table changes: the live
    views other modules keep (``TERM_TABLE``, GMWM's ``PROCESSES``, ``COMPONENT_KINDS``, ...), so that a registered
    process appears in every one of them.

    Examples
    --------
    >>> letters = TableView(lambda: {p.name: p.key for p in processes()}, "letters")
    >>> letters["N"], len(letters) >= 7
    ('white', True)
    """

    def __init__(self, build, name: str = "view"):
        self._build, self._name, self._cache = build, name, (None, {})

    def _rows(self) -> dict:
        if self._cache[0] != _VERSION[0]:
            self._cache = (_VERSION[0], self._build())
        return self._cache[1]

    def __getitem__(self, key):
        return self._rows()[key]

    def __iter__(self):
        return iter(self._rows())

    def __len__(self):
        return len(self._rows())

    def __repr__(self):
        return f"{self._name}({list(self)})"


def process(name) -> NoiseProcess:
    """The row of ``name``: its letter (``"N"``), key (``"white"``), GMWM name (``"WN"``) or an alias (``"ARW"``).

    Raises
    ------
    ConfigError
        No such process (the message lists the letters).
    """
    key = str(name).strip().upper()
    for p in _TABLE.values():
        if key in _spellings(p):
            return p
    raise ConfigError(f"no noise process {name!r}; expected one of {', '.join(_TABLE)}")


def latent_processes() -> dict:
    """GMWM name -> :class:`LatentSpec` of every row that has a per-sample form."""
    return {p.latent.name: p.latent for p in processes() if p.latent is not None}


def component_specs() -> dict:
    """Component kind -> :class:`ComponentSpec` of every row that becomes a Kalman component."""
    return {p.component.kind: p.component for p in sorted(_TABLE.values(), key=lambda p: p.component_rank)
            if p.component is not None}


def power_law_sdf(name, A, dt_s):
    """Per-sample two-sided rate spectrum (rate^2 per cycle/sample, ``|f| <= 1/2``) of the power-law row ``name`` whose
    Allan law has the coefficient ``A`` [(deg/h)^2 s^-power]: its GMWM form (``latent.sdf``) at the parameters that
    give that Allan coefficient (the first parameter scaled linearly; the Allan fit's covariance of a registered
    process).

    Examples
    --------
    >>> s = power_law_sdf("N", 4.0, 0.01)            # white noise: A = N^2 = sigma2 dt
    >>> round(float(s(0.25)), 9)
    400.0
    """
    p = process(name)
    if p.latent is None or p.latent.sdf is None or p.term is None:
        raise ConfigError(f"noise process {p.name!r} has no per-sample spectrum (its row gives no latent sdf)")
    n_par = len(p.latent.params)
    unit = np.ones(n_par)
    reading = p.latent.ieee(unit, float(dt_s))
    a_unit = p.term.to_A(reading[p.name + p.term.suffix])
    theta = unit.copy()
    theta[0] = float(A) / a_unit
    return lambda f: p.latent.sdf(theta, np.asarray(f, dtype=np.float64))


def model_sdf(A, dt_s):
    """Per-sample two-sided rate spectrum of a sum of power-law terms with Allan-law coefficients ``A`` (one per
    :func:`power_law_names`, deg/h and s): the sum of each row's GMWM spectral density (:func:`power_law_sdf`).  A
    process without a spectrum (the deterministic ramp R) adds nothing; its effect on the estimates' variance is
    :func:`fogdrift.noise.covariance.ramp_cross_variance`.

    For the built-in rows: quantization ``4 Qs^2 sin^2(pi f)`` with ``Qs^2 = A_-2 / (3 dt^2)``, white ``A_-1 / dt``,
    flicker ``A_0 / (4 ln2 |f|)``, random walk ``3 A_1 dt / (4 sin^2(pi f))``.

    Examples
    --------
    >>> S = model_sdf([0, 4.0, 0, 0, 0], 0.01)
    >>> round(float(S(np.array([0.25]))[0]), 9)
    400.0
    """
    parts = [power_law_sdf(name, a, dt_s) for name, a in zip(power_law_names(), A)
             if float(a) > 0 and process(name).latent is not None and process(name).latent.sdf is not None]

    def spectrum(f):
        f = np.asarray(f, dtype=np.float64)
        out = np.zeros(f.shape)
        for s in parts:
            out = out + s(f)
        return out

    return spectrum


def register(p: NoiseProcess) -> NoiseProcess:
    """Add a row to the table (a process defined outside the package).

    Raises
    ------
    ConfigError
        Not a :class:`NoiseProcess`, or a letter, key or GMWM name already taken.
    """
    if not isinstance(p, NoiseProcess):
        raise ConfigError(f"a noise process must be a NoiseProcess; got {type(p).__name__}")
    taken = {s for q in _TABLE.values() for s in _spellings(q)}
    clash = sorted(set(_spellings(p)) & taken)
    if clash:
        raise ConfigError(f"noise process {p.name!r}: {', '.join(clash)} already names a process")
    if p.power_law and p.term.name != p.name:
        raise ConfigError(f"noise process {p.name!r}: its term is named {p.term.name!r}")
    _TABLE[p.name] = p
    _changed()
    return p


def unregister(name) -> None:
    """Remove a row added by :func:`register` (the built-in rows stay)."""
    p = process(name)
    if any(p is r for r in _ROWS):
        raise ConfigError(f"noise process {p.name!r} is built in and cannot be removed")
    del _TABLE[p.name]
    _changed()


@contextmanager
def registered(p: NoiseProcess):
    """``with registered(row):`` the row is in the table inside the block only."""
    register(p)
    try:
        yield p
    finally:
        unregister(p.name)
