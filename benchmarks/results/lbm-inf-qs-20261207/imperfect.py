"""Is the soft laws' missing quasi-static answer a branch chosen by rounding? The same preset at two
speeds from the same seeded imperfect blank (jaxform.calibrate.imperfections: a smooth random
out-of-plane field, tapered to 0 near the tools, `AMPLITUDE_MM` at its largest), compared by
forming.quasi_static_check (shear map p95 < 1 deg, edge draw-in < 2 %, the same flange wrinkles).

    python imperfect.py OUT.jsonl PRESET SIZE_MM AMPLITUDE_MM[,AMPLITUDE_MM...] [SPEEDS, default 62.5,31.25] [SEED, default 1]

Amplitude 0 is the perfect blank. One JSON line per amplitude; exits 1 if a run failed."""
import dataclasses
import json
import sys

import jax.numpy as jnp
import numpy as np

from jaxform import cases, forming
from jaxform.calibrate.imperfections import imperfections
from jaxform.forming.summary import half_turn_symmetry
from jaxform.contact import ToolLoad

out, name, size = sys.argv[1], sys.argv[2], float(sys.argv[3])
amps = [float(a) for a in sys.argv[4].split(",")]
speeds = [float(v) for v in (sys.argv[5] if len(sys.argv) > 5 else "62.5,31.25").split(",")]
seed = int(sys.argv[6]) if len(sys.argv) > 6 else 1
failed = False
for amp in amps:
    runs, rungs = [], []
    for v in speeds:
        case = cases.apply_overrides(cases.with_element_size(cases.load(name), size * 1e-3), [f"process.speed_mm_per_s={v}"])
        model, state, info = forming.build(case)
        if amp > 0:
            clearance = np.min([np.asarray(ld.gap(state.x, state.t, ls), float) for ld, ls in zip(model.loads, state.loads)
                                if isinstance(ld, ToolLoad)], axis=0)
            dz = jnp.asarray(imperfections(info.x0, seed + 1, amp * 1e-3, case.blank_size, clearance)[seed], state.x.dtype)
            state = dataclasses.replace(state, x=state.x + dz, u=state.u + dz.T)
        r = forming.run(forming.Rig(model, state, info), catch=True)
        s = r.summary
        ht = half_turn_symmetry(r)
        rung = {"speed_mm_per_s": v, "complete": r.complete, "reason": r.reason, "wall_s": r.wall_time_s,
                "n_steps": info.n_steps, "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"],
                "draw_in_edge_mid_mm": 1e3 * s["draw_in"]["edge_mid_m"], "flange_wrinkles": s["flange_wrinkles"],
                "half_turn_deviation": None if ht is None else ht["deviation"]}
        failed |= not r.complete
        print(f"[imperfect] {name} {size:g} mm, {amp:g} mm seed {seed}, {v:g} mm/s: {rung}", flush=True)
        runs.append(r)
        rungs.append(rung)
    c = forming.quasi_static_check(runs[0], runs[1])
    c = {k: c.get(k) for k in ("speed_mm_per_s", "half_speed_mm_per_s", "shear_p95_deg", "draw_in_edge_mid_rel",
                               "flange_wrinkles", "quasi_static", "reason")}
    print(f"[imperfect]   {c}", flush=True)
    with open(out, "a") as f:
        f.write(json.dumps({"preset": name, "size_mm": size, "amplitude_mm": amp, "seed": seed, "rungs": rungs,
                            "check": c}) + "\n")
sys.exit(1 if failed else 0)
