"""Dispersion of the shell's out-of-plane bending on a free woven strip (2 mm elements): the
discrete omega^2(k) against the continuum B k^4 / rho_A, and what a Chebyshev mass filter on a
fixed bending operator of degree n would do to a 6-element wrinkle vs the mesh-scale mode."""
import json
import numpy as np, jax, jax.numpy as jnp
jax.config.update("jax_enable_x64", True)
from jaxform import materials
from jaxform.mesh import Mesh
from jaxform.shell import Shell, energy_parts
from jaxform.fibre_mass import chebyshev, _q, peak
from jaxform.materials import max_stiffness

h = 2e-3
nx, ny = 120, 4
fab = materials.preset("woven-38616")
mesh = Mesh.strip(nx * h, ny * h, nx, ny)
shell = Shell.build(mesh, fab)
X = jnp.asarray(mesh.nodes)
zf = lambda z: energy_parts(X.at[:, 2].set(z), shell)["bending"]
K = np.asarray(jax.hessian(zf)(jnp.zeros(len(X))))
m = np.asarray(shell.node_masses())
B = float(np.max(np.asarray(max_stiffness(fab.bending[0]))))
rho = float(np.max(np.asarray(fab.areal_mass)))
Mi = 1 / np.sqrt(m)
lam = np.linalg.eigvalsh(Mi[:, None] * K * Mi[None, :])
lmax = lam[-1]
x = np.asarray(mesh.nodes[:, 0])
# Rayleigh quotients of bending waves along x, uniform across the width, under a smooth (Hann)
# window over the strip's inner part (away from the free ends), summed over four phases: the
# discrete omega^2(k) of the plane wave, to the window's spread in k
a0, a1 = 5 * h, (nx - 5) * h
win = np.where((x > a0) & (x < a1), np.sin(np.pi * (x - a0) / (a1 - a0)) ** 2, 0.0)
rows = []
for nel in (2, 3, 4, 5, 6, 8, 10, 12):
    k = 2 * np.pi / (nel * h)
    num = den = 0.0
    for ph in np.arange(4) * np.pi / 4:
        z = win * np.cos(k * x + ph)
        num, den = num + z @ K @ z, den + z @ (m * z)
    w2 = float(num / den)
    rows.append({"wavelength_elements": nel, "omega2": w2, "omega2_continuum": B / rho * k**4,
                 "ratio_discrete_continuum": w2 / (B / rho * k**4), "y_over_max": w2 / lmax})
y6 = next(r["y_over_max"] for r in rows if r["wavelength_elements"] == 6)
filt = []
for n in range(2, 9):
    th, a, b, q0 = chebyshev(n)
    q6 = float(_q(np.array([y6]), n, th, a, b)[0]) / q0
    filt.append({"degree": n, "wrinkle6_frequency_ratio": float(np.sqrt(q6)), "mesh_mode_frequency_ratio": float(np.sqrt(peak(n)) / n)})
out = {"element_m": h, "B_Nm": B, "rho_A": rho, "lambda_max": float(lmax), "estimate_omega_b2": (8 * np.sqrt(B / rho) / (h / np.sqrt(2))**2)**2,
       "y_6_elements": y6, "waves": rows, "filter": filt}
print(json.dumps(out, indent=1))

# the largest bending eigenvalue of a square plate (both fibre families bend): is the strip's max the plate's?
pm = Mesh.grid(np.arange(41) * h, np.arange(41) * h)
ps = Shell.build(pm, fab)
PX = jnp.asarray(pm.nodes)
Kp = np.asarray(jax.hessian(lambda z: energy_parts(PX.at[:, 2].set(z), ps)["bending"])(jnp.zeros(len(PX))))
mp = np.asarray(ps.node_masses())
lp = float(np.linalg.eigvalsh(Kp / np.sqrt(mp)[:, None] / np.sqrt(mp)[None, :])[-1])
print(json.dumps({"plate_40x40_lambda_max": lp, "plate_over_strip": lp / float(lmax),
                  "estimate_over_plate_omega": float(np.sqrt(out["estimate_omega_b2"] / lp))}))
