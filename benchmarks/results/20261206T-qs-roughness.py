"""How rough is the round trip's loss at the truth? The local fit with FIRST_STEP saw 137 -> 600
for a 0.001 change of log B_init near its end (20261206T-qs-local-step-new). Here the truth
(loss 81 at 8 mm smoothing) moved by +-0.001 and +-0.003 in log B_init and +-0.001 in log kappa0.
Run: python 20261206T-qs-roughness.py OUT.json (both cores, nothing else running; about 5 min)."""
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
t0 = time.perf_counter()
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
qt = q_from_law(VoceBending(*TRUTH), "voce")
pts = {f"B_init {d:+g}": qt + d * np.eye(3)[0] for d in (-0.003, -0.001, 0.001, 0.003)}
pts.update({f"kappa0 {d:+g}": qt + d * np.eye(3)[2] for d in (-0.001, 0.001)})
losses, _ = wrinkle_fit.section_loss(case, sections, list(pts.values()))
out = {k: {"q": list(map(float, q)), "loss": float(l)} for (k, q), l in zip(pts.items(), losses)}
out["wall_s"] = time.perf_counter() - t0
print(json.dumps(out, indent=1))
json.dump(out, open(sys.argv[1], "w"), indent=1)
if not np.all(np.isfinite(losses)):
    sys.exit(f"{sys.argv[0]}: a forming run failed (an infinite loss in the output)")
