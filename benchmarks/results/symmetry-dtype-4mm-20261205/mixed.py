"""Is the float32 run's excess kinetic energy and asymmetry the rounding of the fibre mass's
polynomial? The 4 mm woven preset in float32 with x64 enabled in the process, (a) the polynomial
inverse mass (jaxform.fibre_mass.inverse_mass_times) evaluated in float64 and cast back to float32
(a monkeypatch for this experiment, not library code), (b) the control: the same process setting
without the patch. Run: .venv/bin/python mixed.py patched|control OUT_DIR (both cores)."""
import json
import sys
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402

from jaxform import cases, fibre_mass, forming  # noqa: E402
from jaxform.forming.summary import mirror_index, shear_mirror_odd  # noqa: E402
import numpy as np  # noqa: E402

mode, out = sys.argv[1], Path(sys.argv[2])
if mode == "patched":
    orig = fibre_mass.inverse_mass_times

    def wide(fs, units, mass, free, fm, shell):
        f64 = lambda a: a.astype(jnp.float64)  # noqa: E731
        fm64 = fm.replace(weight=f64(fm.weight)) if hasattr(fm, "replace") else fm
        return orig(f64(fs), tuple(f64(u) for u in units), f64(jnp.asarray(mass)), f64(free), fm64, shell).astype(fs.dtype)

    fibre_mass.inverse_mass_times = wide
case = cases.apply_overrides(cases.with_element_size(cases.load("case-a-woven-nlbm"), 4e-3), ["numerics.dtype='float32'"])
t0 = time.time()
r = forming.simulate(case, catch=True)
wall = time.time() - t0
x0 = r.info.x0


def errors(v, odd):
    res = {}
    for name, sx, sy, sign in (("mirror_x", 1, -1, -1.0 if odd else 1.0), ("mirror_y", -1, 1, -1.0 if odd else 1.0),
                               ("rot180", -1, -1, 1.0)):
        d = v - sign * v[mirror_index(x0, sx, sy)]
        res[name] = {"max": float(np.max(np.abs(d)) / np.max(np.abs(v))), "rms": float(np.sqrt(np.mean(d**2) / np.mean(v**2)))}
    return res


s = r.summary
rec = {"mode": mode, "x_dtype": str(r.x.dtype), "wall_s": wall, "complete": r.complete, "reason": r.reason,
       "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"], "draw_in": s["draw_in"],
       "flange_wrinkles": s["flange_wrinkles"],
       "deviation": errors(np.asarray(r.fields["deviation"][-1], np.float64), False),
       "shear": errors(np.asarray(r.fields["shear_angle"][-1], np.float64), shear_mirror_odd(case))}
(out / f"mixed-{mode}.json").write_text(json.dumps(rec, indent=1))
print(json.dumps(rec), flush=True)
