"""The fibre mass's spectral bound: the scalar operator's largest eigenvalue (Lanczos, this commit) against
the block Gershgorin bound before it (a5ac763, kept below verbatim as the reference). Woven Case A NLBM at
SIZE mm as shipped (automatic numerics, 62.5 mm/s): the same case run with each bound (the polynomial's
degree 13 against 14), compared with the quasi-static check's three figures (forming.quasi_static_check:
shear map p95, edge mid-side draw-in, flange wrinkles), each run's energy balance and wall time.
Exit 1 if a run is incomplete. Run: .venv/bin/python run.py SIZE_MM OUT_DIR  (both cores, nothing else running)."""
import json
import sys
import time
from pathlib import Path

import numpy as np

from jaxform import cases, forming
from jaxform import fibre_mass as F

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from energy_balance import balance  # noqa: E402  (benchmarks/)


def gershgorin_before(shell, mass_scale=1.0) -> list:
    """a5ac763's ``fibre_mass.spectral_bound`` (block Gershgorin), verbatim but for the name."""
    mesh = shell.mesh
    m = np.asarray(shell.node_masses(mass_scale), np.float64)
    tris = np.asarray(mesh.tris)
    coef = np.asarray(shell.ref.tri_coef, np.float64)
    area = np.asarray(shell.ref.tri_area, np.float64)
    out = []
    for (t0, t1), fab in zip(mesh.ply_tris, shell.fabrics):
        eh = F._tension_stiffness(fab)
        t = tris[t0:t1]
        row = np.zeros(len(m))
        for f in range(2):
            c = np.abs(np.stack([coef[t0:t1, f, 0] + coef[t0:t1, f, 1], coef[t0:t1, f, 0], coef[t0:t1, f, 1]], 1))
            for i in range(3):
                s = sum(c[:, j] / np.sqrt(m[t[:, i]] * m[t[:, j]]) for j in range(3))
                np.add.at(row, t[:, i], area[t0:t1] * eh[f] * c[:, i] * s)
        out.append(float(row.max()))
    return out


size, out = float(sys.argv[1]), Path(sys.argv[2])
out.mkdir(parents=True, exist_ok=True)
case = cases.with_element_size(cases.load("case-a-woven-nlbm"), size * 1e-3)
lanczos = F.spectral_bound
rec, res = {"element_size_mm": size}, {}
for name, bound in (("gershgorin_before", gershgorin_before), ("lanczos", lanczos)):
    F.spectral_bound = bound
    t0 = time.time()
    r = forming.simulate(case, catch=True)
    s = r.summary
    res[name] = r
    rec[name] = {"wall_s": time.time() - t0, "complete": r.complete, "reason": r.reason,
                 "numerics": {k: s["numerics"][k] for k in ("dt_s", "n_steps", "fibre_mass_scaling", "fibre_mass_degree")},
                 "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"], "draw_in": s["draw_in"],
                 "flange_wrinkles": s["flange_wrinkles"], "energy_balance": balance(r)}
    print(name, json.dumps(rec[name]), flush=True)
    (out / "bound.json").write_text(json.dumps(rec, indent=1))
F.spectral_bound = lanczos
rec["check"] = forming.quasi_static_check(res["lanczos"], res["gershgorin_before"])
print("check", json.dumps({k: v for k, v in rec["check"].items() if "per_frame" not in k}), flush=True)
(out / "bound.json").write_text(json.dumps(rec, indent=1))
sys.exit(0 if all(r.complete for r in res.values()) else "run.py: a run is incomplete: see bound.json")
