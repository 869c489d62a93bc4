"""The replayed sigma check (20261205T-qs-joint-check-replay.json) read with the final rule of the
commit: an axis's sd is the widest secant of any of its rounds (the replay's code took the last
round's; the rounds and probes, which only the growth rule decides, are the same under both).
Prints the checked sds and where the truth lies in them. Run: python 20261205T-qs-joint-check-replay-final.py"""
import json, math, pathlib
import numpy as np
import jax
jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp
from jaxform.calibrate.transforms import _physical, moment_band, q_from_law
from jaxform.materials import VoceBending

here = pathlib.Path(__file__).parent
rep = json.load(open(here / "20261205T-qs-joint-check-replay.json"))
fit = json.load(open(here / "20261205T-qs-joint-axes.json"))["fit"]
q = np.array(fit["local_fits"][0]["q_final"])
q_true = q_from_law(VoceBending(3e-5, 1e-2, 40.0), "voce")
V = np.array([a["direction"] for a in rep["sigma_check"]["axes"]]).T
s = np.array([max([a["laplace_sd"]] + [x for x in a["sd_per_round"] if x is not None and math.isfinite(x)])
              for a in rep["sigma_check"]["axes"]])
C = (V * s**2) @ V.T
T = np.asarray(jax.jacfwd(lambda v: _physical(v, "voce"))(jnp.asarray(q)), float)
phys = np.asarray(_physical(jnp.asarray(q), "voce"), float)
truth = np.asarray(_physical(jnp.asarray(q_true), "voce"), float)
sig = np.sqrt(np.diag(T @ C @ T.T))
d = q - q_true
m, sm, _ = moment_band(q, C, np.array(fit["moment_band"]["kappa_per_m"]))
mt = np.asarray(VoceBending(3e-5, 1e-2, 40.0).moment(np.array(fit["moment_band"]["kappa_per_m"])))
out = {"axis_sd": s.tolist(), "widened_by": (s / np.array([a["laplace_sd"] for a in rep["sigma_check"]["axes"]])).tolist(),
       "sd": dict(zip(("b_inf", "m0", "kappa0", "b_init"), sig.tolist())),
       "sd_rel": dict(zip(("b_inf", "m0", "kappa0", "b_init"), (sig / phys).tolist())),
       "truth_in_sds": dict(zip(("b_inf", "m0", "kappa0", "b_init"), ((phys - truth) / sig).tolist())),
       "mahalanobis": float(np.sqrt(d @ np.linalg.solve(C, d))),
       "moment_sd_rel": (sm / m).tolist(), "moment_truth_in_sds": ((m - mt) / sm).tolist()}
print(json.dumps(out, indent=1))
