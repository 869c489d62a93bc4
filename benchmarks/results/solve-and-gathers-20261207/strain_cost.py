"""The exact fibre strain's cost, in one process: the shell's forces on displacements (2 mm preset's rig, 200
evaluations in a scan) with the strain from the displacement parts (as shipped) and from |g| - 1 (the code
before), alternating, five rounds. python strain_cost.py"""
import time, jax, jax.numpy as jnp, numpy as np
import jaxform.shell as S
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod
m, s, info = rigmod.build(cases.with_element_size(cases.load("case-a-woven-nlbm"), 2e-3))
shell, mesh = m.shell, m.shell.mesh
u0 = jnp.asarray(np.random.default_rng(0).normal(size=(3, mesh.n_nodes)) * 1e-5, jnp.float32)


def forces(us, exact):
    e1, e2, D, base = S._kinematics(us, shell, True)
    if exact:
        parts, (g1, g2, gD) = S._local_gradients(e1, e2, D, shell, None, base)
    else:
        b = jnp.asarray(base, us.dtype)
        parts, (g1, g2, gD) = S._local_gradients(e1 + b[0], e2 + b[1], D, shell)
    return S.assemble_corners(jnp.concatenate([-(g1 + g2), g1, g2], axis=1), mesh) + jnp.sum(gD)


def many(u, exact):
    return jax.lax.scan(lambda c, _: (c + 1e-9 * forces(c, exact), None), u, None, length=200)[0]


fs = {k: jax.jit(lambda u, k=k: many(u, k), compiler_options=integrate.COMPILER_OPTIONS) for k in (True, False)}
for f in fs.values():
    f(u0).block_until_ready()
for r in range(5):
    for k, f in fs.items():
        t = time.perf_counter(); f(u0).block_until_ready()
        print(f"{'exact strain' if k else '|g| - 1     '}: {(time.perf_counter() - t) / 200 * 1e3:.3f} ms", flush=True)
