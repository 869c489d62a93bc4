"""The round trip's global phase with more starts (today's runs): the section loss of the data of
20261203T-qs-rt.py at the starting law and at the Latin hypercube fit_wrinkles draws for n_starts = 8
(its default) and 16, in the same box (wrinkle_fit.START_HALF_WIDTH around the preset's law). Does a
wider global phase start in the truth's basin (the truth scores 80.9, the stalled fit 528.7)?
Run: python 20261205T-qs-rt-starts.py OUT.json (nothing else running; about 12 min)."""
import dataclasses, json, sys, time
import numpy as np
from scipy.stats.qmc import LatinHypercube
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, OVERRIDES, make_sections
from jaxform import cases
from jaxform.calibrate import wrinkle_fit
from jaxform.calibrate.section_runs import SectionRuns
from jaxform.calibrate.transforms import q_from_law

case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
q0 = q_from_law(SectionRuns(case, sections, "voce", 1, 0.0, 1, 1).law0, "voce")
lo, hi = wrinkle_fit._bounds(q0, "voce")
half = np.array(wrinkle_fit.START_HALF_WIDTH[:3])
sets = {n: list(np.clip(q0 + (2.0 * LatinHypercube(d=3, seed=0).random(n - 1) - 1.0) * half, lo, hi)) for n in (8, 16)}
pts = [q0] + sets[8] + sets[16]
t0 = time.perf_counter()
losses, _ = wrinkle_fit.section_loss(case, sections, pts)
out = {"q0": q0.tolist(), "start_loss": float(losses[0]),
       "n8": [{"q": q.tolist(), "loss": float(l)} for q, l in zip(sets[8], losses[1:8])],
       "n16": [{"q": q.tolist(), "loss": float(l)} for q, l in zip(sets[16], losses[8:])], "wall_s": time.perf_counter() - t0}
print(json.dumps(out, indent=1))
json.dump(out, open(sys.argv[1], "w"), indent=1)
