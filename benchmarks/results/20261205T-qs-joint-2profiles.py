"""The joint fit of issue 16 (done-when 3) as 20261204T-qs-joint-cstart.py (max_iter 16, no gradient check, the
fit's defaults, both cores), with the benchmark's two cantilever specimens (80 and 65 mm overhang; until
this record one, 80 mm). Run: python 20261205T-qs-joint-2profiles.py OUT.json (nothing else running).
"""
import json, pathlib, sys, time
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import bench_wrinkle_joint as J
from jaxform.calibrate import wrinkle_fit
orig = wrinkle_fit.fit_wrinkles
def fw(*a, **k):
    k.setdefault("gradient_check", False)
    k.setdefault("max_iter", 16)
    t0 = time.perf_counter()
    k["callback"] = lambda p: print(f"[{time.perf_counter() - t0:.0f} s] {p.stage}: {p.forming_runs} runs, best {p.loss:.4g} at {[round(v, 4) for v in p.q]}", flush=True)
    return orig(*a, **k)
wrinkle_fit.fit_wrinkles = fw
res = J.run(False)
json.dump(res, open(sys.argv[1], "w"), indent=1, default=str)
print(json.dumps({k: v for k, v in res.items() if k != "fit"}, indent=1, default=str))
f = res["fit"]; print({k: f[k] for k in ("b_inf_Nm", "m0_N", "kappa0_per_m", "b_init_Nm", "converged", "reason", "forming_runs", "loss_final", "determined", "misfit", "local_fits", "cantilever_start")})
