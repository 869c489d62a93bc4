import time, jax, jax.numpy as jnp, meshio
from jaxform import cases, broadphase
from jaxform.forming import rig as rigmod
case = cases.with_element_size(cases.load("case-a-woven-nlbm"), 2e-3)
m, s, info = rigmod.build(case)
ld = m.loads[3]
x = jnp.asarray(meshio.read("/tmp/q/woven-2mm/frames_00006.vtu").points, jnp.float32)
def nodes_only(l, x):
    tri_x = x[l.triangles]
    ids, _ = broadphase.candidates(x, tri_x, l.k, l.gap0 + l.skin, mask=l.plausible, refine=l.allowed, fallback=l.fallback, cap=l.cap)
    return ids
def nodes_edges(l, x):
    ids = nodes_only(l, x)
    return l.edge_candidates(x, ids)
for name, fn in (("whole search", lambda l, x: l.search(x)), ("node candidates", nodes_only), ("node + edge candidates", nodes_edges)):
    f = jax.jit(fn)
    jax.block_until_ready(f(ld, x))
    ts = []
    for _ in range(3):
        t0 = time.perf_counter(); jax.block_until_ready(f(ld, x)); ts.append(time.perf_counter() - t0)
    print(f"{name:25s} {min(ts):.3f} s", flush=True)
