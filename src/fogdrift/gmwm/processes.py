"""Latent error processes of a gyro and the composite models built from them.

The processes are the ``latent`` parts of the rows of :mod:`fogdrift.noise.processes` (one home per process:
per-sample definition, Haar WV, SDF, IEEE reading, simulator); this module composes them into models, evaluates
their WV and Jacobian (a compiled kernel for the built-in rows, the rows' own ``wv`` for a registered one) and
parses model strings.

Each process is defined per sample (interval ``dt_s``) with its rate in deg/h, so its
variances are in (deg/h)^2 ([GMWM]_ §2).  ``tau`` is the Haar scale in samples (filter
width, ``tau = 2^j`` for the WV) and ``m = tau / 2`` the matching Allan averaging factor:

========  ==============================================  ===================================
process   per-sample definition (parameters)              Haar WV  nu2(tau)
========  ==============================================  ===================================
QN        x_t = q (U_t - U_{t-1}) sqrt(12), U ~ U(0,1)     6 q2 / tau^2
          (``q2`` = Q^2 in (deg/h)^2)
WN        x_t = e_t, Var e = ``sigma2``                     sigma2 / tau
RW        x_t = x_{t-1} + e_t, Var e = ``gamma2``           gamma2 (tau^2 + 2) / (12 tau)
DR        x_t = omega t (``omega`` deg/h per sample)       omega^2 tau^2 / 16
FLICKER   two-sided SDF b2 / (2 pi |f|), |f| <= 1/2        b2 c(m), c -> ln2 / pi (flat)
GM        x_t = phi x_{t-1} + e_t, phi = exp(-beta),      stable closed form, see
          Var e = ``sigma2`` (AR(1), Gauss-Markov)         :func:`ar1_wv`
========  ==============================================  ===================================

Components are independent, so WVs (and SDFs) add.  The free (optimisation) parameters
are the logarithms of the natural ones (``log sigma2``, ``log beta`` ...), so every value
stays positive and ``1 - phi`` is never formed.  FLICKER gives bias instability its own
flat WV ``0.2206 B^2`` (``b2 = B^2``); alternatively B is represented by one to three GMs
([GMWM]_ §4), which is what a Kalman filter needs.

IEEE-952 mapping per process ([GMWM]_ §4): N = sqrt(sigma2 dt) (deg/h sqrt(s), /60 ->
deg/sqrt(h)); Q = sqrt(q2) dt (arcsec); K = sqrt(gamma2 / dt) (x60 -> deg/h/sqrt(h));
R = omega / dt (x3600 -> deg/h^2); GM: T_c = dt / beta (s), sigma_GM = sqrt(sigma2 / (1 - phi^2))
(deg/h); FLICKER: B = sqrt(b2) (deg/h).

References
----------
.. [GMWM] fogdrift GMWM method notes, ``shared/docs/gmwm-notes.md`` §2 (table, SDFs, the
   AR(1) numerical trap) and §4 (IEEE mapping).
.. [PW2000] D. B. Percival, A. T. Walden, *Wavelet Methods for Time Series Analysis* (2000),
   §8.2 (WV as the integral of the squared Haar gain times the SDF).
"""

from __future__ import annotations

import math
import re
from typing import Callable

import numpy as np

from ..errors import ConfigError
from ..noise.processes import LatentSpec, TableView, latent_processes
from ..noise.processes.flicker import B_FLAT_WV, flicker_wv_factor
from ..noise.processes.gauss_markov import ar1_wv

__all__ = [
    "Process",
    "PROCESSES",
    "ALIASES",
    "LatentModel",
    "parse_model",
    "ar1_wv",
    "flicker_wv_factor",
    "haar_gain2",
    "WvEvaluator",
    "B_FLAT_WV",
]



