"""The wrinkle fit's starting laws (its global phase, :func:`jaxform.calibrate.fit_wrinkles` step 3),
in the fit's log space ``q = (log B_init, log B_inf/B_init, log kappa0[, log s])``: a seeded Latin
hypercube around a centre, and the law cantilever side profiles give alone. SI units; host-side numpy."""
from __future__ import annotations

import time

import numpy as np
from scipy.stats.qmc import LatinHypercube

from jaxform.calibrate.cantilever_fit import fit_cantilever
from jaxform.calibrate.transforms import q_from_law


def hypercube(centre, half, n: int, lo, hi) -> list:
    """``n`` laws of a Latin hypercube (seed 0: the same laws every fit) in the box ``centre +- half``
    (each (p,)), clipped to the bounds ``lo``, ``hi``."""
    centre = np.asarray(centre, float)
    return list(np.clip(centre + (2.0 * LatinHypercube(d=len(centre), seed=0).random(n) - 1.0) * np.asarray(half),
                        lo, hi))


def cantilever_start(prof, areal_mass, profile_kwargs, noise, p, lo, hi) -> dict:
    """The law the cantilever profiles alone give (:func:`~jaxform.calibrate.fit_cantilever`, the
    same model and noise as the joint residual), as a start of the global phase (clipped to its
    bounds): the profiles pin B_init and M at their curvatures without a forming run."""
    t0 = time.perf_counter()
    cf = fit_cantilever(prof.profiles, areal_mass=areal_mass, simulate_kwargs=dict(profile_kwargs or {}), noise=noise)
    law = cf.law
    q = np.clip(np.append(q_from_law(law, "voce"), [0.0] * (p - 3)), lo, hi)
    sd = np.sqrt(np.clip(np.diag(np.asarray(cf.covariance, float)), 0.0, None))
    return {"b_inf_Nm": float(law.b_inf), "m0_N": float(law.m0), "kappa0_per_m": float(law.kappa0),
            "b_init_Nm": float(law.b_init), "converged": bool(cf.converged), "q": list(map(float, q)),
            "sd_q": list(map(float, sd)), "wall_time_s": time.perf_counter() - t0}


__all__ = ["hypercube", "cantilever_start"]
