"""The joint fit's sigma check replayed at its fit (record 20261205T-qs-joint-axes: the same q, rows,
Jacobian and scale as fit_wrinkles builds them; the forming runs are deterministic, so the rows
reproduce the fit's chi-square 255.44) with the check of the commit after f09056f: principal axes,
probed further out while the loss stays flatter than modelled, each probe profiled (one Gauss-Newton
step of the other axes). Reports the checked sds and where the truth lies in them. Its records were
made by code before the commit's final rule: the JSON of this name took each axis's last round on
its flatter side, ``-meanside`` the mean of the two sides; ``-final.py`` reads this JSON's probes with
the committed rule (the widest round).
Run: python 20261205T-qs-joint-check-replay.py OUT.json (nothing else running; about 12 min)."""
import json, pathlib, runpy, sys, time
import numpy as np
import jax.numpy as jnp

V = runpy.run_path(str(pathlib.Path(__file__).with_name("20261205T-qs-joint-valley.py")), run_name="replay")
from jaxform.calibrate import sections as sec_mod
from jaxform.calibrate.uncertainty import checked_covariance, open_share
from jaxform.calibrate.transforms import _physical, moment_band
from jaxform.calibrate.wrinkle_fit import NAMES, _bounds
import jax

q, runs, R, meas, prof, sections, case = (V[k] for k in ("q_fit", "runs", "R", "meas", "prof", "sections", "case"))
noise = V["_bw"].NOISE
q_true = V["q_true"]


def rows(x):
    y, v, ok, _ = runs.evaluate([np.asarray(x, float)])[0]
    r = np.concatenate([R @ np.where(v, y - meas, 0.0), np.asarray(prof.rows(jnp.asarray(x)), float) * 1e-3 / noise])
    return r if ok and np.all(np.isfinite(r)) else np.full(r.shape, np.inf)


t0 = time.perf_counter()
lo, hi = _bounds(np.asarray(V["fit"]["starts"][0]["q"]), "voce")
pts = [q + 0.05 * e if q[i] + 0.05 <= hi[i] else q - 0.05 * e for i, e in enumerate(np.eye(3))]
runs.evaluate([q] + pts)
r0 = rows(q)
J = np.stack([(rows(x) - r0) / (x - q)[i] for i, x in enumerate(pts)], axis=1)
J[R.shape[0]:] = np.asarray(prof.jac(jnp.asarray(q)), float) * 1e-3 / noise
n_sec, n_prof = len(meas), sum(len(p.x) for p in prof.profiles)
n_eff = sum(sec_mod.independent_points(s, float(case.element_size)) for s in sections) + n_prof
chi2 = float(r0 @ r0)
c = max(1.0, chi2 / max(n_eff - 3, 1)) * (n_sec + n_prof) / n_eff
cov0 = c * np.linalg.pinv(J.T @ J)
cov, rep = checked_covariance(rows, q, r0, J, cov0, lo, hi, names=NAMES[:3], prefetch=runs.evaluate)
T = np.asarray(jax.jacfwd(lambda v: _physical(v, "voce"))(jnp.asarray(q)), float)
phys = np.asarray(_physical(jnp.asarray(q), "voce"), float)
truth = np.asarray(_physical(jnp.asarray(q_true), "voce"), float)
out = {"chi_square": chi2, "c": c, "runs": runs.runs, "wall_s": time.perf_counter() - t0, "sigma_check": rep,
       "open_share": open_share(rep, T).tolist()}
for name, C in (("laplace", cov0), ("checked", cov)):
    sig = np.sqrt(np.diag(T @ C @ T.T))
    d = q - q_true
    out[name] = {"sd": dict(zip(("b_inf", "m0", "kappa0", "b_init"), sig.tolist())),
                 "truth_in_sds": dict(zip(("b_inf", "m0", "kappa0", "b_init"), ((phys - truth) / sig).tolist())),
                 "mahalanobis": float(np.sqrt(d @ np.linalg.solve(C, d)))}
    m, sm, _ = moment_band(q, C, np.array(V["fit"]["moment_band"]["kappa_per_m"]))
    out[name]["moment_sd_rel"] = (sm / m).tolist()
print(json.dumps({k: v for k, v in out.items() if k != "sigma_check"}, indent=1))
json.dump(out, open(sys.argv[1], "w"), indent=1)
