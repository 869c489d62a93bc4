"""The same preset at two speeds with mass-proportional damping (forming.simulate's ``damping``,
1/s: a force -c m v on every node): does damping the flange's snaps give the soft law a quasi-static
answer? Compared by forming.quasi_static_check.

    python damped.py OUT.jsonl PRESET SIZE_MM DAMPING[,DAMPING...] [SPEEDS, default 62.5,31.25]

One JSON line per damping; exits 1 if a run failed."""
import json
import sys

from jaxform import cases, forming
from jaxform.forming.summary import half_turn_symmetry

out, name, size = sys.argv[1], sys.argv[2], float(sys.argv[3])
damps = [float(c) for c in sys.argv[4].split(",")]
speeds = [float(v) for v in (sys.argv[5] if len(sys.argv) > 5 else "62.5,31.25").split(",")]
failed = False
for c in damps:
    runs, rungs = [], []
    for v in speeds:
        case = cases.apply_overrides(cases.with_element_size(cases.load(name), size * 1e-3), [f"process.speed_mm_per_s={v}"])
        r = forming.simulate(case, catch=True, damping=c)
        s, ht = r.summary, half_turn_symmetry(r)
        h = r.history
        rung = {"speed_mm_per_s": v, "complete": r.complete, "reason": r.reason, "wall_s": r.wall_time_s,
                "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"],
                "draw_in_edge_mid_mm": 1e3 * s["draw_in"]["edge_mid_m"], "flange_wrinkles": s["flange_wrinkles"],
                "half_turn_deviation": None if ht is None else ht["deviation"],
                "damping_work_end_J": float(h["damping_work_J"][-1]),
                "boundary_work_end_J": float(h["boundary_work_J"][-1])}
        failed |= not r.complete
        print(f"[damped] {name} {size:g} mm, damping {c:g} 1/s, {v:g} mm/s: {rung}", flush=True)
        runs.append(r)
        rungs.append(rung)
    q = forming.quasi_static_check(runs[0], runs[1])
    q = {k: q.get(k) for k in ("speed_mm_per_s", "half_speed_mm_per_s", "shear_p95_deg", "draw_in_edge_mid_rel",
                               "flange_wrinkles", "quasi_static", "reason")}
    print(f"[damped]   {q}", flush=True)
    with open(out, "a") as f:
        f.write(json.dumps({"preset": name, "size_mm": size, "damping_per_s": c, "rungs": rungs, "check": q}) + "\n")
sys.exit(1 if failed else 0)
