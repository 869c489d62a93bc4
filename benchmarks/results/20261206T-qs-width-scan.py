"""Is the round trip's landscape smoother at a wider residual smoothing? The section loss of the
round trip's data (bench_wrinkle_fit: its hidden law, rng 16, 8 mm, the automatic speed) on the
straight line from the law where the fit stalls (20261205T-qs-rt-stall-points) to the truth, around
the truth (log B_init +-0.03, +-0.1; log kappa0 +-0.1) and at the preset start, each law run once
and scored at smoothing widths 0 to 48 mm, every width's loss in its own noise sds.
Run: python 20261206T-qs-width-scan.py OUT.json (both cores, nothing else running; about 8 min)."""
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
pts = {f"line t={t:.1f}": qs_ + t * (qt - qs_) for t in (0.0, 0.2, 0.4, 0.6, 0.8)}
pts["truth"] = qt
pts.update({f"truth B_init {d:+g}": qt + d * np.eye(3)[0] for d in (-0.1, -0.03, 0.03, 0.1)})
pts.update({f"truth kappa0 {d:+g}": qt + d * np.eye(3)[2] for d in (-0.1, 0.1)})
width, workers = parallel(None, None, len(pts))
runs = SectionRuns(case, sections, "voce", 1, 0.0, width, 1, workers)
pts["preset start"] = q_from_law(runs.law0, "voce")
evs = runs.evaluate(list(pts.values()))
meas = np.concatenate([s.amplitude for s in sections])
out = {"truth_q": qt.tolist(), "stall_q": qs_.tolist(), "widths_mm": [0, 4, 8, 16, 24, 32, 48], "points": {}}
for (k, q), (y, v, ok, reach) in zip(pts.items(), evs):
    row = {"q": list(map(float, q)), "ok": ok, "kappa_reach": reach}
    for w in out["widths_mm"]:
        R = sec_mod.weights(sections, 5e-5, w * 1e-3)
        row[f"loss_w{w}"] = 0.5 * float(np.sum((R @ np.where(v, y - meas, 0.0)) ** 2)) if ok else None
    out["points"][k] = row
    print(k, {w: round(row[f"loss_w{w}"]) for w in out["widths_mm"]} if ok else "failed", flush=True)
out["chi2_mean_at_truth"] = {w: sec_mod.chi_square_moments(sec_mod.weights(sections, 5e-5, w * 1e-3), 5e-5)[0]
                             for w in out["widths_mm"]}
out["wall_s"] = time.perf_counter() - t0
json.dump(out, open(sys.argv[1], "w"), indent=1)
if not all(r["ok"] for r in out["points"].values()):
    sys.exit(f"{sys.argv[0]}: a forming run failed (ok false in {sys.argv[1]})")
