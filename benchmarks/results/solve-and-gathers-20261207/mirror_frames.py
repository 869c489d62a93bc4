"""Mirror symmetry of every frame of a finished ``jaxform run`` folder (issue 13, done-when 6): the
deviation and shear maps of ply 1 against their images about the x and y axes
(``forming.symmetry_error``, as ``../symmetry-2mm-kahan-20261207/mirror.py`` does for the last
frame), with each frame's punch travel and largest deviation. Prints one JSON object.
Run: .venv/bin/python mirror_frames.py RUN"""
import json
import sys
from pathlib import Path

import meshio
import numpy as np

from jaxform import forming
from jaxform.forming.case import from_dict
from jaxform.forming.summary import shear_mirror_odd
from jaxform.io.frames import read_frame_index

folder = Path(sys.argv[1])
s = json.loads((folder / "summary.json").read_text())
odd = shear_mirror_odd(from_dict(s["inputs"]))
rows = []
for name, t in read_frame_index(folder / "frames.pvd").items():
    f = meshio.read(folder / name)
    p1 = np.asarray(f.point_data["ply_id"]) == 1
    x0 = (f.points - f.point_data["displacement_m"])[p1]
    dev = np.asarray(f.point_data["deviation_m"])[p1]
    rows.append({"time_s": t, "max_deviation_mm": float(np.max(np.abs(dev)) * 1e3),
                 "mirror_deviation": forming.symmetry_error(x0, dev),
                 "mirror_shear": forming.symmetry_error(x0, np.radians(f.point_data["shear_angle_deg"][p1]), odd=odd)})
print(json.dumps({"complete": s["complete"], "wall_s": s["wall_time_s"], "n_steps": s["numerics"]["n_steps"],
                  "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"], "draw_in_edge_mid_m": s["draw_in"]["edge_mid_m"],
                  "draw_in_corner_m": s["draw_in"]["corner_m"], "flange_wrinkles": s["flange_wrinkles"], "frames": rows}, indent=1))