# ----------------------------------------------------------------------------------------
# Squared gain of the Haar filter
# ----------------------------------------------------------------------------------------
def haar_gain2(f, m):
    """Squared gain ``|H(f)|^2 = sin^4(pi f m) / (m^2 sin^2(pi f))`` of the Haar filter of width 2m.

    ``f`` in cycles per sample, ``m`` the half-width (Allan averaging factor).  The Allan
    filter's squared gain is twice this.  At ``f = 0`` the value is 0.

    Examples
    --------
    >>> round(float(haar_gain2(0.25, 1)), 12)   # sin^2(pi/4)
    0.5
    """
    f = np.asarray(f, dtype=np.float64)
    s = np.sin(np.pi * f)
    with np.errstate(divide="ignore", invalid="ignore"):
        g = np.sin(np.pi * f * m) ** 4 / (m * m * s * s)
    return np.where(s == 0.0, 0.0, g)


# ----------------------------------------------------------------------------------------
# Compiled WV and Jacobian of a composite model (the optimiser's inner loop)
# ----------------------------------------------------------------------------------------
# least_squares evaluates the model WV and its Jacobian a few hundred thousand times per
# ``fogdrift noise`` run on ~20 scales each: the NumPy path spends almost all of that in
# per-call overhead (one ufunc per operation, one lambda per component).  The kernel below
# evaluates every component at every scale, and the Jacobian, in one compiled call, with the
# same operations in the same order as :func:`ar1_wv` and the registry's ``wv`` (so the same
# values: tested against them).
_CODE = {"QN": 0, "WN": 1, "RW": 2, "DR": 3, "FLICKER": 4, "GM": 5}
_JAC_H = 1e-3  # central-difference step in log beta (see LatentModel.wv_jacobian)
_EXP_H, _EXP_MH = math.exp(_JAC_H), math.exp(-_JAC_H)  # numba freezes these module constants into the kernel
_BETA3 = np.array([1.0, _EXP_H, _EXP_MH])  # beta, beta e^h, beta e^-h (x 1.0 is exact)


def _ar1_unit_py(b, m, v):
    """AR(1) Haar WV per unit innovation variance at one half-width ``m`` (as :func:`ar1_wv`), given
    ``v = -expm1(-m b)`` (computed by NumPy, as in :func:`ar1_wv`: its vectorised ``expm1`` may differ from
    libm's in the last bit, and the values are to be the same)."""
    mb = m * b
    if mb < 1e-3:
        return ((2.0 * m * m + 1.0) / (12.0 * m)
                - b * (3.0 * math.pow(m, 3.0) - 4.0 * m * m - 2.0) / (24.0 * m)
                + b * b * (m - 1.0) * (7.0 * math.pow(m, 3.0) - 8.0 * m * m - 3.0 * m - 3.0) / (120.0 * m))
    u = -math.expm1(-b)
    return (m * u * (2.0 - u) - (1.0 - u) * v * (2.0 + v)) / (2.0 * m * m * math.pow(u, 3.0) * (2.0 - u))


def _wv_kernel_py(codes, starts, theta, t, flick, vv, dr_p2, comps, total, jac, want_jac):
    """Fill ``comps`` (n_comp, n_tau), ``total`` (n_tau) and, if ``want_jac``, ``jac`` (n_tau, n_params)."""
    n_tau = t.shape[0]
    g = 0  # GM counter: rows of vv (3 per GM with the Jacobian: beta, beta e^h, beta e^-h)
    for c in range(codes.shape[0]):
        code = codes[c]
        i = starts[c]
        p = theta[i]
        for k in range(n_tau):
            tk = t[k]
            if code == 0:
                val = 6.0 * p / (tk * tk)
            elif code == 1:
                val = p / tk
            elif code == 2:
                val = p * (tk * tk + 2.0) / (12.0 * tk)
            elif code == 3:
                val = dr_p2 * (tk * tk) / 16.0  # dr_p2 = omega ** 2 by libm pow, as the registry
            elif code == 4:
                val = p * flick[k]
            else:
                m = tk / 2.0
                s2 = theta[i + 1]
                r = 3 * g if want_jac else g
                val = s2 * _ar1_unit(p, m, vv[r, k])
                if want_jac:
                    up = s2 * _ar1_unit(p * _EXP_H, m, vv[r + 1, k])
                    dn = s2 * _ar1_unit(p * _EXP_MH, m, vv[r + 2, k])
                    jac[k, i] = (up - dn) / (2.0 * _JAC_H)
                    jac[k, i + 1] = val
            comps[c, k] = val
            if c == 0:
                total[k] = val
            else:
                total[k] = total[k] + val
            if want_jac and code != 5:
                jac[k, i] = 2.0 * val if code == 3 else val
        if code == 5:
            g += 1


