import time, sys, jax, jax.numpy as jnp, meshio, numpy as np
from jaxform import cases
from jaxform.forming import rig as rigmod
name, size, frame_file, out = sys.argv[1], float(sys.argv[2]), sys.argv[3], sys.argv[4]
case = cases.with_element_size(cases.load(name), size * 1e-3)
m, s, info = rigmod.build(case)
ld = m.loads[3]
x = jnp.asarray(meshio.read(frame_file).points, jnp.float32)
f = jax.jit(lambda l, x: l.search(x))
c = jax.block_until_ready(f(ld, x))
ts = []
for _ in range(3):
    t0 = time.perf_counter(); jax.block_until_ready(f(ld, x)); ts.append(time.perf_counter() - t0)
print(name, size, "search", f"{min(ts):.3f} s", "active nodes", int((c.active_nodes >= 0).sum()), "edges", int((c.active_edges >= 0).sum()), "overflow", bool(c.overflow))
np.savez(out, nodes=np.asarray(c.nodes), edges=np.asarray(c.edges), an=np.asarray(c.active_nodes), ae=np.asarray(c.active_edges), ov=np.asarray(c.overflow))
