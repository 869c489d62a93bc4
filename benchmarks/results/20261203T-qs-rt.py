"""Round trip of bench_wrinkle_fit at the automatic (quasi-static) speed, without the gradient check.
Run: python 20261203T-qs-rt.py OUT.json [NOISE_SEED, default 16; the argument since 2026-12-07]. 20261203T-qs-rt-before-moves.json: at a78b477 (before the fit moved to a better probe); 20261203T-qs-rt.json: at 8343669.
"""
import dataclasses, json, sys, time
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, HELD_OUT, OVERRIDES, make_sections, moment_error, held_out_rms
from jaxform import cases
from jaxform.calibrate import wrinkle_fit
from jaxform.materials import VoceBending

out = sys.argv[1]
case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
print("speed", case.process.speed, flush=True)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
truth = VoceBending(*TRUTH)
rng = np.random.default_rng(int(sys.argv[2]) if len(sys.argv) > 2 else 16)
sections, _ = make_sections(truth_case, FIT_LINES, rng)
held, held_clean = make_sections(truth_case, HELD_OUT, rng)
t0 = time.perf_counter()
def stamp(p):
    print(f"[{time.perf_counter() - t0:.0f} s] {p.stage}: {p.forming_runs} runs, best loss {p.loss:.4g} q={np.round(p.q, 3)}", flush=True)
fit = wrinkle_fit.fit_wrinkles(case, sections, callback=stamp, gradient_check=False)
wall = time.perf_counter() - t0
err = moment_error(fit.law, truth, fit.kappa_reach)
err0 = moment_error(fit.law_initial, truth, fit.kappa_reach)
rms0, rms0c = held_out_rms(case, fit.law_initial, held, held_clean)
rms1, rms1c = held_out_rms(case, fit.law, held, held_clean)
res = {"speed_m_per_s": case.process.speed, "fit": fit.as_dict(), "fit_wall_s": wall, "moment_err_fitted": err,
       "moment_err_start": err0, "kappa_reach": fit.kappa_reach,
       "held_out_rms_mm": {"start": 1e3 * rms0, "fitted": 1e3 * rms1, "start_vs_clean": 1e3 * rms0c,
                           "fitted_vs_clean": 1e3 * rms1c, "improvement": rms0 / rms1}}
json.dump(res, open(out, "w"), indent=1, default=str)
print(json.dumps({k: v for k, v in res.items() if k != "fit"}, indent=1, default=str))
print("fit", fit.values, fit.converged, fit.reason, fit.forming_runs)
