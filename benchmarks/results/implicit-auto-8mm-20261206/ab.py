"""contact.implicit_normal = "auto" against the explicit contact (issue 13: a contact whose stiffness
does not dictate the step): each woven Case A preset at 8 mm as shipped (automatic numerics, 62.5
mm/s), run with contact.implicit_normal=false and with the default ("auto", which picks the backward
normal there), one after the other in one process; compared by forming.quasi_static_check (shear map
p95, edge draw-in, flange wrinkles), each run's energy balance, deepest penetration, half-turn
symmetry, steps and wall time. Appends a JSON line per preset to OUT.jsonl; exits 1 if a run failed.
Run: python ab.py OUT.jsonl PRESET[,PRESET...] [SIZE_MM, default 8]"""
import json
import sys
from pathlib import Path

from jaxform import cases, forming
from jaxform.forming.summary import half_turn_symmetry

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from energy_balance import balance  # noqa: E402  (benchmarks/)

out, presets = sys.argv[1], sys.argv[2].split(",")
size = float(sys.argv[3]) if len(sys.argv) > 3 else 8.0
failed = False
for name in presets:
    runs, rec = {}, {"preset": name, "size_mm": size}
    for label, keys in (("explicit", ["contact.implicit_normal=false"]), ("auto", [])):
        r = forming.simulate(cases.resolve(name, element_size=size * 1e-3, overrides=keys), catch=True)
        s, n = r.summary, r.summary["numerics"]
        ht = half_turn_symmetry(r)
        rec[label] = {"complete": r.complete, "reason": r.reason, "wall_s": r.wall_time_s,
                      "implicit_normal": n.get("contact_implicit_normal"), "n_steps": n["n_steps"], "dt_s": n["dt_s"],
                      "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"],
                      "draw_in_edge_mid_mm": 1e3 * s["draw_in"]["edge_mid_m"], "flange_wrinkles": s["flange_wrinkles"],
                      "max_penetration_ply": n.get("max_penetration_ply"),
                      "half_turn_deviation": None if ht is None else ht["deviation"], "energy_balance": balance(r)}
        failed |= not r.complete
        print(f"[ab] {name} {label}: {rec[label]}", flush=True)
        runs[label] = r
    c = forming.quasi_static_check(runs["auto"], runs["explicit"])
    rec["check"] = {k: v for k, v in c.items() if "per_frame" not in k}
    print(f"[ab] {name} check: {rec['check']}", flush=True)
    with open(out, "a") as f:
        f.write(json.dumps(rec) + "\n")
sys.exit(1 if failed else 0)
