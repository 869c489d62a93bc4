"""Does a batch of several laws in one program (vmap over BATCH_AXIS, ``width``) run faster per law
than one law a program on a CPU core? 4 laws at woven Case A h (m), one worker, widths 1, 2, 4
(one core pinned by the caller: taskset -c 0), nothing else running. The sections are those of the
round trip (bench_wrinkle_fit: its hidden law, 0.05 mm noise).
Run: taskset -c 0 python 20261204T-fit-width.py 8e-3 OUT.json"""
import dataclasses, importlib.util, json, sys, time
import numpy as np
B = str(__import__("pathlib").Path(__file__).resolve().parents[1])
spec = importlib.util.spec_from_file_location("bw", B + "/bench_wrinkle_fit.py"); bw = importlib.util.module_from_spec(spec); spec.loader.exec_module(bw)
from jaxform import cases
from jaxform.calibrate import section_runs, transforms
h = float(sys.argv[1])
case = cases.resolve("case-a-woven-nlbm", element_size=h, overrides=bw.OVERRIDES)
truth = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=bw.TRUTH))
secs, _ = bw.make_sections(truth, bw.FIT_LINES, np.random.default_rng(16))
out = {"element_size_mm": h * 1e3, "cores": section_runs.cores()}
ys = {}
for width in (1, 2, 4):
    R = section_runs.SectionRuns(case, secs, "voce", 1, 0.0, width, 1, 1)
    q0 = transforms.q_from_law(R.law0, "voce")
    t = time.perf_counter(); R.evaluate([q0]); out[f"compile_and_run_width_{width}_s"] = time.perf_counter() - t
    qs = [q0 + d for d in (0.01, 0.02, 0.03, 0.04)]
    t = time.perf_counter(); ev = R.evaluate(qs); out[f"four_runs_width_{width}_s"] = time.perf_counter() - t
    out[f"ok_{width}"] = [bool(e[2]) for e in ev]
    ys[width] = np.array([e[0] for e in ev])
    print(out, flush=True)
for w in (2, 4):
    out[f"speedup_width_{w}"] = out["four_runs_width_1_s"] / out[f"four_runs_width_{w}_s"]
    out[f"max_abs_diff_width_{w}_vs_1_m"] = float(np.nanmax(np.abs(ys[w] - ys[1])))
json.dump(out, open(sys.argv[2], "w"), indent=1)
print(out)
