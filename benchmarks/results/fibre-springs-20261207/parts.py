"""ms of the parts of a 2 mm woven Case A NLBM step as shipped (each jitted alone, 200 reps; the whole step over 500),
then the pieces of the shell force (edges, fibre-curvature stencil, local gradients, assembly) at a perturbed
state. Run: python parts.py"""
import time, jax, jax.numpy as jnp, numpy as np
from jaxform import cases, integrate, fibre_mass as F
from jaxform.forming import rig as rigmod
from jaxform.shell import forces_and_energy_soa
from jaxform import shell as S
from jaxform.mesh import assemble_corners
case = cases.with_element_size(cases.load("case-a-woven-nlbm"), 2e-3)
r = rigmod.build(case); m, st = r.model, r.state
def bench(name, fn, *args, reps=200):
    f = jax.jit(fn); jax.block_until_ready(f(*args))
    t0 = time.perf_counter()
    for _ in range(reps): out = f(*args)
    jax.block_until_ready(out)
    print(f"{name:28s} {1e3*(time.perf_counter()-t0)/reps:.3f} ms", flush=True)
us = st.u
bench("shell forces", lambda u: forces_and_energy_soa(u, m.shell, displacement=True)[0], us)
free = jnp.ones_like(us)
bench("inverse mass (13)", lambda p, x: F.inverse_mass_times(p, F.fibre_units(x, m.fibre_mass, m.shell), m.mass, free, m.fibre_mass, m.shell), us, st.x.T)
for i, (ld, ls) in enumerate(zip(m.loads, st.loads)):
    bench(f"load {i} {type(ld).__name__}", lambda x, v, ls, ld=ld: ld.force(x, v, st.t, ls)[0], st.x, st.v, ls)
adv = jax.jit(integrate.advance)
adv(m, st, 1).x.block_until_ready()
t0 = time.perf_counter(); e = adv(m, st, 500); e.x.block_until_ready(); print("whole step", 1e3*(time.perf_counter()-t0)/500, "ms")
for w in [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]:
    bench(f"shell weights {w}", lambda u, w=w: forces_and_energy_soa(u, m.shell, weights=w, displacement=True)[0], us)
# the shell's pieces
sh, mesh = m.shell, m.shell.mesh
us = st.u + 1e-4 * jnp.asarray(np.random.default_rng(0).normal(size=st.u.shape), st.u.dtype)
bench("edges", lambda u: S._edges(u, mesh, sh.ref.edge0), us)
bench("derivs", lambda u: S._derivs_soa(u, mesh, sh.ref.deriv0), us)
e1, e2, D = jax.jit(lambda u: S._kinematics(u, sh, True))(us)
bench("grad local (all)", lambda e1, e2, D: jax.grad(lambda a, b, c: S._local_energy(a, b, c, sh)[0], argnums=(0,1,2))(e1, e2, D), e1, e2, D)
bench("grad membrane only", lambda e1, e2: jax.grad(lambda a, b: sum(jnp.sum(x) for x in S._membrane_density(a, b, sh, 0, e1.shape[1], sh.fabrics[0])), argnums=(0,1))(e1, e2), e1, e2)
bench("grad bending only", lambda D: jax.grad(lambda c: jnp.sum(S._bending_density(c, sh, 0, D.shape[2], sh.fabrics[0])))(D), D)
g = jnp.concatenate([e1, e1, e2], axis=1)
bench("assemble corners", lambda g: assemble_corners(g, mesh), g)
H = jax.jit(lambda D: S._derivs_transpose(D, mesh))(D)
bench("derivs transpose", lambda D: S._derivs_transpose(D, mesh), D)
bench("bending scatter", lambda H, u: jnp.zeros_like(u).at[:, mesh.nbr_k.reshape(-1)].add(H.reshape(3, -1)) - jnp.sum(H, axis=1), H, us)
print("D shape", D.shape, "H", H.shape, "nbr_k", mesh.nbr_k.shape)
