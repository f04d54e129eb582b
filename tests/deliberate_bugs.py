"""Deliberate bugs for issue 14's holes outside the pipeline: apply one (an exact one-line replacement), run the
test that guards it, restore the file; prints one markdown row per bug (docs/testing.md).

    .venv/bin/python tests/deliberate_bugs.py        # needs a clean src/ (refuses otherwise); ~5 min on 2 cores

Not collected by pytest (no ``test_`` prefix): it edits the source, so it must not run inside the suite.
"""
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
BUGS = [
    ("symmetric boundary: half-sample instead of whole-sample reflection (numba kernel)",
     "src/fogdrift/lifting/_numba.py", "        j = p - j\n", "        j = p - j - 1 if p - j - 1 >= 0 else 0\n",
     ["tests/test_lifting_symmetric.py"]),
    ("symmetric boundary: half-sample reflection (NumPy backend)",
     "src/fogdrift/lifting/_kernels.py", "    return p - j if j > m - 1 else j\n", "    return p - j - 1 if j > m - 1 else j\n",
     ["tests/test_lifting_symmetric.py"]),
    ("K conversion factor 60 -> 61 (deg/h^1.5)",
     "src/fogdrift/noise/terms.py", '"K [deg/h^1.5]", 60.0,', '"K [deg/h^1.5]", 61.0,',
     ["tests/test_noise.py", "-k", "single_term"]),
    ("p0 divides by |y_hat| instead of |y|",
     "src/fogdrift/metrics.py", "    ay = np.abs(a)\n", "    ay = np.abs(b)\n",
     ["tests/test_metrics.py"]),
    ("grey-Elman eq. (13): restore subtracts half the previous AGO sum",
     "src/fogdrift/models/elman.py", "return self.x1_mean_ + self.x1_std_ * out - x1_prev  # eq. (13)",
     "return self.x1_mean_ + self.x1_std_ * out - 0.5 * x1_prev  # eq. (13)",
     ["tests/test_elman.py", "-k", "eq13 or restores"]),
    ("EDF flicker PM (alpha = +1): (N-1)/(2m) -> (N-1)/m",
     "src/fogdrift/allan/ci.py", "np.log((N - 1) / (2 * mm)) * np.log(", "np.log((N - 1) / mm) * np.log(",
     ["tests/test_allan_ci.py"]),
    ("Elman normalisation from training + validation data (leakage)",
     "src/fogdrift/models/elman.py", "        self.x_mean_ = float(np.mean(s_fit))\n",
     "        self.x_mean_ = float(np.mean(np.concatenate([s_fit, s_va])))\n",
     ["tests/test_elman.py", "-k", "validation_block"]),
    ("report figures saved blank (figure cleared before saving)",
     "src/fogdrift/report/figures.py", "            fig.savefig(tmp, dpi=DPI)", "            fig.clf(); fig.savefig(tmp, dpi=DPI)",
     ["tests/test_golden.py", "-k", "figures_have_content"]),
    # H-structure
    ("out-of-core Allan: the old copied tail (auto alpha from the slopes, without the long-tau EDF rule)",
     "src/fogdrift/allan/chunked.py", "                            noise_alpha=noise_alpha)\n",
     "                            noise_alpha=resolve_alpha(noise_alpha, m * source.dt_s, sums / (2.0 * m**2 * (n - 2 * m + 1)), "
     "slopes=get_statistic(\"adev\").dev_slopes, candidates=IEEE952_ALPHAS)[0] if noise_alpha == \"auto\" else noise_alpha)\n",
     ["tests/test_allan_result_shared.py", "-k", "quantization_long_tau"]),
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
