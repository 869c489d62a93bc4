"""The time step each fibre-mass factor gives and what governs it (the shell or the contact). Run: python dts.py PRESET SIZE_MM FACTOR... ."""
import sys
from jaxform import forming, cases
name, mm = sys.argv[1], float(sys.argv[2])
for s in sys.argv[3:]:
    c = cases.apply_overrides(cases.with_element_size(cases.load(name), mm * 1e-3), [f"numerics.fibre_mass_scaling={s}"])
    model, state, info = forming.build(c)
    fm = model.fibre_mass
    print(s, "dt", info.dt, "stable", info.stable_dt, "steps", info.n_steps, "deg", None if fm is None else fm.degree, info.numerics.governed_by, info.numerics.why, flush=True)
