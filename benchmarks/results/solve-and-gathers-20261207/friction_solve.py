"""ms per call of friction.backward_friction (the code on PYTHONPATH) on N random nodes (half in contact), 100 calls in a scan, three times: python friction_solve.py N"""
import time, jax, jax.numpy as jnp, numpy as np
from jaxform import friction, integrate
N = int(__import__("sys").argv[1])
rng = np.random.default_rng(0)
m = jnp.asarray(rng.uniform(1e-5, 2e-5, N), jnp.float32)
p = jnp.asarray(rng.normal(size=(N, 3)) * 1e-6, jnp.float32)
fn = jnp.asarray(np.c_[np.zeros(N), np.zeros(N), rng.uniform(0, 1e-2, N) * (rng.uniform(size=N) < 0.5)], jnp.float32)
v = jnp.array([0, 0, -0.0625], jnp.float32)
def many(p):
    def body(c, _):
        f, pw = friction.backward_friction(c, m, 2e-6, fn, 0.2, 1e-4, v)
        return c + 1e-3 * f, None
    return jax.lax.scan(body, p, None, length=100)[0]
f = jax.jit(many, compiler_options=integrate.COMPILER_OPTIONS)
f(p).block_until_ready()
for _ in range(3):
    t = time.perf_counter(); f(p).block_until_ready(); print(f"{(time.perf_counter()-t)/100*1e3:.3f} ms per call", flush=True)
