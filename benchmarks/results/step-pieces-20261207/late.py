"""A/B of the step at a late state (contacts active): ms/step with friction.backward_friction as shipped
and with its Newton loop unrolled (patched into jaxform.contact). python late.py SIZE STEPS_BEFORE"""
import sys, time, jax, numpy as np
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parent))
from jaxform import cases, integrate, contact
from jaxform import friction as Fr
from jaxform.forming import rig as rigmod
from friction_unrolled import unrolled
size, before = float(sys.argv[1]), int(sys.argv[2])
r = rigmod.build(cases.with_element_size(cases.load("case-a-woven-nlbm"), size * 1e-3))
m, s, info = r
adv = jax.jit(integrate.advance, static_argnums=2)
s = adv(m, s, before); s.x.block_until_ready()
print("at step", int(s.step), "t", float(s.t), "bad", int(s.bad_step), flush=True)
def timed(tag, reps=3, N=300):
    f = jax.jit(integrate.advance, static_argnums=2)
    out = f(m, s, N); out.x.block_until_ready()
    ts = []
    for _ in range(reps):
        t0 = time.perf_counter(); o = f(m, s, N); o.x.block_until_ready(); ts.append(1e3 * (time.perf_counter() - t0) / N)
    print(f"{tag:10s} " + " ".join(f"{t:.3f}" for t in ts) + " ms/step", flush=True)
    return np.asarray(o.x)
orig = contact.backward_friction
for rnd in range(2):
    contact.backward_friction = orig; Fr.backward_friction = orig
    xa = timed("while")
    contact.backward_friction = unrolled; Fr.backward_friction = unrolled
    xb = timed("unrolled")
print("identical", bool(np.array_equal(xa, xb)), float(np.abs(xa - xb).max()))
