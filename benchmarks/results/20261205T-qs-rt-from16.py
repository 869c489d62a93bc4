"""The round trip's local fit from the best of 16 starts (20261205T-qs-rt-starts: loss 3,965 at log
(B_init, B_inf/B_init, kappa0) = (-8.04, -2.34, 3.34)): the fit run with that law as its start and
one start (n_starts=1), no restarts, no gradient check, the sigma check's first probes only and no
scatter runs (the local fit is the question). Run: python 20261205T-qs-rt-from16.py OUT.json."""
import dataclasses, json, sys, time
import numpy as np
import jax.numpy as jnp
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, OVERRIDES, make_sections, moment_error
from jaxform import cases
from jaxform.calibrate import wrinkle_fit
from jaxform.calibrate.transforms import law_from_q
from jaxform.materials import VoceBending

case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
best = json.load(open(__import__("pathlib").Path(__file__).with_name("20261205T-qs-rt-starts.json")))
q16 = min(best["n16"], key=lambda e: e["loss"])["q"]
law = law_from_q(jnp.asarray(q16), "voce")
start = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=(float(law.b_inf), float(law.m0), float(law.kappa0))))
t0 = time.perf_counter()
stamp = lambda p: print(f"[{time.perf_counter() - t0:.0f} s] {p.stage}: {p.forming_runs} runs, best loss {p.loss:.4g} q={np.round(p.q, 3)}", flush=True)
fit = wrinkle_fit.fit_wrinkles(start, sections, n_starts=1, restarts=0, gradient_check=False, check_rounds=0,
                               scatter_seeds=0, callback=stamp)
truth = VoceBending(*TRUTH)
out = {"q_start": q16, "loss_final": fit.loss_final, "q": fit.q.tolist(), "converged": fit.converged, "reason": fit.reason,
       "forming_runs": fit.forming_runs, "wall_s": time.perf_counter() - t0, "kappa_reach": fit.kappa_reach,
       "moment_err": moment_error(fit.law, truth, fit.kappa_reach), "values": fit.values,
       "misfit_p": fit.misfit["p_value"]}
print(json.dumps(out, indent=1, default=str))
json.dump(out, open(sys.argv[1], "w"), indent=1, default=str)
