"""20261203T-qs-joint.py (bench_wrinkle_joint at the automatic speed, no gradient check) with twice
the default evaluations (max_iter 16: at 8 the joint fit ran out of them, 20261203T-qs-joint.json)
and the runs on both cores (workers: the default, one thread per core).
Run: python 20261204T-qs-joint.py OUT.json (both cores, nothing else running).
"""
import pathlib, runpy, sys
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from jaxform.calibrate import wrinkle_fit
orig = wrinkle_fit.fit_wrinkles
def fw(*a, **k):
    k.setdefault("max_iter", 16)
    return orig(*a, **k)
wrinkle_fit.fit_wrinkles = fw
runpy.run_path(str(pathlib.Path(__file__).with_name("20261203T-qs-joint.py")), run_name="__main__")
