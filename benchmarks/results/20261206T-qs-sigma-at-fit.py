"""Does the fit's reported uncertainty cover the truth where the local fit ends consistent with the
noise but 16 % off in B_init (20261206T-qs-local-step-old/new: loss 174 / 137, p = 0.015 / 0.059)?
fit_wrinkles started at the law the local fit reached (20261206T-qs-local-step-new.json), on the
round trip's data, one start, one optimiser evaluation, no gradient check, the sigma check's
default rounds and scatter seeds: its sd per parameter against the truth's offset.
Run: python 20261206T-qs-sigma-at-fit.py OUT.json (both cores, nothing else running)."""
import dataclasses, json, sys, time
from pathlib import Path
import numpy as np
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, OVERRIDES, make_sections
from jaxform import cases
from jaxform.calibrate import wrinkle_fit
from jaxform.calibrate.transforms import law_from_q

case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
q = np.array(json.load(open(Path(__file__).with_name("20261206T-qs-local-step-new.json")))["q_final"])
law = law_from_q(q, "voce")
start_case = dataclasses.replace(case, fabric=dataclasses.replace(
    case.fabric, voce=(float(law.b_inf), float(law.m0), float(law.kappa0))))
t0 = time.perf_counter()
fit = wrinkle_fit.fit_wrinkles(start_case, sections, n_starts=1, restarts=0, max_iter=1, gradient_check=False,
                               callback=lambda p: print(f"[{time.perf_counter() - t0:.0f} s] {p.stage}: {p.forming_runs} runs,"
                                                        f" best {p.loss:.4g}", flush=True))
d = fit.as_dict()
tr = {"b_inf": TRUTH[0], "m0": TRUTH[1], "kappa0": TRUTH[2], "b_init": TRUTH[0] + TRUTH[1] / TRUTH[2]}
d["truth_offset_in_sds"] = {k: (d[f"{k}_{u}"] - tr[k]) / d[f"sigma_{k}_{u}"] if d[f"sigma_{k}_{u}"] else None
                            for k, u in (("b_inf", "Nm"), ("m0", "N"), ("kappa0", "per_m"), ("b_init", "Nm"))}
d["wall_s"] = time.perf_counter() - t0
print(json.dumps({k: d[k] for k in ("b_init_Nm", "sigma_b_init_Nm", "truth_offset_in_sds", "determined", "converged",
                                    "reason", "loss_final", "forming_runs")}, indent=1, default=str))
json.dump(d, open(sys.argv[1], "w"), indent=1, default=str)
