"""The contacts' normal forces integrated backward (``contact.implicit_normal = true``,
jaxform.backward_normal) against the shipped explicit penalty: the same preset at the same mesh and
automatic speed, each with its automatic numerics (the implicit normal takes nothing from the step).
Compared with the quasi-static check's three figures (forming.quasi_static_check: shear map p95,
edge mid-side draw-in, flange wrinkle count), each run's energy balance, KE/IE, wall time and
steps. Exit 1 if a run is incomplete.
Run: .venv/bin/python run.py PRESET SIZE_MM OUT_DIR  (one core each run, one after the other)."""
import json
import sys
import time
from pathlib import Path

import numpy as np

from jaxform import cases, forming

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from energy_balance import balance  # noqa: E402  (benchmarks/)

name, mm, out = sys.argv[1], float(sys.argv[2]), Path(sys.argv[3])
out.mkdir(parents=True, exist_ok=True)
case = cases.with_element_size(cases.load(name), mm * 1e-3)
implicit = cases.apply_overrides(case, ["contact.implicit_normal=true"])


rec, res = {"preset": name, "element_size_mm": mm}, {}
for key, c in (("explicit", case), ("implicit", implicit)):
    t0 = time.time()
    r = forming.simulate(c, catch=True)
    s = r.summary
    res[key] = r
    rec[key] = {"wall_s": time.time() - t0, "complete": r.complete, "reason": r.reason,
                "numerics": {kk: s["numerics"].get(kk) for kk in ("dt_s", "stable_dt_s", "n_steps", "fibre_mass_scaling",
                                                                  "fibre_mass_degree", "contact_safety", "step_budget",
                                                                  "dt_governed_by", "step_choice", "max_penetration_ply")},
                "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"], "draw_in": s["draw_in"],
                "flange_wrinkles": s["flange_wrinkles"], "energy_balance": balance(r),
                "history": {kk: np.asarray(r.history[kk]).tolist() for kk in ("t_s", "punch_force_N", "holder_force_N",
                                                                               "max_penetration_m") if kk in r.history}}
    print(key, json.dumps({kk: v for kk, v in rec[key].items() if kk != "history"}), flush=True)
    (out / "compare.json").write_text(json.dumps(rec, indent=1))
rec["check"] = forming.quasi_static_check(res["implicit"], res["explicit"])
print("check", json.dumps({kk: v for kk, v in rec["check"].items() if "per_frame" not in kk}), flush=True)
(out / "compare.json").write_text(json.dumps(rec, indent=1))
sys.exit(0 if all(r.complete for r in res.values()) else "run.py: a run is incomplete: see compare.json")
