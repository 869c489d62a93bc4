"""The local fit alone (fit_wrinkles step 4-5, one start, no restarts) from the best start of the
round trip's global phase (20261205T-qs-rt-implicit: q = (-8.394, -4.154, 4.085), the stall's
basin), on the round trip's data (bench_wrinkle_fit: its hidden law, rng 16, 8 mm, the automatic
speed): each law the fit runs and its loss, in order. Run with the code to compare (its first
trust radius: |q0| in q, or FIRST_STEP). Run: python 20261206T-qs-local-step.py OUT.json (both
cores, nothing else running; about 20 min). No sigma check rounds, no scatter runs.

Records of 2026-12-06: -old.json is 749ed0c's code (least_squares in q with bounds). -new.json is a
variant that was not kept: least_squares unbounded in u = (q - q_start) / 0.1 (FIRST_STEP = 0.1, so
the first trust radius is 0.1 in q), the law clipped to the bounds. Both took the same first step
(about +0.04 in log B_init) and ended at losses 174 and 137: the first radius was not what stalled
the earlier fits, so the variant was dropped."""
import dataclasses, json, sys, time
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, OVERRIDES, make_sections
from jaxform import cases
from jaxform.calibrate import sections as sec_mod, wrinkle_fit
from jaxform.calibrate.section_runs import SectionRuns
from jaxform.calibrate.transforms import law_from_q

case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
start = np.array([-8.393645716357995, -4.153530901590972, 4.085455322584545])
law = law_from_q(start, "voce")
start_case = dataclasses.replace(case, fabric=dataclasses.replace(
    case.fabric, voce=(float(law.b_inf), float(law.m0), float(law.kappa0))))
R = sec_mod.weights(sections, 5e-5, 8e-3)
meas = np.concatenate([s.amplitude for s in sections])
trace = []
_evaluate = SectionRuns.evaluate


def evaluate(self, qs):
    out = _evaluate(self, qs)
    for q, (y, v, ok, _) in zip(qs, out):
        loss = 0.5 * float(np.sum((R @ np.where(v, y - meas, 0.0)) ** 2)) if ok else None
        if not trace or trace[-1]["q"] != list(map(float, q)):
            trace.append({"q": list(map(float, q)), "loss": loss, "runs": self.runs})
    return out


SectionRuns.evaluate = evaluate
t0 = time.perf_counter()
fit = wrinkle_fit.fit_wrinkles(start_case, sections, n_starts=1, restarts=0, gradient_check=False, check_rounds=0,
                               scatter_seeds=0)
out = {"first_step": getattr(wrinkle_fit, "FIRST_STEP", "|q0| (scipy's default)"), "start": start.tolist(),
       "trace": trace, "q_final": fit.q.tolist(), "loss_final": fit.loss_final, "iterations": fit.iterations,
       "moves": fit.moves, "forming_runs": fit.forming_runs, "wall_s": time.perf_counter() - t0,
       "misfit": fit.misfit}
for t in trace:
    print(np.round(np.array(t["q"]) - start, 3), t["loss"] and round(t["loss"]), t["runs"])
print("final", fit.q, fit.loss_final, fit.forming_runs)
json.dump(out, open(sys.argv[1], "w"), indent=1)
