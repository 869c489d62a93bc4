"""half_turn_symmetry and the findings of a finished run folder, read back. python sym_check.py RUN_DIR"""
import json, sys
from pathlib import Path
from types import SimpleNamespace
import meshio, numpy as np
from jaxform.forming.case import from_dict
from jaxform.forming.rig import _edge_nodes, build_mesh
from jaxform.forming.summary import half_turn_symmetry, findings
from jaxform.io.frames import read_frame_index
folder = Path(sys.argv[1])
s = json.loads((folder / "summary.json").read_text())
case = from_dict(s["inputs"])
index = read_frame_index(folder / "frames.pvd")
fr = [meshio.read(folder / f) for f in index]
x0 = fr[0].points - fr[0].point_data["displacement_m"]
mesh = build_mesh(case)
mid, cor = _edge_nodes(mesh, mesh.ply_nodes[0][0])
h = s["history"]
t = np.array(list(index.values()))
r = SimpleNamespace(info=SimpleNamespace(case=case, x0=x0, edge_mid=mid, corners=cor), ply_id=fr[0].point_data["ply_id"],
                    x=np.array([f.points for f in fr]), t=t, faces=fr[0].cells_dict["quad"],
                    history={k: np.array(h[k]) for k in ("t_s", "punch_displacement_m")},
                    fields={"deviation": np.array([f.point_data["deviation_m"] for f in fr]),
                            "shear_angle": np.radians([f.point_data["shear_angle_deg"] for f in fr])})
sym = half_turn_symmetry(r)
print(json.dumps({k: v for k, v in sym.items() if k != "deviation_per_frame"}))
print([round(100 * v, 1) for v in sym["deviation_per_frame"]])
s["half_turn_symmetry"] = sym
for f in findings(s):
    print(f["level"], f["kind"], f["text"])
