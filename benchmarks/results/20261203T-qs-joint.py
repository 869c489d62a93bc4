"""bench_wrinkle_joint at the automatic (quasi-static) speed, without the gradient check.
Run: python 20261203T-qs-joint.py 20261203T-qs-joint.json (at a78b477, before the fit moved to a better probe; the other core ran the round trip).
"""
import json, sys, time
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
import bench_wrinkle_joint as J
from jaxform.calibrate import wrinkle_fit
orig = wrinkle_fit.fit_wrinkles
def fw(*a, **k):
    k.setdefault("gradient_check", False)
    t0 = time.perf_counter()
    k["callback"] = lambda p: print(f"[{time.perf_counter() - t0:.0f} s] {p.stage}: {p.forming_runs} runs, best {p.loss:.4g}", flush=True)
    return orig(*a, **k)
wrinkle_fit.fit_wrinkles = fw
res = J.run(False)
json.dump(res, open(sys.argv[1], "w"), indent=1, default=str)
print(json.dumps({k: v for k, v in res.items() if k != "fit"}, indent=1, default=str))
f = res["fit"]; print({k: f[k] for k in ("b_inf_Nm", "m0_N", "kappa0_per_m", "b_init_Nm", "converged", "reason", "forming_runs", "loss_final", "determined")})
