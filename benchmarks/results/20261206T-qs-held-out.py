"""The round trip's held-out section (bench_wrinkle_fit: HELD_OUT, its noisy and clean data from
rng 16 after the fit's sections) predicted by the preset start, the stall of the earlier fits
(-8.344, -4.054, 4.085), the law the local fit reached with the first trust radius FIRST_STEP (a variant not kept)
(20261206T-qs-local-step-new.json) and the truth; RMS against the noisy and the clean data, and
each law's largest M(kappa) error over 0 < kappa <= 50.6 1/m (the round trip's kappa_reach).
Run: python 20261206T-qs-held-out.py OUT.json (about 5 min)."""
import dataclasses, json, sys, time
from pathlib import Path
import numpy as np
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, HELD_OUT, OVERRIDES, make_sections, held_out_rms, moment_error
from jaxform import cases
from jaxform.calibrate.transforms import law_from_q, q_from_law
from jaxform.materials import VoceBending

case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
rng = np.random.default_rng(16)
make_sections(truth_case, FIT_LINES, rng)
held, clean = make_sections(truth_case, HELD_OUT, rng)
fitted = json.load(open(Path(__file__).with_name("20261206T-qs-local-step-new.json")))["q_final"]
laws = {"preset start": None, "stall": law_from_q(np.array([-8.344, -4.054, 4.085]), "voce"),
        "local fit, FIRST_STEP": law_from_q(np.array(fitted), "voce"), "truth": VoceBending(*TRUTH)}
t0, out = time.perf_counter(), {}
for k, law in laws.items():
    noisy, cl = held_out_rms(case, law, held, clean)
    law_ = VoceBending(1.549e-5, 7.57e-3, 20.0) if law is None else law  # the woven preset (bench_wrinkle_fit)
    out[k] = {"q": q_from_law(law_, "voce").tolist(), "held_out_rms_mm": 1e3 * noisy, "held_out_rms_clean_mm": 1e3 * cl,
              "moment_error": moment_error(law_, VoceBending(*TRUTH), 50.6)}
    print(k, out[k], flush=True)
out["ratio_start_over_fit_noisy"] = out["preset start"]["held_out_rms_mm"] / out["local fit, FIRST_STEP"]["held_out_rms_mm"]
out["ratio_start_over_fit_clean"] = (out["preset start"]["held_out_rms_clean_mm"]
                                     / out["local fit, FIRST_STEP"]["held_out_rms_clean_mm"])
out["wall_s"] = time.perf_counter() - t0
print(out["ratio_start_over_fit_noisy"], out["ratio_start_over_fit_clean"])
json.dump(out, open(sys.argv[1], "w"), indent=1)
