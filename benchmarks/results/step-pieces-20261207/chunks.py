"""Per-chunk ms/step over a preset's stroke (driver.run) against the bare integrate.advance at the start and the
end state: python chunks.py SIZE_MM PRESET"""
import sys, time, jax, numpy as np
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod, driver
size, preset = float(sys.argv[1]), sys.argv[2]
r = rigmod.build(cases.with_element_size(cases.load(preset), size * 1e-3))
rows = []
def prog(step, n, t, d, el):
    rows.append((step, el))
res = driver.run(r, on_progress=prog)
print("wall", res.wall_time_s, "complete", res.complete, "sub_steps", r.info.sub_steps, flush=True)
st, el = np.array([a for a, b in rows]), np.array([b for a, b in rows])
ms = 1e3 * np.diff(el) / np.diff(st)
for k in range(0, len(ms), max(1, len(ms) // 20)):
    print(f"step {st[k+1]:7d}  {ms[k]:.3f} ms/step", flush=True)
print("first chunk (incl compile)", el[0], "median", np.median(ms), "mean", np.mean(ms))
adv = jax.jit(integrate.advance, static_argnums=2)
for name, s in (("start", r.state), ("end", res.final_state)):
    s1 = adv(r.model, s, 300); s1.x.block_until_ready()
    t0 = time.perf_counter(); s2 = adv(r.model, s1, 300); s2.x.block_until_ready()
    print(f"bare advance at {name}: {1e3*(time.perf_counter()-t0)/300:.3f} ms/step", flush=True)
