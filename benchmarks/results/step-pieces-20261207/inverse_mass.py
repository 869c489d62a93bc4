"""The fibre mass's inverse at 2 mm (woven Case A), alone, in variants: python inverse_mass.py 2. Run at e28544b,
where 'current' was the springs' product with indexed adds (`.at[].add`); 'pad' is what ca9b347 ships."""
import sys, time, jax, jax.numpy as jnp, numpy as np
from jaxform import cases
from jaxform import fibre_mass as F
from jaxform.forming import rig as rigmod
size = float(sys.argv[1])
r = rigmod.build(cases.with_element_size(cases.load("case-a-woven-nlbm"), size * 1e-3))
m, s, info = r
fm, shell = m.fibre_mass, m.shell
print("degree", fm.degree, "strides", fm.strides, "N", s.x.shape)
xs = s.x.T + 1e-4 * jax.random.normal(jax.random.PRNGKey(0), s.x.T.shape)
ps = jax.random.normal(jax.random.PRNGKey(1), xs.shape)
free = jnp.where(m.fixed.T, 0.0, 1.0).astype(xs.dtype)
mass = m.mass

@jax.jit
def current(xs, ps):
    return F.inverse_mass_times(ps, F.fibre_units(xs, fm, shell), mass, free, fm, shell)

def stiff_pad(ps, wus, units):
    out = 0.0
    for d, wu, u in zip(fm.strides, wus, units):
        q = F._dot(u, ps[:, d:] - ps[:, :-d]) * wu
        out = out + jnp.pad(q, ((0, 0), (d, 0))) - jnp.pad(q, ((0, 0), (0, d)))
    return out

def make(unroll):
    @jax.jit
    def v(xs, ps):
        units = F.fibre_units(xs, fm, shell)
        wus = tuple(w.astype(xs.dtype) * u for w, u in zip(fm.springs, units))
        n = fm.degree
        theta, a, b, q0 = F.chebyshev(n)
        fm_ = free / mass[None, :].astype(ps.dtype)
        r = fm_ * ps
        a, b = jnp.asarray(a, ps.dtype), jnp.asarray(b, ps.dtype)
        def it(k, c):
            z, r, d = c
            r = r - fm_ * stiff_pad(d, wus, units)
            return z + d, r, a[k] * d + b[k] * r
        z, _, d = jax.lax.fori_loop(0, n - 1, it, (jnp.zeros_like(r), r, r / theta), unroll=unroll)
        return (z + d) / q0
    return v

fns = {"current": current, "pad": make(1), "pad unroll 2": make(2), "pad unrolled": make(True)}
ref = np.asarray(current(xs, ps))
for k, f in fns.items():
    o = np.asarray(f(xs, ps)); print(k, "max rel diff", float(np.max(np.abs(o - ref)) / np.max(np.abs(ref))))
for rnd in range(3):
    for k, f in fns.items():
        f(xs, ps).block_until_ready()
        t0 = time.perf_counter()
        for _ in range(200): o = f(xs, ps)
        o.block_until_ready()
        print(f"{k:16s} {1e3*(time.perf_counter()-t0)/200:.3f} ms", flush=True)
