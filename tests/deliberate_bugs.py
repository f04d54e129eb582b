"""Deliberate bugs: each entry is one plausible one-line bug (an exact replacement in one source file) and the test
that must fail on it.  Run by hand, it applies each alone, runs its test and restores the file, printing one markdown
row per bug (docs/testing-rounds.md):

    .venv/bin/python tests/deliberate_bugs.py        # needs a clean src/ (refuses otherwise); ~5 min on 2 cores

Not collected by pytest (no ``test_`` prefix): it edits the source, so it must not run inside the suite.  The suite
checks that every entry still applies (``tests/project/test_deliberate_bugs.py``: the text to replace is found once,
the bugged file still compiles, the named tests exist), so that an entry cannot go stale silently.
"""
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
BUGS = [
    ("symmetric boundary: half-sample instead of whole-sample reflection (numba kernel)",
     "src/fogdrift/lifting/_numba.py", "        j = p - j\n", "        j = p - j - 1 if p - j - 1 >= 0 else 0\n",
     ["tests/lifting/test_lifting_symmetric.py"]),
    ("symmetric boundary: half-sample reflection (NumPy backend)",
     "src/fogdrift/lifting/_kernels.py", "    return p - j if j > m - 1 else j\n", "    return p - j - 1 if j > m - 1 else j\n",
     ["tests/lifting/test_lifting_symmetric.py"]),
    ("K conversion factor 60 -> 61 (deg/h^1.5)",
     "src/fogdrift/noise/processes/random_walk.py", '"K [deg/h^1.5]", 60.0,', '"K [deg/h^1.5]", 61.0,',
     ["tests/noise/test_noise.py", "-k", "single_term"]),
    ("p0 divides by |y_hat| instead of |y|",
     "src/fogdrift/metrics.py", "    ay = np.abs(a)\n", "    ay = np.abs(b)\n",
     ["tests/test_metrics.py"]),
    ("grey-Elman eq. (13): restore subtracts half the previous AGO sum",
     "src/fogdrift/models/elman.py", "return self.x1_mean_ + self.x1_std_ * out - x1_prev  # eq. (13)",
     "return self.x1_mean_ + self.x1_std_ * out - 0.5 * x1_prev  # eq. (13)",
     ["tests/models/test_elman.py", "-k", "eq13 or restores"]),
    ("EDF flicker PM (alpha = +1): (N-1)/(2m) -> (N-1)/m",
     "src/fogdrift/allan/ci.py", "np.log((n - 1) / (2 * q)) * np.log(", "np.log((n - 1) / q) * np.log(",
     ["tests/allan/test_allan_ci.py"]),
    ("Elman normalisation from training + validation data (leakage)",
     "src/fogdrift/models/elman.py", "        self.x_mean_ = float(np.mean(s_fit))\n",
     "        self.x_mean_ = float(np.mean(np.concatenate([s_fit, s_va])))\n",
     ["tests/models/test_elman.py", "-k", "validation_block"]),
    ("report figures saved blank (figure cleared before saving)",
     "src/fogdrift/report/figures.py", "            fig.savefig(tmp, **{", "            fig.clf(); fig.savefig(tmp, **{",
     ["tests/report/test_golden.py", "-k", "figures_have_content"]),
    # H-structure
    ("out-of-core Allan: the old copied tail (auto alpha from the slopes, without the long-tau EDF rule)",
     "src/fogdrift/allan/chunked.py", "                            noise_alpha=noise_alpha)\n",
     "                            noise_alpha=resolve_alpha(noise_alpha, m * source.dt_s, sums / (2.0 * m**2 * (n - 2 * m + 1)), "
     "slopes=get_statistic(\"adev\").dev_slopes, candidates=IEEE952_ALPHAS)[0] if noise_alpha == \"auto\" else noise_alpha)\n",
     ["tests/allan/test_allan_result_shared.py", "-k", "quantization_long_tau"]),
    # H-compensate (issue 24: compensation with a declared unit and with a latitude; issue 21: the scale carried)
    ("compensate: bias re-estimated without removing the bundle's Earth-rate projection",
     "src/fogdrift/compensate/engine.py", "                a.bias_out_dph = float(level[k]) - earth\n",
     "                a.bias_out_dph = float(level[k])\n",
     ["tests/compensate/test_compensate_io.py", "-k", "earth_rate"]),
    ("compensate: the declared unit labels numbers read in the --unit given (output header/unit wrong)",
     "src/fogdrift/compensate/sources.py", "        return self.signal.channels[0].unit_as_read\n",
     "        return self.declared_unit or self.signal.channels[0].unit_as_read\n",
     ["tests/compensate/test_compensate_io.py", "-k", "another_unit"]),
    ("compensate: writers divide by the unit's factor, not the reader's scale (an increment unit ignores dt)",
     "src/fogdrift/compensate/run.py", "    scale = match.scale_to_dph  #",
     "    scale = source.signal.channels[0].unit.factor  #",
     ["tests/compensate/test_compensate_io.py", "-k", "increment"]),
]


