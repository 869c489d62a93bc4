"""The largest eigenvalue of C K_shell (C the inverse mass with the rig's fibre mass) by power
iteration at the flat blank, against the step estimate the rig used (jaxform.shell.stable_time_step):
how conservative the shell's part of the step is, per preset and element size."""
import json, sys
import numpy as np, jax, jax.numpy as jnp
jax.config.update("jax_enable_x64", True)
from jaxform import cases, forming
from jaxform import fibre_mass as fm_
from jaxform.shell import forces_and_energy_soa

out = []
for name, size in [(a, float(b)) for a, b in (s.split(":") for s in sys.argv[1:])]:
    case = cases.with_element_size(cases.load(name), size * 1e-3)
    case = cases.apply_overrides(case, ['numerics.dtype="float64"'])
    model, state, info = forming.build(case)
    shell, fm = model.shell, model.fibre_mass
    x0 = jnp.asarray(shell.mesh.nodes).T
    u0 = jnp.zeros_like(x0)
    free = jnp.ones_like(x0)
    mass = model.mass

    @jax.jit
    def ck(v):
        kv = -jax.jvp(lambda u: forces_and_energy_soa(u, shell, displacement=True)[0], (u0,), (v,))[1]
        if fm is None:
            return kv / mass[None, :]
        return fm_.inverse_mass_times(kv, fm_.fibre_units(x0, shell), mass, free, fm, shell)

    v = jnp.asarray(np.random.default_rng(0).normal(size=x0.shape))
    lam = []
    for i in range(400):
        w = ck(v)
        lam.append(float(jnp.vdot(v, w) / jnp.vdot(v, v)))
        v = w / jnp.linalg.norm(w)
    exact = 2.0 / np.sqrt(lam[-1])
    out.append({"case": name, "element_mm": size, "dt_used_s": float(info.dt), "lambda_max": lam[-1],
                "lambda_at_200": lam[199], "dt_exact_linear_s": float(exact),
                "fibre_mass_degree": None if fm is None else int(fm.degree)})
    print(json.dumps(out[-1]), flush=True)
