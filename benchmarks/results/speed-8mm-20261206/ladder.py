"""Punch-speed ladder at 8 mm with the code of today (issue 13 / 16): each preset at a ladder of
speeds, every faster rung compared with its half AND with the slowest rung by
forming.quasi_static_check, plus the half-turn symmetry of each run.

    python ladder.py OUT.json PRESET[,PRESET...] [SPEEDS_MM_PER_S, default 250,125,62.5,31.25] [SIZE_MM, default 8]

Appends one JSON line per preset to OUT.json (a line is written when its ladder ends); exits 1 if a
run failed.
"""
import json
import sys

from jaxform import cases, forming
from jaxform.forming.summary import half_turn_symmetry

out, presets = sys.argv[1], sys.argv[2].split(",")
ladder = [float(v) for v in (sys.argv[3] if len(sys.argv) > 3 else "250,125,62.5,31.25").split(",")]
size = float(sys.argv[4]) if len(sys.argv) > 4 else 8.0
failed = False
for name in presets:
    runs, rungs = [], []
    for v in ladder:
        case = cases.apply_overrides(cases.with_element_size(cases.load(name), size * 1e-3),
                                     [f"process.speed_mm_per_s={v}"])
        r = forming.simulate(case, catch=True)
        s = r.summary
        ht = half_turn_symmetry(r)
        rung = {"speed_mm_per_s": v, "complete": r.complete, "reason": r.reason, "wall_s": r.wall_time_s,
                "n_steps": r.info.n_steps, "dt_s": r.info.dt, "max_ke_ie": s["max_ke_ie"],
                "max_shear_deg": s["max_shear_angle_deg"], "draw_in_edge_mid_mm": 1e3 * s["draw_in"]["edge_mid_m"],
                "flange_wrinkles": s["flange_wrinkles"],
                "half_turn_deviation": None if ht is None else ht["deviation"]}
        failed |= not r.complete
        print(f"[ladder] {name} {size:g} mm {v:g} mm/s: {rung}", flush=True)
        runs.append(r)
        rungs.append(rung)
    checks = []
    for i in range(len(ladder) - 1):
        for j in sorted({i + 1, len(ladder) - 1}):
            c = forming.quasi_static_check(runs[i], runs[j])
            c = {k: c.get(k) for k in ("speed_mm_per_s", "half_speed_mm_per_s", "shear_p95_deg",
                                       "draw_in_edge_mid_rel", "flange_wrinkles", "quasi_static", "reason")}
            print(f"[ladder]   {c}", flush=True)
            checks.append(c)
    with open(out, "a") as f:
        f.write(json.dumps({"preset": name, "size_mm": size, "rungs": rungs, "checks": checks}) + "\n")
sys.exit(1 if failed else 0)
