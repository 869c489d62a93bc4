"""ms a step over W steps (default 2000) from saved states of the shipped 2 mm woven run (profile_run.py), with
the jaxform first on sys.path; exit 1 if a window went bad. Run: python ab_windows.py start,41450,82900,124350 2000 STATE_DIR"""
from pathlib import Path
import sys, time, pickle, json, jax, jax.numpy as jnp
import jaxform
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod
case = cases.with_element_size(cases.load("case-a-woven-nlbm"), 2e-3)
r = rigmod.build(case)
model = r.model
adv = jax.jit(integrate.advance)
W = int(sys.argv[2]) if len(sys.argv) > 2 else 2000
out = {"tree": jaxform.__file__, "rows": []}
for name in sys.argv[1].split(","):
    st = r.state if name == "start" else jax.tree_util.tree_map(jnp.asarray, pickle.load(open(Path(sys.argv[3]) / f"state_{name}.pkl", "rb")))
    st = jax.tree_util.tree_unflatten(jax.tree_util.tree_structure(r.state), jax.tree_util.tree_leaves(st))
    adv(model, st, 1).x.block_until_ready()
    t0 = time.perf_counter(); e = adv(model, st, W); e.x.block_until_ready(); dt = time.perf_counter() - t0
    row = {"state": name, "step": int(st.step), "ms_per_step": 1e3 * dt / W, "refreshes": int(e.loads[3].refreshes) - int(st.loads[3].refreshes), "bad": int(e.bad_step)}
    out["rows"].append(row); print(row, flush=True)
print(json.dumps(out))
sys.exit("ab_windows.py: a window left its bounds (bad step)" if any(r["bad"] >= 0 for r in out["rows"]) else 0)
