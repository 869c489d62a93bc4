"""The joint fit (bench_wrinkle_joint: woven Case A, 8 mm, automatic 62.5 mm/s) with a finer
forward-difference step: one local fit (restarts 0) from the better of the preset law and the
profiles' own law (n_starts 1), max_iter 16, no gradient check, the profiles' rows of the Jacobian
exact (the cantilever's AD, since this commit's parent). Run: python THIS OUT.json FD_STEP (both
cores; here 0.0125 against the default 0.05; a 7-min study smoke test and unit tests ran beside it
for part of the time, so its wall time is no benchmark)."""
import json, pathlib, sys, time
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import bench_wrinkle_joint as J
from jaxform.calibrate import wrinkle_fit
orig = wrinkle_fit.fit_wrinkles
def fw(*a, **k):
    k.update(gradient_check=False, max_iter=16, restarts=0, n_starts=1, fd_step=float(sys.argv[2]))
    t0 = time.perf_counter()
    k["callback"] = lambda p: print(f"[{time.perf_counter() - t0:.0f} s] {p.stage}: {p.forming_runs} runs, best {p.loss:.4g} at {[round(v, 4) for v in p.q]}", flush=True)
    return orig(*a, **k)
wrinkle_fit.fit_wrinkles = fw
res = J.run(False)
json.dump(res, open(sys.argv[1], "w"), indent=1, default=str)
print(json.dumps({k: v for k, v in res.items() if k != "fit"}, indent=1, default=str))
f = res["fit"]; print({k: f.get(k) for k in ("b_inf_Nm", "m0_N", "kappa0_per_m", "b_init_Nm", "converged", "reason", "forming_runs", "loss_final", "determined", "misfit", "local_fits", "cantilever_start")})
