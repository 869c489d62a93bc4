"""jaxform: differentiable explicit forming simulation of engineering fabrics in JAX.

Public names only; see the README for a tour. SI units everywhere (``jaxform.units``).
"""
from jaxform import materials, units
from jaxform.materials import NCF_FCIM359, WOVEN_38616, Fabric

__version__ = "0.1.0"

__all__ = ["materials", "units", "Fabric", "WOVEN_38616", "NCF_FCIM359", "__version__"]
