"""ms/step of the 2 mm woven preset: a plain jax.jit of integrate.advance (no compiler options) against the
forming driver's _advance_jit, side by side in one process, three rounds: python ab.py 2"""
import sys, time, jax, jax.numpy as jnp
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod, driver
size = float(sys.argv[1])
r = rigmod.build(cases.with_element_size(cases.load("case-a-woven-nlbm"), size * 1e-3))
m, s, info = r
e0, xr = s.energies, s.x
floor = jnp.asarray(1e-3, s.x.dtype)
adv = jax.jit(integrate.advance, static_argnums=2)
s = adv(m, s, 500); s.x.block_until_ready()
N = 300
def t_static(s):
    t0 = time.perf_counter(); s2 = adv(m, s, N); s2.x.block_until_ready(); return 1e3*(time.perf_counter()-t0)/N
def t_driver(s):
    t0 = time.perf_counter(); s2 = driver._advance_jit(m, s, e0, xr, jnp.asarray(N, jnp.int32), floor); s2.x.block_until_ready(); return 1e3*(time.perf_counter()-t0)/N
t_static(s); t_driver(s)
for k in range(3):
    print(f"static n, defaults: {t_static(s):.3f}   driver's: {t_driver(s):.3f} ms/step", flush=True)
