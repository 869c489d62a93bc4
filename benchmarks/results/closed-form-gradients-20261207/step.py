"""ms a step of `integrate.advance` for a preset as shipped at SIZE mm, after STEPS steps from the flat start,
and its positions saved: python step.py SIZE STEPS PRESET OUT.npy
(run with PYTHONPATH=<a worktree> from outside the repository to time another commit's code)"""
import sys, time, jax, jaxform
import numpy as np
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod
print(jaxform.__file__)
size, steps, preset = float(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
r = rigmod.build(cases.with_element_size(cases.load(preset), size * 1e-3))
adv = jax.jit(integrate.advance, static_argnums=2)
st = adv(r.model, r.state, steps); st.x.block_until_ready()
t0 = time.perf_counter(); st2 = adv(r.model, st, steps); st2.x.block_until_ready()
print(f"{preset} {size} mm: {1e3 * (time.perf_counter() - t0) / steps:.3f} ms/step", flush=True)
np.save(sys.argv[4], np.asarray(st2.x))