_WV_KERNEL = []


def _wv_kernel():
    """The compiled kernel (numba, cached on disk), compiled on first use."""
    if not _WV_KERNEL:
        import numba

        unit = numba.njit(cache=True, error_model="numpy")(_ar1_unit_py)
        globals()["_ar1_unit"] = unit
        _WV_KERNEL.append(numba.njit(cache=True, error_model="numpy")(_wv_kernel_py))
    return _WV_KERNEL[0]


# ----------------------------------------------------------------------------------------
# Registry: the latent forms of the rows of fogdrift.noise.processes
# ----------------------------------------------------------------------------------------
#: One latent process (parameters, Haar WV, SDF, IEEE reading, simulator): the ``latent`` part of a row of
#: :mod:`fogdrift.noise.processes`.
Process = LatentSpec


#: GMWM name (``"WN"``, ``"QN"``, ``"RW"``, ``"DR"``, ``"FLICKER"``, ``"GM"``, and any registered row's) -> Process.
PROCESSES = TableView(latent_processes, "PROCESSES")


#: A natural parameter in words, as shown to the user (``"RW.gamma2"`` -> ``"RW variance"``).
_PARAM_WORDS = {"q2": "variance", "sigma2": "variance", "gamma2": "variance", "omega": "slope",
                "b2": "variance", "beta": "inverse correlation time 1/T_c"}


def param_label(name: str) -> str:
    """A parameter name of :attr:`LatentModel.param_names` in words (``"GM1.beta"`` -> ``"GM1 inverse
    correlation time 1/T_c"``), for messages; JSON keys keep the names.

    Examples
    --------
    >>> param_label("QN.q2"), param_label("DR.omega")
    ('QN variance', 'DR slope')
    """
    comp, _, par = str(name).partition(".")
    return f"{comp} {_PARAM_WORDS.get(par, par)}" if par else comp




#: Accepted spellings in model strings (upper-cased) -> registry key (GM = AR1, WN = ARW, RW = RRW, DR = RAMP, ...).
ALIASES = TableView(lambda: {a: p.name for p in latent_processes().values() for a in (p.name, *p.aliases)},
                    "ALIASES")
_BUILTIN_ORDER = ("QN", "WN", "RW", "DR", "FLICKER", "GM")


def _order() -> tuple:
    """Canonical component order of a model: QN, WN, RW, DR, FLICKER, then registered processes, GM last."""
    extra = tuple(k for k in latent_processes() if k not in _BUILTIN_ORDER)
    return _BUILTIN_ORDER[:-1] + extra + ("GM",)
_MAX_GM = 6


