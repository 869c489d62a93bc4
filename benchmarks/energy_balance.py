"""The energy balance of a finished forming run, from its summary's energy history (shared by the
records that compare two runs' numerics): :meth:`jaxform.model.Energies.balance` and ``scale`` on
the sampled accounts, the residual measured from the first sample."""
import jax
import numpy as np

from jaxform.forming.fields import ENERGY_KEYS
from jaxform.model import Energies


def balance(r) -> dict:
    """``r`` a :class:`jaxform.forming.FormingResult`: the largest residual of stored energy against
    net work over the samples (J), relative to the largest energy scale, and the net work at the end."""
    e = Energies(**{key: np.asarray(r.summary["history"]["energies_J"][key], float) for key in ENERGY_KEYS})
    e0 = jax.tree_util.tree_map(lambda a: a[0], e)
    res = np.asarray(e.balance(e0))
    scale = float(np.max(np.asarray(e.scale())))
    work = np.asarray(e.gravity_work + e.external_work + e.boundary_work - e.damping_work)
    return {"max_abs_residual_J": float(np.max(np.abs(res))), "end_residual_J": float(res[-1]),
            "max_scale_J": scale, "max_rel": float(np.max(np.abs(res)) / scale),
            "net_work_end_J": float(work[-1] - work[0])}
