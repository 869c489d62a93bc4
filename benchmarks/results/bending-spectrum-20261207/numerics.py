"""The presets' automatic numerics (step, steps, what governs the step, contact, fibre mass) with the jaxform first on sys.path."""
import jaxform
from jaxform import cases, forming
print(jaxform.__file__)
for name, size in [("case-a-woven-nlbm", 8), ("case-a-woven-nlbm", 4), ("case-a-woven-nlbm", 2), ("case-a-woven-lbm-inf", 4), ("case-a-woven-membrane", 4), ("case-a-ncf-nlbm", 8), ("case-a-ncf-nlbm", 4), ("case-a-ncf-nlbm", 2), ("case-b-woven-nlbm", 2), ("case-b-ncf-nlbm", 2)]:
    case = cases.with_element_size(cases.load(name), size * 1e-3)
    model, state, info = forming.build(case)
    n = info.numerics
    print(f"{name:24s} {size} dt {float(info.dt):.4e} steps {info.n_steps} {n.governed_by} implicit={n.implicit_normal} safety={n.safety:.3g} fm={None if model.fibre_mass is None else (model.fibre_mass.factor, model.fibre_mass.degree)}", flush=True)