# ----------------------------------------------------------------------------------------
# Composite model
# ----------------------------------------------------------------------------------------
class LatentModel:
    """A sum of independent latent processes, e.g. ``"QN+WN+RW+2GM"``.

    Parameters are stacked per component in the canonical order QN, WN, RW, DR, FLICKER,
    GM1, GM2, ... (GMs numbered by decreasing ``beta``, i.e. increasing correlation time).

    Attributes
    ----------
    components : tuple of str
        Registry keys, one per component (``"GM"`` repeated).
    name : str
        Canonical model string.
    param_names : tuple of str
        ``"WN.sigma2"``, ``"GM1.beta"`` ...
    n_params : int

    Examples
    --------
    >>> m = parse_model("wn+2gm+RW")
    >>> m.name, m.param_names
    ('WN+RW+2GM', ('WN.sigma2', 'RW.gamma2', 'GM1.beta', 'GM1.sigma2', 'GM2.beta', 'GM2.sigma2'))
    >>> [round(float(v), 6) for v in parse_model("WN+RW").wv([1.0, 0.01], [2, 8])]
    [0.5025, 0.131875]
    """

    def __init__(self, components):
        comps = tuple(components)
        self.components = comps
        n_gm = comps.count("GM")
        self.n_gm = n_gm
        parts = []
        for key in _order():
            k = comps.count(key)
            if k:
                parts.append(key if k == 1 else f"{k}{key}")
        self.name = "+".join(parts)
        names, slices, labels = [], [], []
        i = gm = 0
        for key in comps:
            proc = PROCESSES[key]
            if key == "GM":
                gm += 1
                label = f"GM{gm}"
            else:
                label = key
            labels.append(label)
            names.extend(f"{label}.{p}" for p in proc.params)
            slices.append(slice(i, i + len(proc.params)))
            i += len(proc.params)
        self.labels = tuple(labels)
        self.param_names = tuple(names)
        self.slices = tuple(slices)
        self.n_params = i
        self._compiled_ok = all(k in _CODE for k in comps)  # a registered process has no kernel code: NumPy path
        self._codes = np.array([_CODE.get(k, -1) for k in comps], dtype=np.int64)
        self._starts = np.array([sl.start for sl in slices], dtype=np.int64)
        self._has_flicker = "FLICKER" in comps
        self._dr = slices[comps.index("DR")].start if "DR" in comps else -1
        self._gm_beta = np.array([sl.start for k, sl in zip(comps, slices) if k == "GM"], dtype=np.int64)
        self._flick = {}

    def __repr__(self) -> str:
        return f"LatentModel({self.name!r})"

    def __eq__(self, other) -> bool:
        return isinstance(other, LatentModel) and other.components == self.components

    def __hash__(self) -> int:
        return hash(self.components)

    def has(self, key: str) -> bool:
        """True if the model contains the process ``key``."""
        return key in self.components

    def _theta(self, theta) -> np.ndarray:
        th = np.asarray(theta, dtype=np.float64)
        if th.shape != (self.n_params,):
            raise ConfigError(f"{self.name} has {self.n_params} parameters {self.param_names}; got shape {th.shape}")
        return th

    def _flicker_factors(self, t) -> np.ndarray:
        """The kernel's ``flick`` argument at the contiguous 1-D scales ``t``: the flicker WV factors (cached per
        scale set), or ``t`` itself when the model has no flicker term (then the kernel does not read it)."""
        if not self._has_flicker:
            return t
        key = t.tobytes()
        flick = self._flick.get(key)
        if flick is None:
            flick = np.ascontiguousarray(flicker_wv_factor(t), dtype=np.float64)
            if len(self._flick) > 64:
                self._flick.clear()
            self._flick[key] = flick
        return flick

    def _numpy(self, theta, tau, want_jac):
        """As :meth:`_compiled`, by the rows' ``wv`` (a model with a registered process the kernel does not know)."""
        th = self._theta(theta)
        t = np.asarray(tau, dtype=np.float64)
        comps = np.stack([np.broadcast_to(PROCESSES[k].wv(th[sl], t), t.shape)
                          for k, sl in zip(self.components, self.slices)])
        jac = self._jacobian_numpy(th, t.ravel()) if want_jac else np.empty((0, 0))
        return comps, comps.sum(axis=0), jac

    def _jacobian_numpy(self, th, t):
        cols = []
        for key, sl in zip(self.components, self.slices):
            p = th[sl]
            if key == "GM":
                h = 1e-3
                d_beta = (ar1_wv(p[0] * math.exp(h), p[1], t) - ar1_wv(p[0] * math.exp(-h), p[1], t)) / (2.0 * h)
                cols.extend([d_beta, ar1_wv(p[0], p[1], t)])
            elif key == "DR":
                cols.append(2.0 * PROCESSES[key].wv(p, t))
            elif key in _CODE:
                cols.append(PROCESSES[key].wv(p, t))
            else:  # a registered process: central differences in the log of each parameter
                h = _JAC_H
                for j in range(p.size):
                    up, dn = p.copy(), p.copy()
                    up[j] *= math.exp(h)
                    dn[j] *= math.exp(-h)
                    cols.append((PROCESSES[key].wv(up, t) - PROCESSES[key].wv(dn, t)) / (2.0 * h))
        return np.column_stack(cols)

    def _compiled(self, theta, tau, want_jac):
        """Components, total and (if ``want_jac``) Jacobian in one compiled call (see :func:`_wv_kernel`)."""
        if not self._compiled_ok:
            return self._numpy(theta, tau, want_jac)
        th = self._theta(theta)
        t = np.asarray(tau, dtype=np.float64)
        shape = t.shape
        t = np.ascontiguousarray(t.ravel())
        flick = self._flicker_factors(t)
        if self.n_gm:
            beta = th[self._gm_beta]
            if want_jac:
                beta = np.multiply.outer(beta, _BETA3).ravel()
            with np.errstate(over="ignore", invalid="ignore"):
                vv = -np.expm1(-np.multiply.outer(beta, t / 2.0))
        else:
            vv = np.empty((0, 0))
        dr_p2 = float(th[self._dr]) ** 2 if self._dr >= 0 else 0.0
        n = t.size
        comps = np.empty((len(self.components), n))
        total = np.empty(n)
        jac = np.empty((n, self.n_params)) if want_jac else np.empty((0, 0))
        _wv_kernel()(self._codes, self._starts, np.ascontiguousarray(th), t, flick, vv, dr_p2, comps, total, jac, want_jac)
        return comps.reshape((comps.shape[0],) + shape), total.reshape(shape), jac

    def evaluator(self, tau) -> "WvEvaluator":
        """A :class:`WvEvaluator` of this model at fixed 1-D scales ``tau`` (samples): the optimiser's inner loop."""
        return WvEvaluator(self, tau)

    def wv_components(self, theta, tau) -> np.ndarray:
        """WV of each component, shape ``(n_components, n_tau)`` in rate^2."""
        return self._compiled(theta, tau, False)[0]

    def wv(self, theta, tau) -> np.ndarray:
        """Theoretical Haar WV ``sum_k nu2_k(tau; theta_k)`` in rate^2 at scales ``tau`` (samples)."""
        return self._compiled(theta, tau, False)[1]

    def wv_jacobian(self, theta, tau) -> np.ndarray:
        """``d nu2(tau) / d log theta``, shape ``(n_tau, n_params)``.

        Every WV is linear in its variance parameter, so that column is the component's WV
        (twice it for the drift, quadratic in ``omega``); the GM ``beta`` column is a central
        difference in ``log beta`` with step 1e-3 (truncation error about 1e-7; where
        ``m beta`` is small the WV hardly depends on ``beta`` and the column's relative
        error can reach about 1e-4, which only affects the optimiser's path and the SEs at that
        level).  For 1-D ``tau`` the values come from one compiled call (:func:`_wv_kernel`), equal to
        this NumPy composition (tested).
        """
        t = np.asarray(tau, dtype=np.float64)
        if t.ndim == 1:
            return self._compiled(theta, t, True)[2]
        return self._jacobian_numpy(self._theta(theta), t)

    def avar(self, theta, m) -> np.ndarray:
        """Theoretical Allan variance at averaging factors ``m`` (integers >= 1): ``2 nu2(2m)``."""
        return 2.0 * self.wv(theta, 2.0 * np.asarray(m, dtype=np.float64))

    def sdf(self, theta) -> Callable:
        """Two-sided SDF ``f -> S(f)`` (rate^2 per cycle/sample) of the stochastic part (DR omitted)."""
        th = self._theta(theta).copy()
        parts = [(PROCESSES[k].sdf, th[s]) for k, s in zip(self.components, self.slices)
                 if PROCESSES[k].sdf is not None]

        def s(f):
            f = np.asarray(f, dtype=np.float64)
            out = np.zeros(f.shape)
            for fn, p in parts:
                out = out + fn(p, f)
            return out

        return s

    def to_free(self, theta) -> np.ndarray:
        """Free parameters ``z = log(theta)`` (every natural parameter is > 0)."""
        th = self._theta(theta)
        if np.any(th <= 0):
            raise ConfigError(f"all parameters of {self.name} must be > 0, got {th.tolist()}")
        return np.log(th)

    def from_free(self, z) -> np.ndarray:
        """Natural parameters ``exp(z)``."""
        return np.exp(np.asarray(z, dtype=np.float64))

    def sort_gm(self, theta, cov=None):
        """Reorder the GMs by decreasing ``beta`` (increasing T_c); also permute ``cov`` if given."""
        th = np.asarray(theta, dtype=np.float64)
        gm_slices = [s for k, s in zip(self.components, self.slices) if k == "GM"]
        if len(gm_slices) < 2:
            return (th, cov) if cov is not None else th
        order = sorted(range(len(gm_slices)), key=lambda i: -th[gm_slices[i].start])
        perm = np.arange(th.size)
        for dst, src in zip(gm_slices, (gm_slices[i] for i in order)):
            perm[dst] = np.arange(src.start, src.stop)
        th2 = th[perm]
        if cov is None:
            return th2
        return th2, np.asarray(cov)[np.ix_(perm, perm)]

    def ieee(self, theta, dt_s) -> list[dict]:
        """IEEE-952 quantities per component: ``[{"component": label, key: value, ...}, ...]``."""
        th = self._theta(theta)
        return [dict(component=lab, **PROCESSES[k].ieee(th[s], dt_s))
                for k, lab, s in zip(self.components, self.labels, self.slices)]


