"""Variants of the 2 mm step compiled in one process, timed in alternating rounds (min and median ms/step)."""
import sys, time, dataclasses, contextlib, statistics
import jax, jax.numpy as jnp, meshio
from jaxform import cases, integrate, broadphase
from jaxform.forming import rig as rigmod
size = float(sys.argv[1]); frame = int(sys.argv[2]); rundir = sys.argv[3]; names = sys.argv[4].split(",")
rounds = int(sys.argv[5]) if len(sys.argv) > 5 else 5
N = 200
def build(case):
    m, s, info = rigmod.build(case)
    pts = meshio.read(f"{rundir}/frames_{frame:05d}.vtu").points
    t = info.stroke_time * frame / (info.n_frames - 1)
    x = jnp.asarray(pts, s.x.dtype)
    ls = (None, None, None) + tuple(ld.initial_state(x) for ld in m.loads[3:])
    s = integrate.init_state(m, x=x, load_states=ls)
    s = dataclasses.replace(s, t=jnp.asarray(t, s.t.dtype), step=jnp.asarray(1, jnp.int32))
    return m, s, info
case = cases.with_element_size(cases.load("case-a-woven-nlbm"), size * 1e-3)
import os
if os.environ.get("IMPLICIT"):
    case = cases.apply_overrides(case, ["contact.implicit_normal=" + os.environ["IMPLICIT"]])
m, s, info = build(case)
print(info.numerics.why, info.dt)
s = jax.jit(lambda mm, ss: integrate.run_steps(mm, ss, 300)[0], compiler_options=integrate.COMPILER_OPTIONS)(m, s)
orig_refreshed = broadphase.refreshed
PATCHES = {}
def norefresh(state, x, search, half, every=0):
    return state._replace(step=state.step + 1)
PATCHES["norefresh"] = [(broadphase, "refreshed", norefresh)]
PATCHES["full"] = []
import variants  # noqa: extra patches registered by a module beside this script
PATCHES.update(variants.PATCHES)
@contextlib.contextmanager
def patched(items):
    old = [(mod, nm, getattr(mod, nm)) for mod, nm, _ in items]
    for mod, nm, new in items: setattr(mod, nm, new)
    try: yield
    finally:
        for mod, nm, o in old: setattr(mod, nm, o)
fs = {}
for nm in names:
    f = jax.jit(lambda mm, ss: integrate.run_steps(mm, ss, N)[0], compiler_options=integrate.COMPILER_OPTIONS)
    with patched(PATCHES[nm]):
        f = f.lower(m, s).compile()
    s1 = f(m, s); s1.x.block_until_ready()
    fs[nm] = (f, s1)
times = {nm: [] for nm in names}
for r in range(rounds):
    for nm in names:
        f, s1 = fs[nm]
        t0 = time.perf_counter(); out = f(m, s1); out.x.block_until_ready(); times[nm].append((time.perf_counter() - t0) / N * 1e3)
for nm in names:
    f, s1 = fs[nm]; out = f(m, s1)
    print(nm, "refreshes in window", int(out.loads[3].refreshes) - int(s1.loads[3].refreshes))
    print(f"{nm:20s} min {min(times[nm]):.3f} median {statistics.median(times[nm]):.3f} ms/step  all {' '.join(f'{t:.2f}' for t in times[nm])}", flush=True)
