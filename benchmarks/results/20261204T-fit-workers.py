"""Do two threads of the fit's runs use a CPU's two cores? 4 laws at woven Case A h (m), workers 1 vs 2, nothing else running.
Run: python 20261204T-fit-workers.py 8e-3 OUT.json"""
import json, sys, time
import numpy as np
B = str(__import__("pathlib").Path(__file__).resolve().parents[1])
import importlib.util
spec = importlib.util.spec_from_file_location("bw", B + "/bench_wrinkle_fit.py"); bw = importlib.util.module_from_spec(spec); spec.loader.exec_module(bw)
import dataclasses
from jaxform import cases
from jaxform.calibrate import section_runs, transforms
h = float(sys.argv[1])
case = cases.resolve("case-a-woven-nlbm", element_size=h, overrides=bw.OVERRIDES)
truth = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=bw.TRUTH))
secs, _ = bw.make_sections(truth, bw.FIT_LINES, np.random.default_rng(16))
out = {"element_size_mm": h * 1e3, "cores": section_runs.cores()}
for workers in (1, 2):
    R = section_runs.SectionRuns(case, secs, "voce", 1, 0.0, 1, 1, workers)
    q0 = transforms.q_from_law(R.law0, "voce")
    t = time.perf_counter(); R.evaluate([q0]); out[f"warm_{workers}"] = time.perf_counter() - t
    qs = [q0 + d for d in (0.01, 0.02, 0.03, 0.04)]
    t = time.perf_counter(); ev = R.evaluate(qs); out[f"four_runs_workers_{workers}_s"] = time.perf_counter() - t
    out[f"ok_{workers}"] = [bool(e[2]) for e in ev]
    out[f"y_{workers}"] = [float(np.nanmean(e[0])) for e in ev]
    print(out, flush=True)
out["speedup"] = out["four_runs_workers_1_s"] / out["four_runs_workers_2_s"]
json.dump(out, open(sys.argv[2], "w"), indent=1)
print(out)
