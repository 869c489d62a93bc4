"""ms/step of a preset with pieces removed: python ablate.py SIZE_MM [PRESET] (run_steps scan, 200 steps after 500;
best of 3). Without the fibre mass the preset's step is unstable and a NaN state makes the contact search
rebuild every step: that variant is not timed."""
import sys, time, dataclasses, jax
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod
size = float(sys.argv[1])
r = rigmod.build(cases.with_element_size(cases.load(sys.argv[2] if len(sys.argv) > 2 else "case-a-woven-nlbm"), size * 1e-3))
m, s, info = r
adv = jax.jit(integrate.advance, static_argnums=2)
s = adv(m, s, 500); s.x.block_until_ready()
N = 200
def variant(name, model, state):
    f = jax.jit(lambda mm, ss: integrate.run_steps(mm, ss, N)[0])
    f(model, state).x.block_until_ready()
    best = 1e9
    for _ in range(3):
        t0 = time.perf_counter(); f(model, state).x.block_until_ready(); best = min(best, (time.perf_counter()-t0)/N*1e3)
    print(f"{name:40s} {best:.3f} ms/step", flush=True)
names = [type(l).__name__ + ("" if getattr(l, "tool", None) is None else ":" + type(l.tool).__name__) for l in m.loads]
variant("full", m, s)
for i, nm in enumerate(names):
    keep = [j for j in range(len(m.loads)) if j != i]
    variant(f"without load {nm}", dataclasses.replace(m, loads=tuple(m.loads[j] for j in keep)),
            dataclasses.replace(s, loads=tuple(s.loads[j] for j in keep)))
variant("no loads", dataclasses.replace(m, loads=()), dataclasses.replace(s, loads=()))
