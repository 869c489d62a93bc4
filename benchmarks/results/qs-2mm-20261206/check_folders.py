"""The quasi-static check of issue 13 (``forming.quasi_static_check``: shear map p95, edge mid-side
draw-in, flange wrinkles) between two finished ``jaxform run`` folders of one case and mesh, read
back from what they wrote (summary.json and the VTU frames), and each run's mirror symmetry of the
last frame (``forming.symmetry_error`` of the deviation and shear maps, ply 1). Writes OUT.json;
exit 1 if a run is incomplete. Run: .venv/bin/python check_folders.py RUN HALF_SPEED_RUN OUT.json"""
import json
import sys
from pathlib import Path
from types import SimpleNamespace

import meshio
import numpy as np

from jaxform import forming
from jaxform.forming.case import from_dict
from jaxform.forming.summary import shear_mirror_odd
from jaxform.io.frames import read_frame_index


def load(folder):
    """A stand-in for the FormingResult that ``quasi_static_check`` reads, from a run folder."""
    folder = Path(folder)
    s = json.loads((folder / "summary.json").read_text())
    case = from_dict(s["inputs"])  # the normalised case the run wrote
    index = read_frame_index(folder / "frames.pvd")  # file -> time
    frames = [meshio.read(folder / f) for f in index]
    x0 = frames[0].points - frames[0].point_data["displacement_m"]
    h = s["history"]
    return SimpleNamespace(
        complete=s["complete"], reason=s["reason"], summary=s, t=np.array(list(index.values())),
        info=SimpleNamespace(case=case, x0=x0),
        fields={"shear_angle": np.radians([f.point_data["shear_angle_deg"] for f in frames]),
                "deviation": np.array([f.point_data["deviation_m"] for f in frames])},
        ply1=np.asarray(frames[0].point_data["ply_id"]) == 1,
        history={"t_s": np.array(h["t_s"]), "punch_displacement_m": np.array(h["punch_displacement_m"])})


def symmetry(r):
    p = r.ply1
    return {"deviation": forming.symmetry_error(r.info.x0[p], r.fields["deviation"][-1][p]),
            "shear": forming.symmetry_error(r.info.x0[p], r.fields["shear_angle"][-1][p], odd=shear_mirror_odd(r.info.case))}


runs = {k: load(p) for k, p in (("run", sys.argv[1]), ("half", sys.argv[2]))}
rec = {k: {"folder": sys.argv[i + 1], "complete": r.complete, "reason": r.reason, "wall_s": r.summary["wall_time_s"],
           "n_steps": r.summary["numerics"]["n_steps"], "dt_s": r.summary["numerics"]["dt_s"],
           "speed_mm_per_s": 1e3 * r.summary["numerics"]["punch_speed_m_per_s"], "max_ke_ie": r.summary["max_ke_ie"],
           "max_shear_deg": r.summary["max_shear_angle_deg"], "draw_in": r.summary["draw_in"],
           "flange_wrinkles": r.summary["flange_wrinkles"], "mirror_symmetry_last_frame": symmetry(r)}
       for i, (k, r) in enumerate(runs.items())}
rec["check"] = forming.quasi_static_check(runs["run"], runs["half"])
Path(sys.argv[3]).write_text(json.dumps(rec, indent=1))
print(json.dumps({k: (v if k != "check" else {q: w for q, w in v.items() if "per_frame" not in q}) for k, v in rec.items()},
                 indent=1))
sys.exit(0 if all(r.complete for r in runs.values()) else "check_folders.py: a run is incomplete")
