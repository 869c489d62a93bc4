"""Counts the YNNPACK fusions in the 8 mm woven step program: python ynn_count.py none "" (no option; the option empty)."""
import jax, sys
from jaxform import cases, integrate
from jaxform.forming import rig as rigmod
m, s, info = rigmod.build(cases.with_element_size(cases.load("case-a-woven-nlbm"), 8e-3))
for v in sys.argv[1:]:
    opts = None if v == "none" else {"xla_cpu_experimental_ynn_fusion_type": v}
    hlo = jax.jit(integrate.advance, static_argnums=2, compiler_options=opts).lower(m, s, 10).compile().as_text()
    print(repr(v), "ynn fusions:", len([l for l in hlo.splitlines() if "ynn_fusion" in l and "fusion(" in l]), flush=True)
