"""How rough the round trip's loss is at the law the seed-17 fit moved to (chi-square 118 in its run):
the same section chi-square (`truth-and-fit.py`'s program) there and at steps of 1e-4, 1e-3 and 1e-2
along each log parameter.

    python roughness.py 17"""
import dataclasses, math, sys, time
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[2]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, OVERRIDES, make_sections
from jaxform import cases
from jaxform.calibrate import sections as sec_mod
from jaxform.calibrate.section_runs import SectionRuns, parallel, start_law
from jaxform.calibrate.transforms import q_from_law
from jaxform.calibrate.wrinkle_fit import SPAN
from jaxform.materials import VoceBending
seed = int(sys.argv[1])
case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
rng = np.random.default_rng(seed)
sections, _ = make_sections(truth_case, FIT_LINES, rng)
bw, wk = parallel(None, None, 6)
runs = SectionRuns(case, sections, "voce", 1, 0.1 * case.ply_thickness, bw, 1, wk,
                   step_b_init=SPAN * math.exp(q_from_law(start_law(case), "voce")[0]))
R = sec_mod.weights(sections, sec_mod.NOISE, float(case.element_size))
meas = np.concatenate([s.amplitude for s in sections])
qt = np.asarray(q_from_law(VoceBending(*TRUTH), "voce"), float)
qx = np.array([-8.208021400870726, -4.429896704317465, 3.8964534215809024])
qs = {"exact118": qx}
for k, e in enumerate(np.eye(3)):
    for h in (1e-4, 1e-3, 1e-2):
        qs[f"+{h:g}e{k}"] = qx + h * e
t0 = time.perf_counter()
evs = runs.evaluate(list(qs.values()))
for (k, q), (y, v, ok, reach) in zip(qs.items(), evs):
    r = R @ np.where(v, y - meas, 0.0)
    print(k, np.round(q, 3), "chi2", round(float(r @ r), 1) if ok else "fail", flush=True)
print("wall", time.perf_counter() - t0)
