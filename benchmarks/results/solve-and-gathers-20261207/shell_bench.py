"""ms per shell force evaluation (forces_and_energy_sym on displacements) of the 2 mm preset's rig, 200 in a scan."""
import time, jax, jax.numpy as jnp, numpy as np
from jaxform import cases, integrate
from jaxform.shell import forces_and_energy_sym
from jaxform.forming import rig as rigmod
m, s, info = rigmod.build(cases.with_element_size(cases.load("case-a-woven-nlbm"), 2e-3))
mesh = m.shell.mesh
print("N", mesh.n_nodes, "K", np.shape(mesh.nbr_k)[0], "M", np.shape(getattr(mesh, "nbr_t", np.zeros((0,))))[0], flush=True)
u0 = jnp.asarray(np.random.default_rng(0).normal(size=(3, mesh.n_nodes)) * 1e-5, jnp.float32)
def many(u):
    def body(c, _):
        f, parts = forces_and_energy_sym(c, m.shell)
        return c + 1e-9 * f, None
    return jax.lax.scan(body, u, None, length=200)[0]
f = jax.jit(many, compiler_options=integrate.COMPILER_OPTIONS)
f(u0).block_until_ready()
ts = []
for _ in range(5):
    t = time.perf_counter(); f(u0).block_until_ready(); ts.append((time.perf_counter() - t) / 200 * 1e3)
print(" ".join(f"{t:.3f}" for t in ts), "ms per evaluation", flush=True)
