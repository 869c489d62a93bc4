"""Mirror symmetry of a finished ``jaxform run`` folder's last frame (issue 13, done-when 6): the
deviation and shear maps of ply 1 against their images about the x and y axes
(``forming.symmetry_error``, the measure of ``../qs-2mm-20261206/check_folders.py``), with the run's
own figures from summary.json. Prints one JSON object. Run: .venv/bin/python mirror.py RUN"""
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
last = meshio.read(folder / list(read_frame_index(folder / "frames.pvd"))[-1])
p1 = np.asarray(last.point_data["ply_id"]) == 1
x0 = (last.points - last.point_data["displacement_m"])[p1]
odd = shear_mirror_odd(from_dict(s["inputs"]))
print(json.dumps({
    "complete": s["complete"], "warnings": s.get("warnings"), "wall_s": s["wall_time_s"],
    "n_steps": s["numerics"]["n_steps"], "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"],
    "draw_in": s["draw_in"], "flange_wrinkles": s["flange_wrinkles"], "half_turn_symmetry": s.get("half_turn_symmetry"),
    "mirror_deviation": forming.symmetry_error(x0, last.point_data["deviation_m"][p1]),
    "mirror_shear": forming.symmetry_error(x0, np.radians(last.point_data["shear_angle_deg"][p1]), odd=odd)}, indent=1))
