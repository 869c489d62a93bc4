"""The shipped 2 mm woven run stepped in windows: ms a step, self-contact refreshes, its active
set and overflow, along the whole stroke; states saved at a quarter, half and three quarters. Exit 1 if
the run left its bounds. Run: python profile_run.py OUT_DIR"""
from pathlib import Path
import sys, time, json, pickle, numpy as np, jax, jax.numpy as jnp
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod
W = 2000
OUT = Path(sys.argv[1]); OUT.mkdir(parents=True, exist_ok=True)
case = cases.with_element_size(cases.load("case-a-woven-nlbm"), 2e-3)
r = rigmod.build(case)
model = r.model
adv = jax.jit(integrate.advance)
s = r.state
adv(model, s, 1).x.block_until_ready()
n = r.info.n_steps
out = open(OUT / "profile_run.jsonl", "w")
t_all = time.perf_counter()
save_at = {n // 4, n // 2, 3 * n // 4}

while int(s.step) < n:
    m = min(W, n - int(s.step))
    t0 = time.perf_counter()
    s2 = adv(model, s, m); s2.x.block_until_ready()
    dt = time.perf_counter() - t0
    c = s2.loads[3].candidates
    row = {"step": int(s2.step), "ms_per_step": 1e3 * dt / m, "refreshes": int(s2.loads[3].refreshes) - int(s.loads[3].refreshes),
           "active_nodes": int(jnp.sum(c.active_nodes >= 0)), "active_edges": int(jnp.sum(c.active_edges >= 0)),
           "overflow": bool(c.overflow), "bad_step": int(s2.bad_step), "punch_mm": float(s2.t) * 62.5}
    out.write(json.dumps(row) + "\n"); out.flush()
    s = s2
    if int(s.bad_step) >= 0:
        break
    for a in list(save_at):
        if int(s.step) >= a:
            pickle.dump(jax.tree_util.tree_map(np.asarray, s), open(OUT / f"state_{a}.pkl", "wb"))
            save_at.discard(a)
out.write(json.dumps({"total_s": time.perf_counter() - t_all, "steps": int(s.step)}) + "\n")
pickle.dump(jax.tree_util.tree_map(np.asarray, s), open(OUT / "state_end.pkl", "wb"))
sys.exit(f"profile_run.py: the run left its bounds at step {int(s.bad_step)}" if int(s.bad_step) >= 0 else 0)
