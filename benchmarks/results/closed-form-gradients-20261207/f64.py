"""python f64.py OUT.npy: 3000 steps of woven Case A NLBM at 8 mm in float64"""
import sys, jax
jax.config.update("jax_enable_x64", True)
import numpy as np
import jaxform
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod
print(jaxform.__file__)
r = rigmod.build(cases.resolve("case-a-woven-nlbm", element_size=8e-3, overrides=("numerics.dtype=float64",)))
st = jax.jit(integrate.advance, static_argnums=2)(r.model, r.state, 3000)
print(st.x.dtype, float(st.t))
np.save(sys.argv[1], np.asarray(st.x))