def main() -> None:
    if subprocess.run(["git", "status", "--porcelain", "src"], cwd=ROOT, capture_output=True, text=True).stdout:
        sys.exit("src/ has uncommitted changes; commit or stash them first (this script edits and restores src/)")
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    for what, rel, old, new, test in BUGS:
        f = ROOT / rel
        src = f.read_text()
        assert src.count(old) == 1, (rel, old)
        f.write_text(src.replace(old, new))
        try:
            r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-x", "--no-header", *test],
                               cwd=ROOT, env=env, capture_output=True, text=True, timeout=900)
        finally:
            f.write_text(src)
        failed = [l for l in r.stdout.splitlines() if l.startswith("FAILED")]
        print(f"| {what} | `{rel}` | {'CAUGHT' if r.returncode else 'NOT CAUGHT'}: {failed[0][7:].split(' - ')[0] if failed else ''} |", flush=True)
    clean = subprocess.run(["git", "status", "--porcelain", "src"], cwd=ROOT, capture_output=True, text=True).stdout
    print("src clean after:", clean == "")


if __name__ == "__main__":
    main()


# H-tests24 (issue 24, round 2: the GMWM statistics, evaluation at dt != 1 s, edges of tables).  Each entry is one
# realistic one-line bug and the test of tests/*/test_rules_*.py that must fail on it (docs/testing-rounds.md, "Round 2
# (issue 24)").  Run as part of the whole script (after the entries above), or one at a time from Python:
#     import runpy; m = runpy.run_path("tests/deliberate_bugs.py"); m["H_TESTS24"]   # then apply/run/restore by hand
H_TESTS24 = [
    ("GMWM J test: dof from every scale of the WV, not the scales used",
     "src/fogdrift/gmwm/estimator.py", "    df = J - mdl.n_params\n", "    df = len(wv) - mdl.n_params\n",
     ["tests/gmwm/test_rules_gmwm.py", "-k", "chi2_survival"]),
    ("GMWM J test: p-value with one degree of freedom too many",
     "src/fogdrift/gmwm/estimator.py", "jp = float(chi2_sf(j_q, df))", "jp = float(chi2_sf(j_q, df + 1))",
     ["tests/gmwm/test_rules_gmwm.py", "-k", "chi2_survival"]),
    ("GMWM J test: the chi2 cdf instead of the survival function",
     "src/fogdrift/gmwm/estimator.py", "jp = float(chi2_sf(j_q, df))", "jp = float(1.0 - chi2_sf(j_q, df))",
     ["tests/gmwm/test_rules_gmwm.py", "-k", "uniform"]),
    ("WIC without its penalty (Q alone)",
     "src/fogdrift/gmwm/estimator.py", "penalty=penalty, wic=q + penalty,", "penalty=penalty, wic=q,",
     ["tests/gmwm/test_rules_gmwm.py", "-k", "nested"]),
    ("WIC penalty 2 tr(P) (the Omega = V^-1 shortcut) under any Omega",
     "src/fogdrift/gmwm/estimator.py", "    penalty = 2.0 * float(np.trace(proj @ WV))\n",
     "    penalty = 2.0 * float(np.trace(proj))\n",
     ["tests/gmwm/test_rules_gmwm.py", "-k", "general_formula"]),
    ("selection: each candidate under its own V (no common Omega)",
     "src/fogdrift/gmwm/selection.py", "fit = _finish(wv, mdl, idx, *step1[mdl], V=V, omega_source=src)",
     "fit = _finish(wv, mdl, idx, *step1[mdl])",
     ["tests/gmwm/test_rules_gmwm.py", "-k", "nested"]),
    ("heading: angle error integrated without dt",
     "src/fogdrift/evaluation/heading.py", "        return np.cumsum(resid) * (dt_s / S_PER_H)\n",
     "        return np.cumsum(resid) / S_PER_H\n",
     ["tests/evaluation/test_rules_evaluation.py", "-k", "ramp_at_dt"]),
    ("heading: horizons taken in samples, not seconds",
     "src/fogdrift/evaluation/heading.py", "        H = int(round(h / dt))\n", "        H = int(round(h))\n",
     ["tests/evaluation/test_rules_evaluation.py", "-k", "ramp_at_dt"]),
    ("heading: origin spacing passed to the non-overlapping count in samples",
     "src/fogdrift/evaluation/heading.py", "horizon_s=h, step_s=step * dt,", "horizon_s=h, step_s=step,",
     ["tests/evaluation/test_rules_evaluation.py", "-k", "overlapping_origins_at_dt"]),
    ("heading: a NaN error not counted as worse",
     "src/fogdrift/evaluation/heading.py", "int(np.sum(~(ei <= ebi)))", "int(np.sum(ei > ebi))",
     ["tests/evaluation/test_rules_evaluation.py", "-k", "nan_forecast"]),
    ("judge: a row without counts judged on all (overlapping) origins",
     "src/fogdrift/evaluation/verdicts.py", "        n = independent_origins(row.n_origins, step_s, row.horizon_s)\n",
     "        n = row.n_origins\n",
     ["tests/evaluation/test_rules_evaluation.py", "-k", "row_without_counts"]),
    ("headline: a diverged horizon not counted as worsening",
     "src/fogdrift/evaluation/verdicts.py", "            elif jd.worsens:\n",
     "            elif jd.outcome == \"worsens\":\n",
     ["tests/evaluation/test_rules_evaluation.py", "-k", "mixed"]),
    ("artefact check: ADEV claim read at tau = 1/f",
     "src/fogdrift/evaluation/artefacts.py", "claims = {f: ratio_at(ALLAN_PEAK / f) for f in freqs}",
     "claims = {f: ratio_at(1.0 / f) for f in freqs}",
     ["tests/evaluation/test_rules_evaluation.py", "-k", "artefact_adev"]),
    ("artefact check: ADEV ratio interpolated on m instead of tau",
     "src/fogdrift/evaluation/artefacts.py", "    lt = np.log(a.tau_s)\n", "    lt = np.log(a.tau_s / dt)\n",
     ["tests/evaluation/test_rules_evaluation.py", "-k", "artefact_adev"]),
    ("decade tau grid drops m_max when it is a 1-2-5 value",
     "src/fogdrift/allan/grid.py", "            m = m[m <= m_max]\n", "            m = m[m < m_max]\n",
     ["tests/test_rules_table_edges.py", "-k", "decade"]),
    ("Earth-rate rule on the sum of the axis means, not the vector length",
     "src/fogdrift/plausibility.py", "and float(np.linalg.norm(means)) * factor < EARTH_FRACTION",
     "and abs(float(np.sum(means))) * factor < EARTH_FRACTION",
     ["tests/test_rules_table_edges.py", "-k", "quiet_triad"]),
    ("GMWM batch row: fit_n_points counts the excluded scales too",
     "src/fogdrift/fleet/commands.py", "fit_n_points=int(len(axis.wvar.scale_s) - len(sel.excluded)))",
     "fit_n_points=int(len(axis.wvar.scale_s)))",
     ["tests/test_rules_table_edges.py", "-k", "gmwm_batch"]),
]
if __name__ == "__main__":
    BUGS[:] = H_TESTS24  # main() above ran the earlier entries; now this block's, with the same apply/run/restore
    main()


