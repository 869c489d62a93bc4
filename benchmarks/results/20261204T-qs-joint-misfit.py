"""The misfit test (jaxform.calibrate.uncertainty.misfit) on the joint fit at 62.5 mm/s
(20261204T-qs-joint.json: loss 557.0, converged by the rules of then) and at the hidden law itself
(loss 95.38, 20261204T-qs-joint-truth.py), and on the round trip (20261203T-qs-rt.json: loss 279;
the truth 51). Run: python 20261204T-qs-joint-misfit.py OUT.json"""
import dataclasses, json, pathlib, sys
import numpy as np
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import bench_wrinkle_fit as bw
import bench_wrinkle_joint as J
from jaxform import cases
from jaxform.calibrate import sections as S
from jaxform.calibrate.uncertainty import misfit
case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=bw.OVERRIDES)
truth = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=bw.TRUTH))
secs, _ = bw.make_sections(truth, bw.FIT_LINES, np.random.default_rng(16))
mean, var = S.chi_square_moments(S.weights(secs, bw.NOISE, 8e-3), bw.NOISE)
out = {"round_trip": {"fit": misfit(2 * 279.0, mean, var), "truth": misfit(2 * 51.0, mean, var)},
       "joint": {"fit": misfit(2 * 557.0076, mean + J.N_POINTS, var + 2 * J.N_POINTS),
                 "truth": misfit(2 * 95.3809, mean + J.N_POINTS, var + 2 * J.N_POINTS)}}
json.dump(out, open(sys.argv[1], "w"), indent=1)
print(json.dumps(out, indent=1))
