import time, sys, jax, jax.numpy as jnp, meshio
from jaxform import cases
from jaxform.forming import rig as rigmod
size = float(sys.argv[1])
case = cases.with_element_size(cases.load("case-a-woven-nlbm"), size * 1e-3)
m, s, info = rigmod.build(case)
ld = m.loads[3]
print("skin", float(ld.skin), "h", float(ld.gap0), "k", ld.k, "edges", ld.edges.shape, "edge_near", ld.edge_near.shape)
x = jnp.asarray(meshio.read(f"{sys.argv[2]}/frames_{int(sys.argv[3]):05d}.vtu").points, jnp.float32)
f = jax.jit(lambda l, x: l.search(x))
jax.block_until_ready(f(ld, x))
for _ in range(3):
    t0 = time.perf_counter(); jax.block_until_ready(f(ld, x)); print("search", time.perf_counter() - t0)
