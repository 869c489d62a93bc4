"""Material laws of engineering fabrics (source paper section 2, Table 1), SI units.

Bending per fibre family (moment per unit width against curvature), in-plane shear (normalised
force against shear angle), the laminate conversion of appendix A, and the :class:`Fabric`
description with the paper's two fabrics as presets.
"""
from jaxform.materials.bending import AsymmetricBending, BendingLaw, LinearBending, VoceBending, max_stiffness
from jaxform.materials.fabric import (
    FIBRE_MODULUS,
    LBM_VARIANTS,
    NCF_FCIM359,
    PRESETS,
    TABLE1_LBM,
    WOVEN_38616,
    Fabric,
    lbm_variant,
    membrane_only,
    preset,
)
from jaxform.materials.laminate import laminate_moduli, ply_properties
from jaxform.materials.shear import CompositeShear, PiecewiseLinearShear, PolynomialShear, ShearLaw, ncf_shear

__all__ = [
    "LinearBending",
    "VoceBending",
    "AsymmetricBending",
    "BendingLaw",
    "max_stiffness",
    "PolynomialShear",
    "PiecewiseLinearShear",
    "CompositeShear",
    "ShearLaw",
    "ncf_shear",
    "laminate_moduli",
    "ply_properties",
    "Fabric",
    "WOVEN_38616",
    "NCF_FCIM359",
    "PRESETS",
    "TABLE1_LBM",
    "LBM_VARIANTS",
    "FIBRE_MODULUS",
    "preset",
    "lbm_variant",
    "membrane_only",
]