# H-tests36 (issue 36: the holes of "Why" 7 and the wall-clock / lock / process rules of "Why" 6).  Each entry is
# one plausible one-line bug and the test that must fail on it; every one was applied by hand when its test was
# written and passed the tests that existed then (the commit messages say which).
H_TESTS36 = [
    ("consistency: the ramp variance loses the square on its slope",
     "src/fogdrift/evaluation/consistency.py", "        return (r * (h * h / 2.0 + h * T / 2.0)) ** 2\n",
     "        return r * (h * h / 2.0 + h * T / 2.0) ** 2\n",
     ["tests/evaluation/test_consistency.py", "-k", "ramp_closed_form_by_hand_at_a_slope"]),
    ("unit table: K in m/s/h/sqrt(h) divided by 3600, not 3600^1.5",
     "src/fogdrift/export/conversions.py", '("K", "m/s/h/sqrt(h)"): ("accel", 1.0 / S_PER_H**1.5)',
     '("K", "m/s/h/sqrt(h)"): ("accel", 1.0 / S_PER_H)', ["tests/export/test_unit_table.py"]),
    ("unit table: R in m/s/h^2 divided by 3600, not 3600^2",
     "src/fogdrift/export/conversions.py", '("R", "m/s/h^2"): ("accel", 1.0 / S_PER_H ** 2)',
     '("R", "m/s/h^2"): ("accel", 1.0 / S_PER_H)', ["tests/export/test_unit_table.py"]),
    ("export: an accelerometer's K in m/s^2/sqrt(h) (what allan writes) taken as m/s^2/sqrt(s)",
     "src/fogdrift/export/conversions.py", '("K", "m/s^2/sqrt(h)"): ("accel", 1.0 / 60.0)',
     '("K", "m/s^2/sqrt(h)"): ("accel", 1.0)',
     ["tests/export/test_export.py", "-k", "fogdrift_allan_writes_for_an_accelerometer"]),
    ("S term: every harmonic fitted at the fundamental's power",
     "src/fogdrift/noise/identify.py", "    lines = tuple(periodic.lines) if periodic is not None else ()\n",
     "    lines = tuple((f, 1.0) for f, _ in periodic.lines) if periodic is not None else ()\n",
     ["tests/noise/test_noise_periodic.py", "-k", "sawtooth_fundamental"]),
    ("GMWM batch row (through fogdrift batch): fit_n_points counts the excluded scales too",
     "src/fogdrift/fleet/commands.py", "fit_n_points=int(len(axis.wvar.scale_s) - len(sel.excluded)))",
     "fit_n_points=int(len(axis.wvar.scale_s)))", ["tests/fleet/test_fleet.py", "-k", "batch_noise_row_counts"]),
    ("progress lines: no quiet start",
     "src/fogdrift/cli/_app.py", "            if now - self._t0 < QUIET_S:\n", "            if False:\n",
     ["tests/cli/test_progress_piped.py", "-k", "quiet_start_a_short"]),
    ("progress lines: the still-running line only after more than HEARTBEAT_S",
     "src/fogdrift/cli/_app.py", "and now - self._t_last >= HEARTBEAT_S", "and now - self._t_last > HEARTBEAT_S",
     ["tests/cli/test_progress_piped.py", "-k", "still_running_line_comes"]),
    ("watchdog: ends the process in the middle of a shielded block (a batch's cleanup)",
     "src/fogdrift/interrupt.py", "if _wait_for_shields(SHIELD_MAX_S) and self._done.wait(self.grace_s):",
     "if False and self._done.wait(self.grace_s):", ["tests/test_interrupt.py", "-k", "shielded"]),
    ("watchdog exit (OutputDir.abort) leaves the folder's lock file",
     "src/fogdrift/output.py", "                    self._end()\n            self._folder_lock.release()\n",
     "                    self._end()\n", ["tests/test_output_lock.py", "-k", "watchdogs_exit"]),
    ("batch: a Ctrl-C cuts into the local cluster's start (its workers outlive the batch)",
     "src/fogdrift/fleet/runner.py", "            with _sigint_blocked_for_children(), interrupt.shielded():\n",
     "            with _sigint_blocked_for_children():\n",
     ["tests/fleet/test_fleet_interrupt.py", "-k", "shielded"]),
    ("batch: an interrupted batch's cleanup not shielded from the watchdog",
     "src/fogdrift/fleet/runner.py", "        with interrupt.shielded() if interrupted else contextlib.nullcontext():\n",
     "        with contextlib.nullcontext():\n", ["tests/fleet/test_fleet_interrupt.py", "-k", "shielded"]),
]
if __name__ == "__main__":
    BUGS[:] = H_TESTS36
    main()


