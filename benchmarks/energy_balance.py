"""The energy balance of a finished forming run, from its summary's energy history (shared by the
records that compare two runs' numerics)."""
import numpy as np

from jaxform.forming.fields import ENERGY_KEYS


def balance(r) -> dict:
    """``r`` a :class:`jaxform.forming.FormingResult`: the largest residual of stored energy against
    net work over the samples (J), relative to the largest energy scale, and the net work at the end."""
    e = {key: np.asarray(r.summary["history"]["energies_J"][key]) for key in ENERGY_KEYS}
    stored = e["kinetic"] + e["tension"] + e["shear"] + e["bending"]
    work = e["gravity_work"] + e["external_work"] + e["boundary_work"] - e["damping_work"]
    res = (stored - stored[0]) - (work - work[0])
    scale = np.max(np.abs(stored) + np.abs(e["gravity_work"]) + np.abs(e["external_work"]) + np.abs(e["boundary_work"])
                   + np.abs(e["damping_work"]))
    return {"max_abs_residual_J": float(np.max(np.abs(res))), "end_residual_J": float(res[-1]),
            "max_scale_J": float(scale), "max_rel": float(np.max(np.abs(res)) / scale),
            "net_work_end_J": float(work[-1] - work[0])}
