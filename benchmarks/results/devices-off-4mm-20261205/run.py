"""Issue 13, done-when 5: the 4 mm woven Case A NLBM preset as shipped (automatic numerics: fibre
mass, contact stiffness and step, at the automatic 62.5 mm/s) against the same case and speed
without the fibre mass (true inertia, the step 0.75 x the shell's own), with the same contact
stiffness given (so the fibre mass is the only device that differs). Compared with the quasi-static
check's three figures (forming.quasi_static_check: shear map p95, edge mid-side draw-in, flange
wrinkle count), each run's energy balance (largest residual over the samples, against the
largest energy scale) and the last frame's mirror symmetry (summary.symmetry_error). Exit 1 if either
run is incomplete (the check then says why in its reason). Run: .venv/bin/python run.py OUT_DIR  (both cores, ~50 min)."""
import json
import sys
import time
from pathlib import Path

from jaxform import cases, forming

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from energy_balance import balance  # noqa: E402  (benchmarks/)
from jaxform.forming import rig
from jaxform.forming.summary import shear_mirror_odd, symmetry_error

out = Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)
case = cases.with_element_size(cases.load("case-a-woven-nlbm"), 4e-3)
model, _, _ = rig.build(case)
k = float(model.loads[0].params.stiffness)
off = cases.apply_overrides(case, ["numerics.fibre_mass_scaling=1", f"contact.penalty_stiffness_Pa_per_m={k}"])


rec = {"contact_stiffness_Pa_per_m": k}
res = {}
for name, c in (("shipped", case), ("fibre_mass_off", off)):
    t0 = time.time()
    r = forming.simulate(c, catch=True)
    s = r.summary
    res[name] = r
    rec[name] = {"wall_s": time.time() - t0, "complete": r.complete, "reason": r.reason,
                 "numerics": {kk: s["numerics"][kk] for kk in ("dt_s", "stable_dt_s", "n_steps", "fibre_mass_scaling",
                                                                 "fibre_mass_degree")},
                 "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"], "draw_in": s["draw_in"],
                 "flange_wrinkles": s["flange_wrinkles"], "energy_balance": balance(r),
                 "symmetry_last_frame": {"shear": symmetry_error(r.info.x0, r.fields["shear_angle"][-1],
                                                                 odd=shear_mirror_odd(c)),
                                         "deviation": symmetry_error(r.info.x0, r.fields["deviation"][-1])}}
    print(name, json.dumps(rec[name]), flush=True)
    (out / "devices-off.json").write_text(json.dumps(rec, indent=1))
rec["check"] = forming.quasi_static_check(res["shipped"], res["fibre_mass_off"])
print("check", json.dumps({kk: v for kk, v in rec["check"].items() if "per_frame" not in kk}), flush=True)
(out / "devices-off.json").write_text(json.dumps(rec, indent=1))
sys.exit(0 if all(r.complete for r in res.values()) else "run.py: a run is incomplete: see devices-off.json")
