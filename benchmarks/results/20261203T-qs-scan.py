"""Loss along the straight log-space line from the 500 mm/s round trip's wrong law to the truth, at a given speed.
Run: python 20261203T-qs-scan.py auto 20261203T-qs-scan.json (a78b477; 11 runs at 62.5 mm/s, one core). The 500 mm/s figures of the same line are in the module docstring of jaxform.calibrate.wrinkle_fit.
"""
import dataclasses, json, sys, time
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, make_sections, OVERRIDES
from jaxform import cases
from jaxform.calibrate import wrinkle_fit
from jaxform.calibrate.transforms import q_from_law
from jaxform.materials import VoceBending

speed = sys.argv[1]  # "auto" or e.g. 0.5
out = sys.argv[2]
ov = OVERRIDES + (() if speed == "auto" else (f"process.speed_mm_per_s={speed}",))
case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=ov)
print("speed", case.process.speed, flush=True)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
t0 = time.time()
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
print("truth sections", time.time() - t0, flush=True)
wrong = VoceBending(2.2529047782882117e-05, 0.008426997810602188, 16.857505798339844)
qa, qb = q_from_law(wrong, "voce"), q_from_law(VoceBending(*TRUTH), "voce")
ts = np.linspace(0, 1, int(sys.argv[3]) if len(sys.argv) > 3 else 11)
res = []
for t in ts:
    t1 = time.time()
    l, _ = wrinkle_fit.section_loss(case, sections, [qa + t * (qb - qa)])
    res.append(float(l[0]))
    print(f"t={t:.2f} loss={l[0]:.1f} ({time.time()-t1:.0f} s)", flush=True)
    json.dump({"speed": speed, "t": ts.tolist(), "loss": res}, open(out, "w"))
