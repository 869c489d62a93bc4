"""The joint fit's loss (20261204T-qs-joint.py's sections and profile) at the hidden law itself: the
fit's first evaluation, started from the truth, then stopped. Run: python 20261204T-qs-joint-truth.py"""
import dataclasses, pathlib, sys
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import bench_wrinkle_joint as J
from jaxform.calibrate import wrinkle_fit
orig = wrinkle_fit.fit_wrinkles

class Done(Exception):
    pass

def fw(case, *a, **k):
    case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=J._bw.TRUTH))
    def cb(p):
        print(p.stage, p.forming_runs, p.loss, flush=True)
        if p.forming_runs >= 1:
            raise Done(f"loss at the truth {p.loss:.6g}")
    return orig(case, *a, **{**k, "gradient_check": False, "n_starts": 1, "callback": cb})
wrinkle_fit.fit_wrinkles = fw
try:
    J.run(False)
except Done as d:
    print(d)
