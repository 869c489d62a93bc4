"""Why the round trip stalls at today's code (20261205T-qs-rt-stalled.log): the section loss of its
data (20261203T-qs-rt.py's: the hidden law's sections, rng 16) at the law where it stalled (528.7),
at the law where the 999-s run of 08a9017 ended (120.8 then) and at the truth, with today's runs.
Run: python 20261205T-qs-rt-stall-points.py OUT.json (nothing else running; about 4 min)."""
import dataclasses, json, sys, time
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, OVERRIDES, make_sections
from jaxform import cases
from jaxform.calibrate import wrinkle_fit
from jaxform.calibrate.transforms import q_from_law
from jaxform.materials import VoceBending

case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
pts = {"stalled (today's fit, 528.7)": [-8.344, -4.054, 4.085], "08a9017's fit (120.8 then)": [-8.339, -4.106, 4.071],
       "truth": q_from_law(VoceBending(*TRUTH), "voce").tolist()}
t0 = time.perf_counter()
losses, _ = wrinkle_fit.section_loss(case, sections, [np.array(q) for q in pts.values()])
out = {k: {"q": list(map(float, q)), "loss": float(l)} for (k, q), l in zip(pts.items(), losses)}
out["wall_s"] = time.perf_counter() - t0
print(json.dumps(out, indent=1))
json.dump(out, open(sys.argv[1], "w"), indent=1)
