"""bench_wrinkle_gradient at the automatic (quasi-static) speed, steps 0.05/0.1 in log space.
Run: python 20261204T-qs-gradient.py OUT.json [quick] (rollouts checkpointed in segments of sqrt(every) steps: without them the reverse pass asked for 38 GB).
20261204T-qs-gradient-16mm.json: quick (16 mm), one core here; the 8 mm check on the H200 (20261204T-gpu.sh) had not printed in 520 s.
The same check at 500 mm/s is 20261203T031536Z-vm.json (AD 1e276-1e278 against FD of -2.5e6...).
"""
import json, sys, time
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
import bench_wrinkle_gradient as G
from jaxform.calibrate import wrinkle_fit
G.STEPS = (0.05, 0.1)
orig = wrinkle_fit.section_loss
t0 = time.perf_counter()
def sl(*a, **k):
    out = orig(*a, **k)
    print(f"[{time.perf_counter() - t0:.0f} s] losses {[round(float(v), 1) for v in out[0]]} grad {({k: list(map(float, v)) for k, v in out[1].items()}) if out[1] else None}", flush=True)
    return out
wrinkle_fit.section_loss = sl
res = G.run(len(sys.argv) > 2 and sys.argv[2] == "quick")
json.dump(res, open(sys.argv[1], "w"), indent=1, default=str)
print(json.dumps({k: v for k, v in res.items() if k != "scan"}, indent=1, default=str))
for n, s in res["scan"].items():
    print(n, "ad", s["ad"], "fd", s["fd"], "loss", [round(v, 1) for v in s["loss"]])
