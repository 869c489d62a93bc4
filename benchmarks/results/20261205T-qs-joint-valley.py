"""Where the joint fit's truth lies on the loss (record 20261205T-qs-joint-axes): the chi-square of
the joint fit's rows (sections and the two profiles, rebuilt exactly as fit_wrinkles builds them)
at the fit, at the truth, and along the family of Voce laws whose M(kappa) matches the fit's over
0..kappa_reach (for each log(B_inf/B_init) between the fit's and the truth's and beyond, the
log B_init and log kappa0 that fit the fitted M in the least-squares sense on 200 curvatures).
Run: python 20261205T-qs-joint-valley.py OUT.json (nothing else running; about 6 min)."""
import dataclasses, json, pathlib, sys, time
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
import numpy as np
import jax
jax.config.update("jax_enable_x64", True)
import bench_wrinkle_joint as BJ
_bw = BJ._bw
from scipy.optimize import least_squares
from jaxform import cantilever, cases
from jaxform.calibrate import Profile, sections as sec_mod
from jaxform.calibrate.cantilever_fit import ProfileModel
from jaxform.calibrate.section_runs import SectionRuns, parallel
from jaxform.calibrate.transforms import law_from_q, q_from_law
from jaxform.materials import VoceBending
import jax.numpy as jnp

fit = json.load(open(pathlib.Path(__file__).with_name("20261205T-qs-joint-axes.json")))["fit"]
q_fit = np.array(fit["local_fits"][0]["q_final"])
reach = fit["kappa_reach_per_m"]
case = cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=_bw.OVERRIDES)
truth_case = dataclasses.replace(case, fabric=dataclasses.replace(case.fabric, voce=_bw.TRUTH))
rng = np.random.default_rng(16)
sections, _ = _bw.make_sections(truth_case, _bw.FIT_LINES, rng)
specimens = [(L, *BJ._profile(rng, L)) for L in BJ.OVERHANGS]
prof = ProfileModel([Profile(x, z, L) for L, x, z, _ in specimens], "voce", cantilever.simulate, {}, BJ.MASS, 1e-5,
                    jnp.result_type(float))
width, workers = parallel(None, None, 2)
runs = SectionRuns(case, sections, "voce", 1, 0.0, width, 1, workers)
R = sec_mod.weights(sections, _bw.NOISE, float(case.element_size))
meas = np.concatenate([s.amplitude for s in sections])


def chi(qs):
    out = []
    for q, (y, v, ok, rch) in zip(qs, runs.evaluate([np.asarray(q, float) for q in qs])):
        rs = R @ np.where(v, y - meas, 0.0)
        rp = np.asarray(prof.rows(jnp.asarray(q)), float) * 1e-3 / _bw.NOISE
        out.append({"q": list(map(float, q)), "chi_sections": float(rs @ rs), "chi_profiles": float(rp @ rp),
                    "chi_square": float(rs @ rs + rp @ rp), "kappa_reach": float(rch), "ok": bool(ok)})
    return out


k = np.linspace(reach / 200, reach, 200)
m_fit = np.asarray(law_from_q(jnp.asarray(q_fit), "voce").moment(k))


def equivalent(q1):  # log B_init, log kappa0 that match the fitted M over 0..reach at log ratio q1
    res = least_squares(lambda v: np.asarray(law_from_q(jnp.asarray([v[0], q1, v[1]]), "voce").moment(k)) / m_fit - 1.0,
                        [q_fit[0], q_fit[2]])
    return np.array([res.x[0], q1, res.x[1]]), float(np.max(np.abs(res.fun)))


q_true = q_from_law(VoceBending(*_bw.TRUTH), "voce")
if __name__ == "__main__":  # (20261205T-qs-joint-check-replay.py runs the set-up above only)
    t0 = time.perf_counter()
    family = [equivalent(q1) for q1 in np.linspace(q_fit[1], q_true[1], 5)[1:].tolist() + [q_true[1] - 0.5, q_fit[1] + 0.4]]
    pts = [q_fit, q_true] + [q for q, _ in family]
    res = chi(pts)
    for r, (q, dev) in zip(res[2:], family):
        r["m_max_rel_dev_from_fit"] = dev
    print(json.dumps(res, indent=1))
    json.dump({"q_fit": q_fit.tolist(), "q_true": q_true.tolist(), "points": res, "wall_s": time.perf_counter() - t0},
              open(sys.argv[1], "w"), indent=1)
    if not all(r["ok"] for r in res):
        sys.exit(f"{sys.argv[1]}: a forming run failed (ok false): the scan is incomplete")
