"""Does averaging over seeded imperfections of the blank (the fit's ``seeds``, randomised smoothing)
remove the barrier between the round trip's stall and the truth (20261206T-qs-width-scan: along the
straight line, loss at 8 mm smoothing 564 -> 4,470 -> 3,287 -> 1,689 -> 882 -> 81)? The same line,
each law run from 4 blanks (seed 0 perfect, seeds 1-3 imperfect, the fit's default amplitude: a
tenth of the ply thickness); per blank the loss, and the loss of the blanks' mean amplitude (what
``fit_wrinkles(seeds=4)`` scores), at smoothing widths 0, 8 and 24 mm.
Run: python 20261206T-qs-seed-scan.py OUT.json (both cores, nothing else running; about 13 min)."""
import dataclasses, json, sys, time
import numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1]))
from bench_wrinkle_fit import TRUTH, FIT_LINES, OVERRIDES, make_sections
from jaxform import cases
from jaxform.calibrate import sections as sec_mod
from jaxform.calibrate.section_runs import SectionRuns, _key, parallel
from jaxform.calibrate.transforms import q_from_law
from jaxform.materials import VoceBending

SEEDS = 4
case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=TRUTH))
t0 = time.perf_counter()
sections, _ = make_sections(truth_case, FIT_LINES, np.random.default_rng(16))
qt = q_from_law(VoceBending(*TRUTH), "voce")
qs_ = np.array([-8.344, -4.054, 4.085])
pts = {f"t={t:.1f}": qs_ + t * (qt - qs_) for t in (0.0, 0.2, 0.4, 0.6, 0.8, 1.0)}
width, workers = parallel(None, None, 2)
runs = SectionRuns(case, sections, "voce", SEEDS, 0.1 * case.ply_thickness, width, 1, workers)
chunks = [[(_key(q), i)] for q in pts.values() for i in range(SEEDS)]
done = runs._run(chunks)
meas = np.concatenate([s.amplitude for s in sections])
W = (0, 8, 24)
Rs = {w: sec_mod.weights(sections, 5e-5, w * 1e-3) for w in W}
out = {"seeds": SEEDS, "imperfection_m": 0.1 * case.ply_thickness, "widths_mm": list(W), "points": {}}
for j, (k, q) in enumerate(pts.items()):
    ys = [done[j * SEEDS + i] for i in range(SEEDS)]
    ok = all(bool(d[2][0]) for d in ys)
    valid = np.all([d[1][0] for d in ys], axis=0)
    row = {"q": list(map(float, q)), "ok": ok}
    for w in W:
        per = [0.5 * float(np.sum((Rs[w] @ np.where(valid, d[0][0].astype(float) - meas, 0.0)) ** 2)) if d[2][0] else None
               for d in ys]
        ym = np.mean([d[0][0].astype(float) for d in ys], axis=0)
        row[f"w{w}"] = {"per_blank": per, "mean_of_losses": float(np.mean(per)) if ok else None,
                        "loss_of_mean": 0.5 * float(np.sum((Rs[w] @ np.where(valid, ym - meas, 0.0)) ** 2)) if ok else None}
    out["points"][k] = row
    print(k, ok, {w: row[f"w{w}"] for w in W} if not ok else
          {w: [round(v) for v in row[f"w{w}"]["per_blank"]] + [round(row[f"w{w}"]["loss_of_mean"])] for w in W}, flush=True)
out["forming_runs"] = runs.runs
out["wall_s"] = time.perf_counter() - t0
json.dump(out, open(sys.argv[1], "w"), indent=1)
if not all(r["ok"] for r in out["points"].values()):
    sys.exit(f"{sys.argv[0]}: a forming run failed (ok false in {sys.argv[1]})")
