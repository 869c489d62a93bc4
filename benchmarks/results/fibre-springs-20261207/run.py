"""A preset at SIZE mm as shipped (automatic numerics, 62.5 mm/s), or with the fibre-mass factor FACTOR,
run with the jaxform first on sys.path (this tree, or an older commit's worktree through PYTHONPATH), its
FormingResult pickled to OUT/LABEL.pkl with the wall time, for ../step-cost-20261206/check.py.
Exit 1 if the run is incomplete. Run: .venv/bin/python run.py SIZE_MM OUT_DIR LABEL [PRESET [FACTOR]]
(both cores, nothing else running)."""
import dataclasses
import json
import pickle
import sys
import time
from pathlib import Path

import jaxform
from jaxform import cases, forming

size, out, label = float(sys.argv[1]), Path(sys.argv[2]), sys.argv[3]
out.mkdir(parents=True, exist_ok=True)
case = cases.with_element_size(cases.load(sys.argv[4] if len(sys.argv) > 4 else "case-a-woven-nlbm"), size * 1e-3)
if len(sys.argv) > 5:
    case = dataclasses.replace(case, fibre_mass_scaling=float(sys.argv[5]))
t0 = time.time()
r = forming.simulate(case, catch=True)
wall = time.time() - t0
s = r.summary
print(label, jaxform.__file__, json.dumps({"wall_s": wall, "complete": r.complete, "reason": r.reason,
                                           "n_steps": s["numerics"]["n_steps"], "fibre_mass": s["numerics"].get("fibre_mass_scaling"),
                                           "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"],
                                           "flange_wrinkles": s["flange_wrinkles"]}), flush=True)
with open(out / f"{label}.pkl", "wb") as f:
    pickle.dump({"wall_s": wall, "result": r}, f)
sys.exit(0 if r.complete else f"run.py: the run is incomplete ({r.reason})")
