"""ms of the pieces this record changed, at 2 mm (woven Case A NLBM as shipped), each jitted alone, 300 reps:
(1) the shell's element gradients at a perturbed state, reverse mode through the densities against the closed
forms (jaxform.shell._local_gradients' parts), and the shell's forces, three rounds; (2) each load of the step,
and each tool's distance with its normal (tools.sdf_soa) and without (phi_local alone).
Run from the repository root: python parts.py"""
import time, jax, jax.numpy as jnp, numpy as np
from jaxform import cases, tools as T
from jaxform.forming import rig as rigmod
from jaxform import shell as S
r = rigmod.build(cases.with_element_size(cases.load("case-a-woven-nlbm"), 2e-3))
m, st, sh = r.model, r.state, r.model.shell
us = st.u + 1e-4 * jnp.asarray(np.random.default_rng(0).normal(size=st.u.shape), st.u.dtype)
e1, e2, D = jax.jit(lambda u: S._kinematics(u, sh, True))(us)
fab, Tn, N = sh.fabrics[0], e1.shape[1], D.shape[2]


def bench(name, fn, *args, reps=300):
    f = jax.jit(fn); jax.block_until_ready(f(*args))
    t0 = time.perf_counter()
    for _ in range(reps): out = f(*args)
    jax.block_until_ready(out)
    print(f"{name:40s} {1e3 * (time.perf_counter() - t0) / reps:.3f} ms", flush=True)


for _ in range(3):
    bench("membrane: grad of the density", lambda a, b: jax.grad(lambda a, b: sum(jnp.sum(x) for x in S._membrane_density(a, b, sh, 0, Tn, fab)), argnums=(0, 1))(a, b), e1, e2)
    bench("membrane: closed form", lambda a, b: S._membrane_gradient(a, b, sh, 0, Tn, fab, 1.0, 1.0), e1, e2)
    bench("bending: grad of the density", lambda c: jax.grad(lambda c: jnp.sum(S._bending_density(c, sh, 0, N, fab)))(c), D)
    bench("bending: closed form", lambda c: S._bending_gradient(c, sh, 0, N, fab, 1.0), D)
    bench("shell forces (as shipped)", lambda u: S.forces_and_energy_soa(u, sh, displacement=True)[0], us)
xs = st.x.T
for i, (ld, ls) in enumerate(zip(m.loads, st.loads)):
    bench(f"load {i} {type(ld).__name__}", lambda x, v, ls, ld=ld: ld.force(x, v, st.t, ls)[0], st.x, st.v, ls)
    tool = getattr(ld, "tool", None)
    if tool is not None:
        bench(f"  sdf_soa {type(tool).__name__}", lambda p, tool=tool: T.sdf_soa(tool, p, 0.0), xs)
        bench(f"  phi only {type(tool).__name__}", lambda p, tool=tool: jax.vmap(tool.phi_local, in_axes=1)(p), xs)
