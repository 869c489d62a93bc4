"""Is the round trip's rough loss float32 rounding? The loss at the truth, at the truth moved by 1e-6 in log B_init
(below float32's resolution of the law's own arithmetic: the same law, other rounding), and by +-0.001 and +-0.003,
each in one dtype. Run: python 20261206T-qs-rounding.py float32|float64 OUT.json (both cores, nothing else running)."""
import dataclasses, json, sys, time
dtype = sys.argv[1]
import jax
if dtype == "float64":
    jax.config.update("jax_enable_x64", True)
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, OVERRIDES, make_sections
from jaxform import cases
from jaxform.calibrate import wrinkle_fit
from jaxform.calibrate.transforms import q_from_law
from jaxform.materials import VoceBending
case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=list(OVERRIDES) + [f"numerics.dtype={dtype}"])
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
t0 = time.perf_counter()
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
t1 = time.perf_counter()
qt = q_from_law(VoceBending(*TRUTH), "voce")
pts = {f"B_init {d:+g}": qt + d * np.eye(3)[0] for d in (0.0, 1e-6, -1e-6, -0.003, -0.001, 0.001, 0.003)}
losses, _ = wrinkle_fit.section_loss(case, sections, list(pts.values()))
out = {"dtype": dtype, "sections_s": t1 - t0, "losses_s": time.perf_counter() - t1,
       "points": {k: {"q": list(map(float, q)), "loss": float(l)} for (k, q), l in zip(pts.items(), losses)}}
print(json.dumps(out, indent=1), flush=True)
json.dump(out, open(sys.argv[2], "w"), indent=1)
if not np.all(np.isfinite(losses)):
    sys.exit(f"{sys.argv[0]}: a forming run failed (an infinite loss in the output)")
