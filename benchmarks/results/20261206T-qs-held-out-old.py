"""20261206T-qs-held-out.py for the law where 749ed0c's local fit ended (20261206T-qs-local-step-old.json,
loss 174): its held-out RMS and the ratio to the preset start's (0.16978 mm noisy, 0.17209 mm clean,
in 20261206T-qs-held-out.json). Run: python 20261206T-qs-held-out-old.py OUT.json (about 3 min)."""
import dataclasses, json, sys, time
from pathlib import Path
import numpy as np
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, HELD_OUT, OVERRIDES, make_sections, held_out_rms, moment_error
from jaxform import cases
from jaxform.calibrate.transforms import law_from_q
from jaxform.materials import VoceBending

case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
rng = np.random.default_rng(16)
make_sections(truth_case, FIT_LINES, rng)
held, clean = make_sections(truth_case, HELD_OUT, rng)
here = Path(__file__).parent
q = json.load(open(here / "20261206T-qs-local-step-old.json"))["q_final"]
start = json.load(open(here / "20261206T-qs-held-out.json"))["preset start"]
t0 = time.perf_counter()
law = law_from_q(np.array(q), "voce")
noisy, cl = held_out_rms(case, law, held, clean)
out = {"q": q, "held_out_rms_mm": 1e3 * noisy, "held_out_rms_clean_mm": 1e3 * cl,
       "moment_error": moment_error(law, VoceBending(*TRUTH), 50.6),
       "ratio_start_over_fit_noisy": start["held_out_rms_mm"] / (1e3 * noisy),
       "ratio_start_over_fit_clean": start["held_out_rms_clean_mm"] / (1e3 * cl), "wall_s": time.perf_counter() - t0}
print(json.dumps(out, indent=1))
json.dump(out, open(sys.argv[1], "w"), indent=1)
