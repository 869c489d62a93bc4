"""Newton steps of backward_friction in woven Case A (SIZE mm, state after each K), with the start and stop of the code on PYTHONPATH (the old code: max(u* - a, 0), exact fixed point). python friction_count.py SIZE K1,K2"""
import sys, jax, jax.numpy as jnp
from jaxform import cases, integrate, friction
from jaxform.geometry import safe_norm, safe_normalize
from jaxform.forming import rig as rigmod
orig = friction.backward_friction
start = getattr(friction, "_slip_from_below", lambda us, a, eps: jnp.maximum(us - a, 0.0))
rt = getattr(friction, "FRICTION_RTOL", 0.0)
def counting(p, mass, h, f_normal, mu, eps_v, velocity):
    ps, fs = p.T, jnp.asarray(f_normal, p.dtype).T
    fn = safe_norm(fs, axis=0); n = safe_normalize(fs, axis=0); m = jnp.asarray(mass, p.dtype)
    q = ps - m * jnp.asarray(velocity, p.dtype)[:, None]; qt = q - jnp.sum(q * n, axis=0) * n
    us = safe_norm(qt, axis=0) / m; a = h * mu * fn / m; eps = jnp.asarray(eps_v, p.dtype)
    def newton(c):
        i, u, _ = c
        r = jnp.sqrt(u * u + eps * eps)
        un = jnp.clip(u - (u + a * u / r - us) / (1.0 + a * eps * eps / (r * r * r)), 0.0, us)
        return i + 1, un, jnp.any(jnp.abs(un - u) > rt * jnp.finfo(p.dtype).eps * un)
    i, u, _ = jax.lax.while_loop(lambda c: (c[0] < 12) & c[2], newton, (0, start(us, a, eps), jnp.asarray(True)))
    jax.debug.print("iters {i} contacts {k} max a/eps {x} u*/a in contact: min {lo} max {hi}", i=i, k=jnp.sum(a > 0), x=jnp.max(a / eps),
                    lo=jnp.min(jnp.where(a > 0, us / jnp.where(a > 0, a, 1), jnp.inf)), hi=jnp.max(jnp.where(a > 0, us / jnp.where(a > 0, a, 1), 0)))
    return orig(p, mass, h, f_normal, mu, eps_v, velocity)
size = float(sys.argv[1])
m, s, info = rigmod.build(cases.with_element_size(cases.load("case-a-woven-nlbm"), size * 1e-3))
adv = jax.jit(integrate.advance, static_argnums=2, compiler_options=integrate.COMPILER_OPTIONS)
import jaxform.contact
for k in [int(a) for a in sys.argv[2].split(",")]:
    s = adv(m, s, k); s.x.block_until_ready()
    print("t", float(s.t), flush=True)
    friction.backward_friction = counting; jaxform.contact.backward_friction = counting
    f = jax.jit(lambda mm, ss: integrate.run_steps(mm, ss, 2)[0], compiler_options=integrate.COMPILER_OPTIONS)
    f(m, s).x.block_until_ready()
    friction.backward_friction = orig; jaxform.contact.backward_friction = orig
