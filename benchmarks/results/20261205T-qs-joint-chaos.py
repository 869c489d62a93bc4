"""The run's chaotic scatter as an error of the joint fit (record 20261205T-qs-joint-axes, its rows
rebuilt as 20261205T-qs-joint-valley.py builds them): the rows at the fitted law from imperfect
blanks (seeds 1..S-1 of jaxform.calibrate.imperfections, amplitude a tenth of the ply; seed 0 the
perfect blank the fit ran), and the residual rows of the sigma check's first probes (2 sds along the
Laplace covariance's principal axes) minus the Jacobian's straight-line prediction. Either set of
row deviations, mapped to the parameters by the fit's own linear map A = (J^T J)^-1 J^T, is a
sample of how far the chaotic part of the run moves the fit: cov_chaos = A Cov(rows) A^T. Reports
the truth's distance in sds with the Laplace and the checked covariance (20261205T-qs-joint-check-
replay, read with the committed rule) with and without cov_chaos.
Run: python 20261205T-qs-joint-chaos.py OUT.json (nothing else running; about 8 min)."""
import json, math, pathlib, runpy, sys, time
from concurrent.futures import ThreadPoolExecutor
import numpy as np
import jax.numpy as jnp

here = pathlib.Path(__file__).parent
V = runpy.run_path(str(here / "20261205T-qs-joint-valley.py"), run_name="replay")
import jax
from jaxform.calibrate.section_runs import SectionRuns, _key
from jaxform.calibrate.transforms import _physical, moment_band
from jaxform.calibrate.wrinkle_fit import _bounds
from jaxform.calibrate.uncertainty import _reach

q, runs, R, meas, prof, sections, case = (V[k] for k in ("q_fit", "runs", "R", "meas", "prof", "sections", "case"))
noise, q_true = V["_bw"].NOISE, V["q_true"]
S = int(sys.argv[2]) if len(sys.argv) > 2 else 5
t0 = time.perf_counter()


def rows_of(y, v, ok, x):
    r = np.concatenate([R @ np.where(v, y - meas, 0.0), np.asarray(prof.rows(jnp.asarray(x)), float) * 1e-3 / noise])
    return r if ok and np.all(np.isfinite(r)) else None


lo, hi = _bounds(np.asarray(V["fit"]["starts"][0]["q"]), "voce")
pts = [q + 0.05 * e if q[i] + 0.05 <= hi[i] else q - 0.05 * e for i, e in enumerate(np.eye(3))]
ev = runs.evaluate([q] + pts)
r0 = rows_of(*ev[0][:3], q)
J = np.stack([(rows_of(*e[:3], x) - r0) / (x - q)[i] for i, (e, x) in enumerate(zip(ev[1:], pts))], axis=1)
ns = R.shape[0]
J[ns:] = np.asarray(prof.jac(jnp.asarray(q)), float) * 1e-3 / noise
chi2 = float(r0 @ r0)
n_prof = sum(len(p.x) for p in prof.profiles)
from jaxform.calibrate import sections as sec_mod
n_eff = sum(sec_mod.independent_points(s, float(case.element_size)) for s in sections) + n_prof
c = max(1.0, chi2 / max(n_eff - 3, 1)) * (len(meas) + n_prof) / n_eff
H = np.linalg.pinv(J.T @ J)
cov_lap = c * H
A = H @ J.T

# the seeds: the same law from imperfect blanks
seeded = SectionRuns(case, sections, "voce", S, 0.1 * float(case.ply_thickness), 1, 1, 2)
with ThreadPoolExecutor(2) as pool:
    out = list(pool.map(lambda i: seeded._chunk([(_key(q), i)]), range(1, S)))
seed_rows = [r0] + [rows_of(y[0].astype(float), v[0], bool(ok[0]), q) for y, v, ok, *_ in out]
seed_ok = [r is not None for r in seed_rows]
Rs = np.array([r for r in seed_rows if r is not None])
chi_seeds = [float(r @ r) for r in Rs]

# the first probes of the check, 2 sds along the principal axes of the Laplace covariance
lam, Vax = np.linalg.eigh(cov_lap)
sd = np.sqrt(lam)
probes = [(j, s * _reach(q, s * Vax[:, j], 2.0 * sd[j], lo, hi)) for j in range(3) for s in (-1.0, 1.0)]
xs = [q + h * Vax[:, j] for j, h in probes]
dev = []
for (j, h), x, e in zip(probes, xs, runs.evaluate(xs)):
    r = rows_of(*e[:3], x)
    if r is not None:
        dev.append(r - (r0 + J @ (x - q)))
dev = np.array(dev)

T = np.asarray(jax.jacfwd(lambda v: _physical(v, "voce"))(jnp.asarray(q)), float)
phys = np.asarray(_physical(jnp.asarray(q), "voce"), float)
truth = np.asarray(_physical(jnp.asarray(q_true), "voce"), float)
rep = json.load(open(here / "20261205T-qs-joint-check-replay.json"))["sigma_check"]
Vc = np.array([a["direction"] for a in rep["axes"]]).T
sc = np.array([max([a["laplace_sd"]] + [x for x in a["sd_per_round"] if x is not None and math.isfinite(x)])
               for a in rep["axes"]])
cov_chk = (Vc * sc**2) @ Vc.T
cov_seed = A @ np.cov(Rs.T, ddof=1) @ A.T
cov_probe = A @ (dev.T @ dev / len(dev)) @ A.T
kap = np.array(V["fit"]["moment_band"]["kappa_per_m"])
from jaxform.materials import VoceBending
mt = np.asarray(VoceBending(*V["_bw"].TRUTH).moment(kap))
names = ("b_inf", "m0", "kappa0", "b_init")
res = {"chi_square": chi2, "c": c, "seeds": S, "seed_ok": seed_ok, "chi_square_seeds": chi_seeds,
       "seed_rows_rms_dev": float(np.sqrt(np.mean(np.var(Rs, axis=0, ddof=1)))),
       "probe_rows_rms_dev": float(np.sqrt(np.mean(dev**2))), "q_shift_seeds": [(-(A @ (r - r0))).tolist() for r in Rs[1:]],
       "runs": runs.runs, "wall_s": None, "covariances": {}}
for name, C in (("laplace", cov_lap), ("checked", cov_chk), ("seeds_only", cov_seed), ("laplace+seeds", cov_lap + cov_seed),
                ("checked+seeds", cov_chk + cov_seed), ("laplace+probes", cov_lap + cov_probe),
                ("checked+probes", cov_chk + cov_probe)):
    sig = np.sqrt(np.diag(T @ C @ T.T))
    d = q - q_true
    m, sm, _ = moment_band(q, C, kap)
    res["covariances"][name] = {"sd_rel": dict(zip(names, (sig / phys).tolist())),
                                "truth_in_sds": dict(zip(names, ((phys - truth) / sig).tolist())),
                                "mahalanobis": float(np.sqrt(d @ np.linalg.solve(C, d))),
                                "moment_sd_rel": (sm / m).tolist(), "moment_truth_in_sds": ((m - mt) / sm).tolist()}
res["wall_s"] = time.perf_counter() - t0
print(json.dumps(res, indent=1))
json.dump(res, open(sys.argv[1], "w"), indent=1)
