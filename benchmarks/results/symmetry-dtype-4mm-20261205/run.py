"""Issue 13, done-when 6: is the formed flange's loss of mirror symmetry float32 rounding grown by
the buckling, or the model? Woven Case A NLBM at 4 mm, the preset's automatic numerics, each run in
its own process; the last frame's deviation and shear maps compared with their mirror images about
x and y and with their 180° rotation (which the union-jack mesh, the fabric and the rig all keep
exactly): max |v - v'| / max |v| and the same in RMS.

    .venv/bin/python run.py MODE OUT_DIR      (both cores; exit 1 if the run is incomplete)

MODE: ``float32`` (as shipped) or ``float64`` (writes MODE.json); ``patched``: float32 with x64 on in
the process and the fibre mass's polynomial inverse mass (jaxform.fibre_mass.inverse_mass_times)
evaluated in float64 and cast back (a monkeypatch for this experiment, not library code);
``control``: the same process setting without the patch (these two write mixed-MODE.json)."""
import json
import sys
import time
from pathlib import Path

import jax
import numpy as np

mode, out = sys.argv[1], Path(sys.argv[2])
if mode not in ("float32", "float64", "patched", "control"):
    sys.exit(f"run.py: MODE = {mode!r}: must be float32, float64, patched or control")
if mode != "float32":
    jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402

from jaxform import cases, fibre_mass, forming  # noqa: E402
from jaxform.forming.summary import mirror_index, shear_mirror_odd  # noqa: E402

if mode == "patched":
    orig = fibre_mass.inverse_mass_times

    def wide(fs, units, mass, free, fm, shell):
        f64 = lambda a: jnp.asarray(a).astype(jnp.float64)  # noqa: E731
        return orig(f64(fs), tuple(f64(u) for u in units), f64(mass), f64(free), fm, shell).astype(fs.dtype)

    fibre_mass.inverse_mass_times = wide
dtype = "float64" if mode == "float64" else "float32"
case = cases.apply_overrides(cases.with_element_size(cases.load("case-a-woven-nlbm"), 4e-3), [f"numerics.dtype={dtype!r}"])
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
rec = {"mode": mode, "dtype": dtype, "x_dtype": str(r.x.dtype), "wall_s": wall, "complete": r.complete, "reason": r.reason,
       "n_steps": s["numerics"]["n_steps"], "dt_s": s["numerics"]["dt_s"], "max_ke_ie": s["max_ke_ie"],
       "max_shear_deg": s["max_shear_angle_deg"], "draw_in": s["draw_in"], "flange_wrinkles": s["flange_wrinkles"],
       "deviation_max_m": float(np.max(np.abs(r.fields["deviation"][-1]))),
       "deviation": errors(np.asarray(r.fields["deviation"][-1], np.float64), False),
       "shear": errors(np.asarray(r.fields["shear_angle"][-1], np.float64), shear_mirror_odd(case))}
(out / (f"{mode}.json" if mode in ("float32", "float64") else f"mixed-{mode}.json")).write_text(json.dumps(rec, indent=1))
print(json.dumps(rec), flush=True)
sys.exit(0 if r.complete else f"run.py: the run is incomplete: {r.reason}")
