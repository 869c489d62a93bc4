"""ms per step of a forming run split into the full step, the shell forces, the tool and ply loads, and the fibre mass (its whole inverse and one product with the fibre-tension stiffness), each jitted alone in a lax.scan of n steps, best of 3. Run: python split.py PRESET SIZE_MM N (nothing else running)."""
import sys, time, json
import jax, jax.numpy as jnp
from jaxform import forming, cases
from jaxform import fibre_mass as _fm
from jaxform.shell import forces_and_energy_sym

name, mm = sys.argv[1], float(sys.argv[2])
n = int(sys.argv[3]) if len(sys.argv) > 3 else 50
c = cases.with_element_size(cases.load(name), mm * 1e-3)
model, state, info = forming.build(c)
print("nodes", len(info.x0), "tris", model.shell.mesh.tris.shape if hasattr(model.shell.mesh,'tris') else None, "steps", info.n_steps, "dt", info.dt,
      "fm", None if model.fibre_mass is None else (model.fibre_mass.degree, model.fibre_mass.factor, model.fibre_mass.geometric), flush=True)

def best(f, *a):
    jax.block_until_ready(f(*a)); t = []
    for _ in range(3):
        t0 = time.perf_counter(); jax.block_until_ready(f(*a)); t.append(time.perf_counter() - t0)
    return 1e3 * min(t) / n

def scan(body, c0):
    return jax.lax.scan(lambda c, _: (body(c), None), c0, None, length=n)[0]

full = best(jax.jit(lambda m, s: forming.run_steps(m, s, s.energies, s.x, n=n).x), model, state)
sh = best(jax.jit(lambda m, u: scan(lambda u: u + 1e-12 * forces_and_energy_sym(u, m.shell)[0], u)), model, state.u)
def loads(m, s):
    def body(c):
        x, v = c
        tot = jnp.zeros_like(x)
        for ld, ls in zip(m.loads, s.loads):
            tot = tot + ld.force(x, v, s.t, ls)[0]
        return (x + 1e-12 * tot, v + 1e-9 * tot)
    return scan(body, (s.x, s.v))
co = best(jax.jit(loads), model, state)
res = {"full": full, "shell": sh, "loads": co}
fm = model.fibre_mass
if fm is not None:
    free = jnp.where(model.fixed.T, 0.0, 1.0).astype(state.u.dtype)
    def inv(m, s):
        return scan(lambda p: p + 1e-12 * _fm.inverse_mass_times(p, _fm.fibre_units(s.x.T, m.shell), m.mass, free, m.fibre_mass, m.shell), s.momentum)
    res["inverse_mass"] = best(jax.jit(inv), model, state)
    def one(m, s):
        units = _fm.fibre_units(s.x.T, m.shell)
        return scan(lambda p: p + 1e-12 * _fm.stiffness_times(p, units, m.fibre_mass, m.shell), s.momentum)
    res["one_product"] = best(jax.jit(one), model, state)
    res["degree"] = fm.degree
print(json.dumps({k: round(v, 3) if isinstance(v, float) else v for k, v in res.items()}), flush=True)
