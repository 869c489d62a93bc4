"""Material laws from Python: the paper's fabrics, a custom fabric, and a gradient.

    python examples/material_laws.py

Builds a custom Voce law from the paper's printed units, compares it with the woven preset,
and shows the sensitivity of the moment at a chosen curvature to each Voce parameter.
"""
import jax

from jaxform import units
from jaxform.materials import WOVEN_38616, Fabric, PolynomialShear, VoceBending, lbm_variant


def main() -> None:
    # A law quoted as in the paper: M = 0.02 κ + 0.006 (1 - exp(-κ/0.025)) with κ in 1/mm.
    mine = VoceBending(
        b_inf=units.n_mm_to_n_m(0.02), m0=0.006, kappa0=units.per_mm_to_per_m(0.025)
    )
    fabric = Fabric(
        name="my-twill",
        thickness=units.mm_to_m(0.35),
        areal_mass=units.gsm_to_kg_per_m2(240.0),
        fibre_modulus=units.gpa_to_pa(3.0),
        shear=PolynomialShear([40.0, -300.0, 1400.0]),
        bending=(mine, mine),
    )
    preset = WOVEN_38616.bending[0]
    print(f"{'curvature (1/m)':>16} {'M preset (N)':>14} {'M mine (N)':>12}")
    for k in (1.0, 10.0, 50.0, 200.0):
        print(f"{k:16.1f} {float(preset.moment(k)):14.4e} {float(mine.moment(k)):12.4e}")
    print(f"B_init: preset {float(preset.b_init):.3e} N·m, mine {float(mine.b_init):.3e} N·m")
    g = jax.grad(lambda law: law.moment(50.0))(mine)
    print(f"dM(50/m)/d b_inf = {float(g.b_inf):.3g} 1/m, /d m0 = {float(g.m0):.3g}, /d kappa0 = {float(g.kappa0):.3g} N·m")
    print("LBM with B_init:", lbm_variant(fabric, "init").bending[0])


if __name__ == "__main__":
    main()
