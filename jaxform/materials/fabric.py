"""Fabric descriptions and the source paper's two fabrics as presets (SPEC section 3, Table 1).

A :class:`Fabric` holds everything the shell needs about one ply's material: thickness, areal mass,
the in-plane angles of its two fibre families, the fibre tension modulus, the shear law, one bending
law per fibre family (``None`` for a membrane-only model) and the friction coefficients. Paper units
are converted here, once, with :mod:`jaxform.units`.

Angles are measured in the ply plane from the blank's x axis, which is aligned with the
blank-holder edge: the woven warp lies along x (families at 0° and 90°); the NCF's fibres lie at
+45° and -45° with the stitch along x (0°), so a positive shear (fibre angle closing around the
stitch direction) stretches the stitch.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from jaxform import units, validate
from jaxform._pytree import as_leaf, is_concrete, pytree_dataclass, static_field
from jaxform.materials.bending import AsymmetricBending, LinearBending, VoceBending
from jaxform.materials.shear import PolynomialShear, ncf_shear


@pytree_dataclass
class Fabric:
    """One ply's material.

    Attributes:
        thickness: ply thickness ``h``, m.
        areal_mass: mass per unit area, kg/m².
        fibre_modulus: tension modulus along each fibre family, Pa (scalar, or (2,) per family);
            the tension stiffness of a family is ``fibre_modulus * thickness`` (N/m).
        shear: shear law, normalised force ``F_norm(gamma)`` in N/m.
        bending: ``(law_1, law_2)`` bending law of each fibre family, or ``None`` for the
            membrane-only model (no bending resistance).
        friction_tool: Coulomb coefficient fabric–tool (-).
        friction_fabric: Coulomb coefficient fabric–fabric (-).
        name: static label (preset name, or the user's).
        fibre_angles: static ``(theta_1, theta_2)`` in-plane angles of the families, rad.
        stitch_angle: static angle of the stitch, rad, or ``None`` (woven).
        measured_b41_5: static ``(pos, neg)`` bending stiffness from the standard cantilever test
            (BS EN ISO 9073-7, 41.5°), N·m, if known; used by :func:`lbm_variant`.
    """

    thickness: Any
    areal_mass: Any
    fibre_modulus: Any
    shear: Any
    bending: Any
    friction_tool: Any = 0.23
    friction_fabric: Any = 0.36
    name: str = static_field(default="custom")
    fibre_angles: tuple = static_field(default=(0.0, 0.5 * math.pi))
    stitch_angle: float | None = static_field(default=None)
    measured_b41_5: tuple | None = static_field(default=None)

    def __post_init__(self):
        owner = f"Fabric({self.name!r})"
        if is_concrete(self.thickness, self.areal_mass, self.fibre_modulus, self.friction_tool, self.friction_fabric):
            validate.positive(owner, "thickness", self.thickness, "m")
            validate.positive(owner, "areal_mass", self.areal_mass, "kg/m²")
            validate.positive(owner, "fibre_modulus", self.fibre_modulus, "Pa")
            validate.nonnegative(owner, "friction_tool", self.friction_tool)
            validate.nonnegative(owner, "friction_fabric", self.friction_fabric)
            if np.asarray(self.thickness).ndim == 0 and float(self.thickness) > 0.02:
                raise ValueError(
                    f"{owner}.thickness = {self.thickness!r} m: thicker than 20 mm; jaxform is SI "
                    "(did you give millimetres? use jaxform.units.mm_to_m)"
                )
            for name in ("thickness", "areal_mass", "fibre_modulus", "friction_tool", "friction_fabric"):
                object.__setattr__(self, name, as_leaf(getattr(self, name)))
        angles = tuple(float(a) for a in self.fibre_angles)
        if len(angles) != 2 or not all(math.isfinite(a) for a in angles):
            raise ValueError(f"{owner}.fibre_angles = {self.fibre_angles!r}: need two finite angles in rad")
        if abs(math.sin(angles[1] - angles[0])) < 1e-3:
            raise ValueError(
                f"{owner}.fibre_angles = {self.fibre_angles!r} rad: the two fibre families are parallel; "
                "a biaxial fabric needs two distinct directions"
            )
        object.__setattr__(self, "fibre_angles", angles)
        if self.bending is not None:
            laws = tuple(self.bending) if isinstance(self.bending, (tuple, list)) else None
            if laws is None or len(laws) != 2 or not all(hasattr(b, "moment") for b in laws):
                raise ValueError(
                    f"{owner}.bending = {self.bending!r}: must be None (membrane only) or a pair of "
                    "bending laws, one per fibre family"
                )
            object.__setattr__(self, "bending", laws)
        if not hasattr(self.shear, "force"):
            raise ValueError(f"{owner}.shear = {self.shear!r}: must be a shear law (jaxform.materials.shear)")

    @property
    def membrane_only(self) -> bool:
        """True when the fabric has no bending resistance."""
        return self.bending is None

    @property
    def tension_stiffness(self):
        """Fibre tension stiffness per unit width, ``E * h`` in N/m."""
        return self.fibre_modulus * self.thickness

    def replace(self, **changes) -> "Fabric":
        """A copy with some fields changed (validated again)."""
        return dataclasses.replace(self, **changes)


# ---------------------------------------------------------------------------------------------
# Presets (source paper, Table 1), converted from the paper's units here and nowhere else.
# ---------------------------------------------------------------------------------------------

FIBRE_MODULUS = units.gpa_to_pa(3.0)  # both fabrics, limits fibre strain below 1%


def _voce_from_paper(b_inf_n_mm: float, m0_n: float, kappa0_per_mm: float) -> VoceBending:
    """The paper prints M in N with kappa in 1/mm: ``b_inf`` in N·mm, ``kappa0`` in 1/mm."""
    return VoceBending(
        b_inf=units.n_mm_to_n_m(b_inf_n_mm), m0=m0_n, kappa0=units.per_mm_to_per_m(kappa0_per_mm)
    )


_WOVEN_BENDING = _voce_from_paper(0.01549, 0.00757, 0.02)

WOVEN_38616 = Fabric(
    name="woven-38616",
    thickness=units.mm_to_m(0.3),
    areal_mass=units.gsm_to_kg_per_m2(210.0),
    fibre_modulus=FIBRE_MODULUS,
    shear=PolynomialShear([37.35, -322.61, 1458.51, -3539.56, 4727.84, -3275.20, 930.53]),
    bending=(_WOVEN_BENDING, _WOVEN_BENDING),  # balanced twill: warp and weft alike
    friction_tool=0.23,
    friction_fabric=0.36,
    fibre_angles=(0.0, 0.5 * math.pi),  # warp along the blank-holder edge
    stitch_angle=None,
    measured_b41_5=(2.2e-4, 2.2e-4),
)
"""Carr Reinforcements 38616 balanced twill weave, 0.3 mm, 210 g/m², 0°/90° (Table 1)."""

# Table 1 labels both NCF lines "pos"; the second is the negative side (SPEC section 3).
_NCF_BENDING = AsymmetricBending(
    pos=_voce_from_paper(0.19457, 0.03139, 0.0040),
    neg=_voce_from_paper(0.10279, 0.03619, 0.0065),
)

NCF_FCIM359 = Fabric(
    name="ncf-fcim359",
    thickness=units.mm_to_m(0.4),
    areal_mass=units.gsm_to_kg_per_m2(440.0),
    fibre_modulus=FIBRE_MODULUS,
    shear=ncf_shear(
        yarn_coeffs=[112.19, 94.73, 137.06, -65.56, 29.56],
        # 2000 g - 120 on [0.06, 0.5), -3520 g + 2640 on [0.5, 0.75): a hat through these knots.
        stitch_gamma_knots=[0.06, 0.5, 0.75],
        stitch_force_knots=[0.0, 880.0, 0.0],
    ),
    bending=(_NCF_BENDING, _NCF_BENDING),
    friction_tool=0.23,
    friction_fabric=0.36,
    fibre_angles=(0.25 * math.pi, -0.25 * math.pi),  # ±45°, stitch along x
    stitch_angle=0.0,
    measured_b41_5=(3.8e-3, 3.2e-3),
)
"""Hexcel FCIM359 pillar-stitched biaxial NCF, 0.4 mm, 440 g/m², ±45°, stitch 0° (Table 1)."""

PRESETS: dict[str, Fabric] = {f.name: f for f in (WOVEN_38616, NCF_FCIM359)}

# Table 1's LBM constants as printed (N·m), for checks and reports: (pos, neg).
TABLE1_LBM: dict[str, dict[str, tuple[float, float]]] = {
    "woven-38616": {"init": (3.9e-4, 3.9e-4), "41.5": (2.2e-4, 2.2e-4), "inf": (2e-5, 2e-5)},
    "ncf-fcim359": {"init": (8.0e-3, 5.7e-3), "41.5": (3.8e-3, 3.2e-3), "inf": (2e-4, 1e-4)},
}


def preset(name: str) -> Fabric:
    """The preset fabric called ``name`` (see ``PRESETS``)."""
    try:
        return PRESETS[name]
    except KeyError:
        known = ", ".join(sorted(PRESETS))
        raise ValueError(f"unknown fabric preset {name!r}: known presets are {known}") from None


# ---------------------------------------------------------------------------------------------
# Variants used by the paper: LBM with B_init, B_41.5 or B_inf, and membrane only.
# ---------------------------------------------------------------------------------------------

LBM_VARIANTS = ("init", "41.5", "inf")


def _pos_neg(law) -> tuple[Any, Any]:
    return (law.pos, law.neg) if isinstance(law, AsymmetricBending) else (law, law)


def _linear_pair(b_pos, b_neg):
    if is_concrete(b_pos, b_neg) and np.all(np.asarray(b_pos) == np.asarray(b_neg)):
        return LinearBending(b_pos)
    return AsymmetricBending(LinearBending(b_pos), LinearBending(b_neg))


def lbm_variant(fabric: Fabric, which: str) -> Fabric:
    """The fabric with a linear bending model (LBM) of constant stiffness.

    Args:
        fabric: a fabric with a bending law per family.
        which: ``"init"`` (stiffness at zero curvature of the fabric's law), ``"inf"`` (its
            asymptotic stiffness) or ``"41.5"`` (the standard cantilever test's measured value,
            ``fabric.measured_b41_5``). Positive and negative sides are kept apart.
    """
    if which not in LBM_VARIANTS:
        raise ValueError(f"lbm_variant: which = {which!r}: must be one of {', '.join(LBM_VARIANTS)}")
    if fabric.bending is None:
        raise ValueError(f"lbm_variant: fabric {fabric.name!r} is membrane-only; it has no bending law to linearise")
    if which == "41.5":
        if fabric.measured_b41_5 is None:
            raise ValueError(
                f"lbm_variant: fabric {fabric.name!r} has no measured_b41_5; set it "
                "(fabric.replace(measured_b41_5=(pos, neg))) to use the 41.5° variant"
            )
        pos, neg = fabric.measured_b41_5
        laws = tuple(_linear_pair(pos, neg) for _ in fabric.bending)
    else:
        laws = []
        for law in fabric.bending:
            p, n = _pos_neg(law)
            laws.append(_linear_pair(getattr(p, f"b_{which}"), getattr(n, f"b_{which}")))
        laws = tuple(laws)
    return fabric.replace(bending=laws, name=f"{fabric.name}-lbm-{which}")


def membrane_only(fabric: Fabric) -> Fabric:
    """The fabric without bending resistance (the paper's membrane-element model)."""
    return fabric.replace(bending=None, name=f"{fabric.name}-membrane")


__all__ = [
    "Fabric",
    "WOVEN_38616",
    "NCF_FCIM359",
    "PRESETS",
    "TABLE1_LBM",
    "LBM_VARIANTS",
    "preset",
    "lbm_variant",
    "membrane_only",
    "FIBRE_MODULUS",
]
