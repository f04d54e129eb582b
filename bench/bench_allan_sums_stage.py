"""Usage: python bench/bench_allan_sums_stage.py FILE UNIT (a .npy is read at 100 Hz).

Allan stage of `fogdrift allan` per record: old (one allan_variance per grid/alpha + the plausibility floor's own)
vs new (AllanSums handed on), same process, interleaved; spectra precomputed (same for both)."""
import os, sys, time, numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "tests"))
from test_pipeline_allan_sums import _reference_curves
from fogdrift.io import load
from fogdrift.allan import allan_variance
from fogdrift.noise.spectral import analyse_spectrum
from fogdrift.noise.periodic import null_taus, periodic_content
from fogdrift.allan.ci import periodic_alpha
import fogdrift.pipeline as P
from fogdrift.plausibility import MAX_CHECK_SAMPLES
path, unit = sys.argv[1], sys.argv[2]
rec = load(path, unit=unit, **({"rate_hz": 100.0} if path.endswith(".npy") else {}))
cfg = P.AnalysisConfig().validate()
axes = [np.ascontiguousarray(rec.axis(n)) for n in rec.axis_names]
specs = [analyse_spectrum(x, rec.dt_s) for x in axes]
print(path, rec.rate_dph.shape, "periodic:", [periodic_content(s) is not None for s in specs])
def old():
    for x, s in zip(axes, specs):
        allan_variance(x[:MAX_CHECK_SAMPLES], rec.dt_s, taus="octave", estimator="overlapping")
        _reference_curves(x, rec.dt_s, cfg, s)
def new():
    for x, s in zip(axes, specs):
        sums = P.AllanSums(x[:MAX_CHECK_SAMPLES], rec.dt_s)
        m = sums.grid("octave"); sums.compute((m,)); sums.result(m)
        content = periodic_content(s)
        if not sums.holds(x, rec.dt_s, "adev", "overlapping"):
            sums = P.AllanSums(x, rec.dt_s)
        m_oct = sums.grid("octave"); grids = [m_oct]
        if content is not None:
            t = (m_oct * rec.dt_s).astype(float)
            grids.append(sums.grid(np.union1d(t, null_taus(content.periods_s, rec.dt_s, float(t[0]), float(t[-1])))))
        sums.compute(grids)
        r = sums.result(m_oct)
        for g in grids: sums.result(g, "auto")
old(); new()  # warm
for rep in range(3):
    for name, f in (("old", old), ("new", new)):
        l0 = os.getloadavg()[0]; t = time.perf_counter(); f(); dt = time.perf_counter() - t
        print(f"rep {rep} {name}: {dt:.3f} s (load {l0:.1f})", flush=True)
