"""friction.backward_friction with its Newton loop unrolled (a fixed FRICTION_ITERATIONS steps, no early stop),
for late.py; run alone: the two against each other on 15,625 random nodes."""
import time, jax, jax.numpy as jnp, numpy as np
from jaxform import friction as Fr
n = 15625
rng = np.random.default_rng(0)
p = jnp.asarray(rng.normal(size=(n, 3)) * 1e-6, jnp.float32)
mass = jnp.full((n,), 2e-6, jnp.float32)
fn = np.zeros((n, 3), np.float32); on = rng.random(n) < 0.3; fn[on, 2] = 1e-3 * rng.random(on.sum())
fn = jnp.asarray(fn)
h = jnp.float32(6e-6)

def unrolled(*args, **kwargs):
    """friction.backward_friction with its while_loop run as FRICTION_ITERATIONS plain steps (at trace time)."""
    real = jax.lax.while_loop

    def steps(cond, body, init):
        c = init
        for _ in range(Fr.FRICTION_ITERATIONS):
            c = body(c)
        return c

    jax.lax.while_loop = steps
    try:
        return Fr.backward_friction(*args, **kwargs)
    finally:
        jax.lax.while_loop = real


if __name__ == "__main__":
    args = lambda sc: (p, mass, h, fn * sc, 0.23, 6.25e-4, jnp.zeros(3, jnp.float32))
    f0 = jax.jit(Fr.backward_friction); f1 = jax.jit(unrolled)
    for sc in (0.0, 1.0, 4.0):
        a0, a1 = f0(*args(sc)), f1(*args(sc))
        print("scale", sc, "identical", bool(np.array_equal(np.asarray(a0[0]), np.asarray(a1[0])) and np.array_equal(np.asarray(a0[1]), np.asarray(a1[1]))),
              "max diff", float(np.abs(np.asarray(a0[0]) - np.asarray(a1[0])).max()))
    for sc in (0.0, 1.0):
        for name, f in (("while", f0), ("unrolled", f1)):
            f(*args(sc))[0].block_until_ready()
            t0 = time.perf_counter()
            for _ in range(300): o = f(*args(sc))
            o[0].block_until_ready(); print(f"scale {sc} {name:9s} {1e3*(time.perf_counter()-t0)/300:.3f} ms")
