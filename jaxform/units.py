"""The unit system of jaxform and the conversions from the source paper's units.

jaxform is SI everywhere: m, kg, s, N, Pa. Derived quantities:

==========================  ======  =============================================
quantity                    unit    note
==========================  ======  =============================================
bending moment per width M  N       (= N·m/m)
curvature kappa             1/m     positive when the fibre bends away from the ply normal
bending stiffness B         N·m     B = dM/dkappa
normalised shear force      N/m     picture-frame force normalised per unit length
shear angle gamma           rad     initial minus current angle between the fibre families
areal mass                  kg/m²
==========================  ======  =============================================

The paper quotes mm, N·mm (bending stiffness), 1/mm (curvature) and g/m² (gsm). Those are
converted **once, at the edge** (presets, file readers, command-line options) with the
functions below; kernels never see paper units.
"""
from __future__ import annotations

# Length.
M = 1.0
MM = 1.0e-3
# Mass.
KG = 1.0
G = 1.0e-3
# Gravity used by the cantilever test and forming runs, m/s².
GRAVITY = 9.81


def mm_to_m(x):
    """Length in mm -> m."""
    return x * MM


def m_to_mm(x):
    """Length in m -> mm."""
    return x / MM


def per_mm_to_per_m(x):
    """Curvature in 1/mm -> 1/m."""
    return x / MM


def per_m_to_per_mm(x):
    """Curvature in 1/m -> 1/mm."""
    return x * MM


def n_mm_to_n_m(x):
    """Bending stiffness in N·mm (moment per width N over curvature 1/mm) -> N·m."""
    return x * MM


def n_m_to_n_mm(x):
    """Bending stiffness in N·m -> N·mm."""
    return x / MM


def gsm_to_kg_per_m2(x):
    """Areal mass in g/m² (gsm) -> kg/m²."""
    return x * G


def kg_per_m2_to_gsm(x):
    """Areal mass in kg/m² -> g/m²."""
    return x / G


def mpa_to_pa(x):
    """Modulus in MPa (N/mm²) -> Pa."""
    return x * 1.0e6


def gpa_to_pa(x):
    """Modulus in GPa -> Pa."""
    return x * 1.0e9
