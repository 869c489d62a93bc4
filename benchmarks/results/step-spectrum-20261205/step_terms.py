"""The terms of the shell's step estimate for the presets (jaxform.shell._ply_frequencies) at 8/4/2 mm."""
import json
from jaxform import cases
from jaxform.forming import rig
from jaxform.forming.numerics import auto_fibre_mass
from jaxform.shell import Shell, _ply_frequencies
out = []
for name in ("case-a-woven-nlbm", "case-a-ncf-nlbm"):
    for size in (8e-3, 4e-3, 2e-3):
        case = cases.with_element_size(cases.load(name), size)
        mesh = rig.build_mesh(case)
        shell = Shell.build(mesh, rig.build_fabric(case))
        (wm, wb), = _ply_frequencies(shell)
        s = auto_fibre_mass(shell)
        out.append({"case": name, "element_mm": size * 1e3, "omega_m": wm, "omega_b_estimate": wb, "fibre_mass": s,
                    "omega_m_over_s": wm / s, "bending_share_of_omega2": wb**2 / (wb**2 + (wm / s) ** 2)})
print(json.dumps(out, indent=1))
