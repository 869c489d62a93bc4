"""Loss around the truth at the automatic speed: steps in log B_init and log kappa0.
Run: python 20261203T-qs-valley.py 20261203T-qs-valley.json (8343669).
"""
import dataclasses, json, sys, time
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, make_sections, OVERRIDES
from jaxform import cases
from jaxform.calibrate import wrinkle_fit
from jaxform.calibrate.transforms import q_from_law
from jaxform.materials import VoceBending
case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
qt = q_from_law(VoceBending(*TRUTH), "voce")
pts = {f"{n} {d:+g}": qt + d * np.eye(3)[i] for i, n in ((0, "B_init"), (2, "kappa0")) for d in (-0.1, -0.03, 0.03, 0.1)}
res = {}
for k, q in pts.items():
    l, _ = wrinkle_fit.section_loss(case, sections, [q]); res[k] = float(l[0]); print(k, res[k], flush=True)
    json.dump(res, open(sys.argv[1], "w"), indent=1)
