"""Where float32's extra kinetic energy comes from (issue 13): woven Case A NLBM as shipped at SIZE mm, in
float32, in float64, and in float64 from a blank given a smooth out-of-plane imperfection of AMP m at its
largest (``calibrate.imperfections``, seed 1, tapered near the tools): if the float64 run's kinetic energy
rises to float32's with a seed, float32's excess is the symmetry-breaking its rounding seeds, not its
arithmetic. Prints one JSON line: max KE/IE (late, as the summary), KE/IE and the largest node speed at
each 2 mm of punch travel up to 20 mm, draw-in, and the last frame's mirror error of the deviation.
Run: .venv/bin/python ke_seed.py SIZE MODE [AMP]   (MODE float32 | float64; both cores)"""
import json
import sys

import numpy as np


def measure(res) -> dict:
    """What ke_seed.py and ke_pieces.py print of a finished run: completion, wall time, max KE/IE (late,
    as the summary), draw-in, the last frame's mirror error of the deviation (ply 1), and KE/IE and
    the largest node speed at each 2 mm of punch travel up to 20 mm."""
    from jaxform.forming.summary import symmetry_error

    h, s = res.history, res.summary
    ie = h["tension_J"] + h["shear_J"] + h["bending_J"]
    ratio = np.where(ie > 0, h["kinetic_J"] / np.maximum(ie, 1e-300), np.nan)
    d = np.asarray(h["punch_displacement_m"]) * 1e3
    at = {f"{p:g}": [float(np.nanmax(np.where((d >= p - 1) & (d < p + 1), ratio, np.nan))),
                     float(np.nanmax(np.where((d >= p - 1) & (d < p + 1), h["max_node_speed_m_per_s"], np.nan)))]
          for p in range(2, 21, 2)}
    p1 = np.asarray(res.ply_id) == 1
    x0 = np.asarray(res.info.x0)[p1]
    return {"complete": res.complete, "wall_s": res.wall_time_s, "max_ke_ie": s["max_ke_ie"],
            "draw_in_edge_mid_m": s["draw_in"]["edge_mid_m"],
            "mirror_deviation": symmetry_error(x0, np.asarray(res.fields["deviation"][-1])[p1]),
            "ke_ie_and_vmax_per_2mm": at}

if __name__ == "__main__":
    size, mode = float(sys.argv[1]), sys.argv[2]
    amp = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    if mode == "float64":
        import jax
        jax.config.update("jax_enable_x64", True)
    import dataclasses

    import jax.numpy as jnp

    from jaxform import cases, forming
    from jaxform.calibrate.imperfections import imperfections

    case = cases.resolve("case-a-woven-nlbm", element_size=size * 1e-3, overrides=[f"numerics.dtype={mode}"])
    rig = forming.build(case)
    model, state, info = rig
    if amp > 0:
        x0 = np.asarray(state.x, np.float64)
        clear = np.min(np.stack([np.abs(np.asarray(ld.gap(state.x, 0.0, ls))) for ld, ls in zip(model.loads, state.loads)
                                 if hasattr(ld, "gap")]), axis=0)
        dz = imperfections(x0, 2, amp, case.blank_size, clearance=clear)[1]
        state = dataclasses.replace(state, x=state.x + jnp.asarray(dz, state.x.dtype),
                                    u=state.u + jnp.asarray(dz.T, state.u.dtype))
        rig = type(rig)(model, state, info)
    res = forming.run(rig)
    print(json.dumps({"size_mm": size, "mode": mode, "amp_m": amp, **measure(res)}))