# H-lm (issue 35 deliverable 2: the compiled GMWM solver, gmwm/solver.py).  Each entry is one plausible one-line slip
# in the port of SciPy's trust-region-reflective least squares and the test that must fail on it; each was applied
# by hand when tests/gmwm/test_gmwm_solver.py was written (the first two passed its first version: its far starts and the
# budget-by-budget path to an active bound were added for them).
H_TESTS35 = [
    ("GMWM solver: Levenberg-Marquardt parameter not carried between trust-region tries",
     "src/fogdrift/gmwm/solver.py", "            alpha *= delta / delta_new\n", "            alpha *= 1.0\n",
     ["tests/gmwm/test_gmwm_solver.py"]),
    ("GMWM solver: the step that hits a bound not reflected",
     "src/fogdrift/gmwm/solver.py", "            r_h[i] *= -1\n", "            r_h[i] *= 1\n",
     ["tests/gmwm/test_gmwm_solver.py"]),
    ("GMWM solver: Jacobian scale not kept at its running maximum",
     "src/fogdrift/gmwm/solver.py", "            scale_inv = np.maximum(np.sqrt(_col_sumsq(J)), scale_inv)\n",
     "            scale_inv = np.sqrt(_col_sumsq(J))\n",
     ["tests/gmwm/test_gmwm_solver.py"]),
    ("GMWM solver: no step back from the bound (theta = 1)",
     "src/fogdrift/gmwm/solver.py", "        theta_step = th if th > 0.995 else 0.995\n", "        theta_step = 1.0\n",
     ["tests/gmwm/test_gmwm_solver.py"]),
    ("GMWM solver: step to the bound by the nearer instead of the farther bound",
     "src/fogdrift/gmwm/solver.py", "            steps[i] = _pmax((lb[i] - x[i]) / s[i], (ub[i] - x[i]) / s[i])\n",
     "            steps[i] = min((lb[i] - x[i]) / s[i], (ub[i] - x[i]) / s[i])\n",
     ["tests/gmwm/test_gmwm_solver.py"]),
    ("GMWM solver: scaled step not cut at the bound",
     "src/fogdrift/gmwm/solver.py", "    p_h = p_h * p_stride\n", "    p_h = p_h * 1.0\n",
     ["tests/gmwm/test_gmwm_solver.py"]),
    ("GMWM solver: trust region never grown",
     "src/fogdrift/gmwm/solver.py", "                delta_new *= 2.0\n", "                delta_new *= 1.0\n",
     ["tests/gmwm/test_gmwm_solver.py"]),
    ("GMWM solver: Coleman-Li scaling towards the wrong bound",
     "src/fogdrift/gmwm/solver.py", "            v[i] = x[i] - lb[i]\n", "            v[i] = ub[i] - x[i]\n",
     ["tests/gmwm/test_gmwm_solver.py"]),
]
# Issue 35 item 5: the fused exact-ADEV kernel (src/fogdrift/allan/_kernels.py, _fused2_py and its helpers).
# Each entry is one plausible one-line bug in the carried block sum or the window bounds; tests/allan/test_allan_fused.py
# compares the kernel with the angle-array kernel bit for bit, so every one fails it (applied by hand: all caught).
H_TESTS35_FUSED = [
    ("fused ADEV: the carried block sum misses the last sample before a window",
     "src/fogdrift/allan/_kernels.py", "        for i in range(((x - 1) // block) * block, x - 1):\n",
     "        for i in range(((x - 1) // block) * block, x - 2):\n", ["tests/allan/test_allan_fused.py"]),
    ("fused ADEV: a long-lag stream's carry starts one point early",
     "src/fogdrift/allan/_kernels.py", "            runs[l] = _run_before(y, mu, block, min(k0 + lags[l], n_phase))\n",
     "            runs[l] = _run_before(y, mu, block, min(k0 + lags[l] - 1, n_phase))\n",
     ["tests/allan/test_allan_fused.py"]),
    ("fused ADEV: the last start index of a long-lag tau dropped",
     "src/fogdrift/allan/_kernels.py",
     "                    kend = min(k0 + block, n_phase - 2 * m)\n                    if kend <= k0:\n",
     "                    kend = min(k0 + block, n_phase - 2 * m - 1)\n                    if kend <= k0:\n",
     ["tests/allan/test_allan_fused.py"]),
    ("fused ADEV: the near window not refilled in the record's last block",
     "src/fogdrift/allan/_kernels.py", "                if k0 + block < n_phase:\n",
     "                if k0 + 2 * block < n_phase:\n", ["tests/allan/test_allan_fused.py"]),
]
if __name__ == "__main__":
    BUGS[:] = H_TESTS35 + H_TESTS35_FUSED
    main()
