"""The wrinkle fit's rig step with its box's stiffest law (10x the start's B_init, as fit_wrinkles builds it) against
the start's, woven Case A NLBM at 8, 4 and 2 mm (builds only). Run: python fit_step.py"""
import json
import math

import numpy as np

from jaxform import cases
from jaxform.calibrate import section_runs
from jaxform.calibrate.sections import Section
from jaxform.calibrate.transforms import q_from_law
from jaxform.calibrate.wrinkle_fit import SPAN

sec = Section(s=np.linspace(0.0, 0.03, 31), amplitude=np.zeros(31), start=np.array([0.06, 0.0]), end=np.array([0.09, 0.0]))
for size in (8, 4, 2):
    case = cases.resolve("case-a-woven-nlbm", element_size=size * 1e-3)
    own = section_runs.SectionRuns(case, [sec], "voce", 1, 0.0, 1, 1)
    b0 = math.exp(q_from_law(own.law0, "voce")[0])
    box = section_runs.SectionRuns(case, [sec], "voce", 1, 0.0, 1, 1, step_b_init=SPAN * b0)
    print(json.dumps({"size_mm": size, "b_init_Nm": b0, "dt_start_s": float(own.rig[0].dt), "dt_box_s": float(box.rig[0].dt),
                      "ratio": float(own.rig[0].dt) / float(box.rig[0].dt)}), flush=True)