class WvEvaluator:
    """The WV and the Jacobian of one model at fixed 1-D scales, for an optimiser's inner loop.

    :meth:`wv` and :meth:`jac` make the same kernel call with the same operations as :meth:`LatentModel.wv` and
    :meth:`LatentModel.wv_jacobian` (so the same values, bit for bit: tested), with everything that does not depend
    on ``theta`` (the scales, their half-widths, the flicker factors, the compiled kernel, the work arrays) prepared
    once and ``theta`` not re-validated per call: the GMWM fit evaluates the model some 30 times per optimiser run
    and about 1300 runs per ``fogdrift noise`` of a 3-axis log, where that per-call overhead outweighed the kernel.

    Parameters
    ----------
    model : LatentModel
    tau : array_like (n_tau,)
        Haar scales in samples (1-D).

    Notes
    -----
    ``theta`` must be a C-contiguous float64 array of ``model.n_params`` natural parameters (``np.exp(z)`` of the
    optimiser's free parameters is).  The returned arrays are work arrays, overwritten by the next call of the same
    method: use (or copy) them before calling again.  Overflow in ``expm1`` of a huge ``beta`` is not silenced here
    (callers run under ``np.errstate(over="ignore", invalid="ignore")``, as :meth:`LatentModel.wv` does inside).

    Examples
    --------
    >>> m = parse_model("WN+RW")
    >>> ev = m.evaluator([2.0, 8.0])
    >>> [round(float(v), 6) for v in ev.wv(np.array([1.0, 0.01]))]
    [0.5025, 0.131875]
    """

    __slots__ = ("_t", "_half", "_flick", "_codes", "_starts", "_gm_beta", "_dr", "_kernel", "_comps", "_total",
                 "_jac", "_none")

    def __init__(self, model: LatentModel, tau):
        t = np.asarray(tau, dtype=np.float64)
        if t.ndim != 1:
            raise ConfigError(f"WvEvaluator needs 1-D scales, got shape {t.shape}")
        self._t = np.ascontiguousarray(t)
        self._half = self._t / 2.0  # as LatentModel._compiled's t / 2.0
        self._flick = model._flicker_factors(self._t)
        self._codes, self._starts, self._dr = model._codes, model._starts, model._dr
        self._gm_beta = model._gm_beta if model.n_gm else None
        self._kernel = _wv_kernel()
        n = self._t.size
        self._comps = np.empty((len(model.components), n))
        self._total = np.empty(n)
        self._jac = np.empty((n, model.n_params))
        self._none = np.empty((0, 0))

    def wv(self, theta) -> np.ndarray:
        """Model WV ``nu2(tau)`` in rate^2 (a work array, see the class notes)."""
        if self._gm_beta is None:
            vv = self._none
        else:
            vv = -np.expm1(-np.multiply.outer(theta[self._gm_beta], self._half))
        dr_p2 = float(theta[self._dr]) ** 2 if self._dr >= 0 else 0.0
        self._kernel(self._codes, self._starts, theta, self._t, self._flick, vv, dr_p2, self._comps, self._total,
                     self._none, False)
        return self._total

    def kernel_args(self) -> tuple:
        """What a compiled caller passes to the kernel itself (:mod:`fogdrift.gmwm.solver`): ``(codes, starts, t,
        half, flick, gm_beta, dr, n_comp)``; ``gm_beta`` the parameter index of each GM's ``beta`` (empty without a
        GM), ``dr`` that of the drift slope (-1 without one), ``n_comp`` the number of components."""
        gm = self._gm_beta if self._gm_beta is not None else np.empty(0, dtype=np.int64)
        return (self._codes, self._starts, self._t, self._half, self._flick, gm, self._dr, self._comps.shape[0])

    def jac(self, theta) -> np.ndarray:
        """``d nu2(tau) / d log theta``, ``(n_tau, n_params)`` (a work array, see the class notes)."""
        if self._gm_beta is None:
            vv = self._none
        else:
            beta = np.multiply.outer(theta[self._gm_beta], _BETA3).ravel()
            vv = -np.expm1(-np.multiply.outer(beta, self._half))
        dr_p2 = float(theta[self._dr]) ** 2 if self._dr >= 0 else 0.0
        self._kernel(self._codes, self._starts, theta, self._t, self._flick, vv, dr_p2, self._comps, self._total,
                     self._jac, True)
        return self._jac


