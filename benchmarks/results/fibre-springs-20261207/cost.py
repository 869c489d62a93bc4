"""ms a step of a preset (default woven Case A NLBM) at SIZE mm from the start, over W steps, for fibre-mass factors
S1,S2,... ("auto": the automatic one), and the whole run's stepping time it implies.
Run: python cost.py SIZE W S1,S2 [PRESET]"""
import sys, time, dataclasses, json, jax
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod
size = float(sys.argv[1]); W = int(sys.argv[2])
adv = jax.jit(integrate.advance)
for s in sys.argv[3].split(","):
    case = cases.with_element_size(cases.load(sys.argv[4] if len(sys.argv) > 4 else "case-a-woven-nlbm"), size * 1e-3)
    case = dataclasses.replace(case, fibre_mass_scaling=None if s == "auto" else float(s))
    r = rigmod.build(case)
    adv(r.model, r.state, 1).x.block_until_ready()
    t0 = time.perf_counter(); e = adv(r.model, r.state, W); e.x.block_until_ready(); t = time.perf_counter() - t0
    fm = r.model.fibre_mass
    print(json.dumps({"size": size, "s": s, "factor": fm.factor, "degree": fm.degree, "springs": bool(fm.strides), "dt": float(r.info.dt), "steps": r.info.n_steps, "ms": 1e3 * t / W,
                      "est_s": r.info.n_steps * t / W, "bad": int(e.bad_step)}), flush=True)
