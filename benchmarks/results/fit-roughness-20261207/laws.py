"""The section chi-square of the 8 mm round trip's data (`../20261203T-qs-rt.py`, noise seed SEED) at
chosen laws, each run by the fit's own program (its SectionRuns: the step built for the box's
stiffest law, the perfect blank), the data drawn as the round trip draws them.

    python laws.py SEED line    the fit's law (seed 16: that of qs-rt.json; 17: the law its sigma check
                                moved to, rounded to 3 decimals), the hidden law, the points between
                                (truth-and-fit-{16,17}.log; the first row is labelled fit16 in both)
    python laws.py 17 rough     the exact law seed 17's fit moved to (chi-square 118 in its run) and
                                steps of 1e-4, 1e-3, 1e-2 along each log parameter (roughness-17.log)"""
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
seed, mode = int(sys.argv[1]), sys.argv[2]
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
if mode == "line":
    fit = np.array([-8.343645716357994, -4.103530901590972, 4.085455322584545]) if seed == 16 else np.array([-8.208, -4.430, 3.896])
    qs = {"fit16": fit, "truth": qt, "probe17": np.array([-8.208, -4.430, 3.896])}
    for a in (0.25, 0.5, 0.75):
        qs[f"line{a}"] = fit + a * (qt - fit)
    qs["truth_ratio_fit"] = np.array([qt[0], fit[1], qt[2]])
else:
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
