"""Woven Case A NLBM at 8 mm, float32 against float64 (issue 13, done-when 6: where the float32 runs'
extra kinetic energy and asymmetry come from). Prints one JSON line: max KE/IE, edge mid-side and
corner draw-in, max shear, half-turn asymmetry, fibre-mass factor.
Run: [SIZE_MM=8] python run.py DTYPE [OVERRIDE ...]   (x64 is switched on in the process for either dtype)"""
import jax; jax.config.update("jax_enable_x64", True)
import json, sys
from jaxform import cases, forming
from jaxform.forming.summary import half_turn_symmetry
dtype, extra = sys.argv[1], sys.argv[2:]
c = cases.resolve("case-a-woven-nlbm", element_size=float(__import__("os").environ.get("SIZE_MM", "8")) * 1e-3, overrides=[f"numerics.dtype={dtype}", *extra])
r = forming.simulate(c, catch=True)
s = r.summary
print(json.dumps({"dtype": dtype, "extra": extra, "complete": r.complete, "wall": r.wall_time_s, "ke_ie": s["max_ke_ie"],
                  "draw_in_mm": 1e3 * s["draw_in"]["edge_mid_m"], "corner_mm": 1e3 * s["draw_in"]["corner_m"],
                  "shear": s["max_shear_angle_deg"], "ht": half_turn_symmetry(r)["deviation"],
                  "fm": s["numerics"].get("fibre_mass_scaling")}), flush=True)