_TERM = re.compile(r"^\s*(\d*)\s*([A-Za-z][A-Za-z0-9()\-]*)\s*$")


def parse_model(model) -> LatentModel:
    """Parse a model string such as ``"WN+RW"``, ``"QN+WN+RW+2GM"``, ``"WN+AR1"``.

    Terms are separated by ``+``; an integer prefix repeats a GM (``2GM``).  Names are
    case-insensitive, with aliases (:data:`ALIASES`): GM = AR1, WN = ARW, RW = RRW,
    DR = RAMP, FLICKER = BI.  A :class:`LatentModel` is returned unchanged.

    Raises
    ------
    ConfigError
        Unknown name, repeated non-GM component, more than 6 GMs or an empty string.
    """
    if isinstance(model, LatentModel):
        return model
    if not isinstance(model, str) or not model.strip():
        raise ConfigError(f"model must be a string such as 'WN+RW+GM', got {model!r}")
    comps: list[str] = []
    for term in model.split("+"):
        mt = _TERM.match(term)
        key = ALIASES.get(mt.group(2).upper().replace("-", "")) if mt else None
        if key is None:
            raise ConfigError(
                f"unknown component {term.strip()!r} in model {model!r}; expected terms from "
                f"{sorted(set(ALIASES.values()))} (e.g. 'QN+WN+RW+2GM'); check {{opt:model}}"
            )
        count = int(mt.group(1)) if mt.group(1) else 1
        if count < 1:
            raise ConfigError(f"component count must be >= 1 in {term.strip()!r}")
        comps.extend([key] * count)
    for key in _order():
        if key != "GM" and comps.count(key) > 1:
            raise ConfigError(f"model {model!r} repeats {key}; only GM may appear more than once")
    if comps.count("GM") > _MAX_GM:
        raise ConfigError(f"at most {_MAX_GM} GMs per model, got {comps.count('GM')} in {model!r}")
    comps.sort(key=_order().index)
    return LatentModel(comps)
