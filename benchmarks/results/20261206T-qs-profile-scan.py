"""Is the barrier between the round trip's stall and its truth (20261206T-qs-width-scan: 564 ->
4,470 -> 3,287 -> 1,689 -> 882 -> 81 at 8 mm smoothing along the straight line; not removed by
averaging over imperfect blanks, 20261206T-qs-seed-scan) only the straight line leaving a curved
valley? At t = 0.2, 0.4, 0.6 of that line, the loss with log B_init moved by -0.1, -0.05, +0.05,
+0.1 (the steep direction: +-0.1 from the truth costs 5,185 / 8,402): the loss profiled over B_init.
Run: python 20261206T-qs-profile-scan.py OUT.json (both cores, nothing else running; about 8 min)."""
import dataclasses, json, sys, time
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, OVERRIDES, make_sections
from jaxform import cases
from jaxform.calibrate import sections as sec_mod
from jaxform.calibrate.section_runs import SectionRuns, parallel
from jaxform.calibrate.transforms import q_from_law
from jaxform.materials import VoceBending

case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
t0 = time.perf_counter()
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
qt = q_from_law(VoceBending(*TRUTH), "voce")
qs_ = np.array([-8.344, -4.054, 4.085])
pts = {(t, d): qs_ + t * (qt - qs_) + d * np.eye(3)[0] for t in (0.2, 0.4, 0.6) for d in (-0.1, -0.05, 0.05, 0.1)}
width, workers = parallel(None, None, 2)
runs = SectionRuns(case, sections, "voce", 1, 0.0, width, 1, workers)
evs = runs.evaluate(list(pts.values()))
meas = np.concatenate([s.amplitude for s in sections])
W = (0, 8, 24)
Rs = {w: sec_mod.weights(sections, 5e-5, w * 1e-3) for w in W}
out = {"line": {"from (stall)": qs_.tolist(), "to (truth)": qt.tolist()}, "widths_mm": list(W), "points": []}
for ((t, d), q), (y, v, ok, reach) in zip(pts.items(), evs):
    row = {"t": t, "d_log_b_init": d, "q": list(map(float, q)), "ok": ok}
    row.update({f"loss_w{w}": 0.5 * float(np.sum((Rs[w] @ np.where(v, y - meas, 0.0)) ** 2)) if ok else None for w in W})
    out["points"].append(row)
    print(t, d, ok, [round(row[f"loss_w{w}"]) if ok else None for w in W], flush=True)
out["forming_runs"] = runs.runs
out["wall_s"] = time.perf_counter() - t0
json.dump(out, open(sys.argv[1], "w"), indent=1)
if not all(r["ok"] for r in out["points"]):
    sys.exit(f"{sys.argv[0]}: a forming run failed (ok false in {sys.argv[1]})")
