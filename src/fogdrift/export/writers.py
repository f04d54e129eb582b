"""The writers of the export targets, one function per target (the registry is :mod:`fogdrift.export.targets`).

Each writer takes an :class:`ExportContext` (the gyro and accelerometer channels, the update rate, the
``--missing`` policy) and returns the file's text.  Every number written carries, in a comment above it: the
fogdrift term and estimate with its 95 % interval and status, the continuous-time value, the discrete-time value
at the stated update rate, and the conversion used.  A quantity without a result (no ``--accel`` file) is not
written: its keys are left out and a comment says so (never a zero or a guess).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

from .._util import fmt_number
from ..errors import FogdriftError
from .conversions import DEG, MGAL, gm_discrete, walk_discrete, white_discrete
from .discretize import discrete_model
from .model import ChannelModel, bias_gm, describe, resolve

__all__ = ["ExportContext", "fmt", "write_kalibr", "write_openvins", "write_vins", "write_orbslam3", "write_kfgins",
           "write_matlab", "write_gnss_ins_sim", "write_json"]


@dataclass
class ExportContext:
    """What every writer gets.

    Attributes
    ----------
    gyro, accel : list of ChannelModel
        The channels of each quantity (either may be empty, not both).
    rate_hz : float
        The update rate the discrete values are given at [Hz] (the filter's IMU rate).
    missing : str
        The ``--missing`` policy (:data:`fogdrift.export.model.MISSING_POLICIES`).
    topic : str
        ROS topic written where a target has one.
    notes : list of str
        Lines for the console (bounds, zeros, unresolved estimates, left-out keys), filled by the writers.
    """

    gyro: list
    accel: list
    rate_hz: float
    missing: str = "bound"
    topic: str = "/imu0"
    notes: list = field(default_factory=list)

    def channels(self, quantity: str) -> list:
        return self.gyro if quantity == "gyro" else self.accel

    def note(self, text: str) -> None:
        if text not in self.notes:
            self.notes.append(text)


def fmt(x: float) -> str:
    """A float that every YAML parser reads as a float (a dot in the mantissa: PyYAML reads '1e-05' as a string).

    Examples
    --------
    >>> fmt(1e-5), fmt(0.0), fmt(2.5), fmt(123456789.0)
    ('1.0e-05', '0.0', '2.5', '1.23457e+08')
    """
    return fmt_number(float(x), 6, nonfinite=None, float_literal=True)


_QWORD = {"gyro": "gyroscope", "accel": "accelerometer"}
_SI_RATE = {"gyro": "rad/s", "accel": "m/s^2"}


def _term_lines(ctx: ExportContext, ch: ChannelModel, name: str, prefix: str, out_unit: str, out_factor: float,
                kind: str) -> tuple[float, list[str]]:
    """Resolve one term of one channel; the value in the output unit and its comment lines.

    ``kind``: ``"white"`` (discrete = x sqrt(f)) or ``"walk"`` (discrete = / sqrt(f)) or ``"level"`` (no
    discretisation: a standard deviation)."""
    r = resolve(ch, name, ctx.missing)
    if r.note:
        ctx.note(f"{ch.label}: {r.note}")
    si_unit = r.term.si_unit
    lines = [f"{prefix}{ch.name}: {describe(r.term)}"]
    how = {"estimate": "the estimate", "bound": "its 95 % upper bound (--missing bound)",
           "zero": "0 (--missing zero)"}[r.how]
    cont = f"continuous {fmt(r.si)} {si_unit} ({how}; {r.term.conversion})"
    if kind == "white":
        disc = (f"discrete {fmt(white_discrete(r.si, ctx.rate_hz))} {_SI_RATE[ch.quantity]} per sample at "
                f"{fmt(ctx.rate_hz)} Hz (x sqrt(f))")
    elif kind == "walk":
        disc = (f"discrete {fmt(walk_discrete(r.si, ctx.rate_hz))} {_SI_RATE[ch.quantity]} per-sample bias step at "
                f"{fmt(ctx.rate_hz)} Hz (/ sqrt(f))")
    else:
        disc = "a standard deviation: the same in continuous and discrete time"
    lines.append(f"{prefix}  {cont}; {disc}")
    return r.si * out_factor, lines


def _scalar(ctx, quantity, name, prefix, out_unit, out_factor, kind):
    """One value for all axes (Kalibr-style targets): the largest axis, with every axis in the comments."""
    chans = ctx.channels(quantity)
    vals, lines = [], []
    for ch in chans:
        v, ls = _term_lines(ctx, ch, name, prefix, out_unit, out_factor, kind)
        vals.append((v, ch.name))
        lines += ls
    v, which = max(vals)
    if len(vals) > 1:
        lines.append(f"{prefix}written: the largest of the {len(vals)} axes ({which}) in {out_unit}: this format "
                     "takes one value for all axes")
    else:
        lines.append(f"{prefix}written in {out_unit}")
    return v, lines


def _missing_quantity(ctx, target: str, quantity: str, keys, prefix: str) -> list[str]:
    ctx.note(f"no {_QWORD[quantity]} result given (--{quantity} FILE): the {_QWORD[quantity]} fields of every target "
             "are left out (each file says which)")
    return [f"{prefix}{', '.join(keys)}: not written: no {_QWORD[quantity]} result was given "
            f"(fogdrift export --{quantity} RESULT.json); fogdrift never writes a noise figure it did not measure"]


def _header(ctx, target, prefix, source) -> list[str]:
    files = sorted({ch.source_file for ch in ctx.gyro + ctx.accel})
    shas = sorted({ch.sha256[:16] for ch in ctx.gyro + ctx.accel if ch.sha256})
    fits = [f"{ch.label}: {ch.method} {ch.fit}" for ch in ctx.gyro + ctx.accel]
    return ([f"{prefix}fogdrift export --target {target}: noise model for {source}",
             f"{prefix}from {', '.join(files)}" + (f" (input SHA-256 {', '.join(shas)}...)" if shas else ""),
             f"{prefix}update rate {fmt(ctx.rate_hz)} Hz; --missing {ctx.missing}"]
            + [f"{prefix}{f}" for f in fits]
            + [f"{prefix}continuous -> discrete: white sigma_d = N sqrt(f), random-walk step sigma_bd = K / sqrt(f) "
               "(Kalibr wiki 'IMU Noise Model')"])


# ------------------------------------------------------------------------------------------------------------------
# Kalibr-family: one white density and one random-walk density per sensor
# ------------------------------------------------------------------------------------------------------------------
_KALIBR_KEYS = (("accel", "N", "accelerometer_noise_density", "m/s^2/sqrt(Hz)", "white"),
                ("accel", "K", "accelerometer_random_walk", "m/s^3/sqrt(Hz)", "walk"),
                ("gyro", "N", "gyroscope_noise_density", "rad/s/sqrt(Hz)", "white"),
                ("gyro", "K", "gyroscope_random_walk", "rad/s^2/sqrt(Hz)", "walk"))


def _kalibr_body(ctx, target, keys, indent="") -> list[str]:
    out = []
    done = set()
    for quantity, name, key, unit, kind in keys:
        if not ctx.channels(quantity):
            if quantity not in done:
                out += _missing_quantity(ctx, target, quantity, [k[2] for k in keys if k[0] == quantity], indent + "# ")
                done.add(quantity)
            continue
        v, lines = _scalar(ctx, quantity, name, indent + "# ", unit, 1.0, kind)
        out += lines + [f"{indent}{key}: {fmt(v)}  # [{unit}] continuous time"]
    return out


def write_kalibr(ctx: ExportContext) -> str:
    lines = _header(ctx, "kalibr", "# ", "Kalibr imu.yaml (continuous-time densities; Kalibr discretises at update_rate)")
    lines += _kalibr_body(ctx, "kalibr", _KALIBR_KEYS)
    lines += [f"rostopic: {ctx.topic}", f"update_rate: {fmt(ctx.rate_hz)}  # [Hz]"]
    return "\n".join(lines) + "\n"


def write_openvins(ctx: ExportContext) -> str:
    lines = ["%YAML:1.0", ""] + _header(ctx, "openvins", "# ", "OpenVINS kalibr_imu_chain.yaml (read with cv::FileStorage)")
    lines += ["# T_i_b is the identity: fogdrift does not calibrate extrinsics", "imu0:", "  T_i_b:"]
    lines += [f"    - [{', '.join('1.0' if i == j else '0.0' for j in range(4))}]" for i in range(4)]
    lines += _kalibr_body(ctx, "openvins", _KALIBR_KEYS, indent="  ")
    lines += [f"  rostopic: {ctx.topic}", "  time_offset: 0.0", f"  update_rate: {fmt(ctx.rate_hz)}  # [Hz]",
              '  model: "kalibr"']
    return "\n".join(lines) + "\n"


_VINS_KEYS = (("accel", "N", "acc_n", "m/s^2/sqrt(Hz)", "white"), ("gyro", "N", "gyr_n", "rad/s/sqrt(Hz)", "white"),
              ("accel", "K", "acc_w", "m/s^3/sqrt(Hz)", "walk"), ("gyro", "K", "gyr_w", "rad/s^2/sqrt(Hz)", "walk"))


def write_vins(ctx: ExportContext) -> str:
    lines = ["%YAML:1.0", ""] + _header(ctx, "vins-fusion", "# ", "VINS-Fusion config (IMU noise block; cv::FileStorage)")
    lines += ["# merge these keys into your VINS-Fusion config.  Its comments call them 'measurement noise standard",
              "# deviation' and 'bias random work noise standard deviation' without saying continuous or discrete time (questions open",
              "# in VINS-Mono issues #102, #327); written here: the continuous-time densities, the Kalibr values; the",
              "# per-sample (discrete) values at the update rate are in the comments.  VINS's own EuRoC config uses values",
              "# 10-100x the EuRoC Kalibr densities (inflated by hand)."]
    lines += _kalibr_body(ctx, "vins-fusion", _VINS_KEYS)
    return "\n".join(lines) + "\n"


_ORB_KEYS = (("gyro", "N", "IMU.NoiseGyro", "rad/s/sqrt(Hz)", "white"),
             ("accel", "N", "IMU.NoiseAcc", "m/s^2/sqrt(Hz)", "white"),
             ("gyro", "K", "IMU.GyroWalk", "rad/s^2/sqrt(Hz)", "walk"),
             ("accel", "K", "IMU.AccWalk", "m/s^3/sqrt(Hz)", "walk"))


def write_orbslam3(ctx: ExportContext) -> str:
    lines = ["%YAML:1.0", ""] + _header(ctx, "orbslam3", "# ", "ORB-SLAM3 settings (IMU block; cv::FileStorage)")
    lines += ["# ORB-SLAM3 reads continuous densities and discretises itself: noise x sqrt(IMU.Frequency), "
              "walk / sqrt(IMU.Frequency) (Tracking: IMU::Calib(Tbc, Ng*sf, Na*sf, Ngw/sf, Naw/sf), sf = sqrt(freq))"]
    lines += _kalibr_body(ctx, "orbslam3", _ORB_KEYS)
    lines += [f"IMU.Frequency: {fmt(ctx.rate_hz)}  # [Hz]"]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------------------------------------------------
# per-axis targets
# ------------------------------------------------------------------------------------------------------------------
def _vector(ctx, quantity, name, prefix, out_unit, out_factor, kind):
    vals, lines = [], []
    for ch in ctx.channels(quantity):
        v, ls = _term_lines(ctx, ch, name, prefix, out_unit, out_factor, kind)
        vals.append(v)
        lines += ls
    lines.append(f"{prefix}written per axis ({', '.join(c.name for c in ctx.channels(quantity))}) in {out_unit}")
    return vals, lines


def _gm_vectors(ctx, quantity, prefix, sigma_factor, sigma_unit, tc_factor, tc_unit):
    sig, tcs, lines = [], [], []
    for ch in ctx.channels(quantity):
        g, how = bias_gm(ch, ctx.missing)
        phi, qd = gm_discrete(g.sigma_si, g.tc_s, ctx.rate_hz)
        iv = ("" if g.sigma_lo95_si is None else
              f" [{fmt(g.sigma_lo95_si * sigma_factor)}, {fmt(g.sigma_hi95_si * sigma_factor)}]")
        tiv = "" if g.tc_lo95_s is None or g.tc_hi95_s is None else f" [{fmt(g.tc_lo95_s)}, {fmt(g.tc_hi95_s)}] s"
        lines += [f"{prefix}{ch.name}: bias Gauss-Markov: {how}",
                  f"{prefix}  sigma = {fmt(g.sigma_si)} {_SI_RATE[quantity]}"
                  f"{iv and ' (95 %' + iv + ' ' + sigma_unit + ')'}, "
                  f"T_c = {fmt(g.tc_s)} s{tiv}; discrete at {fmt(ctx.rate_hz)} Hz: phi = exp(-dt/T_c) = {phi:.9f}, "
                  f"driving sigma = sigma sqrt(1 - phi^2) = {fmt(qd)} {_SI_RATE[quantity]}"]
        sig.append(g.sigma_si * sigma_factor)
        tcs.append(g.tc_s * tc_factor)
    lines.append(f"{prefix}written per axis: sigma in {sigma_unit}, T_c in {tc_unit}")
    return sig, tcs, lines


def _list(vals) -> str:
    return "[" + ", ".join(fmt(v) for v in vals) + "]"


def write_kfgins(ctx: ExportContext) -> str:
    lines = _header(ctx, "kf-gins", "# ", "KF-GINS imunoise block (merge into kf-gins.yaml)")
    lines += ["# KF-GINS models each bias as one first-order Gauss-Markov process: gbstd/abstd its 1-sigma,",
              "# corrtime its correlation time (one value for all biases); a random walk K has no place in it", "imunoise:"]
    body, values = [], {}
    for quantity, key, factor, unit in (("gyro", "arw", 60.0 / DEG, "deg/sqrt(h)"), ("accel", "vrw", 60.0, "m/s/sqrt(h)")):
        if ctx.channels(quantity):
            vals, ls = _vector(ctx, quantity, "N", "  # ", unit, factor, "white")
            body += ls + [f"  {key}: {_list(vals)}  # [{unit}]"]
        else:
            body += _missing_quantity(ctx, "kf-gins", quantity, [key], "  # ")
    tcs_all = {}
    for quantity, key, factor, unit in (("gyro", "gbstd", 3600.0 / DEG, "deg/h"), ("accel", "abstd", 1.0 / MGAL, "mGal")):
        if ctx.channels(quantity):
            sig, tcs, ls = _gm_vectors(ctx, quantity, "  # ", factor, unit, 1.0 / 3600.0, "h")
            tcs_all[quantity] = tcs
            body += ls + [f"  {key}: {_list(sig)}  # [{unit}]"]
        else:
            body += _missing_quantity(ctx, "kf-gins", quantity, [key], "  # ")
    body += ["  # gsstd, asstd (scale-factor instability [ppm]): not written: a static record does not observe scale "
             "factors; take them from the datasheet"]
    ctx.note("kf-gins: gsstd, asstd not written (scale factors are not observable in a static record)")
    if tcs_all:
        src = "gyro" if "gyro" in tcs_all else "accel"
        tc = max(tcs_all[src])
        other = ", ".join(f"{q} {', '.join(fmt(t) for t in v)} h" for q, v in tcs_all.items())
        body += [f"  # corrtime: the longest {_QWORD[src]} correlation time; per axis: {other}",
                 f"  corrtime: {fmt(tc)}  # [h]"]
        values["corrtime"] = tc
    lines += body
    return "\n".join(lines) + "\n"


def write_matlab(ctx: ExportContext) -> str:
    pre = "% "
    lines = _header(ctx, "matlab", pre, "MATLAB imuSensor (gyroparams / accelparams, Navigation / Sensor Fusion Toolbox)")
    lines += [f"{pre}Units per the gyroparams / accelparams reference pages: NoiseDensity (rad/s)/sqrt(Hz) and "
              "(m/s^2)/sqrt(Hz), RandomWalk (rad/s)*sqrt(Hz) and (m/s^2)*sqrt(Hz), BiasInstability rad/s and m/s^2",
              f"{pre}(MathWorks Answers 1631045: RandomWalk is the rate random walk K, NoiseDensity the white density N)",
              f"{pre}BiasInstability is B (the flicker floor); BiasInstabilityCoefficients is left at its default"]
    objs = []
    for quantity, fn, var in (("gyro", "gyroparams", "gyro"), ("accel", "accelparams", "accel")):
        if not ctx.channels(quantity):
            lines += _missing_quantity(ctx, "matlab", quantity, [fn], pre)
            continue
        si = _SI_RATE[quantity]
        n, ln = _vector(ctx, quantity, "N", pre, f"({si})/sqrt(Hz)", 1.0, "white")
        k, lk = _vector(ctx, quantity, "K", pre, f"({si})*sqrt(Hz)", 1.0, "walk")
        b, lb = _vector(ctx, quantity, "B", pre, si, 1.0, "level")
        lines += ln + lk + lb
        lines += [f"{var} = {fn}( ...",
                  f"    'NoiseDensity', {_list(n).replace(',', '')}, ...     % ({si})/sqrt(Hz)",
                  f"    'RandomWalk', {_list(k).replace(',', '')}, ...       % ({si})*sqrt(Hz)",
                  f"    'BiasInstability', {_list(b).replace(',', '')});     % {si}"]
        objs.append(("Gyroscope" if quantity == "gyro" else "Accelerometer", var))
    args = "".join(f", '{k}', {v}" for k, v in objs)
    lines += [f"imu = imuSensor('accel-gyro', 'SampleRate', {fmt(ctx.rate_hz)}{args});"]
    return "\n".join(lines) + "\n"


def write_gnss_ins_sim(ctx: ExportContext) -> str:
    pre = "# "
    lines = _header(ctx, "gnss-ins-sim", pre, "gnss-ins-sim imu_err dictionary (README 'Step 1.1'; imu_model.IMU)")
    lines += [f"{pre}b_stability is the 1-sigma of a first-order Gauss-Markov bias with correlation time b_corr "
              "(gnss-ins-sim's bias_drift)", "import numpy as np", "", "imu_err = {"]
    for quantity, pfx, nunit, nfac, bunit, bfac in (("gyro", "gyro", "deg/sqrt(h)", 60.0 / DEG, "deg/h", 3600.0 / DEG),
                                                    ("accel", "accel", "m/s/sqrt(h)", 60.0, "m/s^2", 1.0)):
        if not ctx.channels(quantity):
            keys = [f"{pfx}_b", f"{pfx}_{'arw' if pfx == 'gyro' else 'vrw'}", f"{pfx}_b_stability", f"{pfx}_b_corr"]
            lines += _missing_quantity(ctx, "gnss-ins-sim", quantity, keys, "    # ")
            continue
        n, ln = _vector(ctx, quantity, "N", "    # ", nunit, nfac, "white")
        sig, tcs, lg = _gm_vectors(ctx, quantity, "    # ", bfac, bunit, 1.0, "s")
        m = len(n)
        lines += ["    # constant bias: not a noise term (removed by calibration); 0 = a calibrated sensor",
                  f"    '{pfx}_b': np.array({_list([0.0] * m)}),  # [{bunit}]"]
        lines += ln + [f"    '{pfx}_{'arw' if pfx == 'gyro' else 'vrw'}': np.array({_list(n)}),  # [{nunit}]"]
        lines += lg + [f"    '{pfx}_b_stability': np.array({_list(sig)}),  # [{bunit}]",
                       f"    '{pfx}_b_corr': np.array({_list(tcs)}),  # [s]"]
    lines += ["}"]
    return "\n".join(lines) + "\n"


def write_json(ctx: ExportContext) -> str:
    chans = []
    for ch in ctx.gyro + ctx.accel:
        d = ch.to_dict()
        resolved = {}
        for name in ("N", "K", "B", "Q", "R"):
            if name not in ch.terms:
                continue
            try:
                r = resolve(ch, name, ctx.missing)
                entry = {"si": r.si, "si_unit": r.term.si_unit, "how": r.how, "note": r.note,
                         "conversion": r.term.conversion}
                if name == "N":
                    entry["discrete_sigma"] = white_discrete(r.si, ctx.rate_hz)
                    entry["discrete_note"] = "per-sample 1-sigma = N sqrt(f)"
                elif name == "K":
                    entry["discrete_sigma"] = walk_discrete(r.si, ctx.rate_hz)
                    entry["discrete_note"] = "per-sample bias step 1-sigma = K / sqrt(f)"
            except FogdriftError as exc:  # a refused term is reported; the JSON keeps the others
                entry = {"si": None, "how": "refused", "note": str(exc)}
            resolved[name] = entry
        d["export_values"] = resolved
        try:
            g, how = bias_gm(ch, ctx.missing)
            phi, qd = gm_discrete(g.sigma_si, g.tc_s, ctx.rate_hz)
            d["bias_gauss_markov"] = {**g.to_dict(), "how": how, "phi": phi, "driving_sigma_si": qd}
        except FogdriftError as exc:  # refused: reported in the JSON
            d["bias_gauss_markov"] = {"how": "refused", "note": str(exc)}
        d["state_space"] = discrete_model(ch, ctx.rate_hz)
        if ch.no_fit:
            d["state_space"]["caveat"] = ("no model fits this record: the state-space model uses the best candidate's "
                                          "values, which are not a result")
        chans.append(d)
    doc = {"fogdrift_export": "json", "update_rate_hz": ctx.rate_hz, "missing": ctx.missing,
           "conventions": {"si_rate_units": {"gyro": "rad/s", "accel": "m/s^2"},
                           "white": "continuous density N; discrete 1-sigma N sqrt(f)",
                           "random_walk": "continuous density K; discrete step 1-sigma K / sqrt(f)",
                           "gauss_markov": "phi = exp(-dt/T_c), driving 1-sigma = sigma sqrt(1 - phi^2)",
                           "source": "Kalibr wiki 'IMU Noise Model'; IEEE Std 952-1997 Annex C"},
           "channels": chans}
    return json.dumps(_json_safe(doc), indent=1, allow_nan=False, default=_json_default) + "\n"


def _json_safe(x):
    """``x`` with every non-finite float replaced by None (JSON null): json.dumps never passes a float to
    ``default``, so a NaN (a GMWM result without ``tau_range_s``, say) would otherwise stop the export."""
    if isinstance(x, float) and not math.isfinite(x):
        return None
    if isinstance(x, dict):
        return {k: _json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_json_safe(v) for v in x]
    return x


def _json_default(x):
    raise TypeError(type(x).__name__)
